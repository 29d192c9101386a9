"""Pipelines: a scenario in, plain result objects out (no printing, no files).

Imports go one way: cli -> pipelines -> core.
"""
