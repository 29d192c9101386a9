"""`gcalign modulate` end to end (seed 004): the built-in scenario, the JSON contract, the
results file, `show`, `plot`, `validate`, `batch` over modulate scenarios, and bad input
(exit 2 with one line naming the field, no results file)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.cli.common import builtin_text
from gcalign.io.scenario.loader import loads

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()
BASE = yaml.safe_load(builtin_text("seed004_modulation.yaml"))
DEFAULT = ["fixed", "seed-12", "four-position-12", "dual-16-improved"]


def _run(*args):
    return runner.invoke(app, ["modulate", *map(str, args)])


def _scenario(tmp_path: Path, name: str = "case", **changes) -> Path:
    d = copy.deepcopy(BASE)
    for key, value in changes.items():
        if value is None:
            d.pop(key, None)
        else:
            d[key] = value
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    return p


def test_builtin_equals_configs_copy():
    from gcalign.app.registry import COMMANDS, builtin_text

    text = (ROOT / "configs/seed004_modulation.yaml").read_text()
    assert builtin_text(COMMANDS["modulate"].builtin or "") == text
    assert BASE["modulate"]["compare"] == DEFAULT and BASE["modulate"]["hours"] == 72
    assert BASE["imu"]["rate_hz"] == 100 and BASE["earth"] == "seed004"


@pytest.mark.slow
def test_builtin_run_json_contract_show_and_plot(tmp_path):
    """The built-in case for 1 h at the seed's 100 Hz: the JSON holds every scheme with its
    cycle, cycle mean, horizontal error at 1 h and maximum; the file holds the series, the
    mechanism cycle, the invariants and the linear model; show and plot read it."""
    out = tmp_path / "m.h5"
    res = _run("--hours", 1, "--json", "-o", out)
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["output"] == str(out) and out.is_file()
    assert s["compare"] == DEFAULT and s["hours"] == 1.0
    for name in DEFAULT:
        r = s["schemes"][name]
        assert np.shape(r["cycle_mean"]) == (3, 3)
        assert set(r["horizontal_error_m"]) == {"1h"}
        assert r["max_horizontal_error_m"] >= r["horizontal_error_m"]["1h"] > 0
    assert s["schemes"]["seed-12"]["cycle_s"] == pytest.approx(3744.0)
    np.testing.assert_allclose(s["schemes"]["seed-12"]["cycle_mean"],
                               np.diag([-1, 1, 1]) / 3, atol=1e-12)
    # spec §5 table at 1 h: 2085, 915, 99, 174 m (within 10 %)
    for name, ref in zip(DEFAULT, (2085, 915, 99, 174), strict=True):
        assert s["schemes"][name]["horizontal_error_m"]["1h"] == pytest.approx(ref, rel=0.10)
    # the running integral ∫_0^t C e_j dt ends the cycle at 4(Ts + Tz) = 1248 s on every
    # sensor axis (the parity identity), so its peak is at least that
    assert np.all(np.array(s["schemes"]["seed-12"]["peak_integral_C_s"]) >= 1248 - 1e-9)
    assert s["schemes"]["dual-16-improved"]["schuler_warnings"]
    assert "Schuler" in res.stderr
    with h5py.File(out) as f:
        assert list(f["modulate"].attrs["compare"]) == DEFAULT
        g = f["modulate/seed-12"]
        for key in ("t", "error/pos", "error/phi", "mechanism/angle", "mechanism/C_diag",
                    "invariants/mean_C", "linear/horizontal"):
            assert key in g, key
        assert g["error/pos"].attrs["units"] == "m"
        assert g["mechanism/t"][-1] == pytest.approx(3744.0)
    shown = runner.invoke(app, ["show", str(out)])
    assert shown.exit_code == 0 and "four-position-12" in shown.output
    assert "peak ∫C dt" in shown.output and "Schuler" in shown.output
    plots = runner.invoke(app, ["plot", str(out), "-o", str(tmp_path / "p"), "--json"])
    assert plots.exit_code == 0, plots.output
    names = {Path(p).name for p in json.loads(plots.stdout)["figures"]}
    assert names == {"modulate_position_error.png", "modulate_attitude_error.png",
                     "modulate_mechanism.png"}


@pytest.mark.slow
def test_72h_json_has_every_report_hour(tmp_path):
    """At 10 Hz (the physics allows it, tests/test_modulate_navigation.py) the 72 h run:
    horizontal_error_m holds 1, 4, 12, 24 and 72 h, and the spec's table holds (10 %)."""
    sc = _scenario(tmp_path, imu=dict(BASE["imu"], rate_hz=10))
    res = _run(sc, "--compare", "fixed,four-position-12", "--json", "-o", tmp_path / "m.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    for name, ref in (("fixed", [2085, 4571, 7776, 27619, 79575]),
                      ("four-position-12", [99, 190, 202, 86, 283])):
        r = s["schemes"][name]
        assert list(r["horizontal_error_m"]) == ["1h", "4h", "12h", "24h", "72h"]
        got = [r["horizontal_error_m"][k] for k in r["horizontal_error_m"]]
        np.testing.assert_allclose(got, ref, rtol=0.10 if name == "fixed" else 0.15)
    assert s["max_horizontal_error_m"] == [s["schemes"][n]["max_horizontal_error_m"]
                                           for n in ("fixed", "four-position-12")]


