"""Orchestration of each capability (no click inside): read, clean, model, detect, threshold, record."""
