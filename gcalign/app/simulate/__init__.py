"""`gcalign simulate`: truth and IMU data of a scenario.

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None, progress=None,
            **options) -> Outcome:
    from gcalign.app.simulate.run import execute as run

    return run(sc, seed, cache_key, progress=progress, **options)


def table(summary: dict):
    from gcalign.app.simulate.tables import simulate_table

    return simulate_table(summary)


def figures(f, name: str) -> dict:
    """The truth and the IMU output (the shared figures of :mod:`gcalign.app.plots`)."""
    from gcalign.app.plots import truth_and_imu

    return truth_and_imu(f, name)
