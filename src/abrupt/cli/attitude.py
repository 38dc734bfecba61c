"""Command-line commands for attitude telemetry (registered on the shared groups)."""
