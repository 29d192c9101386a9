"""A simulated run in KF-GINS's file layouts, with its configuration file.

=====================  =================================================================
file                   layout (KF-GINS README §2.2)
=====================  =================================================================
``imu.txt``            GNSS seconds of week, dθ x y z (rad), dv x y z (m/s), body FRD;
                       each row's increments end at its stamp
``gnss.txt``           seconds of week, lat, lon (deg), h (m), σ north, east, down (m)
``truth.nav``          the i2nav-nav layout at every IMU stamp: week, seconds of week,
                       lat, lon (deg), h (m), v north, east, down (m/s), roll, pitch,
                       yaw (deg, yaw in [0, 360))
``truth_imuerr.txt``   KF-GINS's ImuError layout at every whole second: seconds of week,
                       gyro biases (°/h), accelerometer biases (mGal), gyro and
                       accelerometer scale factors (ppm): the drawn sensor errors
``kf-gins.yaml``       KF-GINS's configuration: the files, the start and its σ, the IMU
                       noise and the lever arm of this run; output to ``kfgins/``
``dataset.json``       what was simulated: seed, start, outages, σ range, lever arm
=====================  =================================================================
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from benchmarks.vehicle.dataset import Dataset
from benchmarks.vehicle.imu import DEG, HOUR, MGAL, PPM

KFGINS_OUT = "kfgins"


def write_imu(path: Path, ds: Dataset) -> None:
    rows = np.column_stack([ds.sow(ds.t), ds.dtheta, ds.dv])
    np.savetxt(path, rows, fmt=["%.6f"] + ["%.15e"] * 6)


def write_gnss(path: Path, ds: Dataset) -> None:
    f = ds.fixes
    rows = np.column_stack([ds.sow(f.t), np.degrees(f.lat), np.degrees(f.lon), f.h,
                            f.sigma_ned])
    np.savetxt(path, rows, fmt=["%.3f", "%.12f", "%.12f", "%.6f", "%.4f", "%.4f", "%.4f"])


def nav_rows(week: int, sow, lat, lon, h, v_ned, euler) -> np.ndarray:
    """Rows of the i2nav-nav layout (angles in rad in, deg out; yaw to [0, 360))."""
    e = np.degrees(euler)
    e[:, 2] = np.mod(e[:, 2], 360.0)
    return np.column_stack([np.full(len(sow), week), sow, np.degrees(lat), np.degrees(lon), h,
                            v_ned, e])


def write_truth(path: Path, ds: Dataset) -> None:
    tr = ds.truth
    rows = nav_rows(ds.config.week, ds.sow(ds.t), tr.lat, tr.lon, tr.h, tr.v_ned, tr.euler)
    np.savetxt(path, rows, fmt=["%d", "%.6f", "%.12f", "%.12f", "%.6f"] + ["%.9f"] * 6)


def write_sensor_truth(path: Path, ds: Dataset) -> None:
    s = ds.sensors
    whole = np.flatnonzero(np.abs(ds.t - np.round(ds.t)) < 0.5 / ds.config.imu_rate_hz
                           )  # the sample nearest each whole second
    rows = np.column_stack([ds.sow(ds.t[whole]), s.gyro_bias[whole] / (DEG / HOUR),
                            s.accel_bias[whole] / MGAL, s.gyro_scale[whole] / PPM,
                            s.accel_scale[whole] / PPM])
    np.savetxt(path, rows, fmt=["%.6f"] + ["%.6f"] * 12)


def _list(v, fmt: str = "{:.10g}") -> str:
    return "[" + ", ".join(fmt.format(float(x)) for x in v) + "]"


def kfgins_yaml(ds: Dataset, imu_path: Path, gnss_path: Path, out_dir: Path) -> str:
    """KF-GINS's configuration for this run (its keys and units)."""
    c, s, e = ds.config, ds.start, ds.config.errors
    euler = np.degrees(s.euler)
    euler[2] = np.mod(euler[2], 360.0)
    return "\n".join([
        "# KF-GINS configuration of a simulated vehicle run (benchmarks/vehicle)",
        f"imupath: \"{imu_path}\"", f"gnsspath: \"{gnss_path}\"", f"outputpath: \"{out_dir}\"",
        "imudatalen: 7", f"imudatarate: {c.imu_rate_hz:g}",
        f"starttime: {ds.sow(ds.t[0]):.6f}", "endtime: -1",
        f"initpos: [{np.degrees(s.lat):.12f}, {np.degrees(s.lon):.12f}, {s.h:.6f}]",
        f"initvel: {_list(s.v_ned)}", f"initatt: {_list(euler, '{:.9f}')}",
        "initgyrbias: [0, 0, 0]", "initaccbias: [0, 0, 0]", "initgyrscale: [0, 0, 0]",
        "initaccscale: [0, 0, 0]",
        f"initposstd: {_list(c.init_pos_std)}", f"initvelstd: {_list(c.init_vel_std)}",
        f"initattstd: {_list(c.init_att_std)}",
        "imunoise:", f"  arw: {_list([e.arw] * 3)}", f"  vrw: {_list([e.vrw] * 3)}",
        f"  gbstd: {_list([e.gbstd] * 3)}", f"  abstd: {_list([e.abstd] * 3)}",
        f"  gsstd: {_list([e.gsstd] * 3)}", f"  asstd: {_list([e.asstd] * 3)}",
        f"  corrtime: {e.corrtime:g}",
        f"antlever: {_list(c.lever_frd)}", ""])


