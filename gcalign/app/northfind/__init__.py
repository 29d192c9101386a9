"""`gcalign northfind`: multi-position north-finding with tilt compensation (seed 001).

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    from gcalign.app.northfind.run import execute as run

    return run(sc, seed, cache_key)


def table(summary: dict):
    from gcalign.app.northfind.tables import northfind_table

    return northfind_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.northfind.plots import figures

    return figures(f, name)
