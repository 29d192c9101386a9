"""`gcalign northfind` end to end (seed 001): JSON contract, built-in scenario, noise-free
recovery, `show`, the results file, bad input (exit 2, field named, no file) and determinism.

Reference values come from geometry: on noise-free data the tilt-compensated methods recover
the true azimuth exactly, and the uncompensated error follows the closed form
``asin(tan L sin ε)`` to first order (seed §1: 50′ per degree of tilt at 40°).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from cli_checks import assert_bad_run
from typer.testing import CliRunner

from gcalign.cli import app

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def _ideal(tmp_path: Path, **northfind) -> Path:
    """A north-finder without sensor errors at 40°N; `northfind` updates the section."""
    section = {"positions": 24, "dwell_s": 1, "sweep": {"start_deg": 0, "stop_deg": 360,
                                                         "step_deg": 30},
               "tilt_deg": 0, "tilt_direction_deg": 30, "tilt_reference": "north"}
    section.update(northfind)
    d = {"name": "ideal", "site": {"lat_deg": 40, "lon_deg": 116, "height_m": 0},
         "imu": {"rate_hz": 100, "seed": 3}, "northfind": section}
    d["northfind"] = {k: v for k, v in section.items() if v is not None}
    p = tmp_path / "ideal.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    return p


def _run(*args: str):
    return runner.invoke(app, ["northfind", *args])


def test_builtin_equals_configs_copy():
    from gcalign.app.registry import COMMANDS, builtin_text

    text = (ROOT / "configs/seed001_simulation.yaml").read_text()
    assert builtin_text(COMMANDS["northfind"].builtin or "") == text


def test_builtin_run_json_contract(tmp_path):
    out = tmp_path / "nf.h5"
    res = _run("--json", "-o", str(out))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["output"] == str(out) and out.is_file()
    assert s["azimuth_true_deg"] == pytest.approx(np.arange(0.0, 360.0, 5.0).tolist())
    assert s["latitude_deg"] == 40.0 and s["shape"] == [1, 72]
    assert set(s["methods"]) == {"coordinate", "vector", "naive", "none"}
    for d in s["methods"].values():
        for key in ("max_abs_error_deg", "rms_error_deg", "errors_deg", "mean_deg", "std_deg",
                    "bias_deg", "std_pred_deg", "error_pred_deg"):
            assert key in d
        assert len(d["errors_deg"]) == 72
    assert len(s["tilt_est_deg"]) == 72 and len(s["tilt_direction_est_deg"]) == 72
    m = s["methods"]
    # seed §3.1: ~8.4° without compensation at 10° tilt (exact form 8.55° along a table axis)
    assert 8.3 < m["none"]["max_abs_error_deg"] < 8.8
    # eq. (11) leaves ~ε²/4 = 0.44° (4.4 % of the tilt), plus noise
    assert 0.35 < m["naive"]["max_abs_error_deg"] < 0.6
    # compensated: within a few predicted σ of the gyro noise (0.02°/h per dwell)
    sigma = max(m["coordinate"]["std_pred_deg"])
    assert m["coordinate"]["max_abs_error_deg"] < 5 * sigma
    assert m["coordinate"]["errors_deg"] == pytest.approx(m["vector"]["errors_deg"], abs=1e-9)


def test_noise_free_sweep_recovers_azimuth_and_show_reprints(tmp_path):
    out = tmp_path / "ideal.h5"
    res = _run(str(_ideal(tmp_path)), "--sweep", "0:360:30", "--tilt", "10", "--json",
               "-o", str(out))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["azimuth_true_deg"] == pytest.approx(list(range(0, 360, 30)))
    m = s["methods"]
    for name in ("coordinate", "vector"):
        assert m[name]["max_abs_error_deg"] < 1e-9, name
    assert s["tilt_est_deg"] == pytest.approx([10.0] * 12, abs=1e-9)
    assert s["tilt_direction_est_deg"] == pytest.approx([30.0] * 12, abs=1e-7)
    # tilt fixed to the earth toward ζ = 30°: first-order leak atan2(tan L sin ε sin ζ, ...)
    t = math.tan(math.radians(40.0)) * math.sin(math.radians(10.0))
    first = math.degrees(math.atan2(t * math.sin(math.radians(30)), 1 - t * math.cos(
        math.radians(30))))
    assert np.mean(m["none"]["errors_deg"]) == pytest.approx(first, abs=0.5)
    assert m["none"]["errors_deg"] == pytest.approx(m["none"]["error_pred_deg"], abs=1e-9)

    shown = runner.invoke(app, ["show", str(out)])
    assert shown.exit_code == 0, shown.output
    printed = _run(str(_ideal(tmp_path)), "--sweep", "0:360:30", "--tilt", "10",
                   "-o", str(tmp_path / "again.h5"))
    assert printed.exit_code == 0, printed.output
    for text in ("gcalign northfind: ideal", "12 true azimuths", "closed form"):
        assert text in shown.stdout

    def rows(text):  # the method rows (the caption differs: output path)
        return [ln for ln in text.splitlines() if ln.startswith("│ ")]

    assert len(rows(shown.stdout)) == 4 and rows(shown.stdout) == rows(printed.stdout)
    shown_json = runner.invoke(app, ["show", str(out), "--json"])
    assert json.loads(shown_json.stdout)["methods"] == s["methods"]

    with h5py.File(out) as f:
        assert f.attrs["kind"] == "northfind"
        g = f["northfind"]
        assert g["azimuth_true"].shape == (12,) and g["azimuth_true"].attrs["units"] == "rad"
        for name in ("coordinate", "vector", "naive", "none"):
            assert g[f"{name}/estimate"].shape == (1, 12)
            assert g[f"{name}/error"].attrs["units"] == "rad"
        assert np.allclose(g["azimuth_true"][()], np.radians(np.arange(0, 360, 30)))
        assert np.abs(g["coordinate/error"][()]).max() < 1e-10
        assert g["tilt_est"].shape == (1, 12) and g["tilt_direction_est"].shape == (1, 12)
        assert g.attrs["positions"] == 24 and g.attrs["tilt_direction_ref"] == "north"
        assert g.attrs["tilt"] == pytest.approx(math.radians(10.0))


def test_repeats_table_like_seed_table_1(tmp_path):
    out = tmp_path / "t.h5"
    res = _run(str(ROOT / "configs/seed001_table_experiment.yaml"), "--json", "-o", str(out))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["shape"] == [7, 1] and s["azimuth_true_deg"] == [48.0]
    c = s["methods"]["coordinate"]
    err = np.array(c["errors_deg"])
    assert c["bias_deg"][0] == pytest.approx(err.mean())
    assert c["std_deg"][0] == pytest.approx(err.std(ddof=1))
    assert c["mean_deg"][0] == pytest.approx(48.0 + err.mean())
    shown = runner.invoke(app, ["show", str(out)])
    assert shown.exit_code == 0, shown.output
    for text in ("mean (deg)", "std (′)", "bias (′)", "│ group 7 "):
        assert text in shown.stdout
    with h5py.File(out) as f:
        assert f["northfind/coordinate/error"].shape == (7, 1)


def test_same_seed_same_numbers(tmp_path):
    p = str(ROOT / "configs/seed001_table_experiment.yaml")
    a = _run(p, "--json", "--seed", "5", "-o", str(tmp_path / "a.h5"))
    b = _run(p, "--json", "--seed", "5", "-o", str(tmp_path / "b.h5"))
    c = _run(p, "--json", "--seed", "6", "-o", str(tmp_path / "c.h5"))
    for r in (a, b, c):
        assert r.exit_code == 0, r.output
    ja, jb, jc = (json.loads(r.stdout) for r in (a, b, c))
    assert ja["methods"] == jb["methods"] and ja["tilt_est_deg"] == jb["tilt_est_deg"]
    assert ja["seed"] == 5 and ja["methods"] != jc["methods"]


def test_overrides_method_positions_azimuth(tmp_path):
    res = _run(str(_ideal(tmp_path)), "--azimuth", "123.5", "--positions", "8", "--method",
               "vector", "--method", "none", "--json", "-o", str(tmp_path / "o.h5"))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["method_order"] == ["vector", "none"] and s["positions"] == 8
    assert s["azimuth_true_deg"] == [123.5] and s["sweep"] is None
    assert abs(s["methods"]["vector"]["errors_deg"][0]) < 1e-9


@pytest.mark.parametrize("name", ["seed001_simulation", "seed001_table_experiment"])
def test_validate_configs(name):
    res = runner.invoke(app, ["validate", str(ROOT / f"configs/{name}.yaml"), "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    assert "northfind.tilt" in values and "northfind.gyro (body y)" in values


def _bad(tmp_path: Path, args, field: str, *more: str):
    assert_bad_run(_run, tmp_path, args, field, *more)


@pytest.mark.parametrize(
    ("args", "field", "more"),
    [
        (["--positions", "2"], "northfind.positions", ("3", "got 2")),
        (["--tilt", "90"], "northfind.tilt_deg", ("< 90", "got 90")),
        (["--dwell", "0"], "northfind.dwell_s", ("greater than 0", "got 0")),
        (["--sweep", "10:0:5"], "northfind.sweep.stop_deg", ("empty sweep",)),
        (["--sweep", "0:360"], "northfind.sweep", ("START:STOP:STEP",)),
        (["--method", "foo"], "northfind.methods", ("'coordinate'", "got 'foo'")),
        (["--azimuth", "10", "--sweep", "0:360:30"], "northfind.sweep", ("not both",)),
    ],
)
def test_bad_options_exit_2(tmp_path, args, field, more):
    _bad(tmp_path, [str(_ideal(tmp_path)), *args], field, *more)


@pytest.mark.parametrize(
    ("change", "field", "more"),
    [
        ({"site": {"lat_deg": 90, "lon_deg": 0}}, "site.lat_deg", ("poles", "got 90")),
        ({"site": {"lat_deg": -90, "lon_deg": 0}}, "site.lat_deg", ("poles", "got -90")),
        ({"northfind": {"positions": 2}}, "northfind.positions", ("got 2",)),
        ({"northfind": {"tilt_deg": 95}}, "northfind.tilt_deg", ("got 95",)),
        ({"northfind": {"dwell_s": -1}}, "northfind.dwell_s", ("got -1",)),
        ({"northfind": {"sweep": {"start_deg": 0, "stop_deg": -5, "step_deg": 5}}},
         "northfind.sweep.stop_deg", ("empty sweep",)),
        ({"northfind": {"methods": ["coordinate", "compass"]}}, "northfind.methods.1",
         ("got 'compass'",)),
        ({"northfind": {"azimuth_deg": 48}}, "northfind.sweep", ("not both",)),
        ({"northfind": {"sweep": None}}, "northfind.azimuth_deg", ("missing",)),
        ({"northfind": {"tilt_degrees": 5}}, "northfind.tilt_degrees", ("unknown key",)),
        # sensor terms the north-finder does not model are refused, never silently dropped
        ({"imu": {"gyro": {"bias_gm": {"std_dph": 0.01, "tau_s": 300}}}}, "imu.gyro.bias_gm",
         ("not modelled", "allowed: none", "'std_dph'")),
        ({"imu": {"gyro": {"bias_instability_dph": 0.01}}}, "imu.gyro.bias_instability_dph",
         ("allowed: 0", "got [0.01, 0.01, 0.01]")),
        ({"imu": {"accel": {"bias_rw_ughrh": [1, 1, 1]}}}, "imu.accel.bias_rw_ughrh",
         ("allowed: 0", "got [1.0, 1.0, 1.0]")),
        ({"imu": {"gyro": {"asym_ppm": [0, 5, 0]}}}, "imu.gyro.asym_ppm", ("allowed: 0",)),
    ],
)
def test_bad_scenario_exit_2(tmp_path, change, field, more):
    p = _ideal(tmp_path)
    d = yaml.safe_load(p.read_text())
    for section, values in change.items():
        if section == "site":
            d["site"] = values
        else:
            d[section].update(values)
            d[section] = {k: v for k, v in d[section].items() if v is not None}
    p.write_text(yaml.safe_dump(d))
    _bad(tmp_path, [str(p)], field, *more)
