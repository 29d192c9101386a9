"""Calibration of a recording with measured velocity and position from files
(``calibrate.aiding: file``): the MEMS vehicle of transfer_align_fog_mems.mat aided by its
FOG solution (velocity from the MAT file, positions as a GNSS CSV) estimates the MEMS gyro
biases that PSINS's own transfer-alignment demo found (eb0, stored in the file): a second,
independent route to the same numbers. One-line refusals of the files' keys."""

from __future__ import annotations

import json

import h5py
import numpy as np
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
import yaml
from cli_checks import assert_bad_run
from lazy import lazy_attr
from typer.testing import CliRunner

import gcalign
from conftest import ROOT
from gcalign.cli import app
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm
from gcalign.units import DPH, UG

Rotation = lazy_attr("scipy.spatial.transform", "Rotation")
Slerp = lazy_attr("scipy.spatial.transform", "Slerp")

runner = CliRunner()
MAT = ROOT / "tests/data/transfer_align_fog_mems.mat"
#: The filter's prior for a MEMS IMU (the defaults are the seed's navigation grade): biases
#: up to hundreds of °/h and 10 mg, the scale factors taken as known.
MEMS_P0 = {"attitude_arcsec": [600, 600, 1800], "velocity_enu_mps": [0.1, 0.1, 0.1],
           "position_enu_m": [0.5, 0.5, 1], "gyro_bias_dph": [300, 300, 300],
           "accel_bias_ug": [10000, 10000, 10000], "gyro_scale_ppm": [1, 1, 1],
           "accel_scale_ppm": [1, 1, 1]}


def _gnss_csv(path, fog: np.ndarray, t_shift: float = 0.0) -> str:
    rows = np.column_stack([fog[:, 9] + t_shift, np.degrees(fog[:, 6]), np.degrees(fog[:, 7]),
                            fog[:, 8], *np.tile([[0.1], [0.1], [0.2]], len(fog))])
    path.write_text("t,lat,lon,h,sn,se,sd\n" + "\n".join(
        ",".join(repr(float(x)) for x in r) for r in rows) + "\n")
    return str(path)


def _scenario(tmp_path, files: dict, **calibrate) -> str:
    sc = {"name": "mems-files", "imu_file": str(MAT), "reference": {"path": str(MAT)},
          "calibrate": {"aiding": "file", "files": files, "measure": "both",
                        "sigma_v_mps": 0.1, "sigma_p_m": 0.5,
                        "coarse": {"method": "inertial", "duration_s": 1}, "start_s": 0.11,
                        "gnss_noise": False, "filter_rate_hz": 10, "p0_scale": 1,
                        "p0": MEMS_P0, "q": {"arw_dprh": 0.5, "vrw_ugrhz": 300}, **calibrate}}
    path = tmp_path / "cal.yaml"
    path.write_text(yaml.safe_dump(sc))
    return str(path)


