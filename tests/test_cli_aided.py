"""``gcalign calibrate`` on a recording as a KF-GINS user has it (i2nav IMU text, GNSS-RTK
text with σ per fix and an outage, the truth as an i2nav-nav reference), end to end: the
JSON, the file, export and plot. Bounds from the simulation and the filter's consistency."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
from aided_files import SOW0, write_vehicle
from scipy.stats import chi2
from typer.testing import CliRunner

from gcalign.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("vehicle")
    paths = write_vehicle(folder, seed=4, duration=130.0, outages=((60.0, 90.0),))
    out = folder / "out.h5"
    res = runner.invoke(app, ["calibrate", str(paths["scenario"]), "--smoother", "-o",
                              str(out), "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.strip().splitlines()[-1]), out, paths


def test_the_fixes_their_outage_and_the_start_as_given(run):
    s, _, paths = run
    fx = s["fixes"]
    assert s["components"] == "3d" and s["aiding"] == "file"
    assert fx["time_origin"] == "GNSS seconds of week"
    assert fx["sigma"] == "the file's, per fix"
    assert [(round(o["start_data_s"] - SOW0, 3), round(o["end_data_s"] - SOW0, 3))
            for o in fx["outages"]] == [(59.373, 90.373)]
    assert s["start"]["source"].startswith("keys initial")
    assert s["updates"] == fx["epochs"] and s["predict_only_epochs"] >= 30
    lo, hi = chi2.ppf([0.0005, 0.9995], 3 * s["updates"]) / s["updates"]
    assert lo < s["nis"]["mean"] < hi
    assert not s["warnings"], s["warnings"]


def test_errors_inside_and_outside_the_outage(run):
    """Outside: within the fixes' σ (0.05–0.5 m); inside the 31 s outage the tactical IMU
    drifts (a 200 µg bias alone: ½·2e-3·31² ≈ 1 m) and the smoother brings it back to the
    fixes' level."""
    s, _, _ = run
    e = s["solution_errors"]
    assert e["against"] == "reference"
    assert e["outside_outages"]["horizontal_rms_m"] < 0.5
    inside = e["in_outages"]
    assert inside["samples"] == 3100
    assert 0.05 < inside["horizontal_max_m"] < 5.0
    sm = s["epoch_errors"]["smoothed"]["in_outages"]
    fw = s["epoch_errors"]["forward"]["in_outages"]
    assert sm["horizontal_rms_m"] < 0.5 * fw["horizontal_rms_m"]


@pytest.mark.slow
def test_the_solution_at_every_sample_exports_in_gnss_time(run, tmp_path):
    _, out, paths = run
    with h5py.File(out) as f:
        nav = f["calibrate/runs/00/navigation"]
        t, t_run = nav["t"][()], nav["t_run"][()]
        assert nav.attrs["time_origin"] == "GNSS seconds of week"
    n_imu = len(np.loadtxt(paths["imu"], usecols=0))
    assert len(t) == n_imu + 1 and t[0] == pytest.approx(SOW0, abs=1e-6)
    np.testing.assert_allclose(t - t_run, SOW0, atol=1e-6)
    res = runner.invoke(app, ["export", str(out), "--format", "i2nav-nav", "--week", "2100",
                              "-o", str(tmp_path / "sol.nav")])
    assert res.exit_code == 0, res.output
    rows = np.loadtxt(tmp_path / "sol.nav")
    truth = np.loadtxt(paths["truth"])
    assert rows.shape == truth.shape and (rows[:, 0] == 2100).all()
    np.testing.assert_allclose(rows[:, 1], truth[:, 1], atol=1e-6)
    # the exported solution against the truth file, as KF-GINS's plot script would
    r_m = 6.37e6
    north = np.radians(rows[:, 2] - truth[:, 2]) * r_m
    assert np.sqrt(np.mean(north ** 2)) < 1.0
    res = runner.invoke(app, ["plot", str(out), "-o", str(tmp_path / "fig")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "fig" / "solution_errors.png").exists()
