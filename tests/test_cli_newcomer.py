"""What a new user sees of every command: a progress bar on stderr (the compile phase
included), one line saying where the results file went, options that match across
commands, a warning when a requested span is cut short."""

from __future__ import annotations

import copy
import re
import time

import pytest
import yaml
from align_cases import small_align
from calibrate_cases import tiny_flight
from typer.testing import CliRunner

from gcalign.cli import app

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")

STATIC = {"name": "static", "site": {"lat_deg": 45, "lon_deg": 126},
          "motion": {"kind": "static", "duration_s": 20}}
SHORT_FLIGHT = tiny_flight(conventional_segments=2)
NORTHFIND = {"name": "nf", "site": {"lat_deg": 40, "lon_deg": 116, "height_m": 0},
             "imu": {"rate_hz": 100, "seed": 3},
             "northfind": {"positions": 4, "dwell_s": 1, "azimuth_deg": 30}}
REALTIME = {"name": "rt", "site": {"lat_deg": 34.25, "lon_deg": 108.9, "height_m": 400},
            "imu": {"seed": 3}, "realtime": {"semi_physical": False, "cases": [
                {"name": "rate", "steps": [{"axis": "z", "profile": "rate", "rate_dps": 10,
                                            "duration_s": 3}]}]}}


def _write(tmp_path, data: dict, name: str):
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(copy.deepcopy(data), sort_keys=False, allow_unicode=True))
    return p


def _args(tmp_path, command: str) -> list[str]:
    """A small run of `command` (a second or so once its kernels are compiled)."""
    out = str(tmp_path / f"{command}.h5")
    if command in ("simulate", "navigate"):
        return [command, str(_write(tmp_path, STATIC, "static")), "-o", out]
    if command == "align":
        return [command, str(small_align(tmp_path)), "-o", out]
    if command in ("calibrate", "observability"):
        return [command, str(_write(tmp_path, SHORT_FLIGHT, "flight")), "-o", out]
    if command == "northfind":
        return [command, str(_write(tmp_path, NORTHFIND, "nf")), "-o", out]
    if command == "realtime":
        return [command, str(_write(tmp_path, REALTIME, "rt")), "-o", out]
    if command == "modulate":
        return [command, "--scheme", "seed-12", "--hours", "0.05", "--set", "imu.rate_hz=10",
                "-o", out]
    if command == "batch":
        return [command, str(small_align(tmp_path)), "--seeds", "2", "-w", "1", "-o", out]
    raise KeyError(command)


SLOW = {"calibrate", "batch"}  #: over 2 s (a simulated flight; a process pool)
COMMANDS = [pytest.param(c, marks=pytest.mark.slow) if c in SLOW else c for c in (
    "simulate", "navigate", "align", "calibrate", "observability", "northfind", "realtime",
    "modulate", "batch")]


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_shows_a_bar_and_where_its_file_went(tmp_path, monkeypatch, command):
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    args = _args(tmp_path, command)
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    bar = ANSI.sub("", res.stderr).replace("\r", "\n")
    first = "1 scenario × 2 seeds" if command == "batch" else f"{command} running"
    assert first in bar  # for a command, before the first kernel call (numba's compile)
    assert ("2/2" if command == "batch" else "100%") in bar, bar
    assert all(len(x) <= 80 for x in bar.splitlines() if "━" in x), bar
    assert "running" not in res.stdout  # the table's stream holds no bar
    assert f"wrote {args[-1]}\n" in res.stderr


def test_modulate_bar_counts_data_seconds_of_its_scheme(tmp_path, monkeypatch):
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    res = runner.invoke(app, _args(tmp_path, "modulate"))
    assert res.exit_code == 0, res.output
    bar = ANSI.sub("", res.stderr)
    assert "modulate seed-12 " in bar and "180/180" in bar  # 0.05 h = 180 s


def test_progress_lines_fit_80_columns(capsys, monkeypatch):
    """A 72 h modulate run counts to 259200 data seconds per scheme: its lines (the longest
    built-in name, "four-position-12 3/4") stay within 80 columns; a longer description is
    shortened with "…" rather than wrapping the line."""
    from gcalign.cli.common import ProgressBar

    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    monkeypatch.setenv("COLUMNS", "80")
    with ProgressBar("modulate") as bar:
        for what in ("fixed 1/4", "four-position-12 3/4",
                     "a-scheme-name-far-longer-than-any-built-in-one 4/4"):
            bar(100270, 259200, what)
            bar.bar.refresh()  # draw this state now (rich redraws ten times a second)
    err = ANSI.sub("", capsys.readouterr().err).replace("\r", "\n")
    lines = [x for x in err.splitlines() if "━" in x]
    assert lines and all(len(x) <= 80 for x in lines), lines
    assert any("four-position-12 3/4" in x and "100270/259200" in x for x in lines), lines
    long = [x for x in err.splitlines() if "a-scheme-name" in x]
    assert long and all("…" in x and "━" in x for x in long), long  # shortened, not wrapped


