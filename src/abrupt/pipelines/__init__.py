"""Orchestration of each capability (read, series, clean, model, detect, thresholds, events, catalog); no click."""
