"""`gcalign calibrate`: in-flight calibration of an airborne SINS (seed 002).

The room's interface for the registry (:mod:`gcalign.app.registry`); each function imports
its module when called, so tables and figures never load the numerical kernels.
"""

from __future__ import annotations

from gcalign.app.registry import Outcome

UNIT_TEXT = {"arcsec": "″", "arcmin": "′", "deg/h": "°/h", "ug": "µg", "ppm": "ppm",
             "m/s": "m/s", "m": "m"}
"""Printed symbols of the display units (:data:`gcalign.estimation.ins_error.DISPLAY_UNITS`)."""


def execute(sc, seed: int | None = None, cache_key: str | None = None, **options) -> Outcome:
    from gcalign.app.calibrate.run import execute as run

    return run(sc, seed, cache_key, **options)


def table(summary: dict):
    from gcalign.app.calibrate.tables import calibrate_table

    return calibrate_table(summary)


def figures(f, name: str) -> dict:
    from gcalign.app.calibrate.plots import figures

    return figures(f, name)


def components(metric: str, k: int) -> list[str]:
    """Names of a batch metric's components: 21-vectors are the states."""
    from gcalign.estimation.ins_error import STATE_NAMES

    if k == len(STATE_NAMES):
        return list(STATE_NAMES)
    return [str(i) for i in range(k)]


WARM_SCENARIO = {  # a tiny flight: every kernel of a calibration, in milliseconds
    "name": "warm-up",
    "site": {"lat_deg": 38.0, "lon_deg": 121.0},
    "imu": {"rate_hz": 20},
    "motion": {"kind": "flight", "segments": [
        {"kind": "hold", "duration_s": 1}, {"kind": "accelerate", "accel_mps2": 2,
                                            "speed_mps": 4}]},
    "calibrate": {"navigation_rate_hz": 10, "filter_rate_hz": 1},
}


def warm_up() -> None:
    """Run a tiny calibration so that every kernel is loaded in this process."""
    import copy

    from gcalign.io.scenario import parse_scenario

    execute(parse_scenario(copy.deepcopy(WARM_SCENARIO), "warm-up"), 1)
