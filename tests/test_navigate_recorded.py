"""Navigation of a recording against a reference solution: the real MEMS IMU of
transfer_align_fog_mems.mat against its FOG-INS solution (errors labelled "reference" in
the JSON, table and figure; the initial state from the keys, the reference or the header;
one-line refusals), and the MEMS-vs-FOG numbers by two independent strapdown routes
(gcalign's kernel and pyins on the same increments)."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
from cli_checks import assert_bad_run
from lazy import lazy_attr
from typer.testing import CliRunner

from conftest import ROOT
from gcalign.cli import app
from gcalign.io.recorded import read_recording, read_reference, reference_at
from gcalign.nav.navigate import navigate, position_error_enu
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm, misalignment
from gcalign.nav.strapdown import NavState, Vertical

Rotation = lazy_attr("scipy.spatial.transform", "Rotation")

runner = CliRunner()
MAT = ROOT / "tests/data/transfer_align_fog_mems.mat"
K0 = 10  #: the IMU's sample at data time 0.1 s, the FOG solution's first epoch
START = "0.11"  #: navigation.start_s of sample K0 (sample 0 is before the first increment)


def run(*args):
    return runner.invoke(app, ["navigate", *map(str, args)])


def navigate_json(tmp_path, *args) -> dict:
    res = run(MAT, "--reference", MAT, "-o", tmp_path / "nav.h5", "--json", *args)
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def mems():
    imu, ref = read_recording(MAT), read_reference(MAT)
    m = scipy.io.loadmat(MAT)
    return imu, ref, {k: m[k].ravel() for k in ("eb0", "db0", "mu0")}


def test_navigate_against_the_reference_cli(tmp_path, mems):
    """--reference: started from the FOG solution at 0.1 s, errors against it in the same
    JSON fields as against truth, plus error_source; they equal the arrays route's errors
    computed here against the reference interpolated at the stored rows."""
    s = navigate_json(tmp_path, "--start", START)
    assert s["error_source"] == "reference" and s["init"].startswith("reference ")
    assert set(s["final_error"]) == {"attitude_deg", "velocity_mps", "position_m",
                                     "misalignment_deg"}
    assert s["warnings"] == []  # the reference is used: no "does not use it yet"
    with h5py.File(tmp_path / "nav.h5") as f:
        g = f["navigate"]
        assert g.attrs["error_source"] == "reference"
        t, pos, e_pos = g["t"][()], g["pos"][()], g["error/pos"][()]
        att, e_phi = g["att"][()], g["error/phi"][()]
    imu, ref, _ = mems
    assert t[0] == pytest.approx(0.1) and t[-1] == pytest.approx(100.0)
    r_att, _, r_pos = reference_at(ref, t, tol=1e-6)
    np.testing.assert_allclose(e_pos, position_error_enu(pos, r_pos), atol=1e-6)
    np.testing.assert_allclose(e_phi, misalignment(euler_to_dcm(att), euler_to_dcm(r_att)),
                               atol=1e-9)
    assert np.abs(e_pos[0]).max() < 1e-6  # the start is the reference's own state
    assert np.hypot(*s["final_error"]["position_m"][:2]) == pytest.approx(
        np.hypot(*e_pos[-1, :2]), rel=1e-9)
    assert s["max_horizontal_error_m"] == pytest.approx(np.hypot(e_pos[:, 0], e_pos[:, 1]).max(),
                                                        rel=1e-6)


def test_reference_changes_no_navigated_number(tmp_path, mems):
    """A reference is for the errors only: started from the same state by keys and the
    site, the run without it navigates the same numbers (to the round-off of the site's
    degrees and back)."""
    _, ref, _ = mems
    att, v, pos = (a[0] for a in reference_at(ref, [0.1]))
    with_ref = navigate_json(tmp_path, "--start", START)
    keys = [f"--set=initial.att_deg={np.degrees(att).tolist()}",
            f"--set=initial.v_enu_mps={v.tolist()}"]
    res = run(MAT, "--start", START, "--lat", repr(float(np.degrees(pos[0]))), "--lon",
              repr(float(np.degrees(pos[1]))), "--height", repr(float(pos[2])), *keys, "--json",
              "-o", tmp_path / "keys.h5")
    assert res.exit_code == 0, res.output
    alone = json.loads(res.stdout.strip().splitlines()[-1])
    assert alone["init"].startswith("keys") and alone["final_error"] is None
    a, b = alone["final_state"], with_ref["final_state"]
    for key in a:  # the site in degrees and back: round-off
        np.testing.assert_allclose(a[key], b[key], rtol=1e-12, atol=1e-9)


def test_reference_table_and_figure_say_reference(tmp_path):
    from rich.console import Console

    from gcalign.app.navigate.plots import figures
    from gcalign.app.navigate.tables import navigate_table

    s = navigate_json(tmp_path, "--start", START, "--duration", "5")
    console = Console(width=200, record=True)
    console.print(navigate_table(s))
    text = console.export_text()
    assert "estimate − reference" in text and "estimate − truth" not in text
    with h5py.File(tmp_path / "nav.h5") as f:
        fig = figures(f, "mems")["navigate_error"]
    assert "error against reference" in fig.texts[0].get_text()


def test_navigate_recorded_refusals(tmp_path):
    """One line, exit 2, no file: no initial state (the three ways), a reference that does
    not cover the start (the start_s that would), a reference file that does not exist."""
    assert_bad_run(run, tmp_path, [MAT, "--lat", "34.4", "--lon", "111.4"], "initial:",
                   "header", "--reference", "initial: {att_deg")
    assert_bad_run(run, tmp_path, [MAT, "--reference", MAT], "reference:",
                   "covers 0.100 .. 100.000 s", "navigation.start_s 0.11 s")
    assert_bad_run(run, tmp_path, [MAT, "--reference", tmp_path / "none.mat"],
                   "--reference:", "file not found")


def _mems_run(mems, remove_biases: bool, vertical: str):
    """The MEMS increments from 0.1 s (FOG's first epoch), biases removed or not, started
    from the MEMS attitude FOG ∘ mu0 and the FOG velocity and position there; gcalign's
    rows and pyins's solution on the same increments."""
    from pyins_ref import pyins_integrate

    imu, ref, stored = mems
    ts = imu.ts
    dtheta, dv = imu.dtheta[K0 + 1:], imu.dv[K0 + 1:]
    if remove_biases:
        dtheta, dv = dtheta - stored["eb0"] * ts, dv - stored["db0"] * ts
    att0, v0, pos0 = (a[0] for a in reference_at(ref, [imu.t[K0]]))
    C_mu = Rotation.from_rotvec(stored["mu0"]).as_matrix()
    att0 = dcm_to_euler(euler_to_dcm(att0) @ C_mu)
    nav = navigate(dtheta, dv, ts, NavState.from_euler(att0, v0, pos0),
                   vertical=Vertical(vertical), t0=imu.t[K0])
    py = pyins_integrate(imu.t[K0], ts, dtheta, dv, pos0, att0, v0, compensation="rotation",
                         with_altitude=vertical == "free")
    return nav.rows, py, ref, C_mu


@pytest.mark.slow
@pytest.mark.parametrize("remove_biases", [False, True])
def test_mems_against_fog_two_routes(mems, remove_biases):
    """MEMS vs FOG, height free: horizontal error at 10, 30, 60, 100 s and the attitude
    error against FOG ∘ mu0 by gcalign and by pyins on the same increments. The routes
    agree to 2 mm horizontally and 1e-6 rad in attitude after 100 s (residuals: pyins's
    gravity formula, -2.4 µg here, its earth rate 1.5e-12 rad/s apart, its trapezoid
    position and mid-step rates). The physics: the stored biases are the MEMS's dominant
    error (eb0 ≈ 200 °/h tilts the platform by ε·t ≈ 6° in 100 s: about 2 km
    horizontally), and removing them must shrink the error more than ten times. What
    remains (140 m, 0.24° of yaw) is a residual level acceleration of 1-3 mg at the start:
    eb0, db0 and mu0 are the PSINS demo's estimates, not a calibration
    (docs/results_recorded.md)."""
    rows, py, ref, C_mu = _mems_run(mems, remove_biases, "free")
    r_att, _, r_pos = reference_at(ref, rows.t, tol=1e-6)
    e_ours = position_error_enu(rows.pos, r_pos)
    e_py = position_error_enu(py["lla"], r_pos)
    np.testing.assert_allclose(py["t"], rows.t, atol=1e-9)
    assert np.abs(e_ours[:, :2] - e_py[:, :2]).max() < 2e-3
    C_ref = euler_to_dcm(r_att) @ C_mu  # the MEMS attitude the FOG solution implies
    phi_ours = misalignment(euler_to_dcm(rows.att), C_ref)
    phi_py = misalignment(py["C_nb"], C_ref)
    assert np.abs(phi_ours - phi_py).max() < 1e-6
    at = [int(np.argmin(np.abs(rows.t - x))) for x in (10.0, 30.0, 60.0, 100.0)]
    horiz = np.hypot(e_ours[at, 0], e_ours[at, 1])
    phi = np.degrees(phi_ours[at[-1]])
    print(f"biases removed {remove_biases}: horizontal error at 10/30/60/100 s "
          f"{np.round(horiz, 2).tolist()} m (pyins "
          f"{np.round(np.hypot(e_py[at, 0], e_py[at, 1]), 2).tolist()}); φ at 100 s vs "
          f"FOG∘mu0 {np.round(phi, 3).tolist()} deg")
    assert (np.diff(horiz) > 0).all()
    if remove_biases:
        assert horiz[-1] < 199 and np.abs(phi).max() < 0.3  # a tenth of the raw 1 990 m
    else:
        assert horiz[-1] > 1000  # ≈ ½ g ε t³/3 for a platform tilting at ε: kilometres
        # φ' = −C_nb ε: heading north, the x (right) gyro's bias tilts about east,
        # φ_E ≈ −ε_x t (cos roll ≈ 0.9 of it, the roll swinging ±33°)
        assert np.degrees(phi_ours[at[-1], 0]) == pytest.approx(
            -np.degrees(mems[2]["eb0"][0] * 99.9), rel=0.15)


def test_command_route_is_the_arrays_route(tmp_path, mems):
    """`gcalign navigate configs/mems_fog.yaml` (height free, started from the FOG solution
    at 0.1 s) and :func:`gcalign.nav.navigate.navigate` from the same state: the same
    final horizontal error against the reference."""
    res = runner.invoke(app, ["navigate", str(ROOT / "configs/mems_fog.yaml"), "-o",
                              str(tmp_path / "c.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    imu, ref, _ = mems
    att0, v0, pos0 = (a[0] for a in reference_at(ref, [imu.t[K0]]))
    nav = navigate(imu.dtheta[K0 + 1:], imu.dv[K0 + 1:], imu.ts,
                   NavState.from_euler(att0, v0, pos0), vertical=Vertical("free"), t0=imu.t[K0])
    e = position_error_enu(nav.final.pos[None], reference_at(ref, [100.0])[2])[0]
    assert s["vertical"] == "free"
    np.testing.assert_allclose(s["final_error"]["position_m"], e, atol=1e-6)


def test_no_error_inside_a_gap_of_the_reference(tmp_path):
    """A reference with 12 s cut out: the stored errors are NaN inside the gap (not a line
    drawn across it), the maxima come from the compared samples only, and outside the gap
    every error is the full reference's."""
    m = scipy.io.loadmat(MAT)
    fog = m["fogavp"]
    cut = tmp_path / "cut.mat"
    scipy.io.savemat(cut, {"fogavp": fog[(fog[:, 9] < 50.0) | (fog[:, 9] > 62.0)]})
    full = run(MAT, "--reference", MAT, "--start", START, "-o", tmp_path / "full.h5", "--json")
    gap = run(MAT, "--reference", cut, "--start", START, "-o", tmp_path / "gap.h5", "--json")
    assert full.exit_code == 0 and gap.exit_code == 0, gap.output
    with h5py.File(tmp_path / "full.h5") as f, h5py.File(tmp_path / "gap.h5") as g:
        t = f["navigate/t"][()]
        e_full, e_gap = f["navigate/error/pos"][()], g["navigate/error/pos"][()]
    inside = (t > 49.9 + 1e-6) & (t < 62.0 - 1e-6)
    assert np.isnan(e_gap[inside]).all() and np.isfinite(e_gap[~inside]).all()
    np.testing.assert_allclose(e_gap[~inside & (np.abs(t - 56) > 7)],
                               e_full[~inside & (np.abs(t - 56) > 7)], atol=1e-9)
    s = json.loads(gap.stdout.strip().splitlines()[-1])
    peak = s["max_error"]["position_m"]
    assert np.isfinite(peak).all()
    assert np.allclose(peak, np.nanmax(np.abs(e_gap), axis=0))
