"""Pipelines: the orchestration of one capability, read → series → clean → model → detect → events.

One module per capability (``attitude``, ``tracking``, ...), with no click inside: the command line
(:mod:`abrupt.cli`) parses options, calls a pipeline and writes its outputs, and the Python API calls
the same functions.
"""