def test_observability_reports_its_stages(tmp_path, monkeypatch):
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    res = runner.invoke(app, _args(tmp_path, "observability"))
    assert res.exit_code == 0, res.output
    bar = ANSI.sub("", res.stderr)
    assert "observability simulating the flight" in bar
    assert "observability PWCS + SVD table" in bar and "100% 1/1" in bar


@pytest.mark.slow
def test_calibrate_single_run_reports_its_stages(tmp_path, monkeypatch):
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    res = runner.invoke(app, _args(tmp_path, "calibrate"))
    assert res.exit_code == 0, res.output
    bar = ANSI.sub("", res.stderr)
    assert "calibrate simulating / reading the data" in bar
    assert "calibrate filter run" in bar and "1/1" in bar


def test_a_silent_stage_is_drawn_after_the_delay(monkeypatch):
    """A report before the delay is shown once the delay has passed, with no further report
    (a first run's compile): the bar's timer draws it."""
    from gcalign.cli.common import ProgressBar

    monkeypatch.setenv("GCALIGN_PROGRESS", "auto")
    bar = ProgressBar("x", delay_s=0.3)
    bar.enabled = True  # as on a terminal
    try:
        bar(0, 1, "starting")
        assert bar.bar is None  # not yet: short runs stay quiet
        deadline = time.monotonic() + 30  # waits on the state, not on a clock
        while "starting" not in bar.tasks and time.monotonic() < deadline:
            time.sleep(0.01)
        assert bar.bar is not None and "starting" in bar.tasks
    finally:
        bar.close()
    late = ProgressBar("y", delay_s=60.0)
    late.enabled = True
    late(0, 1, "starting")
    late.close()  # done before the delay: never drawn
    assert late.timer is not None and late.timer.finished.is_set()  # cancelled
    late._late_start()  # a timer that fired as close() ran: it draws nothing either
    assert late.bar is None


# ------------------------------------------------------------------ options that match

REAL = __import__("pathlib").Path(__file__).resolve().parent / "data/lasergyro.imu.xz"


