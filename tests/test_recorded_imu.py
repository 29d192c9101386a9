"""Recordings of foreign layouts (gcalign.io.recorded): the real lasergyro.imu rewritten in
each layout of spec 005 must align exactly as the PSINS file does; wrong axes, units and
timing are refused with one line naming the file and what is allowed."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
from cli_checks import assert_bad_input
from typer.testing import CliRunner

from conftest import LASERGYRO_XZ, ROOT
from gcalign.cli import app
from gcalign.errors import ScenarioError
from gcalign.io.imu_files import read_imu_file, read_psins_imu
from gcalign.io.recorded import Layout, read_recording, rotation_to_rfu
from gcalign.units import DEG

runner = CliRunner()
SITE = ["--lat", "34.246048", "--lon", "108.909664", "--height", "380"]  # lasergyro's header
SOW0 = 456300.0  # GNSS seconds of week of the recording's t = 0 (any value does)
KEEP = 30_500  # samples written: the recorded-data alignment reads [0, 300 s]


@pytest.fixture(scope="module")
def laser(lasergyro):
    imu = read_psins_imu(lasergyro)
    return imu.t[:KEEP], imu.dtheta[:KEEP], imu.dv[:KEEP], imu.ts


def frd(v):
    """RFU rows -> the same vectors in FRD axes (x forward, y right, z down)."""
    return np.column_stack([v[:, 1], v[:, 0], -v[:, 2]])


@pytest.fixture(scope="module")
def foreign(laser, tmp_path_factory):
    """lasergyro's first 305 s in three foreign layouts."""
    t, dth, dv, ts = laser
    d = tmp_path_factory.mktemp("foreign")
    i2nav = d / "laser_i2nav.txt"  # KF-GINS: sow, dθ, dv in FRD
    np.savetxt(i2nav, np.column_stack([SOW0 + t, frd(dth), frd(dv)]), fmt="%.17g")
    rates = d / "laser_rates.csv"  # gnss-ins-sim style: rates in FRD, time first, units named
    np.savetxt(rates, np.column_stack([t, frd(dth) / ts / DEG, frd(dv) / ts]), fmt="%.17g",
               delimiter=",", comments="", header="time (s),gyro_x (deg/s),gyro_y (deg/s),"
               "gyro_z (deg/s),accel_x (m/s^2),accel_y (m/s^2),accel_z (m/s^2)")
    mat = d / "laser.mat"  # PSINS [wm vm t], time last
    scipy.io.savemat(mat, {"imu": np.column_stack([dth, dv, t])})
    return {"i2nav": i2nav, "rates": rates, "mat": mat}


