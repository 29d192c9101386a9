"""`gcalign align --mode transfer` end to end on PSINS's FOG/MEMS file (spec 006): the config
runs the demo case with one command; the JSON contract (states in calibrate's shape, SI);
the results group with units; the figure; bad input exits 2 with one line.

References are the file's own stored values (``mu0``, ``eb0``) read here with scipy, and
the core's result on the same arrays (the command must add nothing to the numbers)."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
import yaml
from cli_checks import assert_bad_input, assert_bad_run
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.units import ARCMIN, DPH

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "configs" / "psins_transfer_fog_mems.yaml"
DATA = ROOT / "tests" / "data" / "transfer_align_fog_mems.mat"
runner = CliRunner()


def _align(*args):
    return runner.invoke(app, ["align", *map(str, args)])


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("transfer") / "demo.h5"
    res = _align(CONFIG, "--json", "-o", out)
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), out


def test_config_runs_the_demo_case_in_one_command(demo):
    s, _ = demo
    d = scipy.io.loadmat(DATA)
    mu = np.array([s["states"][n]["estimate"] for n in ("mux", "muy", "muz")])
    assert np.all(np.abs(mu - d["mu0"].ravel()) < 1 * ARCMIN), mu / ARCMIN
    eb = np.array([s["states"][n]["estimate"] for n in ("ebx", "eby")])
    assert np.all(np.abs(eb - d["eb0"].ravel()[:2]) < 2 * DPH), eb / DPH
    assert set(s["states"]) == set(s["convergence_s"]) and len(s["states"]) == 21
    for v in s["states"].values():
        assert set(v) == {"estimate", "sigma", "sigma0"} and 0 < v["sigma"] <= v["sigma0"]
    assert s["states"]["mux"]["sigma0"] == pytest.approx(np.radians(1.0))  # SI: rad
    e = s["attitude_error_vs_reference_arcmin"]
    assert len(e["final"]) == 3 and len(e["rms_last_10s"]) == 3
    assert s["psins_stored"]["mu0_arcmin"] == pytest.approx(d["mu0"].ravel() / ARCMIN)


def test_command_adds_nothing_to_the_core(demo):
    from gcalign.transfer import MasterSeries, TransferSettings, transfer_align

    s, _ = demo
    d = scipy.io.loadmat(DATA)
    m, f = d["mimu"], d["fogavp"]
    r = transfer_align(m[:, :3], m[:, 3:6], m[:, 6],
                       MasterSeries(f[:, 9], f[:, :3], f[:, 3:6], f[:, 6:9]), TransferSettings())
    for i, n in enumerate(r.names):
        assert s["states"][n]["estimate"] == r.x[-1, i]
        assert s["states"][n]["sigma"] == r.sigma[-1, i]


def test_results_group_and_figure(demo):
    s, out = demo
    with h5py.File(out) as f:
        g = f["align/transfer"]
        names = g.attrs["states"].split(",")
        assert names == list(s["states"])
        assert len(g.attrs["state_units"].split(",")) == len(names)
        for ds in ("t", "estimate", "sigma", "nis", "att", "v_n", "attitude_error"):
            assert "units" in g[ds].attrs, ds
        assert g["estimate"].shape == (s["epochs"], 21)
        np.testing.assert_allclose(g.attrs["psins_mu0"], scipy.io.loadmat(DATA)["mu0"].ravel())
        from gcalign.app.align.plots import figures

        figs = figures(f, "demo")
    assert list(figs) == ["transfer_states"]
    assert len(figs["transfer_states"].axes) == 7


def _mat(tmp_path: Path, t_imu: float = 10.0, fog=None, name: str = "case.mat") -> Path:
    d = scipy.io.loadmat(DATA)
    m = d["mimu"][d["mimu"][:, 6] <= t_imu + 1e-9]
    f = d["fogavp"] if fog is None else fog(d["fogavp"])
    p = tmp_path / name
    scipy.io.savemat(p, {"mimu": m, "fogavp": f, "mu0": d["mu0"]})
    return p


def _scenario(tmp_path: Path, mat: Path, mode: str | None = None, **transfer) -> Path:
    sc = {"name": "t", "imu_file": str(mat),
          "align": {"transfer": {"flexure": False, **transfer}}}
    if mode is not None:
        sc["align"]["mode"] = mode
    p = tmp_path / "sc.yaml"
    p.write_text(yaml.safe_dump(sc))
    return p


def test_mode_option_selects_transfer(tmp_path):
    p = _scenario(tmp_path, _mat(tmp_path, fog=lambda f: f[f[:, 9] <= 10.0 + 1e-9]))
    res = _align(p, "--mode", "transfer", "--json", "-o", tmp_path / "o.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["mode"] == "transfer" and len(s["states"]) == 15 and s["duration_s"] == \
        pytest.approx(9.9)
    res = _align(p, "-o", tmp_path / "o2.h5")  # the section without the mode: an error
    assert res.exit_code == 2 and "align.transfer" in res.output


def test_reference_not_covering_the_run(tmp_path):
    mat = _mat(tmp_path, fog=lambda f: f[f[:, 9] <= 5.0 + 1e-9])
    assert_bad_run(_align, tmp_path, [_scenario(tmp_path, mat), "--mode", "transfer"],
                   "align.transfer.reference", "does not cover")


def test_reference_without_overlap(tmp_path):
    def later(f):
        f = f.copy()
        f[:, 9] += 200.0
        return f

    mat = _mat(tmp_path, fog=later)
    assert_bad_run(_align, tmp_path, [_scenario(tmp_path, mat), "--mode", "transfer"],
                   "align.transfer.reference", "no overlap")


def test_attitude_matching_with_a_reference_without_attitude(tmp_path):
    mat = _mat(tmp_path, fog=lambda f: f[:, 3:])  # [v lat lon h t]
    assert_bad_run(_align, tmp_path, [_scenario(tmp_path, mat), "--mode", "transfer"],
                   "align.transfer.matching", "no attitude")
    # velocity matching runs on it
    res = _align(_scenario(tmp_path, mat, matching="velocity"), "--mode", "transfer",
                 "--json", "-o", tmp_path / "v.h5")
    assert res.exit_code == 0, res.output


def test_misspelt_key_is_an_error(tmp_path):
    p = _scenario(tmp_path, _mat(tmp_path), matchng="velocity")
    assert_bad_run(_align, tmp_path, [p, "--mode", "transfer"], "matchng")


def test_validate_and_void_gyrocompass_keys(tmp_path):
    res = runner.invoke(app, ["validate", str(CONFIG)])
    assert res.exit_code == 0, res.output
    p = _scenario(tmp_path, _mat(tmp_path, fog=lambda f: f[f[:, 9] <= 10.0 + 1e-9]))
    sc = yaml.safe_load(p.read_text())
    sc["align"] |= {"mode": "transfer", "t2_s": 50}
    p.write_text(yaml.safe_dump(sc))
    res = _align(p, "--json", "-o", tmp_path / "w.h5")
    assert res.exit_code == 0, res.output
    w = json.loads(res.stdout)["warnings"]
    assert any(x.startswith("align.t2_s: cannot matter") for x in w), w


def test_validate_reads_the_slave_by_its_variable(tmp_path):
    """A master without attitude has 7 columns, as the slave: validate reads the slave by
    align.transfer.imu_variable, as the run does (not by 'the one 7-column array'); a
    variable the file lacks is one line naming the key, in validate and in the run."""
    mat = _mat(tmp_path, fog=lambda f: f[f[:, 9] <= 10.0 + 1e-9][:, 3:])
    p = _scenario(tmp_path, mat, mode="transfer", matching="velocity")
    res = runner.invoke(app, ["validate", str(p)])
    assert res.exit_code == 0, res.output  # was: 'more than one array of 7 columns'
    p = _scenario(tmp_path, mat, mode="transfer", matching="velocity", imu_variable="imu")
    res = runner.invoke(app, ["validate", str(p)])
    assert_bad_input(res, tmp_path / "none.h5", "align.transfer.imu_variable", "'imu'")
    assert_bad_run(_align, tmp_path, [p], "align.transfer.imu_variable", "'imu'")
    p = _scenario(tmp_path, mat, mode="transfer", reference={"variable": "fog"})
    assert_bad_run(_align, tmp_path, [p], "align.transfer.reference.variable", "'fog'")


def test_validate_and_the_run_cost_the_filter_alike(monkeypatch, tmp_path):
    """The cost model counts the filter's arithmetic from the files' sizes: per IMU step
    Φ P Φᵀ (2·21³), per master epoch the update (4·21³): (2·10001 + 4·1000)·21³ =
    2.22e8 operations on the demo; a smaller limit refuses validate and the run with one
    and the same line before any work."""
    monkeypatch.setenv("GCALIGN_MAX_WORK", "2.2e8")
    run = _align(CONFIG, "-o", tmp_path / "o.h5")
    check = runner.invoke(app, ["validate", str(CONFIG)])
    assert_bad_input(run, tmp_path / "o.h5", "align: needs 2.22e+08 operations",
                     "GCALIGN_MAX_WORK")
    assert check.output == run.output
    monkeypatch.setenv("GCALIGN_MAX_WORK", "2.3e8")
    assert runner.invoke(app, ["validate", str(CONFIG)]).exit_code == 0
