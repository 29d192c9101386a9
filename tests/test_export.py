"""`gcalign export` and the series of a results file: CSV and MAT read back equal the HDF5
series; the KF-GINS (NED, FRD) attitude equals the matrices'; xarray sees the time
coordinate; pandas gets a DataFrame."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
import yaml
from cli_checks import assert_bad_input
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.io import results
from gcalign.nav.rotation import euler_to_dcm

runner = CliRunner()
SWING = {
    "name": "swing-export",
    "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 20},
    "imu": {"rate_hz": 100, "seed": 3, "gyro": {"bias_dph": 0.01, "arw_dprh": 0.001},
            "accel": {"bias_ug": 50, "vrw_ugrhz": 10}},
    "motion": {"kind": "swing", "attitude_deg": [1, -2, 150], "duration_s": 20,
               "swing": {"amplitude_deg": [2, 3, 40], "period_s": [10, 10, 20]}},
}


@pytest.fixture(scope="module")
def nav(tmp_path_factory):
    d = tmp_path_factory.mktemp("export")
    (d / "s.yaml").write_text(yaml.safe_dump(SWING))
    out = d / "nav.h5"
    res = runner.invoke(app, ["navigate", str(d / "s.yaml"), "-o", str(out)])
    assert res.exit_code == 0, res.output
    return out


def h5_series(path):
    """The navigate group's series read with plain h5py (errors in its subgroup)."""
    with h5py.File(path) as f:
        g = f["navigate"]
        out = {k: g[k][()] for k in ("t", "att", "v_n", "pos")}
        out |= {f"error_{k}": g["error"][k][()] for k in g["error"]}
        return out


def test_csv_round_trip(nav, tmp_path):
    out = tmp_path / "nav.csv"
    res = runner.invoke(app, ["export", str(nav), "--format", "csv", "-o", str(out)])
    assert res.exit_code == 0, res.output
    header = out.read_text().splitlines()[1].split(",")
    assert header[:4] == ["t (s)", "att_pitch (rad)", "att_roll (rad)", "att_yaw (rad)"]
    assert "pos_h (m)" in header and "v_n_e (m/s)" in header
    back = np.loadtxt(out, delimiter=",", skiprows=2)
    stored = h5_series(nav)
    assert set(results.series(nav, "navigate")) == set(stored)  # errors too
    column = 0
    for name in results.series(nav, "navigate"):
        a = stored[name].reshape(len(stored["t"]), -1)
        np.testing.assert_array_equal(back[:, column:column + a.shape[1]], a)
        column += a.shape[1]
    assert column == back.shape[1]


def test_mat_round_trip_with_units(nav, tmp_path):
    out = tmp_path / "nav.mat"
    res = runner.invoke(app, ["export", str(nav), "--format", "mat", "-o", str(out)])
    assert res.exit_code == 0, res.output
    m = scipy.io.loadmat(out, squeeze_me=True)
    for name, a in h5_series(nav).items():
        np.testing.assert_array_equal(np.asarray(m[name]).reshape(a.shape), a)
    assert str(m["units"]["pos"]) == "rad, rad, m" and str(m["units"]["t"]) == "s"
    assert str(m["group"]) == "navigate"


