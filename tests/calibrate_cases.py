"""Flights for the calibration tests (spec 002 §3), from the core's ``flight`` motion.

* :func:`designed` -- ``configs/seed002_designed.yaml``: the 21-stage 590 s take-off, IMU at
  100 Hz, navigation at 25 Hz (4 increments per step), as ``gcalign calibrate`` runs it;
  the conventional take-off is its first 6 segments (:func:`conventional`).
* :func:`short` -- the same manoeuvres in 162 s, simulated at 25 Hz (Monte Carlo runs).

Simulations are cached per session: every test corrupts the same noise-free data.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from gcalign.calibrate import flight_from_ideal, motion_spans, white_noise
from gcalign.io.scenario import load_scenario, parse_scenario
from gcalign.sim.errors import ImuErrors

ROOT = Path(__file__).resolve().parents[1]
DESIGNED = ROOT / "configs" / "seed002_designed.yaml"
TS = 0.04  #: navigation step (s), the seed's 25 Hz

SHORT = {
    "name": "short",
    "site": {"lat_deg": 38.0, "lon_deg": 121.0},
    "imu": {"rate_hz": 25},
    "motion": {"kind": "flight", "segments": [
        {"kind": "hold", "duration_s": 30, "name": "static"},
        {"kind": "accelerate", "accel_mps2": 6.5, "speed_mps": 90, "name": "ground roll"},
        {"kind": "pitch", "rate_dps": 2, "angle_deg": 20, "name": "pitch-up"},
        {"kind": "hold", "duration_s": 20, "name": "climb"},
        {"kind": "pitch", "rate_dps": 2, "angle_deg": 0, "name": "level-off"},
        {"kind": "roll", "rate_dps": 5, "angle_deg": -45, "name": "roll left"},
        {"kind": "hold", "duration_s": 10, "name": "bank hold"},
        {"kind": "roll", "rate_dps": 5, "angle_deg": 0, "name": "roll right"},
        {"kind": "turn", "rate_dps": 9, "angle_deg": -90, "name": "turn right"},
        {"kind": "hold", "duration_s": 10, "name": "turn hold"},
        {"kind": "turn", "rate_dps": 9, "angle_deg": 90, "name": "turn left"},
        {"kind": "hold", "duration_s": 10, "name": "cruise"},
    ]},
}


@lru_cache(maxsize=4)
def scenario(which: str = "designed"):
    if which == "designed":
        return load_scenario(DESIGNED)[0]
    # "short" at 25 Hz, "short100" at 100 Hz (both navigated at the IMU rate)
    return parse_scenario({**SHORT, "imu": {"rate_hz": 100 if which == "short100" else 25}},
                          which)


@lru_cache(maxsize=4)
def _raw(which: str):
    """(scenario, noise-free RunData, spans, subsamples) of a flight."""
    from gcalign.app.data import noise_free

    sc = scenario(which)
    raw = noise_free(sc)
    spans = motion_spans(sc.motion.to_motion(), float(raw.truth.t[-1]))
    n = sc.calibrate.subsamples(sc.imu.rate_hz) if sc.calibrate else 1
    return sc, raw, spans, n


def site(which: str = "designed") -> np.ndarray:
    return scenario(which).site.to_si()


def flight(which: str = "designed", x_true=None, noise: bool = False, seed: int = 0,
           errors: ImuErrors | None = None):
    """FlightData of a flight with the errors `x_true` (default none), white noise at the
    filter's Q densities when `noise`, and the truth's manoeuvres."""
    from gcalign.estimation import ins_error as ie

    sc, raw, spans, n = _raw(which)
    x = np.zeros(21) if x_true is None else np.asarray(x_true, float)
    base = errors or (white_noise(ie.ARW_DEFAULT, ie.VRW_DEFAULT) if noise else ImuErrors())
    return flight_from_ideal(raw.truth, raw.imu, x, base, np.random.default_rng(seed), spans,
                             n, sc.earth_model)


def designed(x_true=None, noise: bool = False, seed: int = 0):
    return flight("designed", x_true, noise, seed)


def conventional(x_true=None, noise: bool = False, seed: int = 0):
    """The first 6 segments of the designed flight (seed §5.2), the same data."""
    d = designed(x_true, noise, seed)
    return d.between(0.0, d.segments[5].end)


def short(x_true=None, noise: bool = False, seed: int = 0, rate: int = 25):
    return flight("short" if rate == 25 else "short100", x_true, noise, seed)


def ideal(which: str = "designed"):
    """(Truth, ImuData) of the flight at the IMU rate, noise-free."""
    raw = _raw(which)[1]
    return raw.truth, raw.imu


def motion(which: str = "designed"):
    return scenario(which).motion.to_motion()


def tiny_flight(**calibrate) -> dict:
    """A 30-second flight scenario (hold, ground roll, a 90° turn, cruise) at 25 Hz, for
    command-line and health checks that need a flight but not its statistics."""
    return {
        "name": "short-flight", "site": {"lat_deg": 38.0, "lon_deg": 121.0},
        "imu": {"rate_hz": 25, "seed": 2},
        "motion": {"kind": "flight", "segments": [
            {"kind": "hold", "duration_s": 10, "name": "static"},
            {"kind": "accelerate", "accel_mps2": 6.5, "speed_mps": 40, "name": "ground roll"},
            {"kind": "turn", "rate_dps": 9, "angle_deg": -90, "name": "turn"},
            {"kind": "hold", "duration_s": 5, "name": "cruise"}]},
        "calibrate": {"navigation_rate_hz": 25, **calibrate},
    }
