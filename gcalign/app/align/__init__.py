"""`gcalign align`: gyrocompass alignment with forward/reverse passes (seed 000).

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome


def execute(sc, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    from gcalign.app.align.run import execute as run

    return run(sc, seed, cache_key)


def table(summary: dict):
    from gcalign.app.align.tables import align_table

    return align_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.align.plots import figures

    return figures(f, name)


def components(metric: str, k: int) -> list[str]:
    """Names of a batch metric's components: attitude triples are pitch, roll, yaw."""
    if k == 3 and metric.endswith("_deg"):
        return ["pitch", "roll", "yaw"]
    return [str(i) for i in range(k)]


def label(metric: str) -> str:
    """A metric's name in tables and figures: one component of an attitude triple by its
    name (``error_t3_deg.2`` -> ``error_t3_deg yaw``)."""
    head, _, tail = metric.rpartition(".")
    if head.endswith("_deg") and tail in ("0", "1", "2"):
        return f"{head} {components(head, 3)[int(tail)]}"
    return metric
