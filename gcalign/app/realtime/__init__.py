"""`gcalign realtime`: attitude at external sync pulses, filter delay and prediction
(seed 003).

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load scipy or the numba kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    from gcalign.app.realtime.run import execute as run

    return run(sc, seed, cache_key)


def table(summary: dict):
    from gcalign.app.realtime.tables import realtime_table

    return realtime_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.realtime.plots import figures

    return figures(f, name)