def align(*args):
    res = runner.invoke(app, ["align", *map(str, args), "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


@pytest.fixture(scope="module")
def psins_yaw(tmp_path_factory):
    out = tmp_path_factory.mktemp("ref") / "psins.h5"
    s = align("--imu-file", LASERGYRO_XZ, "-o", out)
    assert s["scenario"] == "lasergyro"  # the file's name, not the built-in scenario's
    return s["coarse_attitude_deg"][2], s["attitude_t3_deg"][2]


def test_the_psins_file_alone_aligns_with_the_recorded_data_defaults(psins_yaw):
    """`align --imu-file lasergyro.imu.xz` alone: inertial coarse over 60 s, one gyrocompass
    pass to 300 s; the yaw lands on the known −90.6° (DESIGN: −90.58…−90.62°)."""
    coarse, fine = psins_yaw
    assert fine == pytest.approx(-90.6, abs=0.03)
    assert coarse == pytest.approx(-90.6, abs=1.0)


@pytest.mark.slow
def test_the_psins_file_alone_calibrates_with_the_recorded_data_defaults(tmp_path):
    """`calibrate --imu-file lasergyro.imu.xz` alone: the recording taken as parked
    (inertial coarse over 60 s, zero-velocity updates), named after the file; the INS yaw
    at the end lands on the known −90.6°."""
    res = runner.invoke(app, ["calibrate", "--imu-file", str(LASERGYRO_XZ), "--json", "-o",
                              str(tmp_path / "c.h5")])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["scenario"] == "lasergyro"
    assert s["attitude_deg"][2] == pytest.approx(-90.6, abs=0.03)


@pytest.mark.parametrize("case, options", [
    ("i2nav", ["--format", "i2nav", "--axes", "FRD"]),
    ("rates", ["--format", "csv", "--axes", "FRD"]),
    ("mat", ["--format", "psins-mat", "--axes", "RFU"]),
])
def test_foreign_layouts_align_as_the_psins_file(case, options, foreign, psins_yaw, tmp_path):
    """The same increments in FRD with GNSS seconds of week, as rates in °/s and m/s² with
    time first, and as a PSINS [wm vm t] MAT array: the same inertial-coarse and
    gyrocompass yaw, with no option but the format and axes (and the site, which these
    files do not carry)."""
    s = align("--imu-file", foreign[case], *options, *SITE, "-o", tmp_path / "a.h5")
    coarse, fine = psins_yaw
    print(f"{case}: coarse yaw {s['coarse_attitude_deg'][2]:.9f}° (PSINS {coarse:.9f}°), "
          f"gyrocompass yaw {s['attitude_t3_deg'][2]:.9f}° (PSINS {fine:.9f}°)")
    assert abs(s["coarse_attitude_deg"][2] - coarse) < 0.01
    assert abs(s["attitude_t3_deg"][2] - fine) < 0.01
    # the increments are the same numbers (round-off of the unit conversion only)
    assert abs(s["attitude_t3_deg"][2] - fine) < 1e-6
    import h5py

    with h5py.File(tmp_path / "a.h5") as f:
        record = json.loads(f["recording"].attrs["record_json"])
    assert record["axes"] == options[3] and record["format"] == options[1]
    if case == "rates":
        assert record["units"] == {"gyro": "deg/s", "accel": "m/s^2"}
        assert record["quantity"] == "rates" and record["units_source"] == "header row"
    if case == "i2nav":
        assert record["t_first_s"] == pytest.approx(SOW0 + 0.01)
        assert record["time_origin"] == "GNSS seconds of week"


@pytest.mark.slow
def test_i2nav_through_the_installed_command_line(foreign, psins_yaw, tmp_path):
    """The same through `python -m gcalign` (a fresh process, as a user runs it)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    res = subprocess.run([sys.executable, "-m", "gcalign", "align", "--imu-file",
                          str(foreign["i2nav"]), "--format", "i2nav", "--axes", "FRD", *SITE,
                          "-o", str(tmp_path / "a.h5"), "--json"], capture_output=True,
                         text=True, env=env, cwd=tmp_path, timeout=300)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["attitude_t3_deg"][2] == pytest.approx(psins_yaw[1],
                                                                         abs=1e-6)


def test_the_frd_file_read_as_rfu_is_refused_by_the_gravity_check(foreign, tmp_path):
    out = tmp_path / "a.h5"
    res = runner.invoke(app, ["align", "--imu-file", str(foreign["i2nav"]), "--format",
                              "i2nav", "--axes", "RFU", *SITE, "-o", str(out)])
    assert_bad_input(res, out, "imu_file", "looks like FRD", "file z points down",
                     "-9.79 m/s² along z (up)")
    print(res.output.strip())


def test_the_reader_record_and_gravity_in_rfu(foreign, laser):
    t, dth, dv, ts = laser
    imu = read_recording(foreign["i2nav"], Layout(format="i2nav"))  # FRD is i2nav's own
    np.testing.assert_array_equal(imu.dtheta, dth)  # a signed permutation: exact
    np.testing.assert_array_equal(imu.dv, dv)
    np.testing.assert_allclose(imu.t, SOW0 + t, rtol=0, atol=1e-9)
    assert imu.ts == pytest.approx(ts, rel=1e-12)
    rec = imu.meta["recording"]
    assert rec["axes"] == "FRD" and rec["axes_source"] == "i2nav default"
    f = np.asarray(rec["gravity_check"]["specific_force_rfu_mps2"])
    assert f[2] == pytest.approx(9.79, abs=0.01) and rec["gravity_check"]["tilt_deg"] < 2
    rates = read_recording(foreign["rates"], Layout(format="csv", axes="FRD"))
    np.testing.assert_allclose(rates.dtheta, dth, rtol=1e-14, atol=1e-22)
    np.testing.assert_allclose(rates.dv, dv, rtol=1e-14, atol=1e-20)


def test_compressed_files_are_read_by_read_imu_file(lasergyro):
    """read_imu_file reads .xz (and .gz) as the plain file."""
    a, b = read_imu_file(LASERGYRO_XZ), read_imu_file(lasergyro)
    np.testing.assert_array_equal(a.dtheta, b.dtheta)
    np.testing.assert_array_equal(a.dv, b.dv)
    assert a.source == str(LASERGYRO_XZ)


# --------------------------------------------------------------------------- axes


def test_every_proper_signed_permutation_and_no_other():
    """All 48 letter triples of one letter per pair: the 24 right-handed ones are rotations
    (C C^T = I, det +1), the 24 others are refused naming the handedness."""
    import itertools

    good = bad = 0
    for pairs in itertools.permutations(["RL", "FB", "UD"]):
        for signs in itertools.product([0, 1], repeat=3):
            text = "".join(p[s] for p, s in zip(pairs, signs, strict=True))
            try:
                C = rotation_to_rfu(text)
            except ScenarioError as err:
                assert "left-handed" in str(err)
                bad += 1
                continue
            np.testing.assert_array_equal(C @ C.T, np.eye(3))
            assert np.linalg.det(C) == pytest.approx(1.0)
            good += 1
    assert good == bad == 24
    np.testing.assert_array_equal(rotation_to_rfu("enu"), np.eye(3))
    np.testing.assert_array_equal(rotation_to_rfu("NED"), rotation_to_rfu("FRD"))
    # FLU (ROS): x forward = our y, y left = our -x, z up
    np.testing.assert_array_equal(rotation_to_rfu("f, l, u") @ [1, 0, 0], [0, 1, 0])
    np.testing.assert_array_equal(rotation_to_rfu("FLU") @ [0, 1, 0], [-1, 0, 0])


@pytest.mark.parametrize("axes, message", [
    ("FRU", "left-handed"), ("FFU", "two axes point F/B"), ("XYZ", "three letters"),
    ([[1, 0, 0], [0, 1, 0], [0, 0, -1]], "reflection"), ([[1, 0], [0, 1]], "3x3"),
    ([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], "not orthonormal"),
])
def test_axes_that_are_not_rotations_are_refused(axes, message):
    with pytest.raises(ScenarioError, match=message):
        rotation_to_rfu(axes)


# --------------------------------------------------------------------------- bad input


def _small_i2nav(path, t, rows=400, gravity=-9.79):
    """A static FRD recording at 100 Hz (gravity along -z of FRD is up)."""
    dth = np.tile([7e-7, 0.0, -4e-7], (rows, 1))
    dv = np.tile([0.0, 0.0, gravity * 0.01], (rows, 1))
    np.savetxt(path, np.column_stack([t, dth, dv]), fmt="%.17g")
    return path


@pytest.mark.parametrize("edit, options, field, more", [
    (None, ["--format", "kf-gins"], "imu_file.format", ("'kf-gins' is not a format",
                                                        "psins, psins-mat, i2nav, csv")),
    (None, ["--format", "i2nav", "--axes", "FRU"], "imu_file.axes",
     ("'FRU' is not a rotation", "left-handed")),
    (None, ["--format", "i2nav", "--axes", "FXD"], "imu_file.axes", ("F/B",)),
    ("nan", ["--format", "i2nav"], "d.txt:101", ("must be finite", "nan")),
    ("gap", ["--format", "i2nav"], "d.txt:201", ("time jumps from", "max_gap_s: 0.5 to fill it")),
    ("backwards", ["--format", "i2nav"], "d.txt:201", ("time must increase strictly",)),
    ("g", ["--format", "i2nav"], "imu_file", ("accelerometer units",)),
    (None, ["--format", "psins-mat"], "d.txt", ("not a MATLAB file",)),
])
def test_bad_recordings_exit_2_with_one_line(tmp_path, edit, options, field, more):
    t = SOW0 + 0.01 * np.arange(1, 401)
    if edit == "gap":
        t[200:] += 0.5
    if edit == "backwards":
        t[200] = t[198]
    path = _small_i2nav(tmp_path / "d.txt", t, gravity=-9.79 / 9.8 if edit == "g" else -9.79)
    if edit == "nan":
        lines = path.read_text().splitlines()
        lines[100] = lines[100].rsplit(" ", 1)[0] + " nan"
        path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "n.h5"
    res = runner.invoke(app, ["align", "--imu-file", str(path), *options, *SITE, "-o",
                              str(out)])
    assert_bad_input(res, out, field, *more)


def test_a_key_the_format_fixes_is_refused(tmp_path):
    """Units of a PSINS file come from its header: declaring them is an error (and --set
    cannot reach into imu_file, which the override checker knows as a path: --format,
    --axes or the mapping in the scenario declare a layout; decision 011)."""
    out = tmp_path / "n.h5"
    res = runner.invoke(app, ["align", "--imu-file", str(LASERGYRO_XZ), "--set",
                              "imu_file.units={gyro: deg}", "-o", str(out)])
    assert_bad_input(res, out, "--set imu_file.units", "no keys")
    sc = {"name": "x", "imu_file": {"path": str(LASERGYRO_XZ), "units": {"gyro": "deg"}}}
    from gcalign.io.scenario import parse_scenario

    with pytest.raises(ScenarioError, match="imu_file.units: cannot matter with format "
                       "'psins'"):
        read_recording(LASERGYRO_XZ, parse_scenario(sc, "t").recording_layout())


def test_a_gap_within_max_gap_s_is_filled_and_said(tmp_path):
    t = SOW0 + 0.01 * np.arange(1, 401)
    t[200:] += 0.03  # three samples lost
    path = _small_i2nav(tmp_path / "d.txt", t)
    imu = read_recording(path, Layout(format="i2nav", max_gap_s=0.05))
    assert len(imu) == 403
    np.testing.assert_allclose(np.diff(imu.t), 0.01, atol=1e-8)
    rec = imu.meta["recording"]
    assert rec["gaps"] == [{"after_t_s": pytest.approx(SOW0 + 2.0), "length_s":
                            pytest.approx(0.03), "samples_filled": 3}]
    assert "filled with 3 sample(s)" in rec["warnings"][0]
    np.testing.assert_allclose(imu.dtheta[200:203], imu.dtheta[199:202])  # the rate held


def test_jitter_is_accepted_with_a_warning(tmp_path):
    t = SOW0 + 0.01 * np.arange(1, 401) + 0.0002 * np.sin(np.arange(400))
    imu = read_recording(_small_i2nav(tmp_path / "d.txt", t), Layout(format="i2nav"))
    rec = imu.meta["recording"]
    assert 0.015 < rec["jitter_max"] < 0.05
    assert "jitter by up to" in rec["warnings"][0]


def test_week_rollover_is_unwrapped(tmp_path):
    t = 604799.0 + 0.01 * np.arange(1, 401)
    t = np.where(t >= 604800.0, t - 604800.0, t)
    imu = read_recording(_small_i2nav(tmp_path / "d.txt", t), Layout(format="i2nav"))
    np.testing.assert_allclose(np.diff(imu.t), 0.01, atol=1e-8)
    assert imu.meta["recording"]["week_rollovers"] == 1


def test_mat_file_variable_choice(tmp_path):
    """A MAT file with one [wm vm t] array needs no variable; with two it names them."""
    real = read_recording(ROOT / "tests/data/transfer_align_fog_mems.mat",
                          Layout(format="psins-mat"))
    assert len(real) == 10001 and real.ts == pytest.approx(0.01)
    assert real.meta["recording"]["variable"] == "mimu"
    two = tmp_path / "two.mat"
    a = np.column_stack([np.zeros((50, 5)), np.full(50, 0.098), 0.01 * np.arange(1, 51)])
    scipy.io.savemat(two, {"imu": a, "mimu": a})
    with pytest.raises(ScenarioError, match="more than one array of 7 columns.*imu"):
        read_recording(two)
    assert len(read_recording(two, Layout(format="psins-mat", variable="imu"))) == 50


def test_validate_shows_what_was_assumed(foreign, tmp_path):
    import yaml

    sc = {"name": "ride", "site": {"lat_deg": 34.246048, "lon_deg": 108.909664},
          "imu_file": {"path": str(foreign["rates"]), "format": "csv", "axes": "FRD"}}
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["validate", str(p), "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    assert values["imu_file.format"]["value"] == "csv"
    assert values["imu_file.axes"]["value"] == "FRD (declared)"
    assert values["imu_file.axes"]["si"] == "v_rfu = C v_file, C = [[0, 1, 0], [1, 0, 0], " \
        "[0, 0, -1]]"
    assert values["imu_file.units"]["value"] == "gyro deg/s, accel m/s^2"
    assert values["imu_file.units"]["si"].startswith("rates: rectangular")
    assert values["imu_file.rate"]["value"] == "100 Hz (median time step)"
    assert values["imu_file.gaps"]["value"] == "none"


def test_the_imu_file_mapping_survives_a_dump():
    """A scenario with a layout dumps (the API's scenario text) to the same mapping and
    loads back to the same model; a plain path stays a plain path."""
    from gcalign.io.scenario import parse_scenario

    data = {"name": "x", "imu_file": {"path": "/d/ride.txt", "format": "csv", "axes": "FLU",
                                      "units": {"gyro": "deg/s", "accel": "g"},
                                      "max_gap_s": 0.05}}
    sc = parse_scenario(json.loads(json.dumps(data)), "t")
    dumped = sc.model_dump(mode="json", exclude_unset=True)
    assert dumped == data
    assert parse_scenario(dumped, "t") == sc
    plain = parse_scenario({"name": "x", "imu_file": "/d/a.imu"}, "t")
    assert plain.model_dump(mode="json", exclude_unset=True)["imu_file"] == "/d/a.imu"
    assert plain.recording_layout() == Layout()


def _still_csv(path, header, seconds=4.0):
    """A CSV of a still IMU at 100 Hz (rad and m/s increments, z up) under `header`."""
    t = np.arange(1, int(seconds * 100) + 1) * 0.01
    rows = np.column_stack([t, np.zeros((len(t), 5)), np.full(len(t), 0.098)])
    np.savetxt(path, rows, fmt="%.6g", delimiter=",", comments="", header=header)
    return path


def test_unrecognised_header_is_refused_pointing_to_columns_and_units(tmp_path):
    """A header row whose names gcalign does not know is never read as rad and m/s in
    silence: the refusal says how to declare the layout; declared units read it."""
    f = _still_csv(tmp_path / "own.csv", "stamp,rx,ry,rz,sx,sy,sz")
    out = tmp_path / "out.h5"
    res = runner.invoke(app, ["align", "--imu-file", str(f), *SITE, "-o", str(out)])
    assert_bad_input(res, out, "imu_file", "'stamp,rx,ry,rz,sx,sy,sz'", "columns: [t, gx",
                     "units: {gyro: rad | deg", "accel: m/s | m/s^2 | g}")
    imu = read_recording(f, Layout(format="csv", gyro_units="rad", accel_units="m/s"))
    np.testing.assert_allclose(imu.dv[:, 2], 0.098)


def test_recording_too_short_names_the_times_not_the_motion(tmp_path):
    f = _still_csv(tmp_path / "short.csv", "t,gx,gy,gz,ax,ay,az")
    out = tmp_path / "out.h5"
    res = runner.invoke(app, ["align", "--imu-file", str(f), *SITE, "-o", str(out)])
    assert_bad_input(res, out, "align.t1_s", "past the end of the data (4.00 s)", "--t1")
    assert "motion.duration_s" not in res.output


def test_block_parse_gives_the_line_by_line_rows(monkeypatch):
    """A table parsed a block of lines at a time (without a list of its lines) gives the
    rows of the line-by-line parse to the bit, across block edges, with a header, comments,
    blank lines and CRLF; a bad field goes to the line-by-line parse and its message."""
    from gcalign.io.imu_files import ImuFileError
    from gcalign.io.recorded import imu as rec

    rng = np.random.default_rng(3)
    rows = rng.standard_normal((500, 7)) * [1e5, 1e-6, 1e-6, 1e-6, 1e-3, 1e-3, 1e-1]
    lines = ["# a comment", "t gx gy gz ax ay az", ""]
    for i, r in enumerate(rows):
        lines.append(" ".join(repr(float(x)) for x in r) + ("  % tail" if i % 97 == 0 else ""))
        if i % 131 == 0:
            lines.append("")
    data = "\r\n".join(lines).encode()
    monkeypatch.setattr(rec, "_BLOCK_BYTES", 777)  # many blocks, cut inside lines
    fast, (head, _) = rec._table_of("f.txt", data, 7, tuple("abcdefg"))
    slow, (head2, _) = rec._table("f.txt", rec._text_lines("f.txt", data), 7, tuple("abcdefg"))
    assert np.array_equal(fast, slow) and fast.shape == (500, 7) and head == head2
    bad = data.replace(repr(float(rows[250, 3])).encode(), b"nan", 1)
    with pytest.raises(ImuFileError, match=r"f\.txt:\d+: field 4 \(d\) must be finite"):
        rec._table_of("f.txt", bad, 7, tuple("abcdefg"))