def test_scheme_option_runs_one_scheme_and_dwell_sets_its_timing(tmp_path):
    res = _run("--scheme", "dual-16", "--dwell", 200, "--hours", 0.5, "--json",
               "-o", tmp_path / "d.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["compare"] == ["dual-16"]
    assert s["schemes"]["dual-16"]["cycle_s"] == pytest.approx(16 * 212.0)
    assert s["schemes"]["dual-16"]["reference"] == "body"
    with h5py.File(tmp_path / "d.h5") as f:
        stored = loads(f.attrs["scenario_yaml"], "scenario_yaml")  # no key given twice
    assert stored["mechanism.scheme"] == "dual-16" and stored["mechanism.dwell_s"] == 200


@pytest.mark.slow
def test_a_user_table_that_returns_runs(tmp_path):
    """A single-axis table of rows, its own name in the comparison beside a built-in."""
    row = {"axis": "z", "profile": "trapezoid", "accel_s": 2, "const_s": 8, "decel_s": 2,
           "dwell_s": 100}
    mech = {"name": "my-table", "reference": "body",
            "steps": [dict(row, angle_deg=a) for a in (180, -180, -180, 180)]}
    sc = _scenario(tmp_path, mechanism=mech, modulate={"compare": ["fixed", "my-table"],
                                                       "hours": 0.5})
    res = _run(sc, "--json", "-o", tmp_path / "t.h5")
    assert res.exit_code == 0, res.output
    r = json.loads(res.stdout)["schemes"]["my-table"]
    assert r["cycle_s"] == pytest.approx(4 * 112.0)
    np.testing.assert_allclose(np.diag(r["cycle_mean"]), [0, 0, 1], atol=1e-12)


def _bad_table(tmp_path):
    row = {"axis": "z", "profile": "trapezoid", "angle_deg": 90, "accel_s": 2, "const_s": 2,
           "decel_s": 2, "dwell_s": 10}
    return ["--hours", 1, str(_scenario(tmp_path, "bad", mechanism={"steps": [row]},
                                        modulate={"hours": 1}))]


@pytest.mark.parametrize("args, field", [
    (["--scheme", "seed-13"], "mechanism.scheme: unknown scheme 'seed-13'"),
    (["--compare", "fixed,seed-13"], "modulate.compare: unknown scheme 'seed-13'"),
    (["--dwell", -1], "mechanism.dwell_s"),
    (["--dwell", 1e23],  # seed-12's cycle: 12 (Ts + Tz)
     "mechanism.dwell_s: the mechanism's cycle is 1.2e+24 s; at most 1e+06 s"),
    (["--hours", 0], "modulate.hours"),
    (["--hours", -2], "modulate.hours"),
    ("turn", "mechanism.turn_s: the turn (6 s) is shorter than its acceleration plus "
             "deceleration (4 + 4 s)"),
    ("axis", "mechanism.steps.0.axis: must be a unit vector (norm 1), got [1.0, 1.0, 0.0]"),
    ("table", "mechanism.steps: the table does not return the IMU to its start: after the "
              "last row it is turned by 90 deg about [0.0, 0.0, 1.0]"),
    (["--compare", "fixed,fixed"], "modulate.compare"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, args, field):
    if args == "turn":
        args = [_scenario(tmp_path, "turn", mechanism={"scheme": "seed-12", "turn_s": 6})]
    elif args == "axis":
        row = {"axis": [1, 1, 0], "profile": "trapezoid", "angle_deg": 180, "accel_s": 4,
               "const_s": 4, "decel_s": 4}
        args = [_scenario(tmp_path, "axis", mechanism={"steps": [row]})]
    elif args == "table":
        args = _bad_table(tmp_path)
    out = tmp_path / "never.h5"
    res = _run(*args, "-o", out)
    assert res.exit_code == 2, res.output
    lines = [x for x in res.output.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), res.output
    assert field in lines[0]
    assert not out.exists()


def test_validate_lists_the_schemes(tmp_path):
    res = runner.invoke(app, ["validate", str(ROOT / "configs/seed004_modulation.yaml"),
                              "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    assert values["modulate.hours"]["value"] == "72 h"
    assert "modulate.compare: seed-12" in values
    bad = runner.invoke(app, ["validate", _bad_table(tmp_path)[-1]])
    assert bad.exit_code == 2 and "does not return the IMU" in bad.output


@pytest.mark.slow
def test_batch_over_modulate_scenarios(tmp_path):
    """A dwell sweep (dual-16 around the Schuler period, 0.5 h at 10 Hz): every run ok, the
    metrics read from the modulate summary, the batch equal to the single runs."""
    base = copy.deepcopy(BASE)
    base["imu"]["rate_hz"] = 10
    base["mechanism"] = {"scheme": "dual-16"}
    base["modulate"] = {"compare": ["dual-16"], "hours": 0.5}
    sweep = tmp_path / "s.yaml"
    sweep.write_text(yaml.safe_dump({
        "name": "dwell", "base": base, "grid": {"mechanism.dwell_s": [100, 300]},
        "seeds": 1, "metrics": ["schemes.dual-16.max_horizontal_error_m",
                                "max_horizontal_error_m"]}))
    res = runner.invoke(app, ["batch", str(sweep), "--workers", "1", "-o",
                              str(tmp_path / "b.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["command"] == "modulate" and s["ok"] == 2
    got = [v["stats"]["schemes.dual-16.max_horizontal_error_m"]["mean"] for v in s["variants"]]
    for dwell, value in zip((100, 300), got, strict=True):
        single = _scenario(tmp_path, f"d{dwell}", imu=base["imu"],
                           mechanism={"scheme": "dual-16", "dwell_s": dwell},
                           modulate=base["modulate"])
        one = _run(single, "--json", "-o", tmp_path / f"d{dwell}.h5")
        assert one.exit_code == 0, one.output
        assert value == pytest.approx(
            json.loads(one.stdout)["schemes"]["dual-16"]["max_horizontal_error_m"], rel=1e-12)


def test_figures_read_over_72_hours():
    """The seed's Fig. 4 analogue: one solid line per scheme (the linear model dashed, out of
    the legend but for one shared entry), log scale, hour ticks every 12 h, the title whole;
    the mechanism legends sit above the panels, not over the dwell levels."""
    from gcalign.app.modulate.plots import mechanism_figure, position_error_figure

    t = np.linspace(0.0, 72 * 3600.0, 2001)
    series = {n: (t, (i + 1) * 100 * (1 + t / 3600), (t, (i + 1) * 100 * (1 + t / 3600)),
                  [1, 4, 12, 24, 72]) for i, n in enumerate(DEFAULT)}
    fig = position_error_figure(series, "case: horizontal position error")
    (ax,) = fig.axes
    data = [ln.get_label() for ln in ax.lines if not ln.get_label().startswith("_")]
    assert data == DEFAULT
    assert ax.get_yscale() == "log" and ax.get_xlabel() == "time (h)"
    ticks = [x for x in ax.get_xticks() if 0 <= x <= 72]
    assert ticks == [0, 12, 24, 36, 48, 60, 72]
    legend = [x.get_text() for x in ax.get_legend().get_texts()]
    assert legend == DEFAULT + ["linear model (same errors)", "report hours"]
    cyc = {"seed-12": (np.linspace(0, 3744, 50), np.zeros((50, 3)), np.ones((50, 3)),
                       "navigation")}
    mfig = mechanism_figure(cyc, "case: the mechanism over one cycle")
    for a in mfig.axes[:2]:
        assert a.get_legend().get_bbox_to_anchor().y0 >= a.get_window_extent().y1 - 1
