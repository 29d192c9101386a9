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


WARM_SCENARIO = {  # a tiny align scenario: every align kernel, in milliseconds
    "name": "warm-up",
    "site": {"lat_deg": 45.0, "lon_deg": 126.0},
    "imu": {"gyro": {"bias_dph": [0.01, 0.01, 0.01]}, "accel": {"bias_ug": [50, 50, 50]}},
    "motion": {"kind": "moving", "attitude_deg": [0, 0, 30], "duration_s": 3,
               "segments": [{"duration_s": 1}, {"duration_s": 2, "accel_mps2": 0.5}]},
    "align": {"t1_s": 1, "t2_s": 2, "t3_s": 2.5, "passes": 3, "level_s": 0.1,
              "aiding": {"source": "odometer"}},
}


def warm_up() -> None:
    """Run a tiny alignment so that every align kernel is loaded in this process."""
    import copy

    from gcalign.io.scenario import parse_scenario

    execute(parse_scenario(copy.deepcopy(WARM_SCENARIO), "warm-up"), 1)
