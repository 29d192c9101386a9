"""A simulated land vehicle with GNSS fixes at their own epochs, for the aided-navigation
tests: gcalign's own simulation of a turning, stopping vehicle (truth and IMU), and fixes
of an antenna at a lever arm taken between IMU samples, each with its own σ and noise
drawn from it, with outages cut out."""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import numpy as np

from gcalign.app.data import noise_free
from gcalign.calibrate import Settings, flight_from_ideal, motion_spans
from gcalign.calibrate.fixes import Fixes
from gcalign.estimation import ins_error as ie
from gcalign.io.scenario import parse_scenario
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm
from gcalign.units import DPH, PPM, UG

LEVER = np.array([0.3, 0.8, 1.0])  #: antenna: right, forward, up of the IMU (m)
SEGMENTS = [
    {"kind": "hold", "duration_s": 20, "name": "parked"},
    {"kind": "accelerate", "accel_mps2": 1.5, "speed_mps": 15, "name": "away"},
    {"kind": "turn", "rate_dps": 10, "angle_deg": 90, "name": "left 90"},
    {"kind": "hold", "duration_s": 20, "name": "straight"},
    {"kind": "turn", "rate_dps": 12, "angle_deg": -90, "name": "right 90"},
    {"kind": "accelerate", "accel_mps2": -1.0, "speed_mps": 8, "name": "slow"},
    {"kind": "turn", "rate_dps": 15, "angle_deg": 180, "name": "U-turn"},
    {"kind": "accelerate", "accel_mps2": 1.0, "speed_mps": 12, "name": "faster"},
    {"kind": "turn", "rate_dps": 8, "angle_deg": 360, "name": "circle"},
    {"kind": "accelerate", "accel_mps2": -1.5, "speed_mps": 0, "name": "stop"},
    {"kind": "hold", "duration_s": 10, "name": "stopped"},
    {"kind": "accelerate", "accel_mps2": 1.0, "speed_mps": 10, "name": "again"},
    {"kind": "turn", "rate_dps": 10, "angle_deg": -270, "name": "right 270"},
    {"kind": "hold", "duration_s": 30, "name": "straight 2"},
    {"kind": "turn", "rate_dps": 5, "angle_deg": 180, "name": "slow left 180"},
    {"kind": "hold", "duration_s": 40, "name": "straight 3"},
]
#: a tactical-grade IMU (KF-GINS's A15-like numbers, in gcalign's keys)
GYRO = {"arw_dprh": 0.003, "bias_gm": {"std_dph": 1.0, "tau_s": 600.0}}
ACCEL = {"vrw_ugrhz": 30.0, "bias_gm": {"std_ug": 200.0, "tau_s": 600.0}}


def scenario(rate: float = 100.0):
    motion = {"kind": "flight", "attitude_deg": [0, 0, 30], "segments": SEGMENTS}
    return parse_scenario({"name": "vehicle", "site": {"lat_deg": 30.5, "lon_deg": 114.3,
                                                       "height_m": 20},
                           "imu": {"rate_hz": rate, "gyro": GYRO, "accel": ACCEL},
                           "motion": motion})


@lru_cache(maxsize=1)
def _raw():
    return noise_free(scenario())


def p0_sigma() -> np.ndarray:
    """The filter's initial σ (21,), SI: the start's errors and the processes' std."""
    sc = scenario()
    g, a = sc.imu.errors().gyro, sc.imu.errors().accel
    s = np.concatenate([[0.05 * np.pi / 180] * 2 + [0.5 * np.pi / 180], [0.1] * 3,
                        [1.0 / 6.4e6] * 2 + [1.0], g.bias_gm_std, a.bias_gm_std,
                        [100 * PPM] * 6])
    return s


