"""`gcalign modulate`: navigation on a turning IMU, several rotation schemes on the same data
(seed 004).

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None, **options) -> Outcome:
    from gcalign.app.modulate.run import execute as run

    return run(sc, seed, cache_key, **options)


def table(summary: dict):
    from gcalign.app.modulate.tables import modulate_table

    return modulate_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.modulate.plots import figures

    return figures(f, name)
