"""`gcalign align` end to end: the JSON contract, the built-in scenario, `show`, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from align_cases import small_align
from typer.testing import CliRunner

from gcalign.cli import app

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def test_builtin_equals_configs_copy():
    from gcalign.app.registry import COMMANDS, builtin_text

    text = (ROOT / "configs/seed000_moving_full_cycle.yaml").read_text()
    assert builtin_text(COMMANDS["align"].builtin or "") == text


def test_align_json_contract_and_show(tmp_path):
    out = tmp_path / "a.h5"
    res = runner.invoke(app, ["align", str(small_align(tmp_path)), "-o", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    for key in (
        "error_t2_deg",
        "error_t3_deg",
        "attitude_t3_deg",
        "truth_t3_deg",
        "passes",
        "compute_s",
        "output",
    ):
        assert key in s
    assert [p["direction"] for p in s["passes"]] == ["forward", "reverse", "forward"]
    assert s["output"] == str(out) and out.is_file()
    assert s["t3_s"] == 70.0 and s["truth_t3_deg"][2] == pytest.approx(30.0, abs=1e-9)
    shown = runner.invoke(app, ["show", str(out), "--json"])
    assert shown.exit_code == 0, shown.output
    assert json.loads(shown.stdout)["error_t3_deg"] == s["error_t3_deg"]
    import h5py

    with h5py.File(out) as f:
        assert f["align/pass_02"].attrs["direction"] == "reverse"
        assert f["align/pass_01/error"].attrs["units"] == "rad"
        assert f["align/pass_03"].attrs["stage"] == 1 and "align/pass_00" not in f
        assert f["align/result/att_t3"].shape == (3,)
        assert "moving" in f.attrs["scenario_yaml"]


def test_same_seed_same_numbers_and_overrides(tmp_path):
    p = small_align(tmp_path)
    a = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "1.h5"), "--json", "--seed", "4"])
    b = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "2.h5"), "--json", "--seed", "4"])
    c = runner.invoke(
        app,
        [
            "align",
            str(p),
            "-o",
            str(tmp_path / "3.h5"),
            "--json",
            "--seed",
            "5",
            "--mode",
            "half-cycle",
            "--compensation",
            "one-off",
        ],
    )
    assert a.exit_code == b.exit_code == c.exit_code == 0, c.output
    sa, sb, sc = (json.loads(r.stdout) for r in (a, b, c))
    assert sa["error_t3_deg"] == sb["error_t3_deg"]
    assert sc["mode"] == "half-cycle" and sc["compensation"] == "one-off"
    assert [p["kind"] for p in sc["passes"]] == ["compass", "attitude", "compass"]
    assert sc["error_t3_deg"] != sa["error_t3_deg"]


@pytest.mark.parametrize(
    "align, args, field",
    [
        ({"t1_s": 30, "t2_s": 20}, [], "align.t2_s"),
        ({"t3_s": 50}, [], "align.t3_s"),
        ({}, ["--t2", "500", "--t3", "510"], "align.t2_s"),
        ({"stages": [{"t_xy_s": 20, "t_z_s": 0}]}, [], "align.stages.0.t_z_s"),
        ({"stages": [{"xi": 1.0}]}, [], "align.stages.0.xi"),
        ({"stages": [{"xi": 0}]}, [], "align.stages.0.xi"),
        ({"stages": [{"passes": 5}, {"t_z_s": 200}]}, [], "align.stages.1.passes"),
        ({"stages": [{"t_z_s": 200}, {"passes": 2}]}, [], "align.stages"),
        ({"mode": "full-cycle", "stages": [{"passes": 1}]}, [], "align.stages"),
        ({}, ["--mode", "half-cycle", "--passes", "1"], "align.stages"),
        ({}, ["--passes", "4"], "align.stages"),
        ({"passes": 5}, [], "align.passes: removed"),
        ({"coarse": {"method": "given", "duration_s": 10}}, [], "align.coarse.duration_s: "
         "removed"),
        ({"coarse": {"method": "analytic", "error_deg": [0, 0, 1]}}, [],
         "align.coarse.error_deg: cannot matter"),
        ({"coarse": {"method": "given", "offset_deg": [0, 0, 1]}}, [],
         "align.coarse.offset_deg: cannot matter"),
        ({}, ["--mode", "sideways"], "align.mode"),
        ({}, ["--t3", "soon"], "align.t3_s"),
    ],
)
def test_bad_input_exits_2_without_file(tmp_path, align, args, field):
    out = tmp_path / "bad.h5"
    res = runner.invoke(app, ["align", str(small_align(tmp_path, **align)), "-o", str(out), *args])
    assert res.exit_code == 2, res.output
    assert field in res.output and "Traceback" not in res.output
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.suffix in {".h5", ".tmp"}]


def test_scenario_file_errors(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nsite: {lat_deg: 45\n")
    res = runner.invoke(app, ["align", str(bad)])
    assert res.exit_code == 2 and "YAML syntax error at line" in res.output
    res = runner.invoke(app, ["align", str(tmp_path / "missing.yaml")])
    assert res.exit_code == 2 and "file not found" in res.output


@pytest.mark.parametrize(
    "align, args, field",
    [
        ({}, ["--t3", "nan"], "align.t3_s"),
        ({"t3_s": float("nan")}, [], "align.t3_s"),
        (
            {"coarse": {"method": "given", "error_deg": [float("inf"), 0, 0]}},
            [],
            "align.coarse.error_deg.0",
        ),
        ({"coarse": {"method": "inertial"}, "t1_s": 0.01}, [], "align.t1_s"),
    ],
)
def test_non_finite_and_too_short_inputs_exit_2_on_one_line(tmp_path, align, args, field):
    res = runner.invoke(app, ["align", str(small_align(tmp_path, **align)), *args])
    assert res.exit_code == 2, res.output
    assert field in res.output and res.output.count("\n") == 1, res.output


def test_unwritable_output_is_a_clear_error(tmp_path):
    res = runner.invoke(app, ["align", str(small_align(tmp_path)), "-o", str(tmp_path)])
    assert res.exit_code == 2 and "is a directory; give a file name" in res.output


def test_moving_base_without_aiding_warns(tmp_path):
    res = runner.invoke(
        app,
        [
            "align",
            str(small_align(tmp_path, aiding={"source": "none"})),
            "-o",
            str(tmp_path / "w.h5"),
            "--json",
        ],
    )
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["warnings"] and "warning: a moving base" in res.stderr


def test_misalignment_reported_and_pole_default_survives_a_data_file(tmp_path):
    sim = tmp_path / "sim.h5"
    res = runner.invoke(app, ["simulate", str(small_align(tmp_path)), "-o", str(sim)])
    assert res.exit_code == 0
    d = yaml.safe_load((tmp_path / "small.yaml").read_text())
    d.pop("motion")
    d.pop("site")
    d["align"].pop("azimuth_poles")
    d["align"]["aiding"] = {"source": "none"}
    d["imu_file"] = str(sim)
    p = tmp_path / "from_file.yaml"
    p.write_text(yaml.safe_dump(d))
    res = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "f.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["azimuth_poles"] == "double-oscillator"  # the stored motion is a moving base
    phi, err = np.array(s["misalignment_t3_deg"]), np.array(s["error_t3_deg"])
    # Level base, small angles: yaw error = -φ_U.
    assert phi[2] == pytest.approx(-err[2], abs=1e-3)
