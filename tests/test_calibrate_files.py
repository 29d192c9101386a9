"""Calibration of a recording with measured velocity and position from files
(``calibrate.aiding: file``): the MEMS vehicle of transfer_align_fog_mems.mat aided by its
FOG solution (velocity from the MAT file, positions as a GNSS CSV) estimates the MEMS gyro
biases that PSINS's own transfer-alignment demo found (eb0, stored in the file): a second,
independent route to the same numbers. One-line refusals of the files' keys."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
import yaml
from cli_checks import assert_bad_run
from lazy import lazy_attr
from typer.testing import CliRunner

import gcalign
from conftest import ROOT
from gcalign.cli import app
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm, quat_to_euler
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


#: The FOG solution's positions written as 1 Hz GNSS fixes with this σ (north, east; down
#: twice it), m. The FOG solution is not GNSS: its noise is far below; 0.1 m is an RTK-grade
#: receiver's σ and covers the unknown MEMS-to-FOG lever arm (0.2 m swings ±0.1 m at ±33°
#: of roll).
SIGMA_P_M = 0.1
SIGMA_V_MPS = 0.1  #: the 1 Hz velocities' σ, the transfer demo's velocity R


def _whole_seconds(fog: np.ndarray) -> np.ndarray:
    """The FOG epochs on whole seconds (1 Hz from its 10 Hz)."""
    return fog[np.abs(fog[:, 9] - np.round(fog[:, 9])) < 1e-6]


def _i2nav_gnss(path, fog: np.ndarray, sigma: float = SIGMA_P_M) -> str:
    """KF-GINS GNSS-RTK text (t, lat, lon deg, h m, σ N, E, D m) of the FOG's 1 Hz epochs."""
    rows = [[f[9], np.degrees(f[6]), np.degrees(f[7]), f[8], sigma, sigma, 2 * sigma]
            for f in _whole_seconds(fog)]
    path.write_text("\n".join(" ".join(repr(float(x)) for x in r) for r in rows) + "\n")
    return str(path)


def _velocity_csv(path, fog: np.ndarray) -> str:
    """The FOG's 1 Hz velocities, ``t ve vn vu`` (velocity-enu)."""
    rows = _whole_seconds(fog)[:, [9, 3, 4, 5]]
    path.write_text("t,ve,vn,vu\n" + "\n".join(",".join(repr(float(x)) for x in r)
                                                for r in rows) + "\n")
    return str(path)