def test_i2nav_nav_is_the_same_attitude_in_ned_frd(nav, tmp_path):
    """roll, pitch, yaw of the KF-GINS file, as z-y-x Euler angles of C_ned_frd, rebuild
    the same rotation as gcalign's C_enu_rfu (a check against the matrices, not the formula
    that wrote the file)."""
    out = tmp_path / "nav.nav"
    res = runner.invoke(app, ["export", str(nav), "--format", "i2nav-nav", "--week", "2190",
                              "-o", str(out)])
    assert res.exit_code == 0, res.output
    rows = np.loadtxt(out)
    s = h5_series(nav)
    assert rows.shape == (len(s["t"]), 11) and (rows[:, 0] == 2190).all()
    np.testing.assert_array_equal(rows[:, 1], s["t"])
    np.testing.assert_allclose(np.radians(rows[:, 2:4]), s["pos"][:, :2], rtol=1e-15)
    np.testing.assert_allclose(rows[:, 5:8], s["v_n"][:, [1, 0, 2]] * [1, 1, -1], atol=0)
    roll, pitch, yaw = np.radians(rows[:, 8:11]).T
    cr, sr, cp, sp, cy, sy = (np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                              np.cos(yaw), np.sin(yaw))
    z, o = np.zeros_like(roll), np.ones_like(roll)
    Rz = np.stack([np.stack([cy, -sy, z], -1), np.stack([sy, cy, z], -1),
                   np.stack([z, z, o], -1)], -2)
    Ry = np.stack([np.stack([cp, z, sp], -1), np.stack([z, o, z], -1),
                   np.stack([-sp, z, cp], -1)], -2)
    Rx = np.stack([np.stack([o, z, z], -1), np.stack([z, cr, -sr], -1),
                   np.stack([z, sr, cr], -1)], -2)
    C_ned_frd = Rz @ Ry @ Rx
    T = np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, -1]])  # ENU <-> NED, RFU <-> FRD alike
    C_enu_rfu = T @ C_ned_frd @ T
    np.testing.assert_allclose(C_enu_rfu, euler_to_dcm(s["att"]), atol=1e-13)
    assert np.ptp(rows[:, 10]) > 60  # the yaw swings ±40°: a real test of the heading


def test_psins_avp_layout(nav, tmp_path):
    out = tmp_path / "nav.avp.mat"
    res = runner.invoke(app, ["export", str(nav), "--format", "psins-avp", "-o", str(out)])
    assert res.exit_code == 0, res.output
    avp = scipy.io.loadmat(out)["avp"]
    s = h5_series(nav)
    np.testing.assert_array_equal(avp, np.column_stack([s["att"], s["v_n"], s["pos"], s["t"]]))


def test_xarray_sees_the_time_coordinate(nav):
    xr = pytest.importorskip("xarray")  # in the dev extras, with h5netcdf
    pytest.importorskip("h5netcdf")
    ds = xr.open_dataset(nav, group="navigate", engine="h5netcdf")
    assert "t" in ds.coords and ds["att"].dims == ("t", "component")
    np.testing.assert_array_equal(ds["t"].values, h5_series(nav)["t"])
    assert not any(d.startswith("phony_dim") for d in ds.dims)
    ds.close()


def test_series_and_dataframe(nav):
    s = results.series(nav, "navigate")
    assert s["att"][1] == "rad" and s["t"][0].shape == (2001,)
    pd = pytest.importorskip("pandas")
    df = results.dataframe(nav, "navigate")
    assert isinstance(df, pd.DataFrame) and df.index.name == "t"
    np.testing.assert_array_equal(df["att_yaw"].to_numpy(), s["att"][0][:, 2])
    assert df.attrs["units"]["pos_h"] == "m" and df.attrs["units"]["pos_lat"] == "rad"


@pytest.mark.parametrize("reader", [results.series, results.columns])
def test_a_group_without_series_is_named_by_every_reader(nav, reader):
    """series() and columns() (and so dataframe()) refuse a missing group, or one without
    a time, in the same words: not as a damaged file."""
    with pytest.raises(ValueError, match=r"--group: .*nav\.h5 has no group 'nope'; it has "
                                         r"navigate$"):
        reader(nav, "nope")
    with pytest.raises(ValueError, match=r"/navigate/error has no time series \(no 1-D "
                                         r"dataset 't'\); groups that have: navigate$"):
        reader(nav, "navigate/error")


def test_the_python_result_gives_the_same_series(nav):
    import gcalign

    res = gcalign.read(nav)
    s, direct = res.series(), results.series(nav, "navigate")
    assert list(s) == list(direct)
    np.testing.assert_array_equal(s["v_n"][0], direct["v_n"][0])
    np.testing.assert_array_equal(res.dataframe()["pos_h"].to_numpy(), direct["pos"][0][:, 2])


@pytest.mark.parametrize("args, field, more", [
    (["--format", "xls"], "--format", ("'xls' is not an export format", "csv, mat")),
    (["--format", "csv", "--group", "align"], "--group", ("no group 'align'",)),
    (["--format", "i2nav-nav", "--group", "truth"], "--group", ("no group 'truth'",)),
])
def test_bad_export_exits_2_with_one_line(nav, tmp_path, args, field, more):
    out = tmp_path / "x.out"
    res = runner.invoke(app, ["export", str(nav), *args, "-o", str(out)])
    assert_bad_input(res, out, field, *more)
    assert not list(tmp_path.iterdir())  # no temporary file left either