def summary(ds: Dataset) -> dict:
    c, s, f = ds.config, ds.start, ds.fixes
    return {"seed": c.seed, "route": c.route, "week": c.week,
            "imu": {"rate_hz": c.imu_rate_hz, "first_sow": float(ds.sow(ds.t[0])),
                    "last_sow": float(ds.sow(ds.t[-1])), "samples": int(len(ds.t))},
            "gnss": {"epochs": int(len(f.t)), "first_sow": float(ds.sow(f.t[0])),
                     "last_sow": float(ds.sow(f.t[-1])),
                     "sigma_h_m": [float(f.sigma_ned[:, 0].min()), float(f.sigma_ned[:, 0].max())],
                     "sigma_d_m": [float(f.sigma_ned[:, 2].min()), float(f.sigma_ned[:, 2].max())]},
            "outages_sow": [[float(ds.sow(a)), float(ds.sow(b))] for a, b in f.outages],
            "marks_sow": {m[0]: [float(ds.sow(m[1])), float(ds.sow(m[2]))]
                          for m in ds.notes["marks"]},
            "lever_frd_m": list(c.lever_frd),
            "start": {"lat_deg": float(np.degrees(s.lat)), "lon_deg": float(np.degrees(s.lon)),
                      "h_m": s.h, "v_ned_mps": s.v_ned.tolist(),
                      "euler_deg": np.degrees(s.euler).tolist(),
                      "errors": {"pos_ned_m": s.dpos_ned.tolist(),
                                 "vel_ned_mps": s.dvel_ned.tolist(),
                                 "phi_ned_deg": np.degrees(s.phi).tolist()},
                      "std": {"pos_ned_m": list(c.init_pos_std),
                              "vel_ned_mps": list(c.init_vel_std),
                              "att_deg": list(c.init_att_std)}},
            "imu_errors": vars(c.errors)}


def write(ds: Dataset, out_dir) -> dict[str, Path]:
    """All of the run's files into `out_dir` (module docstring); their paths by name."""
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    (out / KFGINS_OUT).mkdir(exist_ok=True)
    p = {"imu": out / "imu.txt", "gnss": out / "gnss.txt", "truth": out / "truth.nav",
         "sensor_truth": out / "truth_imuerr.txt", "kfgins_yaml": out / "kf-gins.yaml",
         "kfgins_out": out / KFGINS_OUT, "summary": out / "dataset.json"}
    write_imu(p["imu"], ds)
    write_gnss(p["gnss"], ds)
    write_truth(p["truth"], ds)
    write_sensor_truth(p["sensor_truth"], ds)
    p["kfgins_yaml"].write_text(kfgins_yaml(ds, p["imu"], p["gnss"], p["kfgins_out"]))
    p["summary"].write_text(json.dumps(summary(ds), indent=1) + "\n")
    return p
