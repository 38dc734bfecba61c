"""Typed series and their synchronisation onto a common grid (timetable)."""