def _scenario(tmp_path, files: dict, **calibrate) -> str:
    sc = {"name": "mems-files", "imu_file": str(MAT), "reference": {"path": str(MAT)},
          "calibrate": {"aiding": "file", "files": files, "measure": "both",
                        "sigma_v_mps": 0.1,
                        "start_s": 1.01,  # data time 1.00 s (sample 0 is -0.01 s)
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
    # files are measured in 3-D (velocity with its vertical, position with its height):
    # nothing grows unheld; R (0.1 m/s, the CSV's 0.1 m, 0.2 m up) is wider than the FOG
    # solution's noise: the health check says so, nothing else warns (the vehicle is not
    # taken as parked)
    assert s["components"] == "3d"
    assert len(s["warnings"]) == 1, s["warnings"]
    assert "below its 95 % band" in s["warnings"][0]
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
    # the epochs count from sample 0, one 10 ms step before the MAT's first row (t = 0 s):
    # the reference is taken at the file's time
    t_data = t + float(m["mimu"][0, 6]) - 0.01
    assert fog[0, 9] - 1e-6 <= t_data <= fog[-1, 9] + 1e-6
    t_data = float(np.clip(t_data, fog[0, 9], fog[-1, 9]))  # to round-off
    with h5py.File(tmp_path / "c.h5") as f:  # the INS solution at that epoch
        g = f["calibrate/runs/00"]
        k = int(np.argmin(np.abs(g["t"][()] - t)))
        att, v_n = g["att"][k], g["v_n"][k]
        series = {n: g["reference_error"][n][()] for n in ("t", "att", "v_n", "pos")}
    # the stored series ends on the summary's numbers, and plot draws it
    assert series["t"][-1] == t and np.degrees(series["att"][-1]).tolist() == e["attitude_deg"]
    assert series["pos"][-1].tolist() == e["position_m"]
    assert "reference_errors" in gcalign.read(tmp_path / "c.h5").figures()
    ref_att = dcm_to_euler(Slerp(fog[:, 9], rot)([t_data]).as_matrix())[0]
    err = (att - ref_att + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(e["attitude_deg"], np.degrees(err), atol=1e-9)
    ref_v = [np.interp(t_data, fog[:, 9], fog[:, 3 + i]) for i in range(3)]
    np.testing.assert_allclose(e["velocity_mps"], v_n - ref_v, atol=1e-9)
    # the aiding holds the horizontal position and velocity to the FOG's; the attitude
    # stays within the filter's prior of the FOG's (the mounting mu0, 18′ at most, is not
    # separated in 100 s)
    # (to 0.1 m: taken 10 ms off, at 15 m/s, the reference would be 0.15 m away)
    assert np.hypot(*e["position_m"][:2]) < 0.1 and np.hypot(*e["velocity_mps"][:2]) < 0.3
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
    for key, bad, why in (("position", [0, 1.2], "at least 3 items"),
                          ("position", [0, ".nan", 0], "finite number"),
                          ("velocity", [0, 1.2, 0.8, 0], "at most 3 items"),
                          ("velocity", [0, 250, 0], "must be within [-100, 100] m")):
        files = {"velocity": dict(vel), "position": {"path": near, "format": "csv"}}
        files[key]["lever_arm_m"] = bad
        text = open(_scenario(tmp_path, files)).read().replace("'.nan'", ".nan")
        (tmp_path / "cal.yaml").write_text(text)
        assert_bad_run(run, tmp_path, [tmp_path / "cal.yaml"],
                       f"calibrate.files.{key}.lever_arm_m", why)
    # a file that ends before the run does (the FOG's positions to 60 s only): the run goes
    # on unaided to the end and says so; the rest is an outage in the JSON
    short = {"path": _gnss_csv(tmp_path / "short.csv", fog[fog[:, 9] < 60.05]),
             "format": "csv"}
    res = runner.invoke(app, ["calibrate", _scenario(tmp_path, {"velocity": vel,
                                                                 "position": short}),
                              "-o", str(tmp_path / "short.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert any("short.csv ends at 60.000 s, 40.0 s before the end of the run: the rest ran "
               "unaided" in w for w in s["warnings"]), s["warnings"]
    last = s["fixes"]["outages"][-1]
    assert last["start_data_s"] == pytest.approx(60.0) and last["end_data_s"] == \
        pytest.approx(100.0, abs=0.011)
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


def _one_hz(tmp_path, files: dict, measure: str, **calibrate) -> str:
    """The 1 Hz GNSS-like runs: the start (from the reference) at data time 1.00 s, fixes
    on the FOG's whole seconds, σ of the fixtures, horizontal as the seed measures (as
    docs/results_transfer.md tabulates them)."""
    return _scenario(tmp_path, files, measure=measure, filter_rate_hz=1, sigma_p_m=SIGMA_P_M,
                     sigma_v_mps=SIGMA_V_MPS, **({"components": "horizontal"} | calibrate))


def test_lever_arms_reach_the_filter_and_the_start(tmp_path):
    """The file route: each file's lever_arm_m is the FlightData's (the filter applies it),
    the INS starts at the IMU (the files' first fix minus C_b^n l and the antenna's
    velocity C_b^n(ω × l) − ω_ie × C_b^n l), and the FOG's positions read from the MAT file
    (a reference format) are the 1 Hz fixes written from it, at every filter epoch."""
    from gcalign.app.calibrate.run import recorded_case
    from gcalign.io.scenario import load_scenario

    m = scipy.io.loadmat(MAT)
    fog = m["fogavp"]
    l_v, l_p = [0.3, -1.2, 0.9], [0.1, 0.8, 1.5]
    gnss = {"velocity": {"path": _velocity_csv(tmp_path / "v.csv", fog),
                         "format": "velocity-enu", "lever_arm_m": l_v},
            "position": {"path": _i2nav_gnss(tmp_path / "p.gnss", fog), "format": "i2nav-gnss",
                         "lever_arm_m": l_p}}
    a = recorded_case(load_scenario(_one_hz(tmp_path, gnss, "both"))[0])
    d = a.data
    assert d.fixes.lever_arm_v_b.tolist() == l_v and d.fixes.lever_arm_p_b.tolist() == l_p
    k = np.argmin(np.abs(fog[:, 9] - 1.0))  # the start: the FOG at 1.0 s
    C = euler_to_dcm(fog[k, :3])
    assert d.t[0] + a.t0 == pytest.approx(1.0)
    np.testing.assert_allclose(quat_to_euler(d.start.q_nb), fog[k, :3], atol=1e-12)
    r_m, r_n = WGS84.radii(fog[k, 6])
    h = fog[k, 8]
    Cl = C @ l_p
    want = fog[k, 6:9] - [Cl[1] / (r_m + h), Cl[0] / ((r_n + h) * np.cos(fog[k, 6])), Cl[2]]
    np.testing.assert_allclose(d.start.pos, want, rtol=0, atol=1e-12)
    w = d.dtheta[0] / d.ts
    w_ie = WGS84.omega_ie * np.array([0.0, np.cos(fog[k, 6]), np.sin(fog[k, 6])])
    v_ant = C @ np.cross(w, l_v) - np.cross(w_ie, C @ l_v)
    np.testing.assert_allclose(d.start.v_n, fog[k, 3:6] - v_ant, atol=1e-9)

    mat = {"position": {"path": str(MAT), "format": "psins-mat", "interval_s": 1.0}}
    b = recorded_case(load_scenario(_one_hz(tmp_path, mat, "position"))[0]).data
    # the MAT file's 10 Hz solution on its whole seconds: the 1 Hz fixes written from it
    assert b.fixes.t.tolist() == pytest.approx(d.fixes.t.tolist(), abs=1e-9)
    np.testing.assert_allclose(b.fixes.pos[:, :2], d.fixes.pos[:, :2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.fixes.pos[:, 2], d.fixes.pos[:, 2], rtol=0, atol=1e-8)
    assert np.abs(b.fixes.t + a.t0 - np.round(b.fixes.t + a.t0)).max() < 1e-6


def test_smoother_on_a_recording(tmp_path):
    """--smoother on file aiding runs, is stored and printed; the RTS smoother's closed
    properties on the real data: the smoothed σ never exceeds the filtered σ at any epoch,
    and at the last epoch the smoothed estimate and σ are the filtered ones."""
    fog = scipy.io.loadmat(MAT)["fogavp"]
    files = {"velocity": {"path": _velocity_csv(tmp_path / "v.csv", fog),
                          "format": "velocity-enu"},
             "position": {"path": _i2nav_gnss(tmp_path / "p.gnss", fog), "format": "i2nav-gnss"}}
    out = tmp_path / "s.h5"
    res = runner.invoke(app, ["calibrate", _one_hz(tmp_path, files, "both", duration_s=30),
                              "--smoother", "-o", str(out)], env={"COLUMNS": "120"})
    assert res.exit_code == 0, res.output
    assert "RTS smoother: φ at the start (E, N, U)" in res.stdout
    assert "position from p.gnss (i2nav-gnss), measured at the IMU" in res.stdout
    with h5py.File(out) as f:
        g = f["calibrate/runs/00"]
        est, sig = g["estimate"][()], g["sigma"][()]
        s_est, s_sig = g["smoothed/estimate"][()], g["smoothed/sigma"][()]
    assert len(sig) == 31  # the start (data time 1 s) and 30 updates, 2 ... 31 s
    assert np.all(s_sig <= sig * (1 + 1e-9))
    np.testing.assert_allclose(s_sig[-1], sig[-1], rtol=1e-12)
    np.testing.assert_allclose(s_est[-1], est[-1], rtol=1e-12, atol=0)
    assert np.all(s_sig[0, :3] < sig[0, :3])  # the start attitude gains


def _run_json(args) -> dict:
    res = runner.invoke(app, ["calibrate", *map(str, args), "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.strip().splitlines()[-1])


def _est(s: dict, names) -> tuple[np.ndarray, np.ndarray]:
    return (np.array([s["states"][n]["estimate"] for n in names]),
            np.array([s["states"][n]["sigma"] for n in names]))


EB, DB, PHI = ("ebx", "eby", "ebz"), ("dbx", "dby", "dbz"), ("phiE", "phiN", "phiU")


@pytest.mark.slow
def test_fog_positions_and_velocities_beside_the_transfer_alignment(tmp_path):
    """The MEMS calibrated with the FOG solution as a 1 Hz GNSS receiver would give it
    (positions σ 0.1 m as KF-GINS GNSS-RTK text, velocities σ 0.1 m/s as a velocity CSV):
    position only, velocity only and both, beside the transfer alignment of the same data
    (attitude + velocity matching at 10 Hz, gcalign.transfer, the demo's settings) and
    PSINS's stored eb0, db0, mu0.

    * The gyro x, y biases agree with eb0 and with the transfer alignment within 3σ (a
      second filter, other measurements, on the same data); the accelerometer biases with
      the transfer alignment within 3σ of the two combined.
    * Adding a measurement never raises a sensor state's σ (both ≤ each alone, to 1 %).
    * What 100 s of positions or velocities do not support: the heading to the mounting's
      scale (σ(φU) at the end above |mu0 z| = 17.6′), and the up gyro to the 8.5 °/h by
      which the transfer alignment and eb0 differ (σ(ε z) above it): this route cannot
      decide between them.
    * The smoothed start attitude (the INS starts from the FOG's attitude, the MEMS is the
      FOG turned by mu0, so φ0 = C_b^n mu0) lies within 3σ of C_b^n mu0, and at the end the
      turn from the FOG to the calibrated MEMS attitude (body axes; ≈ ENU here: heading
      −3°, pitch −3.5°, roll 0.7°) within 3σ(φ) of mu0.
    * configs/mems_fog_calibrate.yaml (the FOG read from the MAT file, no derived file) gives
      the fixtures' 'both' run to 1e-6.
    """
    from gcalign.transfer import MasterSeries, TransferSettings, transfer_align
    from gcalign.units import ARCMIN

    m = scipy.io.loadmat(MAT)
    fog, mimu = m["fogavp"], m["mimu"]
    eb0, db0, mu0 = m["eb0"].ravel(), m["db0"].ravel(), m["mu0"].ravel()
    pos = {"path": _i2nav_gnss(tmp_path / "fog_1hz.gnss", fog), "format": "i2nav-gnss"}
    vel = {"path": _velocity_csv(tmp_path / "fog_1hz_vel.csv", fog), "format": "velocity-enu"}
    runs = {}
    for measure, files in (("position", {"position": pos}), ("velocity", {"velocity": vel}),
                           ("both", {"position": pos, "velocity": vel})):
        (tmp_path / measure).mkdir()
        runs[measure] = _run_json([_one_hz(tmp_path / measure, files, measure, smoother=True),
                                   "-o", tmp_path / measure / "c.h5"])
    tr = transfer_align(mimu[:, 0:3], mimu[:, 3:6], mimu[:, 6],
                        MasterSeries(fog[:, 9], fog[:, 0:3], fog[:, 3:6], fog[:, 6:9]),
                        TransferSettings())
    fin = tr.final()
    t_eb = np.array([fin[n][0] for n in EB]), np.array([fin[n][1] for n in EB])
    t_db = np.array([fin[n][0] for n in DB]), np.array([fin[n][1] for n in DB])
    k0 = int(np.argmin(np.abs(fog[:, 9] - 1.0)))
    phi0 = euler_to_dcm(fog[k0, :3]) @ mu0  # the start attitude error of the INS

    for measure, s in runs.items():
        eb, sb = _est(s, EB)
        db, sd = _est(s, DB)
        with h5py.File(tmp_path / measure / "c.h5") as f:
            g = f["calibrate/runs/00"]
            att_end = g["att"][-1]
            t, x, sig = g["t"][()], g["estimate"][:, 9:15], g["sigma"][:, 9:15]
        # convergence: the first epoch after which the estimate stays within its final σ of
        # its final value (data time)
        far = np.abs(x - x[-1]) > sig[-1]
        conv = [round(float(t[min(np.nonzero(c)[0][-1] + 1, len(t) - 1)] - 0.01), 2) if c.any() else
                round(float(t[0] - 0.01), 2) for c in far.T]
        C_fog = Rotation.from_matrix(euler_to_dcm(fog[-1, :3]))  # the last epoch: 100.00 s
        mu_end = (C_fog.inv() * Rotation.from_matrix(euler_to_dcm(att_end))).as_rotvec()
        sm = s["smoothed_initial"]
        p0, sp0 = (np.array([sm[n][key] for n in PHI]) for key in ("estimate", "sigma"))
        print(f"{measure:8s} eb {np.round(eb / DPH, 2).tolist()} ± {np.round(sb / DPH, 2).tolist()}"
              f" °/h; db {np.round(db / UG).tolist()} ± {np.round(sd / UG).tolist()} µg; "
              f"σ(φ) end {np.round(_est(s, PHI)[1] / ARCMIN, 1).tolist()}′; smoothed φ0 "
              f"{np.round(p0 / ARCMIN, 1).tolist()} ± {np.round(sp0 / ARCMIN, 1).tolist()}′ "
              f"(C mu0 {np.round(phi0 / ARCMIN, 1).tolist()}′); FOG to MEMS at the end "
              f"{np.round(mu_end / ARCMIN, 1).tolist()}′ (mu0 {np.round(mu0 / ARCMIN, 2).tolist()}"
              f"′); within the final σ after {dict(zip(EB + DB, conv, strict=True))} s; "
              f"NIS {s['nis']['mean']:.3f}/{s['nis']['dof']}; against the FOG at the end "
              f"{s['final_error']}")
        assert np.all(np.abs(eb - eb0)[:2] < 3 * sb[:2]), measure
        assert np.all(np.abs(eb - t_eb[0])[:2] < 3 * np.hypot(sb, t_eb[1])[:2]), measure
        assert np.all(np.abs(db - t_db[0]) < 3 * np.hypot(sd, t_db[1])), measure
        assert _est(s, PHI)[1][2] > np.abs(mu0[2]), measure
        assert sb[2] > abs(eb0[2] - t_eb[0][2]), measure
        assert np.all(np.abs(p0 - phi0) < 3 * sp0), measure
        assert s["final_error"]["t_s"] - 0.01 == pytest.approx(fog[-1, 9])
        assert np.all(np.abs(mu_end - mu0) < 3 * _est(s, PHI)[1]), measure
    mu = [fin[n][0] / ARCMIN for n in ("mux", "muy", "muz")]
    print(f"transfer eb {np.round(t_eb[0] / DPH, 2).tolist()} ± "
          f"{np.round(t_eb[1] / DPH, 2).tolist()} °/h; db {np.round(t_db[0] / UG).tolist()} ± "
          f"{np.round(t_db[1] / UG).tolist()} µg; mu {np.round(mu, 2).tolist()}′; stored eb0 "
          f"{np.round(eb0 / DPH, 2).tolist()} °/h, db0 {np.round(db0 / UG).tolist()} µg")
    both = np.array([runs["both"]["states"][n]["sigma"] for n in EB + DB])
    for one in ("position", "velocity"):
        alone = np.array([runs[one]["states"][n]["sigma"] for n in EB + DB])
        assert np.all(both <= alone * 1.01), one

    cfg = _run_json([ROOT / "configs/mems_fog_calibrate.yaml", "-o", tmp_path / "cfg.h5"])
    for n in EB + DB + PHI:
        assert cfg["states"][n]["estimate"] == pytest.approx(
            runs["both"]["states"][n]["estimate"], rel=1e-6, abs=1e-12), n
        assert cfg["states"][n]["sigma"] == pytest.approx(runs["both"]["states"][n]["sigma"],
                                                          rel=1e-6), n
