"""`gcalign navigate`: strapdown navigation of simulated or recorded data.

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None, progress=None,
            **options) -> Outcome:
    from gcalign.app.navigate.run import execute as run

    return run(sc, seed, cache_key, progress=progress, **options)


def table(summary: dict):
    from gcalign.app.navigate.tables import navigate_table

    return navigate_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.navigate.plots import figures

    return figures(f, name)
