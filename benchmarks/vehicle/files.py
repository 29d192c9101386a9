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
``gcalign.yaml``       the same run as a gcalign scenario (``gcalign calibrate``: the
                       same files, start, σ, noise, processes and lever arm in gcalign's
                       keys, ENU and body right, forward, up)
``dataset.json``       what was simulated: seed, start, outages, σ range, lever arm
=====================  =================================================================
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

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


def gcalign_scenario(ds: Dataset, imu_path: Path, gnss_path: Path) -> dict:
    """The run as a gcalign scenario: ``calibrate`` on the recording, position fixes from
    the GNSS file with its σ, 3-D, the start and σ given (no coarse alignment), the
    sensor states as KF-GINS's Gauss–Markov processes. KF-GINS's NED/FRD become gcalign's
    ENU/RFU: attitude [pitch, roll, −yaw], velocity [v_E, v_N, −v_D], lever arm [right,
    forward, up]; KF-GINS's φ σ (its ``initattstd``: φ north, east, down) becomes φ east,
    north, up. The run starts one sample into the file, at its first stamp (gcalign's data
    time 0 is the start of the first row's increment), where KF-GINS starts."""
    c, s, e = ds.config, ds.start, ds.config.errors
    roll, pitch, yaw = np.degrees(s.euler)
    vn, ve, vd = s.v_ned
    pn, pe, pd = c.init_pos_std
    sn, se, sd = c.init_vel_std
    an, ae, ad = c.init_att_std
    f, r, d = c.lever_frd
    ug = e.abstd * MGAL / 9.80665e-6  # mGal -> µg (gcalign's µg is 1e-6 of 9.80665 m/s²)
    tau = e.corrtime * HOUR
    vrw = e.vrw / 60.0 / 9.80665e-6  # m/s/√h -> µg/√Hz
    return {
        "name": f"vehicle-{c.route}-seed{c.seed}",
        "imu_file": {"path": str(imu_path), "format": "i2nav"},
        "site": {"lat_deg": float(np.degrees(s.lat)), "lon_deg": float(np.degrees(s.lon)),
                 "height_m": float(s.h)},
        "initial": {"att_deg": [float(pitch), float(roll), float(-yaw)],
                    "v_enu_mps": [float(ve), float(vn), float(-vd)],
                    "lat_deg": float(np.degrees(s.lat)), "lon_deg": float(np.degrees(s.lon)),
                    "height_m": float(s.h),
                    "sigma": {"phi_enu_deg": [ae, an, ad], "v_enu_mps": [se, sn, sd],
                              "pos_enu_m": [pe, pn, pd]}},
        "calibrate": {
            "aiding": "file", "measure": "position", "components": "3d",
            "files": {"position": {"path": str(gnss_path), "format": "i2nav-gnss",
                                   "lever_arm_m": [float(r), float(f), float(-d)]}},
            "start_s": 1.0 / c.imu_rate_hz,
            "p0_scale": 1,
            "p0": {"gyro_bias_dph": e.gbstd, "accel_bias_ug": ug,
                   "gyro_scale_ppm": e.gsstd, "accel_scale_ppm": e.asstd},
            "q": {"arw_dprh": e.arw, "vrw_ugrhz": vrw,
                  "gyro_bias_gm": {"std_dph": e.gbstd, "tau_s": tau},
                  "accel_bias_gm": {"std_ug": ug, "tau_s": tau},
                  "gyro_scale_gm": {"std_ppm": e.gsstd, "tau_s": tau},
                  "accel_scale_gm": {"std_ppm": e.asstd, "tau_s": tau}}}}


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


def paths(out_dir) -> dict[str, Path]:
    """The run's files in `out_dir` by name (module docstring)."""
    out = Path(out_dir).resolve()
    return {"imu": out / "imu.txt", "gnss": out / "gnss.txt", "truth": out / "truth.nav",
            "sensor_truth": out / "truth_imuerr.txt", "kfgins_yaml": out / "kf-gins.yaml",
            "kfgins_out": out / KFGINS_OUT, "summary": out / "dataset.json",
            "gcalign_yaml": out / "gcalign.yaml"}


def write(ds: Dataset, out_dir) -> dict[str, Path]:
    """All of the run's files into `out_dir` (module docstring); their paths by name."""
    p = paths(out_dir)
    p["kfgins_out"].mkdir(parents=True, exist_ok=True)
    write_imu(p["imu"], ds)
    write_gnss(p["gnss"], ds)
    write_truth(p["truth"], ds)
    write_sensor_truth(p["sensor_truth"], ds)
    p["kfgins_yaml"].write_text(kfgins_yaml(ds, p["imu"], p["gnss"], p["kfgins_out"]))
    p["gcalign_yaml"].write_text(
        "# gcalign scenario of a simulated vehicle run (benchmarks/vehicle); the KF-GINS\n"
        "# run of the same files: kf-gins.yaml\n"
        + yaml.safe_dump(gcalign_scenario(ds, p["imu"], p["gnss"]), sort_keys=False))
    p["summary"].write_text(json.dumps(summary(ds), indent=1) + "\n")
    return p
