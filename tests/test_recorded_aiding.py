"""Aiding and reference files (gcalign.io.recorded.aiding, .reference): KF-GINS GNSS-RTK
text and RTKLIB .pos as position aiding with σ, velocities, the real FOG reference of
transfer_align_fog_mems.mat interpolated on the rotation group, the initial state, and
one-line refusals (no overlap, no cover, NaN rows)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from conftest import ROOT
from gcalign.cli import app
from gcalign.errors import ScenarioError
from gcalign.io.recorded import read_recording
from gcalign.io.recorded.aiding import overlap, read_gnss, read_odometer, read_velocity
from gcalign.io.recorded.reference import (
    Reference,
    initial_state,
    read_reference,
    reference_at,
)
from gcalign.nav.rotation import euler_to_dcm
from gcalign.units import DEG

runner = CliRunner()
KFGINS = ROOT / "tests/data/gnss_rtk_kfgins.txt"
MAT = ROOT / "tests/data/transfer_align_fog_mems.mat"


def test_kfgins_gnss_rtk_as_position_aiding():
    """The first and last epochs and σ as the file writes them; σ north/east/down become
    [east, north, up]."""
    fixes = read_gnss(KFGINS, "i2nav-gnss", lever_arm_b=[0.1, 0.5, 1.2])
    r = fixes.record
    print(f"first epoch {r['first']}, last epoch {r['last']}, median σ ENU "
          f"{r['sigma_enu_median_m']} m, {r['epochs']} epochs")
    assert r["epochs"] == 21 and r["time_origin"] == "GNSS seconds of week"
    assert r["first"] == {"t_s": 456300.0, "lat_deg": 30.4447873701, "lon_deg": 114.4718632047,
                          "h_m": 20.899, "sigma_enu_m": [0.004, 0.005, 0.008]}
    assert r["last"]["t_s"] == 456320.0 and r["last"]["sigma_enu_m"] == [0.006, 0.007, 0.012]
    np.testing.assert_allclose(fixes.pos[0], [30.4447873701 * DEG, 114.4718632047 * DEG,
                                              20.899], rtol=1e-15)
    np.testing.assert_array_equal(fixes.lever_arm_b, [0.1, 0.5, 1.2])
    # the vehicle's 7 m north per second, as the fixture was written
    np.testing.assert_allclose(np.diff(fixes.pos[:, 0]) / DEG, 7.0 / 111320, atol=1.1e-10)


RTKLIB = (ROOT / "tests/data/rtklib_sample.pos").read_text()  # RTKPOST 2.4.3 layout


def test_rtklib_pos_with_calendar_time(tmp_path):
    """Calendar GPST becomes seconds of week: 2017-11-01 (a Wednesday) 06:45 is
    3 · 86400 + 6.75 · 3600 = 283500 s."""
    p = tmp_path / "rover.pos"
    p.write_text(RTKLIB)
    fixes = read_gnss(p, "rtklib-pos")
    np.testing.assert_array_equal(fixes.t, [283500.0, 283501.0])
    np.testing.assert_array_equal(fixes.sigma_enu, [[0.004, 0.005, 0.008],
                                                    [0.0041, 0.0051, 0.0082]])
    week = p.with_name("week.pos")
    week.write_text(RTKLIB.replace("%  GPST                 ", "%  GPST                 ")
                    .replace("2017/11/01 06:45:00.000", "1973 283500.000")
                    .replace("2017/11/01 06:45:01.000", "1973 283501.000"))
    np.testing.assert_array_equal(read_gnss(week, "rtklib-pos").t, [283500.0, 283501.0])


def test_velocity_and_odometer(tmp_path):
    ned = tmp_path / "v.csv"
    ned.write_text("t,vn,ve,vd\n1.0,3.0,4.0,-0.5\n2.0,3.5,4.5,0.25\n")
    v = read_velocity(ned, "NED")
    np.testing.assert_array_equal(v.v_n, [[4.0, 3.0, 0.5], [4.5, 3.5, -0.25]])
    odo = tmp_path / "odo.txt"
    odo.write_text("0.1 12.0\n0.2 12.5\n")
    o = read_odometer(odo, "F")
    np.testing.assert_array_equal(o.axis_b, [0, 1, 0])
    np.testing.assert_array_equal(o.speed, [12.0, 12.5])
    np.testing.assert_array_equal(read_odometer(odo, "B").axis_b, [0, -1, 0])


def test_the_real_fog_reference_read_and_interpolated():
    """fogavp (10 Hz, from 0.1 s): exact at its epochs; between two epochs the slerp is
    the geodesic, half the rotation from each side."""
    ref = read_reference(MAT, "psins-mat")  # one 10-column array: fogavp
    r = ref.record
    assert r["variable"] == "fogavp" and r["epochs"] == 1000
    assert r["t_first_s"] == pytest.approx(0.1) and r["t_last_s"] == pytest.approx(100.0)
    assert r["rate_hz"] == pytest.approx(10.0)
    att, v, pos = reference_at(ref, ref.t[10:20])
    np.testing.assert_allclose(euler_to_dcm(att), euler_to_dcm(ref.att[10:20]), atol=1e-12)
    np.testing.assert_allclose(v, ref.v_n[10:20], rtol=1e-12)
    mid = (ref.t[:-1] + ref.t[1:]) / 2
    att_mid, _, _ = reference_at(ref, mid)

    def angle(a, b):  # rotation angle between two attitudes
        C = np.einsum("kji,kjl->kil", euler_to_dcm(a), euler_to_dcm(b))
        return np.arccos(np.clip((np.trace(C, axis1=1, axis2=2) - 1) / 2, -1, 1))

    left, right = angle(ref.att[:-1], att_mid), angle(att_mid, ref.att[1:])
    whole = angle(ref.att[:-1], ref.att[1:])
    np.testing.assert_allclose(left, whole / 2, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(right, whole / 2, rtol=1e-6, atol=1e-12)
    assert whole.max() > 0.01  # the roll swings: a real test (>0.5° per 0.1 s somewhere)


def test_slerp_takes_the_short_way_over_the_yaw_wrap():
    t = np.array([0.0, 1.0])
    att = np.radians([[0.0, 0.0, 179.0], [0.0, 0.0, -179.0]])
    ref = Reference(t, att, np.zeros((2, 3)), np.zeros((2, 3)), {"path": "r"})
    mid = reference_at(ref, [0.5])[0][0]
    assert abs(abs(np.degrees(mid[2])) - 180.0) < 1e-9  # component-wise would give 0°


def test_reference_not_covering_the_run_exits_2(tmp_path):
    """mimu's first increment ends at 0 s (the run starts at -0.01 s); fogavp begins at
    0.1 s: validate refuses, naming both spans; starting at 0.2 s it is valid."""
    sc = {"name": "mems", "site": {"lat_deg": 34.4266, "lon_deg": 111.434, "height_m": 172.6},
          "imu_file": {"path": str(MAT), "format": "psins-mat", "variable": "mimu"},
          "reference": {"path": str(MAT), "format": "psins-mat", "variable": "fogavp"}}
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["validate", str(p)])
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
    assert "reference:" in res.output and "covers 0.100 .. 100.000 s, the run needs -0.010 .. " \
        "100.000 s" in res.output
    print(res.output.strip())
    sc["navigation"] = {"start_s": 0.2, "duration_s": 60}
    (tmp_path / "mems.mat").write_bytes(MAT.read_bytes())  # paths relative to the scenario
    sc["imu_file"]["path"] = sc["reference"]["path"] = "mems.mat"
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["validate", str(p)])
    assert res.exit_code == 0, res.output
    assert "reference covers" in res.stdout and "fogavp" in res.stdout
    assert "0.190 .. 60.190 s" in res.stdout  # the window: -0.01 s + start_s, 60 s
    assert "imu_file.format" in res.stdout and "psins-mat" in res.stdout


def test_export_to_i2nav_nav_reads_back_as_a_reference(tmp_path):
    """Navigate, export as KF-GINS text, read it as a reference: the same solution."""
    from gcalign.io import results

    sc = {"name": "s", "site": {"lat_deg": 30.5, "lon_deg": 114.5, "height_m": 20},
          "imu": {"rate_hz": 100},
          "motion": {"kind": "swing", "attitude_deg": [1, 2, 170], "duration_s": 5,
                     "swing": {"amplitude_deg": [2, 3, 30], "period_s": [5, 5, 4]}}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sc))
    nav = tmp_path / "n.h5"
    assert runner.invoke(app, ["navigate", str(tmp_path / "s.yaml"), "-o", str(nav)]
                         ).exit_code == 0
    assert runner.invoke(app, ["export", str(nav), "--format", "i2nav-nav"]).exit_code == 0
    ref = read_reference(tmp_path / "n.nav", "i2nav-nav")
    s = results.series(nav, "navigate")
    np.testing.assert_array_equal(ref.t, s["t"][0])
    np.testing.assert_allclose(euler_to_dcm(ref.att), euler_to_dcm(s["att"][0]), atol=1e-13)
    np.testing.assert_array_equal(ref.v_n, s["v_n"][0])
    np.testing.assert_allclose(ref.pos, s["pos"][0], rtol=1e-15)


def test_a_reference_without_attitude_only_where_allowed(tmp_path):
    """A master of 7 columns [v lat lon h t] (velocity matching in transfer alignment):
    read with att None where the caller allows it, its columns the 10-column avp's last
    seven; refused with one line otherwise, and by reference_at (which needs attitude)."""
    import scipy.io

    full = read_reference(MAT, "psins-mat")
    p = tmp_path / "vp.mat"
    scipy.io.savemat(p, {"vp": scipy.io.loadmat(MAT)["fogavp"][:, 3:]})
    ref = read_reference(p, "psins-mat", "vp", attitude_optional=True)
    assert ref.att is None and ref.record["variable"] == "vp"
    np.testing.assert_array_equal(ref.t, full.t)
    np.testing.assert_array_equal(ref.v_n, full.v_n)
    np.testing.assert_array_equal(ref.pos, full.pos)
    with pytest.raises(ScenarioError, match=r"'vp' is not an N x 10 avp array") as err:
        read_reference(p, "psins-mat", "vp")
    assert "\n" not in str(err.value)
    with pytest.raises(ScenarioError, match="has no attitude"):
        reference_at(ref, ref.t[:2])


def test_initial_state_sources_and_the_refusal_listing_three():
    ref = read_reference(MAT, "psins-mat")
    att, v, src = initial_state("f", 0.1, reference=ref)
    np.testing.assert_allclose(att, ref.att[0], atol=1e-12)
    assert src.startswith("reference")
    att, v, src = initial_state("f", 0.0, att_deg=[1, 2, 3], v_enu_mps=[0, 1, 0],
                                reference=ref)
    np.testing.assert_allclose(att, np.radians([1, 2, 3]))
    assert src.startswith("keys")
    assert initial_state("f", 0.0, header_att=[0, 0, 1.0])[2] == "the file's header"
    with pytest.raises(ScenarioError) as err:
        initial_state("mems.csv", 0.0)
    msg = str(err.value)
    assert "\n" not in msg and "header" in msg and "reference" in msg and "initial:" in msg


@pytest.mark.parametrize("body, fmt, message", [
    ("456300 30.4 114.4 20 0.005 0.004 nan\n", "i2nav-gnss",
     r"g\.txt:1: field 7 \(sd\) must be finite, got nan"),
    ("456300 30.4 114.4 20 0.005 0.004 0.008\n456300 30.4 114.4 20 0.005 0.004 0.008\n",
     "i2nav-gnss", r"g\.txt:2: time must increase strictly"),
    ("456300 95.4 114.4 20 0.005 0.004 0.008\n", "i2nav-gnss",
     r"g\.txt:1: latitude, deg must lie in \[-90, 90\]"),
    ("456300 30.4 114.4 20 0.005 0.004 0.008\n", "nmea", r"aiding\.format: 'nmea'"),
])
def test_bad_gnss_files_are_one_line(tmp_path, body, fmt, message):
    p = tmp_path / "g.txt"
    p.write_text(body)
    with pytest.raises(ScenarioError, match=message) as err:
        read_gnss(p, fmt)
    assert "\n" not in str(err.value)


def test_aiding_with_no_overlap_is_refused():
    fixes = read_gnss(KFGINS, "i2nav-gnss")
    imu = read_recording(MAT, None)  # mimu: seconds 0 .. 100, not seconds of week
    with pytest.raises(ScenarioError) as err:
        overlap(fixes.t, imu.t, str(KFGINS))
    msg = str(err.value)
    print(msg)
    assert "\n" not in msg and "covers 456300.000 .. 456320.000 s and the IMU -0.010 .. " \
        "100.000 s: no common time" in msg
    inside = overlap(fixes.t, fixes.t[5:10] + 0.5, "g")
    assert inside.sum() == 5
