"""One seeded run of the simulator: the drive, the IMU, the GNSS and the start both
programs are given, in memory (:func:`simulate`) or as files (:func:`write`).

Randomness: one ``numpy.random.SeedSequence(seed)`` spawns five independent streams (the
start's errors, the sensor processes, the IMU's white noise, the GNSS σ, the GNSS noise),
so the same seed gives the same numbers and changing one part leaves the others' draws
alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from benchmarks.vehicle import earth, gnss, imu, route
from benchmarks.vehicle.trajectory import Site, State, Trajectory

ROUTES = {"standard": route.standard, "short": route.short, "hour": route.hour}


@dataclass(frozen=True)
class Config:
    """What a run simulates (defaults: the benchmark's 30 min drive).

    route : ``standard`` (30 min) or ``short`` (6 min)
    seed : the run's seed
    imu_rate_hz, imu_offset_s : the IMU rate and its first stamp after the route's start
        (the IMU's stamps fall between GNSS seconds, as a real logger's do)
    sow0, week : GNSS seconds of week and week of the route's start
    lever_frd : the GNSS antenna from the IMU, body forward, right, down (m)
    errors : the IMU's noise and sensor processes (KF-GINS's units)
    init_pos_std, init_vel_std, init_att_std : σ of the start given to both programs
        (north, east, down m; m/s; roll, pitch, yaw deg); its errors are drawn from them
    outage_marks : the manoeuvres (route marks) each GNSS outage is centred on (None: every
        U-turn of the route)
    outage_s : each outage's length, from the last fix to the next (s)
    duration_s : simulate only the drive's first seconds (None: all of it); outages that
        do not end inside are left out
    """

    route: str = "standard"
    seed: int = 1
    site: Site = Site()
    imu_rate_hz: float = 200.0
    imu_offset_s: float = 0.002
    sow0: float = 358200.0
    week: int = 2345
    lever_frd: tuple = (0.5, -0.3, -1.0)
    errors: imu.ImuErrors = imu.ImuErrors()
    init_pos_std: tuple = (0.1, 0.1, 0.2)
    init_vel_std: tuple = (0.02, 0.02, 0.02)
    init_att_std: tuple = (0.01, 0.01, 0.1)
    outage_marks: tuple | None = None
    outage_s: float = 60.0
    duration_s: float | None = None


@dataclass(frozen=True)
class Start:
    """The start given to both programs at the first IMU stamp: lat, lon (rad), h (m),
    v_ned (3,) m/s, euler (3,) roll, pitch, yaw (rad); and its drawn errors (NED m, m/s,
    the misalignment φ rad with C_b^n(given) = (I − [φ×]) C_b^n(true))."""

    lat: float
    lon: float
    h: float
    v_ned: np.ndarray
    euler: np.ndarray
    dpos_ned: np.ndarray
    dvel_ned: np.ndarray
    phi: np.ndarray


@dataclass(frozen=True)
class Dataset:
    """A run in memory. t (N+1,) s from the route's start: the IMU stamps (row k's
    increments cover (t[k] − Δt, t[k]]); dtheta, dv (N+1, 3) measured, ideal_dtheta,
    ideal_dv without errors; sensors: the errors drawn per sample; truth: the state at
    every stamp; fixes; start."""

    config: Config
    trajectory: Trajectory
    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    ideal_dtheta: np.ndarray
    ideal_dv: np.ndarray
    sensors: imu.SensorTruth
    truth: State
    fixes: gnss.Fixes
    start: Start
    notes: dict = field(default_factory=dict)

    @property
    def dt(self) -> float:
        return 1.0 / self.config.imu_rate_hz

    def sow(self, t):
        """GNSS seconds of week of times `t` s from the route's start."""
        return self.config.sow0 + np.asarray(t, float)


def _stamps(cfg: Config, duration: float) -> np.ndarray:
    """IMU stamps from the offset to the end, rounded to the µs they are written with."""
    dt = 1.0 / cfg.imu_rate_hz
    n = int(np.floor((duration - cfg.imu_offset_s) / dt + 1e-9))
    return np.round(cfg.imu_offset_s + dt * np.arange(n + 1), 6)


def _start(cfg: Config, truth: State, rng: np.random.Generator) -> Start:
    dpos = rng.standard_normal(3) * np.asarray(cfg.init_pos_std)
    dvel = rng.standard_normal(3) * np.asarray(cfg.init_vel_std)
    phi = rng.standard_normal(3) * np.radians(cfg.init_att_std)
    lat, lon, h = truth.lat[0], truth.lon[0], truth.h[0]
    r_m, r_n = earth.radii(lat)
    a = np.linalg.norm(phi)
    K = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]])
    # C_given = exp(−[φ×]) C_true: to first order (I − [φ×]) C_true, as KF-GINS's φ-angle
    R = np.eye(3) - np.sin(a) / a * K + (1 - np.cos(a)) / a**2 * K @ K
    C = R @ truth.C_nb[0]
    euler = np.array([np.arctan2(C[2, 1], C[2, 2]), -np.arcsin(C[2, 0]),
                      np.arctan2(C[1, 0], C[0, 0])])
    return Start(float(lat + dpos[0] / (r_m + h)), float(lon + dpos[1] / ((r_n + h) * np.cos(lat))),
                 float(h - dpos[2]), truth.v_ned[0] + dvel, euler, dpos, dvel, phi)


def simulate(cfg: Config = Config(), increments: bool = True) -> Dataset:
    """The drive, its IMU data with errors, the GNSS fixes and the start (module
    docstring). `increments` False: all but the IMU's increments (left empty), which take
    most of the time; the truth, the sensor errors, the fixes and the start are the same
    numbers (enough to score a solution of the files written before)."""
    traj = Trajectory(ROUTES[cfg.route](), cfg.site)
    ss = np.random.SeedSequence(cfg.seed).spawn(5)
    rng_start, rng_proc, rng_noise, rng_sigma, rng_gnss = (np.random.default_rng(s) for s in ss)
    end = traj.duration if cfg.duration_s is None else min(cfg.duration_s, traj.duration)
    t = _stamps(cfg, end)
    dt = 1.0 / cfg.imu_rate_hz
    if increments:
        th, dv = imu.ideal_increments(traj, np.concatenate([[t[0] - dt], t]))
        th_m, dv_m, sensors = imu.measured(th, dv, dt, cfg.errors, rng_proc, rng_noise)
    else:
        th = dv = th_m = dv_m = np.empty((0, 3))
        sensors = imu.sensor_processes(len(t), dt, cfg.errors, rng_proc)
    truth = traj.state(t)
    marks = {m[0]: 0.5 * (m[1] + m[2]) for m in traj.route.marks}
    names = ([m for m in marks if m.startswith("U-turn")] if cfg.outage_marks is None
             else cfg.outage_marks)
    windows = [w for w in gnss.outage_windows([marks[m] for m in names],
                                              cfg.outage_s) if w[1] <= end]
    fixes = gnss.fixes(traj, cfg.lever_frd, windows, rng_sigma, rng_gnss, end=end)
    start = _start(cfg, truth, rng_start)
    return Dataset(cfg, traj, t, th_m, dv_m, th, dv, sensors, truth, fixes, start,
                   notes={"marks": traj.route.marks})