def test_export_json(nav, tmp_path):
    res = runner.invoke(app, ["export", str(nav), "--format", "csv", "-o",
                              str(tmp_path / "a.csv"), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["output"] == str(tmp_path / "a.csv")


@pytest.mark.parametrize("fmt", ["mat", "psins-avp"])
def test_a_mat_export_is_the_same_bytes_on_another_day(nav, tmp_path, monkeypatch, fmt):
    """scipy writes the date into a MAT file's header: two exports of one results file
    differed. The header names gcalign and the source file instead."""
    import time

    outs = []
    for day in ("Mon Jan  5 10:00:00 2026", "Tue Jan  6 11:11:11 2026"):
        monkeypatch.setattr(time, "asctime", lambda *a, day=day: day)
        outs.append(tmp_path / f"{len(outs)}.mat")
        res = runner.invoke(app, ["export", str(nav), "--format", fmt, "-o", str(outs[-1])])
        assert res.exit_code == 0, res.output
    assert outs[0].read_bytes() == outs[1].read_bytes()
    assert outs[0].read_bytes()[:116].rstrip() == b"MATLAB 5.0 MAT-file, written by gcalign " + \
        __import__("gcalign").__version__.encode() + b" from nav.h5"
    assert scipy.io.loadmat(outs[0])  # still a MAT file


@pytest.mark.parametrize("fmt", ["csv", "mat", "i2nav-nav", "psins-avp"])
def test_an_export_past_the_output_limit_is_refused_before_writing(nav, tmp_path, fmt,
                                                                   monkeypatch):
    """GCALIGN_MAX_OUTPUT_MB holds for export too (it wrote whatever the series made)."""
    monkeypatch.setenv("GCALIGN_MAX_OUTPUT_MB", "0.001")
    out = tmp_path / "x.out"
    res = runner.invoke(app, ["export", str(nav), "--format", fmt, "-o", str(out)])
    assert_bad_input(res, out, "GCALIGN_MAX_OUTPUT_MB", f"as {fmt}", "more than the limit")
    assert not list(tmp_path.iterdir())


def test_align_and_calibrate_export_without_group(tmp_path):
    """An alignment exports its last pass (the one whose end is the result), a calibration
    its run, each column named by its component and state with that state's own unit."""
    sc = tmp_path / "s.yaml"
    sc.write_text(yaml.safe_dump(SWING))
    al, cal = tmp_path / "al.h5", tmp_path / "cal.h5"
    res = runner.invoke(app, ["align", str(sc), "--t1", "2", "--t2", "20", "--t3", "20",
                              "--passes", "3", "--set", "align.level_s=5", "-o", str(al)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["calibrate", str(sc), "-o", str(cal)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["export", str(al), "--format", "csv", "-o", str(tmp_path / "a.csv")])
    assert res.exit_code == 0, res.output
    assert "exported /align/pass_03; --group for another: align/pass_01, align/pass_02" \
        in res.output
    lines = (tmp_path / "a.csv").read_text().splitlines()
    assert "group /align/pass_03" in lines[0]
    assert lines[1].split(",")[4:7] == ["error_pitch (rad)", "error_roll (rad)",
                                        "error_yaw (rad)"]
    with h5py.File(al) as f:
        np.testing.assert_array_equal(np.loadtxt(lines[2:], delimiter=",")[:, 1:4],
                                      f["align/pass_03/att"][()])
    res = runner.invoke(app, ["export", str(cal), "--format", "csv", "-o", str(tmp_path / "c.csv")])
    assert res.exit_code == 0, res.output
    header = (tmp_path / "c.csv").read_text().splitlines()[1].split(",")
    for col in ("estimate_phiU (rad)", "estimate_ebz (rad/s)", "estimate_dbx (m/s^2)",
                "sigma_dKgz (1)", "truth_dh (m)"):
        assert col in header
    assert not any("_0 (" in h or "(SI)" in h for h in header)
