"""The ``abrupt`` command line: one entry point, one sub-command per capability."""
