"""The tables' formatting (gcalign.app.report and the rooms' tables): one format per column
or row group, no scientific notation for round-off, angles in the unit their size needs,
labels that fit 80 columns."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml
from align_cases import small_align
from rich.console import Console
from typer.testing import CliRunner

from gcalign.app import readback
from gcalign.app import report as R
from gcalign.cli import app

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def test_one_format_per_group():
    # a column of fixed and scientific values: fixed and scientific mixed (0.0043 │ -5.291e-04)
    assert R.numbers([0.0043, -5.291e-4]) == ["0.004300", "-0.000529"]
    assert R.numbers([12.5, 0.25, -3.0]) == ["12.50", "0.25", "-3.00"]
    assert R.numbers([2.5e7, 1.0]) == ["2.500e+07", "1.000e+00"]  # the group needs it
    assert R.numbers([0.0, 0.0]) == ["0.000", "0.000"]
    assert R.numbers([None, 1.5]) == ["—", "1.500"]
    # below the resolution of a physical quantity: zero, not 4.2e-10
    assert R.numbers([4.2e-10, -1e-9], tiny_as_zero=True) == ["0.000000", "0.000000"]


def test_round_off_prints_as_zero_never_as_negative_zero():
    assert R.angles([-1.529e-13, 30.0, 1e-9], "deg") == ["0.0000", "30.0000", "0.0000"]
    assert R.number(-4e-7, 3) == "0.000"


@pytest.mark.parametrize("values, unit", [([1.5, 0.01], "deg"), ([0.5, -0.02], "′"),
                                          ([0.01, -0.001], "″"), ([], "″")])
def test_angle_unit_by_size(values, unit):
    assert R.angle_unit(values) == unit


def test_angles_fixed_resolution_per_unit():
    assert R.angles([0.5, -0.004], "′") == ["30.000", "-0.240"]
    assert R.angles([0.001], "″") == ["3.60"]


def test_durations_and_run_line():
    assert [R.duration(x) for x in (0.0067, 1.2345, 300.0, 9000.0)] == [
        "6.7 ms", "1.23 s", "5.0 min", "2.50 h"]
    s = {"seed": 3, "compute_s": 0.0123, "wall_s": 1.5, "output": "runs/x.h5"}
    assert R.run_line(s, "compute (the passes)") == (
        "random seed 3; compute (the passes) 12.3 ms of 1.50 s wall; output runs/x.h5")
    assert R.run_line({"seed": None, "wall_s": 2.0}, None) == (
        "recorded data; wall 2.00 s; output —")


def _rendered(kind: str, summary: dict, width: int = 80) -> str:
    console = Console(width=width, record=True, file=open("/dev/null", "w"))  # noqa: SIM115
    console.print(readback.summary_table(kind, summary))
    return console.export_text()


@pytest.fixture(scope="module")
def align_summary(tmp_path_factory):
    folder = tmp_path_factory.mktemp("t")
    p = small_align(folder)
    res = runner.invoke(app, ["align", str(p), "-o", str(folder / "a.h5"), "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


def test_align_table_at_80_columns(align_summary):
    text = _rendered("align", align_summary)
    assert max(len(line) for line in text.splitlines()) <= 80
    for label in ("truth at T2 (deg)", "estimate at T3 (deg)", "last pass, 2nd half (",
                  "  max |error|", "1: forward, compass, stage 1",
                  "2: reverse, compass, stage 1", "error at the end of pass ("):
        assert label in text, label  # whole, not wrapped
    assert not re.search(r"\de[-+]\d", text)  # no scientific notation anywhere
    # the error rows share one unit, chosen by their size
    s = align_summary
    unit = R.UNIT_NAME[R.angle_unit(R.flat([s["error_t2_deg"], s["error_t3_deg"],
                                            s["last_pass_error"]["mean_deg"],
                                            s["last_pass_error"]["std_deg"],
                                            s["last_pass_error"]["max_deg"]]))]
    assert f"error at T3 ({unit})" in text and f"error at T2 ({unit})" in text


def test_last_pass_spread_is_over_its_second_half(align_summary, tmp_path):
    """The std and max beside the instant error: recomputed from the stored pass."""
    import h5py
    import numpy as np

    path = align_summary["output"]
    last = align_summary["last_pass_error"]
    with h5py.File(path) as f:
        err = np.degrees(f["align/pass_03/error"][()])
        t = f["align/pass_03/t"][()]
    half = err[len(err) // 2:]
    np.testing.assert_allclose(last["std_deg"], half.std(0), rtol=1e-12)
    np.testing.assert_allclose(last["max_deg"], np.abs(half).max(0), rtol=1e-12)
    np.testing.assert_allclose(last["mean_deg"], half.mean(0), rtol=1e-12)
    assert last["rows"] == len(half) and last["window_s"][1] == pytest.approx(t[-1])


def test_navigate_table_of_ideal_data_shows_no_round_off(tmp_path):
    sc = {"name": "still", "site": {"lat_deg": 45, "lon_deg": 126},
          "motion": {"kind": "static", "attitude_deg": [0, 0, 30], "duration_s": 30}}
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["navigate", str(p), "-o", str(tmp_path / "n.h5"), "--json"])
    assert res.exit_code == 0, res.output
    text = _rendered("navigate", json.loads(res.stdout))
    assert not re.search(r"\de[-+]\d", text) and "-0.00 " not in text
    assert "attitude error (arcsec)" in text and "velocity error ENU (m/s)" in text


def test_batch_table_metric_names_never_wrap(tmp_path):
    summary = {
        "sweep": "s", "command": "align", "seeds": 3, "seed_start": 1, "metrics":
        ["error_t3_deg.2", "equivalent_s"], "grid": {"align.mode": ["conventional"],
                                                     "align.stages.0.t_z_s": [100.0]},
        "variants": [{"overrides": {"align.mode": "conventional",
                                    "align.stages.0.t_z_s": 100.0}, "failed": 0,
                      "stats": {"error_t3_deg.2": {"n": 3, "units": "deg", "mean": 0.0043,
                                                   "std": -5.291e-4, "rms": 0.004,
                                                   "median": 0.004, "p05": 0.003,
                                                   "p95": 0.005},
                                "equivalent_s": {"n": 3, "units": "s", "mean": 1460.0,
                                                 "std": 0.0, "rms": 1460.0, "median": 1460.0,
                                                 "p05": 1460.0, "p95": 1460.0}}}],
        "runs": 3, "complete": True, "finished": 3, "ok": 3, "failed": 0, "wall_s": 1.0,
        "executor": "local pool", "output": "runs/s-batch.h5"}
    text = _rendered("batch", summary)
    assert "error_t3_deg.2 (arcsec)" in text and "equivalent_s (s)" in text
    assert "mode=conventional" in text and "t_z_s=100" in text
    assert "15.48" in text and "-1.90" in text  # 0.0043° and -5.291e-4° in ″, one format
    assert not re.search(r"\de[-+]\d", text)


def test_batch_of_files_names_break_between_words_at_80_columns():
    """A batch of scenario files labels a variant by its file name without `.yaml`; a name
    too long for the column breaks after `_`, `-` or `.`, never inside a word, and the
    table fits 80 columns."""
    stats = {"n": 4, "units": "deg", "mean": -0.22195, "std": 0.04858, "rms": 0.2259,
             "median": -0.2357, "p05": -0.26073, "p95": -0.16395}
    files = ["seed000_moving_conventional.yaml", "seed000_moving_full_cycle.yaml",
             "a_rather_long_scenario_name_for_the_test.yaml"]
    summary = {
        "sweep": "files", "command": "align", "seeds": 4, "seed_start": 1,
        "metrics": ["error_t3_deg.2"], "grid": None,
        "variants": [{"overrides": {"scenario": f}, "failed": 0,
                      "stats": {"error_t3_deg.2": stats}} for f in files],
        "runs": 12, "complete": True, "finished": 12, "ok": 12, "failed": 0, "wall_s": 1.0,
        "executor": "local pool", "output": "runs/files-batch.h5"}
    text = _rendered("batch", summary)
    assert max(len(line) for line in text.splitlines()) <= 80
    assert ".yaml" not in text
    assert "seed000_moving_conventional " in text and "seed000_moving_full_cycle " in text
    assert re.search(r"a_rather_long_scenario_name_ +-?\d", text)  # broken after a '_'
    assert re.search(r"^ ?for_the_test\s*$", text, re.M)
    assert "-13.317" in text  # −0.22195° in arc-minutes, the unit its size needs
