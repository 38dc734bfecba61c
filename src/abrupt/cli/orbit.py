"""Command-line commands for this capability (registered on the shared groups)."""
