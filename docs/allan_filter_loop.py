"""The filter side of docs/allan.md: the noise `gcalign allan` identifies, as the Kalman
filter's process models (:func:`gcalign.allan.processes.filter_model`), in the zero-velocity
alignment of configs/lasergyro_calibrate.yaml (inertial coarse on 60 s, then 340 s of
zero-velocity updates): the filter's own σ of yaw at the end of each window beside the
spread of its yaw over the windows, on lasergyro.imu and on simulated recordings of a
known IMU.

Run from the repository root:  python docs/allan_filter_loop.py   (prints markdown; about
3 min on one core). The filter's process models are not scenario keys yet: this script
calls the capability functions with them.
"""

from __future__ import annotations

import math
import subprocess
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import yaml

from gcalign.allan import analyse
from gcalign.allan.processes import filter_model
from gcalign.app.calibrate.run import recorded_case, run_filter
from gcalign.app.data import scenario_data
from gcalign.estimation.ins_error import SensorProcesses
from gcalign.io.scenario import parse_scenario
from gcalign.units import DEG, DPSH, UGPSHZ

ROOT = Path(__file__).resolve().parents[1]
LASERGYRO = ROOT / "tests/data/lasergyro.imu.xz"
CAL = yaml.safe_load((ROOT / "configs/lasergyro_calibrate.yaml").read_text())["calibrate"]
STARTS = [0, 200, 400, 600, 800, 1000, 1200, 1440]
KNOWN = {"rate_hz": 100.0, "gyro": {"arw_dprh": 0.003, "bias_instability_dph": 0.005},
         "accel": {"vrw_ugrhz": 10.0, "bias_instability_ug": 5.0}}


def identified(imu_file: Path, fit_tau=None):
    """Settings changes from the noise identified on the whole recording."""
    sc = parse_scenario({"name": "id", "imu_file": str(imu_file)}, "id")
    d = scenario_data(sc)
    res = analyse(d.imu.dtheta, d.imu.dv, d.imu.ts, fit_tau=fit_tau)
    m = filter_model(res.gyro_fit, res.accel_fit)
    processes = SensorProcesses.of(m.kinds, np.nan_to_num(m.std), np.nan_to_num(m.tau, nan=1.0),
                                   np.nan_to_num(m.density))
    change: dict = {"processes": processes}
    for key, value in (("arw", m.arw), ("vrw", m.vrw)):  # unresolved: the configured one
        if math.isfinite(value):
            change[key] = value
    return change, m


def windows(imu_file: Path, change: dict | None, truth_yaw: float | None = None):
    """Yaw at the end of each window (deg) and the filter's σ of φ_U there (deg)."""
    yaw, sig = [], []
    for start in STARTS:
        sc = parse_scenario({"name": "w", "imu_file": str(imu_file),
                             "calibrate": dict(CAL, start_s=start)}, "w")
        case = recorded_case(sc)
        if change is not None:
            case = replace(case, settings=replace(case.settings, **change))
        r = run_filter(case).result
        yaw.append(math.degrees(r.att[-1, 2]))
        sig.append(math.degrees(r.sigma[-1, 2]))
    yaw_a = np.array(yaw)
    if truth_yaw is not None:
        yaw_a = (yaw_a - truth_yaw + 180.0) % 360.0 - 180.0
    return yaw_a, np.array(sig)


def row(name: str, yaw: np.ndarray, sig: np.ndarray) -> str:
    return (f"| {name} | {np.median(sig):.3g}° | {yaw.std(ddof=1):.3g}° | "
            f"{yaw[[0, 2, 4, 6]].std(ddof=1):.3g}° |")


def main() -> None:
    head = ("| filter's Q | filter's σ of yaw at the end (median) | spread of yaw, 8 windows "
            "| 4 disjoint |\n|---|---|---|---|")
    print("## lasergyro.imu\n")
    print(head)
    yaw, sig = windows(LASERGYRO, None)
    print(row(f"as configured (ARW {CAL.get('q', {}).get('arw_dprh', 0.001)} °/√h, "
              "constant biases)", yaw, sig))
    for tag, span in (("whole curve", None), ("τ 10–400 s", (10.0, 400.0))):
        change, m = identified(LASERGYRO, span)
        yaw, sig = windows(LASERGYRO, change)
        kinds = ", ".join(sorted(set(m.kinds[:6])))
        print(row(f"identified on the {tag} (ARW {m.arw / DPSH:.3g} °/√h, VRW "
                  f"{m.vrw / UGPSHZ:.3g} µg/√Hz, nan: as configured; biases: {kinds})",
                  yaw, sig))
    print("\n## Simulated recordings of a known IMU\n")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        files = []
        for seed in (1, 2, 3):
            rec = {"name": f"known{seed}",
                   "site": {"lat_deg": 34.246048, "lon_deg": 108.909664, "height_m": 380.0},
                   "output": {"rate_hz": "full"},
                   "motion": {"kind": "static", "attitude_deg": [0.9, 0.3, -90.6],
                              "duration_s": 1847.18},
                   "imu": dict(KNOWN, seed=seed)}
            (folder / f"k{seed}.yaml").write_text(yaml.safe_dump(rec))
            subprocess.run(["gcalign", "simulate", f"k{seed}.yaml", "-o", f"k{seed}.h5"],
                           cwd=folder, check=True, capture_output=True)
            files.append(folder / f"k{seed}.h5")
        change, m = identified(files[0])
        print(head)
        for name, ch in (("as configured", None), (
                f"identified on recording 1 (ARW {m.arw / DPSH:.3g} °/√h, VRW "
                f"{m.vrw / UGPSHZ:.3g} µg/√Hz; biases: {', '.join(sorted(set(m.kinds[:6])))})",
                change)):
            ys, ss = [], []
            for f in files:
                y, s = windows(f, ch, truth_yaw=-90.6)
                ys.append(y)
                ss.append(s)
            y_all = np.concatenate(ys)
            disjoint = np.concatenate([y[[0, 2, 4, 6]] for y in ys])
            print(f"| {name} | {np.median(np.concatenate(ss)):.3g}° | "
                  f"{y_all.std(ddof=1):.3g}° (24) | {disjoint.std(ddof=1):.3g}° (12); "
                  f"RMS error {math.sqrt(np.mean(y_all ** 2)):.3g}° |")
    _ = DEG


if __name__ == "__main__":
    main()
