"""The simulated vehicle of :mod:`aided_cases` written as a KF-GINS user has it: the IMU as
i2nav text (GNSS seconds of week, increments in FRD), the GNSS fixes as GNSS-RTK text (σ
north, east, down per fix) with outages cut out, the truth as an i2nav-nav reference, and
the gcalign scenario that reads them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from aided_cases import LEVER, scenario, settings, vehicle

from gcalign.units import DPH, UG

SOW0 = 456300.0  #: GNSS seconds of week of the recording's sample 0


def write_vehicle(folder: Path, seed: int = 1, duration: float | None = None,
                  outages=((150.0, 210.0),)) -> dict[str, Path]:
    """IMU, GNSS and truth files of the vehicle in `folder`, and a scenario beside them."""
    data, fixes, x_true = vehicle(seed, duration, outages=outages)
    folder.mkdir(parents=True, exist_ok=True)
    frd = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])  # RFU -> FRD
    t = data.t[1:] + SOW0
    imu = np.column_stack([t, data.dtheta @ frd.T, data.dv @ frd.T])
    paths = {"imu": folder / "imu.txt", "gnss": folder / "gnss.txt", "truth": folder / "truth.nav",
             "scenario": folder / "vehicle.yaml"}
    np.savetxt(paths["imu"], imu, fmt="%.9f")
    s = fixes.sigma_pos
    gnss = np.column_stack([fixes.t + SOW0, np.degrees(fixes.pos[:, 0]),
                            np.degrees(fixes.pos[:, 1]), fixes.pos[:, 2], s[:, 1], s[:, 0],
                            s[:, 2]])
    np.savetxt(paths["gnss"], gnss, fmt="%.10f")
    tr = data.truth
    heading = (np.degrees(-tr.att[:, 2]) + 180.0) % 360.0 - 180.0
    nav = np.column_stack([np.full(len(tr.t), 2100), tr.t + SOW0, np.degrees(tr.pos[:, 0]),
                           np.degrees(tr.pos[:, 1]), tr.pos[:, 2], tr.v_n[:, 1], tr.v_n[:, 0],
                           -tr.v_n[:, 2], np.degrees(tr.att[:, 1]), np.degrees(tr.att[:, 0]),
                           heading])
    np.savetxt(paths["truth"], nav, fmt=["%d"] + ["%.10f"] * 10)
    st = settings()
    sc = scenario()
    g, a = sc.imu.errors().gyro, sc.imu.errors().accel
    p0 = np.asarray(st.p0_sigma)
    start = data.start
    doc = {
        "name": "vehicle",
        "imu_file": {"path": "imu.txt", "format": "i2nav"},
        "reference": {"path": "truth.nav", "format": "i2nav-nav"},
        "initial": {
            "att_deg": np.degrees(start.att).tolist(), "v_enu_mps": start.v_n.tolist(),
            "lat_deg": float(np.degrees(start.pos[0])), "lon_deg": float(np.degrees(start.pos[1])),
            "height_m": float(start.pos[2]),
            "sigma": {"phi_enu_deg": np.degrees(p0[:3]).tolist(), "v_enu_mps": p0[3:6].tolist(),
                      "pos_enu_m": [1.0, 1.0, 1.0]}},
        "calibrate": {
            "aiding": "file", "measure": "position",
            "files": {"position": {"path": "gnss.txt", "format": "i2nav-gnss",
                                   "lever_arm_m": LEVER.tolist()}},
            "p0_scale": 1,
            "p0": {"gyro_bias_dph": (g.bias_gm_std / DPH).tolist(),
                   "accel_bias_ug": (a.bias_gm_std / UG).tolist(),
                   "gyro_scale_ppm": 100, "accel_scale_ppm": 100},
            "q": {"arw_dprh": 0.003, "vrw_ugrhz": 30.0,
                  "gyro_bias_gm": {"std_dph": 1.0, "tau_s": 600.0},
                  "accel_bias_gm": {"std_ug": 200.0, "tau_s": 600.0}}},
    }
    paths["scenario"].write_text(yaml.safe_dump(doc, sort_keys=False))
    return paths


__all__ = ["SOW0", "write_vehicle", "x_true_of"]


def x_true_of(seed: int = 1, duration: float | None = None) -> np.ndarray:
    """The vehicle's injected errors (21,) of `seed` (SI)."""
    return vehicle(seed, duration)[2]