def test_mems_gyro_biases_from_the_fog_solution(tmp_path):
    """Velocity and position of the FOG solution, the start from it at 1.1 s: the gyro
    bias estimates lie within 3σ (the filter's own) of the stored eb0 on every axis, the
    accelerometer biases within 3σ on x and y (z, weakly observable in 100 s, is not
    asserted), and the NIS is not above its band (below it: R is wider than the FOG's
    noise, so the σ are pessimistic, and the health check says so)."""
    m = scipy.io.loadmat(MAT)
    eb0, db0 = m["eb0"].ravel(), m["db0"].ravel()
    files = {"velocity": {"path": str(MAT), "format": "psins-mat"},
             "position": {"path": _gnss_csv(tmp_path / "fog.csv", m["fogavp"]),
                          "format": "csv"}}
    res = runner.invoke(app, ["calibrate", _scenario(tmp_path, files), "-o",
                              str(tmp_path / "c.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert s["aiding"] == "file"
    # the seed's filter measures horizontal velocity and position only (seed eqs. 5-7): the
    # height is unaided, and R (0.1 m/s, 0.5 m) is wider than the FOG solution's noise; the
    # health checks say both, nothing else warns (the vehicle is not taken as parked)
    assert len(s["warnings"]) == 3, s["warnings"]
    assert "below its 95 % band" in s["warnings"][0]
    assert s["warnings"][1].startswith("dvU: σ") and s["warnings"][2].startswith("dh: σ")
    est = {k: (v["estimate"], v["sigma"]) for k, v in s["states"].items()}
    eb = np.array([est[k][0] for k in ("ebx", "eby", "ebz")])
    sb = np.array([est[k][1] for k in ("ebx", "eby", "ebz")])
    db = np.array([est[k][0] for k in ("dbx", "dby", "dbz")])
    sd = np.array([est[k][1] for k in ("dbx", "dby", "dbz")])
    print(f"eb {np.round(eb / DPH, 1).tolist()} ± {np.round(sb / DPH, 1).tolist()} °/h "
          f"(eb0 {np.round(eb0 / DPH, 1).tolist()}); db {np.round(db / UG).tolist()} ± "
          f"{np.round(sd / UG).tolist()} µg (db0 {np.round(db0 / UG).tolist()}); "
          f"NIS {s['nis']['mean']:.3g}")
    assert (np.abs(eb - eb0) < 3 * sb).all()
    assert (np.abs(db - db0)[:2] < 3 * sd[:2]).all()
    # and sharp: σ 2 % of eb0 on the horizontal axes, 20 % on z (the up gyro is seen only
    # through the heading, weakly in 100 s)
    assert (sb[:2] < np.abs(eb0[:2]) / 20).all() and sb[2] < np.abs(eb0[2]) / 3
    lo, hi = s["nis"]["band_95"]
    assert s["nis"]["mean"] < hi
    # against the FOG reference at the last epoch it covers, recomputed here from the FOG
    # array (its two neighbouring epochs, the attitude interpolated by scipy's slerp)
    e = s["final_error"]
    assert s["error_source"] == "reference" and "against the reference at" in res.stderr
    fog = m["fogavp"]
    rot = Rotation.from_matrix(euler_to_dcm(fog[:, :3]))
    t = e["t_s"]
    assert fog[0, 9] <= t <= fog[-1, 9]
    with h5py.File(tmp_path / "c.h5") as f:  # the INS solution at that epoch
        g = f["calibrate/runs/00"]
        k = int(np.argmin(np.abs(g["t"][()] - t)))
        att, v_n = g["att"][k], g["v_n"][k]
        series = {n: g["reference_error"][n][()] for n in ("t", "att", "v_n", "pos")}
    # the stored series ends on the summary's numbers, and plot draws it
    assert series["t"][-1] == t and np.degrees(series["att"][-1]).tolist() == e["attitude_deg"]
    assert series["pos"][-1].tolist() == e["position_m"]
    assert "reference_errors" in gcalign.read(tmp_path / "c.h5").figures()
    ref_att = dcm_to_euler(Slerp(fog[:, 9], rot)([t]).as_matrix())[0]
    err = (att - ref_att + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(e["attitude_deg"], np.degrees(err), atol=1e-9)
    ref_v = [np.interp(t, fog[:, 9], fog[:, 3 + i]) for i in range(3)]
    np.testing.assert_allclose(e["velocity_mps"], v_n - ref_v, atol=1e-9)
    # the aiding holds the horizontal position and velocity to the FOG's; the attitude
    # stays within the filter's prior of the FOG's (the mounting mu0, 18′ at most, is not
    # separated in 100 s)
    assert np.hypot(*e["position_m"][:2]) < 2.0 and np.hypot(*e["velocity_mps"][:2]) < 0.3
    assert np.all(np.abs(e["attitude_deg"]) < 0.5)


def test_calibrate_files_refusals(tmp_path):
    fog = scipy.io.loadmat(MAT)["fogavp"]
    vel = {"path": str(MAT), "format": "psins-mat"}

    def run(*args):
        return runner.invoke(app, ["calibrate", *map(str, args)])

    far = {"path": _gnss_csv(tmp_path / "far.csv", fog, 5000.0), "format": "csv"}
    assert_bad_run(run, tmp_path, [_scenario(tmp_path, {"velocity": vel, "position": far})],
                   "calibrate.files.position:", "no common time")
    assert_bad_run(run, tmp_path, [_scenario(tmp_path, {"velocity": vel})],
                   "calibrate.files.position:", "measure 'both' needs it")
    for name, fmt in (("gnss_rtk_kfgins.txt", "i2nav-gnss"), ("rtklib_sample.pos",
                                                               "rtklib-pos")):
        real = {"path": str(ROOT / "tests/data" / name), "format": fmt}  # seconds of week
        assert_bad_run(run, tmp_path, [_scenario(tmp_path, {"velocity": vel, "position": real})],
                       "calibrate.files.position:", "no common time", "seconds of week")
    near = _gnss_csv(tmp_path / "near.csv", fog)
    assert_bad_run(run, tmp_path, [_scenario(tmp_path, {"velocity": vel, "position": {
        "path": near, "format": "csv", "lever_arm_m": [0, 1.2, 0.8]}})], "lever_arm_m",
        "no lever-arm term")
    assert_bad_run(run, tmp_path, [_scenario(tmp_path, {"velocity": vel}, measure="velocity",
                                             gnss_noise=True)], "calibrate.gnss_noise")
    assert_bad_run(run, tmp_path, [_scenario(tmp_path, {"velocity": vel}, measure="velocity",
                                             aiding="zero-velocity")], "calibrate.files")


def test_validate_shows_the_files(tmp_path):
    """validate: the files beside calibrate.aiding; the reference (from 0.1 s) is not held
    to the navigation window of a scenario that only calibrates."""
    fog = scipy.io.loadmat(MAT)["fogavp"]
    files = {"velocity": {"path": str(MAT), "format": "psins-mat"},
             "position": {"path": _gnss_csv(tmp_path / "fog.csv", fog), "format": "csv"}}
    res = runner.invoke(app, ["validate", _scenario(tmp_path, files)], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert "velocity transfer_align_fog_mems.mat (psins-mat); position fog.csv (csv)" in \
        res.stdout