def processes() -> ie.SensorProcesses:
    """The filter's model of the simulated sensors (the same processes)."""
    sc = scenario()
    g, a = sc.imu.errors().gyro, sc.imu.errors().accel
    std = np.concatenate([g.bias_gm_std, a.bias_gm_std, np.full(6, 100 * PPM)])
    tau = np.concatenate([g.bias_gm_tau, a.bias_gm_tau, np.full(6, np.inf)])
    kinds = ["gauss-markov"] * 6 + ["constant"] * 6
    return ie.SensorProcesses.of(kinds, std, tau, np.zeros(12))


def settings(**kw) -> Settings:
    sc = scenario()
    g, a = sc.imu.errors().gyro, sc.imu.errors().accel
    base = dict(measure="position", components="3d", p0_scale=1.0,
                p0_sigma=tuple(p0_sigma()), arw=float(g.noise[0]), vrw=float(a.noise[0]),
                filter_rate=1.0, gnss_noise=False, processes=processes())
    base.update(kw)
    return Settings(**base)


def vehicle(seed: int, duration: float | None = None, offset: float = 0.373,
            outages: tuple[tuple[float, float], ...] = ((150.0, 210.0),),
            sigma_range: tuple[float, float] = (0.05, 0.5)):
    """``(FlightData with fixes, Fixes, x_true)``: the vehicle with its sensor errors drawn
    with `seed` (initial errors from the filter's P0, processes from the IMU model), 1 Hz
    fixes `offset` s after each whole second of run time, their σ varying slowly between
    `sigma_range`, minus the fixes inside `outages`; the first `duration` s (default all
    of the 295.5 s)."""
    raw = _raw()
    sc = scenario()
    rng = np.random.default_rng([seed, 7])
    x_true = np.zeros(21)
    x_true[:9] = p0_sigma()[:9] * rng.standard_normal(9)
    x_true[ie.DKG] = x_true[ie.DKA] = 0.0
    x_true[15:21] = 100 * PPM * rng.standard_normal(6)
    data = flight_from_ideal(raw.truth, raw.imu, x_true, sc.imu.errors(),
                             np.random.default_rng(seed),
                             motion_spans(sc.motion.to_motion(), float(raw.truth.t[-1])))
    if duration is not None:
        data = data.between(0.0, duration)
    fixes = gnss(data, rng, offset, outages, sigma_range)
    return replace(data, fixes=fixes, ref_v_n=None, ref_pos=None), fixes, x_true


def gnss(data, rng: np.random.Generator, offset: float,
         outages: tuple[tuple[float, float], ...], sigma_range: tuple[float, float]) -> Fixes:
    """The antenna's fixes at ``k + offset`` s from the truth of `data` (interpolated between
    its samples), with σ east, north, up from a slow sine between `sigma_range` (up 1.5×)
    and noise drawn from it."""
    tr = data.truth
    t = np.arange(np.ceil(tr.t[0]), tr.t[-1] - 1.0) + offset
    for a, b in outages:
        t = t[(t < a) | (t > b)]
    pos = np.column_stack([np.interp(t, tr.t, tr.pos[:, i]) for i in range(3)])
    C = euler_to_dcm(tr.att[np.searchsorted(tr.t, t)])
    enu = C @ LEVER  # the antenna's offset, metres east, north, up
    r_m, r_n = WGS84.radii(pos[:, 0])
    lo, hi = sigma_range
    s = lo + (hi - lo) * 0.5 * (1 + np.sin(2 * np.pi * t / 97.0))
    sigma = np.column_stack([s, s, 1.5 * s])
    e = enu + sigma * rng.standard_normal((len(t), 3))
    pos = pos + np.column_stack([e[:, 1] / (r_m + pos[:, 2]),
                                 e[:, 0] / ((r_n + pos[:, 2]) * np.cos(pos[:, 0])), e[:, 2]])
    return Fixes(t=t, pos=pos, sigma_pos=sigma, lever_arm_p_b=LEVER)


__all__ = ["DPH", "GYRO", "LEVER", "UG", "gnss", "processes", "scenario", "settings",
           "vehicle"]