def test_navigate_takes_a_recording_given_alone(tmp_path):
    out = tmp_path / "n.h5"
    res = runner.invoke(app, ["navigate", "--imu-file", str(REAL), "--duration", "2",
                              "-o", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = __import__("json").loads(res.stdout)
    assert s["duration_s"] == 2 and s["init"] == "the file's header" and out.is_file()
    none = runner.invoke(app, ["navigate"])
    assert none.exit_code == 2
    assert none.stderr.strip() == ("error: navigate: give a scenario or a data file "
                                   "(SOURCE), or --imu-file FILE")


def test_align_takes_t1_like_t2_and_t3(tmp_path):
    import json

    res = runner.invoke(app, ["align", str(small_align(tmp_path)), "--t1", "7",
                              "-o", str(tmp_path / "a.h5"), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["t1_s"] == 7.0
    assert "t1_7" in str(__import__("gcalign.cli.common", fromlist=["x"]).output_name(
        "x", "align", 1, [("align.t1_s", 7.0)]))


def test_a_duration_past_the_data_warns(tmp_path):
    import json

    p = _write(tmp_path, {**STATIC, "motion": {"kind": "static", "duration_s": 40}}, "mine")
    res = runner.invoke(app, ["navigate", str(p), "--start", "10", "--duration", "1e9",
                              "-o", str(tmp_path / "n.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["duration_s"] == 30
    assert s["warnings"] == ["navigation.duration_s: 1e+09 s runs past the end of the data: "
                             "ran 30 s (from 10 s)"]
    ok = runner.invoke(app, ["navigate", str(p), "--start", "10", "--duration", "30",
                             "-o", str(tmp_path / "m.h5"), "--json"])
    assert json.loads(ok.stdout)["warnings"] == []  # exactly to the end: nothing to say


def test_warnings_are_said_once(tmp_path):
    """Under --json the table (with its warnings) is on stderr: no second copy there."""
    p = _write(tmp_path, {**STATIC, "motion": {"kind": "static", "duration_s": 40}}, "mine")
    res = runner.invoke(app, ["navigate", str(p), "--duration", "1e9", "-o",
                              str(tmp_path / "n.h5"), "--json"])
    assert ANSI.sub("", res.stderr).count("runs past the end of the data") == 1
    plain = runner.invoke(app, ["navigate", str(p), "--duration", "1e9", "-o",
                                str(tmp_path / "n.h5")])  # table on stdout, not a terminal
    assert plain.stderr.count("warning: navigation.duration_s") == 1
    assert plain.stdout.count("warning: navigation.duration_s") == 1
    d = yaml.safe_load(small_align(tmp_path).read_text())
    d["align"].update(mode="half-cycle", realtime=True)  # realtime: conventional mode only
    v = _write(tmp_path, d, "v")
    val = runner.invoke(app, ["validate", str(v), "--json"])
    assert val.exit_code == 0, val.output
    warnings = __import__("json").loads(val.stdout)["warnings"]
    assert warnings and any("align.realtime" in w for w in warnings)
    for w in warnings:
        assert ANSI.sub("", val.stderr).replace("\n", " ").count(w[:30]) == 1


def test_validate_shows_long_names_whole_at_80_columns(tmp_path, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    name = "a-scenario-whose-name-is-long-as-users-name-them-seed002-designed-variant-b"
    p = _write(tmp_path, {**STATIC, "name": name, "calibrate": {"navigation_rate_hz": 25}},
               "long")
    res = runner.invoke(app, ["validate", str(p)], terminal_width=80)
    assert res.exit_code == 0, res.output
    lines = res.stdout.splitlines()
    assert all(len(x) <= 80 for x in lines)
    cells = "".join(x.split("│")[2].strip() for x in lines if x.count("│") == 4
                    and (x.split("│")[1].strip() in ("name", "")))
    assert name in cells  # folded over lines, not cut
    assert any("calibrate.navigation_rate_hz" in x for x in lines)  # a key on one line
    assert "…" not in res.stdout


def test_batch_set_and_seeds_on_a_sweep(tmp_path):
    import json

    base = yaml.safe_load(small_align(tmp_path).read_text())
    sweep = {"name": "modes", "base": base, "grid": {"align.mode": ["conventional",
                                                                     "half-cycle"]},
             "seeds": 5, "metrics": ["error_t3_deg"]}
    p = _write(tmp_path, sweep, "sweep")
    # T3 = 65 s, not 'measured' (T2 + the passes' wall time: the batch's run and the single
    # run would differ by the machine's load); the literal 'measured' is the last run's.
    res = runner.invoke(app, ["batch", str(p), "--seeds", "2", "--set", "align.t3_s=65",
                              "-w", "1", "-o", str(tmp_path / "b.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["runs"] == 4  # 2 variants × 2 seeds, not × 5
    assert "note: --seeds 2 replaces the sweep's seeds (5)" in res.stderr
    assert f"wrote {tmp_path / 'b.h5'}" in res.stderr
    one = runner.invoke(app, ["align", str(small_align(tmp_path)), "--mode", "half-cycle",
                              "--t3", "65", "--seed", "2", "-o", str(tmp_path / "1.h5"),
                              "--json"])
    import h5py
    import numpy as np

    with h5py.File(tmp_path / "b.h5") as f:
        r = f["batch/runs"]
        sel = (r["variant"][()] == 1) & (r["seed"][()] == 2)
        np.testing.assert_array_equal(r["metrics"]["error_t3_deg"][()][sel][0],
                                      json.loads(one.stdout)["error_t3_deg"])
    twice = runner.invoke(app, ["batch", str(p), "--set", "align.mode=conventional"])
    assert twice.exit_code == 2
    assert "--set align.mode: also set by the sweep's grid or cases" in twice.stderr
    files = runner.invoke(app, ["batch", str(small_align(tmp_path)), "--set",
                                "align.t3_s=measured", "-w", "1", "-o",
                                str(tmp_path / "c.h5"), "--json"])
    assert files.exit_code == 0, files.output


def test_batch_bar_label_is_short():
    from types import SimpleNamespace

    from gcalign.app.batch.sweep import FILE_KEY
    from gcalign.cli.batch import bar_label

    files = SimpleNamespace(name="a+b+c", seeds=10, variants=(1, 2, 3),
                            grid={FILE_KEY: ["a", "b", "c"]})
    assert bar_label(files) == "3 scenarios × 10 seeds"
    sweep = SimpleNamespace(name="seed000-two-stage-moving-variable-long", seeds=1,
                            variants=(1,) * 12, grid={"align.mode": []})
    label = bar_label(sweep)
    assert len(label) <= 30 and label.endswith(" 12 variants × 1 seed")


# ------------------------------------------------------------------ the Python API


def test_result_truth_is_none_without_full_truth(tmp_path):
    import gcalign

    p = _write(tmp_path, STATIC, "static")
    nav = gcalign.run("navigate", p, output=tmp_path / "n.h5")
    assert nav.truth() is None  # its errors against truth are in its own series
    al = gcalign.run("align", small_align(tmp_path), output=tmp_path / "a.h5")
    assert al.truth() is None  # attitude truth only
    assert "att" in al.series("truth")
    sim = gcalign.run("simulate", p, output=tmp_path / "s.h5")
    tr = sim.truth()
    assert tr is not None and tr.v_n.shape == (len(tr.t), 3)


# ------------------------------------------------------------------ batch figures


def test_batch_figure_of_long_file_names_neither_overlaps_nor_clips():
    """Box plot of a batch over three files with long names: the tick labels do not
    overlap each other and the title stays inside the figure (drawn, then measured)."""
    import numpy as np

    from gcalign.app.batch.plots import batch_figure, wrap_words

    names = ["scenario=seed000_moving_conventional.yaml",
             "scenario=seed000_moving_full_cycle.yaml", "scenario=seed000_moving_half_cycle.yaml"]
    variant = np.repeat(np.arange(3), 4)
    values = np.random.default_rng(1).normal(size=(12, 3))
    fig = batch_figure("error_t3_deg", values, variant, names, ["pitch", "roll", "yaw"],
                       title="+".join(names) + ": error_t3_deg over 4 seed(s) per variant")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in fig.axes[-1].get_xticklabels()]
    assert len(boxes) == 3
    for a, b in zip(boxes, boxes[1:], strict=False):
        assert a.x1 < b.x0  # apart
    title = fig._suptitle.get_window_extent(renderer)
    assert title.x0 >= 0 and title.x1 <= fig.bbox.width and title.y1 <= fig.bbox.height
    assert wrap_words("seed000_moving_full_cycle", 14) == "seed000_\nmoving_full_\ncycle"
    from gcalign.app.batch.plots import _variant_label

    assert _variant_label({"scenario": "seed000_moving_conventional.yaml"}, ["scenario"]) \
        == "seed000_moving_conventional"


@pytest.mark.parametrize("data, where, keys", [
    ({**STATIC, "initial": {"att_deg": [0, 0, 0], "vel_enu": [0, 0, 0]}}, "initial.vel_enu",
     "initial has: att_deg, v_enu_mps"),
    ({**STATIC, "align": {"mdoe": "conventional"}}, "align.mdoe", "align has: coarse, mode,"),
    ({**STATIC, "motion": {"kind": "moving", "duration_s": 3,
                           "segments": [{"duration_s": 1, "acel_mps2": 1}]}},
     "motion.segments.0.acel_mps2", "motion.segments.0 has: duration_s, accel_mps2, rate_dps"),
])
def test_unknown_key_lists_the_keys_of_its_mapping(tmp_path, data, where, keys):
    res = runner.invoke(app, ["validate", str(_write(tmp_path, data, "bad"))])
    assert res.exit_code == 2, res.output
    assert f"{where}: unknown key; {keys}" in res.output, res.output


@pytest.mark.slow
def test_a_first_run_says_it_is_compiling_and_a_cached_load_gives_the_same_file(tmp_path):
    """With an empty numba cache the run says, above its bar, that it compiles the kernels
    once; the second run loads them (through the cached-load shortcut of nav/_kernels where
    the numba version is one it was checked on), says nothing of it and writes the same
    numbers."""
    import os
    import subprocess
    import sys

    import h5py
    import numba
    import numpy as np

    from gcalign.cli.common import COMPILING
    from gcalign.nav import _kernels

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "GCALIGN_PROGRESS": "always"}
    args = [sys.executable, "-m", "gcalign", "align", str(small_align(tmp_path)), "-o"]
    first = subprocess.run(args + [str(tmp_path / "a.h5")], env=env, capture_output=True,
                           text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    assert COMPILING[:60] in first.stderr.replace("\n", " ")
    second = subprocess.run(args + [str(tmp_path / "b.h5")], env=env, capture_output=True,
                            text=True, timeout=600)
    assert second.returncode == 0, second.stderr
    assert "compiling" not in second.stderr
    datasets: dict[str, list] = {"a": [], "b": []}
    for name in datasets:
        with h5py.File(tmp_path / f"{name}.h5", "r") as f:
            f.visititems(lambda key, obj, out=datasets[name]: out.append((key, obj[()]))
                         if isinstance(obj, h5py.Dataset) else None)
    assert [k for k, _ in datasets["a"]] == [k for k, _ in datasets["b"]]
    for (key, a), (_, b) in zip(datasets["a"], datasets["b"], strict=True):
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), key
    from numba.core import caching

    shortcut = tuple(map(int, numba.__version__.split(".")[:2])) in _kernels.SHORTCUT_NUMBA
    assert getattr(caching.Cache, "_gcalign_load", False) == shortcut
