"""`gcalign observability`: the PWCS/SVD observability table of a flight (seed 002 §4).

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    from gcalign.app.observability.run import execute as run

    return run(sc, seed, cache_key)


def table(summary: dict):
    from gcalign.app.observability.tables import observability_table

    return observability_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.observability.plots import figures

    return figures(f, name)


def components(metric: str, k: int) -> list[str]:
    from gcalign.app.calibrate import components as state_components

    return state_components(metric, k)


def warm_up() -> None:
    from gcalign.app.calibrate import warm_up as calibrate_warm_up

    calibrate_warm_up()
