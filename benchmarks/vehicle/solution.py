"""A navigation solution held against the simulator's truth: readers of KF-GINS's outputs
and of the i2nav-nav layout, and the figures of the aided-navigation table.

Errors are solution minus truth: position in NED metres (ΔL (R_M + h), Δλ (R_N + h) cos L,
−Δh), velocity NED, attitude as roll, pitch and yaw differences (yaw wrapped to ±180°).
Sensor estimates are held in units of the program's own final σ. NEES: at each GNSS epoch
outside the outages, Σ (δp_i / σ_i)² over north, east and down with the σ the program
states (KF-GINS writes the diagonal only), averaged in bins of the epoch's horizontal σ;
a consistent filter gives 3.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from benchmarks.vehicle import earth
from benchmarks.vehicle.dataset import Dataset
from benchmarks.vehicle.imu import DEG, HOUR, MGAL, PPM

#: the sensor states, KF-GINS's order, and their unit in the files (SI per file unit)
SENSOR_STATES = (("gyro bias", DEG / HOUR, "°/h"), ("accel bias", MGAL, "mGal"),
                 ("gyro scale", PPM, "ppm"), ("accel scale", PPM, "ppm"))
SIGMA_BINS = ((0.0, 0.1), (0.1, 0.2), (0.2, np.inf))


@dataclass(frozen=True)
class Solution:
    """A program's solution: t (M,) GNSS seconds of week; lat, lon (rad), h (m); v_ned
    (M, 3); euler (M, 3) roll, pitch, yaw (rad). σ where the program states it: sigma_t
    (K,), sigma_pos_ned (K, 3) m. Sensor estimates at the end: sensors (4, 3) and their
    σ sensors_sigma (4, 3), SI, KF-GINS's order (gyro bias, accel bias, gyro scale,
    accel scale; body FRD)."""

    name: str
    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    v_ned: np.ndarray
    euler: np.ndarray
    sigma_t: np.ndarray
    sigma_pos_ned: np.ndarray
    sensors: np.ndarray
    sensors_sigma: np.ndarray


def load_columns(path, columns: int) -> np.ndarray:
    """A whitespace-separated numeric text file as (rows, columns) (NumPy's C parser)."""
    data = np.fromstring(Path(path).read_text(), sep=" ")  # noqa: NPY201 (text mode)
    if data.size % columns:
        raise ValueError(f"{path}: {data.size} numbers, not rows of {columns}")
    return data.reshape(-1, columns)


def read_nav(path) -> np.ndarray:
    """i2nav-nav rows (week, sow, lat, lon deg, h, v NED, roll pitch yaw deg), (M, 11)."""
    return load_columns(path, 11)


def read_kfgins(out_dir, name: str = "KF-GINS") -> Solution:
    """KF-GINS's ``KF_GINS_Navresult.nav``, ``KF_GINS_STD.txt`` (σ at every IMU epoch)
    and ``KF_GINS_IMU_ERR.txt`` from its output folder."""
    d = Path(out_dir)
    nav = read_nav(d / "KF_GINS_Navresult.nav")
    std = load_columns(d / "KF_GINS_STD.txt", 22)
    err = load_columns(d / "KF_GINS_IMU_ERR.txt", 13)
    scale = np.array([u for _, u, _ in SENSOR_STATES])[:, None]
    return Solution(name, nav[:, 1], np.radians(nav[:, 2]), np.radians(nav[:, 3]), nav[:, 4],
                    nav[:, 5:8], np.radians(nav[:, 8:11]), std[:, 0], std[:, 1:4],
                    err[-1, 1:13].reshape(4, 3) * scale, std[-1, 10:22].reshape(4, 3) * scale)


def read_gcalign(h5_path, nav_path=None, run: str = "calibrate/runs/00",
                 smoothed: bool = False) -> Solution:
    """gcalign's ``calibrate`` solution: the navigation at every sample from its i2nav-nav
    export `nav_path` (or, without one, from the results file's ``navigation`` group), the
    σ and the sensor estimates at the filter's epochs from the results file, all turned to
    KF-GINS's NED and FRD: attitude [pitch, roll, yaw_ENU] -> roll, pitch, −yaw_ENU;
    position σ from [δL, δλ, δh] through the radii; sensor axes x_FRD = y_RFU,
    y_FRD = x_RFU, z_FRD = −z_RFU (the sign for the biases only). `smoothed`: the RTS
    smoother's solution instead (``smoothed``: at the filter's epochs only)."""
    import h5py

    with h5py.File(h5_path, "r") as f:
        g = f[run]
        t = g["t"][()]
        s = g["smoothed"] if smoothed else g
        sigma, est, pos = s["sigma"][()], s["estimate"][()], s["pos"][()]
        nav = g["navigation"]
        t_gnss = nav["t"][()]
        t_sow = t + float(t_gnss[0] - nav["t_run"][0])  # the filter's epochs in GNSS time
        if smoothed:
            nav, nav_path, t_gnss = s, None, t_sow
        if nav_path is None:
            att, v, p = nav["att"][()], nav["v_n"][()], nav["pos"][()]
            lat, lon, h = p[:, 0], p[:, 1], p[:, 2]
            v_ned = np.column_stack([v[:, 1], v[:, 0], -v[:, 2]])
            euler = np.column_stack([att[:, 1], att[:, 0], -att[:, 2]])
    if nav_path is not None:
        rows = read_nav(nav_path)
        t_gnss, lat, lon, h = rows[:, 1], np.radians(rows[:, 2]), np.radians(rows[:, 3]), rows[:, 4]
        v_ned, euler = rows[:, 5:8], np.radians(rows[:, 8:11])
    r_m, r_n = earth.radii(pos[:, 0])
    sig_ned = np.column_stack([sigma[:, 6] * (r_m + pos[:, 2]),
                               sigma[:, 7] * (r_n + pos[:, 2]) * np.cos(pos[:, 0]), sigma[:, 8]])

    def frd(v: np.ndarray, sign: float) -> np.ndarray:
        return np.array([v[1], v[0], sign * v[2]])

    sensors = np.stack([frd(est[-1, 9:12], -1), frd(est[-1, 12:15], -1),
                        frd(est[-1, 15:18], 1), frd(est[-1, 18:21], 1)])
    sensors_sigma = np.stack([frd(sigma[-1, k:k + 3], 1) for k in (9, 12, 15, 18)])
    return Solution("gcalign, smoothed" if smoothed else "gcalign", t_gnss, lat, lon, h,
                    v_ned, euler, t_sow, sig_ned, sensors, sensors_sigma)


def errors(sol: Solution, ds: Dataset, chunk: int = 50000) -> dict[str, np.ndarray]:
    """Solution minus truth at the solution's epochs: ``pos`` (M, 3) NED m, ``vel`` (M, 3)
    m/s, ``att`` (M, 3) roll, pitch, yaw rad."""
    out = {k: np.empty((len(sol.t), 3)) for k in ("pos", "vel", "att")}
    for k0 in range(0, len(sol.t), chunk):
        sl = slice(k0, k0 + chunk)
        tr = ds.trajectory.state(sol.t[sl] - ds.config.sow0)
        r_m, r_n = earth.radii(tr.lat)
        out["pos"][sl] = np.column_stack([(sol.lat[sl] - tr.lat) * (r_m + tr.h),
                                          (sol.lon[sl] - tr.lon) * (r_n + tr.h) * np.cos(tr.lat),
                                          -(sol.h[sl] - tr.h)])
        out["vel"][sl] = sol.v_ned[sl] - tr.v_ned
        d = sol.euler[sl] - tr.euler
        out["att"][sl] = (d + np.pi) % (2 * np.pi) - np.pi
    return out


def outage_mask(t_sow: np.ndarray, ds: Dataset) -> np.ndarray:
    """True at the epochs strictly inside a GNSS outage."""
    m = np.zeros(len(t_sow), bool)
    for a, b in ds.fixes.outages:
        m |= (t_sow > ds.sow(a)) & (t_sow < ds.sow(b))
    return m


def _rms_max(x: np.ndarray) -> dict:
    return {"rms": np.sqrt((x**2).mean(0)).tolist(), "max": np.abs(x).max(0).tolist(),
            "rms_h": float(np.sqrt((x[:, :2] ** 2).sum(1).mean())),
            "max_h": float(np.hypot(x[:, 0], x[:, 1]).max())}


def table(sol: Solution, ds: Dataset) -> dict:
    """The aided-navigation figures of one solution (module docstring): RMS and max of
    the errors in and out of the outages, the sensor estimates in σ, NEES by σ bin."""
    e = errors(sol, ds)
    inside = outage_mask(sol.t, ds)
    res: dict = {"epochs": int(len(sol.t))}
    for where, m in (("out", ~inside), ("in", inside)):
        res[where] = {k: _rms_max(v[m]) for k, v in e.items()} if m.any() else None
    # sensors: (estimate - truth at the end) / the program's final σ
    s = ds.sensors
    true_end = np.stack([s.gyro_bias[-1], s.accel_bias[-1], s.gyro_scale[-1],
                         s.accel_scale[-1]])
    res["sensors_in_sigma"] = ((sol.sensors - true_end) / sol.sensors_sigma).tolist()
    res["sensors_sigma"] = sol.sensors_sigma.tolist()
    res["nees"] = nees_by_bin(sol, ds, e["pos"])
    return res


def nees_by_bin(sol: Solution, ds: Dataset, pos_err: np.ndarray) -> list[dict]:
    """Position NEES at the GNSS epochs, by the epoch's horizontal σ (module docstring):
    the σ the program states at its first epoch after the fix (its update), the error at
    that epoch. Each bin: epochs, mean NEES, the 95 % band of the mean of that many
    independent χ²(3) (the epochs are not independent: a guide, not a test)."""
    f = ds.fixes
    t_fix = ds.sow(f.t)
    k_sig = np.searchsorted(sol.sigma_t, t_fix + 1e-9)
    k_sol = np.searchsorted(sol.t, t_fix + 1e-9)
    ok = (k_sig < len(sol.sigma_t)) & (k_sol < len(sol.t))
    k_sig, k_sol, sig_h = k_sig[ok], k_sol[ok], f.sigma_ned[ok, 0]
    # the program's σ and the error at the same instant, within one IMU interval of the fix
    near = (np.abs(sol.sigma_t[k_sig] - t_fix[ok]) < 0.011) & \
        (np.abs(sol.t[k_sol] - sol.sigma_t[k_sig]) < 1e-6)
    z = pos_err[k_sol[near]] / sol.sigma_pos_ned[k_sig[near]]
    nees = (z**2).sum(1)
    sig_h = sig_h[near]
    out = []
    for lo, hi in SIGMA_BINS:
        m = (sig_h >= lo) & (sig_h < hi)
        n = int(m.sum())
        band = ([float(chi2.ppf(0.025, 3 * n) / n), float(chi2.ppf(0.975, 3 * n) / n)]
                if n else [np.nan, np.nan])
        out.append({"sigma_m": [lo, hi], "epochs": n,
                    "nees": float(nees[m].mean()) if n else np.nan, "band_95": band,
                    "z_rms": np.sqrt((z[m] ** 2).mean(0)).tolist() if n else None})
    return out
