"""`gcalign observability` end to end (seed 002 §4): the JSON contract on the built-in
designed take-off, the results file and heat maps, the measurement and scaling options,
the conventional take-off as a part of the designed one, batch, and bad input (exit 2).

References: δλ is unobservable with velocity matching and observable with position (its
column of F is zero; position measures it directly), so the cumulative rank is 20 and 21;
the conventional scenario is simulated on its own and must give the designed flight's
first six segments.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from calibrate_cases import DESIGNED
from cli_checks import assert_bad_input
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.estimation import ins_error as ie

ROOT = Path(__file__).resolve().parents[1]
CONVENTIONAL = ROOT / "configs" / "seed002_conventional.yaml"
runner = CliRunner()


def _obs(*args):
    return runner.invoke(app, ["observability", *map(str, args)])


@pytest.fixture(scope="module")
def builtin(tmp_path_factory):
    out = tmp_path_factory.mktemp("obs") / "designed.h5"
    res = _obs("--json", "-o", out)
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), out


def test_json_contract(builtin):
    """``{"states": [21 names], "segments": [{"name", "t0_s", "t1_s", "rank", "degree":
    {state: η}}], "cumulative": [same shape]}``; velocity matching: η(δλ) = 0 everywhere
    and the cumulative rank ends at 20; η of the measured states is 1 (σ_0 is theirs)."""
    s, _ = builtin
    assert s["states"] == list(ie.STATE_NAMES)
    assert s["measure"] == "velocity" and s["scaling"] == "p0"  # the default
    for key in ("segments", "cumulative"):
        rows = s[key]
        assert len(rows) == 21
        for r in rows:
            assert {"name", "t0_s", "t1_s", "rank", "rank_margin", "degree"} <= set(r)
            assert r["rank_margin"] is None or r["rank_margin"] > 1.0
            assert list(r["degree"]) == list(ie.STATE_NAMES)
            assert r["degree"]["dlam"] == 0.0
            assert max(r["degree"]["dvE"], r["degree"]["dvN"]) == pytest.approx(1.0)
    seg = s["segments"]
    assert seg[0]["name"] == "static" and seg[0]["t0_s"] == 0 and seg[0]["t1_s"] == 60
    assert seg[-1]["t1_s"] == pytest.approx(590.0)
    assert all(a["t1_s"] == pytest.approx(b["t0_s"]) for a, b in zip(seg, seg[1:], strict=False))
    ranks = [r["rank"] for r in s["cumulative"]]
    assert ranks == sorted(ranks) and ranks[0] == 9 and s["rank_final"] == 20
    assert s["cumulative"][-1]["t0_s"] == 0.0


@pytest.mark.slow
def test_results_file_show_and_heat_maps(builtin, tmp_path):
    s, out = builtin
    with h5py.File(out) as f:
        g = f["observability"]
        assert g["eta"].shape == (21, 21) and g["rank_cum"][-1] == 20
        np.testing.assert_allclose(g["eta_cum"][-1], s["degree_final"])
    res = runner.invoke(app, ["show", str(out)])
    assert res.exit_code == 0 and "whole run" in res.output
    res = runner.invoke(app, ["plot", str(out), "-o", str(tmp_path), "--json"])
    assert res.exit_code == 0, res.output
    names = {Path(p).stem for p in json.loads(res.stdout)["figures"]}
    assert names == {"trajectory", "observability_segments", "observability_cumulative",
                     "covariance_degree"}


@pytest.mark.slow
def test_position_observes_longitude_and_scaling_changes_degrees(builtin, tmp_path):
    """--measure position: δλ observable (η > 0 once the flight moves), cumulative rank 21;
    --scaling none (the paper's unscaled table) changes the degrees but not the final rank
    of velocity matching."""
    res = _obs("--measure", "position", "--json", "-o", tmp_path / "p.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["rank_final"] == 21
    assert all(r["degree"]["dlam"] > 0 for r in s["cumulative"])
    res = _obs("--scaling", "none", "--json", "-o", tmp_path / "s.h5")
    assert res.exit_code == 0, res.output
    plain, scaled = json.loads(res.stdout), builtin[0]
    assert plain["scaling"] == "none" and plain["rank_final"] == 20
    assert scaled["degree_final"] != plain["degree_final"]


def test_conventional_is_the_designed_flights_first_six_segments(builtin, tmp_path):
    """configs/seed002_conventional.yaml, simulated on its own, gives the designed flight's
    first six segments: the same ranks and the same degrees (to 1e-6 relative)."""
    res = _obs(CONVENTIONAL, "--json", "-o", tmp_path / "c.h5")
    assert res.exit_code == 0, res.output
    conv, des = json.loads(res.stdout)["segments"], builtin[0]["segments"][:6]
    assert [r["name"] for r in conv] == [r["name"] for r in des]
    for a, b in zip(conv, des, strict=True):
        assert a["rank"] == b["rank"] and a["tom_rank"] == b["tom_rank"]
        for n in ie.STATE_NAMES:
            assert a["degree"][n] == pytest.approx(b["degree"][n], rel=1e-6, abs=1e-300)


@pytest.mark.slow
def test_batch_over_scaling(tmp_path):
    """A sweep over observability.scaling (no randomness: one seed)."""
    base = yaml.safe_load(CONVENTIONAL.read_text())
    sweep = {"name": "obs", "base": base, "command": "observability",
             "grid": {"observability.scaling": ["none", "p0"]}}
    p = tmp_path / "sweep.yaml"
    p.write_text(yaml.safe_dump(sweep, allow_unicode=True))
    res = runner.invoke(app, ["batch", str(p), "--workers", "1", "-o", str(tmp_path / "b.h5"),
                              "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["failed"] == 0 and s["metrics"] == ["rank_final"]


def _bad(tmp_path, args, field, *more):
    out = tmp_path / "out.h5"
    assert_bad_input(_obs(*args, "-o", out), out, field, *more)


@pytest.mark.parametrize(
    ("args", "field"),
    [(["--measure", "heading"], "observability.measure"),
     (["--scaling", "sigma"], "observability.scaling")],
)
def test_bad_options_exit_2(tmp_path, args, field):
    _bad(tmp_path, args, field)


@pytest.mark.parametrize(
    ("change", "field"),
    [({"piece_s": 0}, "observability.piece_s"), ({"rank_rtol": 2}, "observability.rank_rtol"),
     ({"scale": "p0"}, "observability.scale")],
)
def test_bad_section_exit_2(tmp_path, change, field):
    d = yaml.safe_load(CONVENTIONAL.read_text())
    d["observability"] = {**d["observability"], **change}
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(copy.deepcopy(d), allow_unicode=True))
    _bad(tmp_path, [p], field)


def test_recorded_data_have_no_flight(tmp_path):
    p = tmp_path / "rec.yaml"
    p.write_text(yaml.safe_dump({"name": "rec", "imu_file": str(DESIGNED)}))
    _bad(tmp_path, [p], "motion")
