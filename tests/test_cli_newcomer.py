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
from typer.testing import CliRunner

from gcalign.cli import app

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")

STATIC = {"name": "static", "site": {"lat_deg": 45, "lon_deg": 126},
          "motion": {"kind": "static", "duration_s": 20}}
SHORT_FLIGHT = {
    "name": "short-flight", "site": {"lat_deg": 38.0, "lon_deg": 121.0},
    "imu": {"rate_hz": 25, "seed": 2},
    "motion": {"kind": "flight", "segments": [
        {"kind": "hold", "duration_s": 10, "name": "static"},
        {"kind": "accelerate", "accel_mps2": 6.5, "speed_mps": 40, "name": "ground roll"},
        {"kind": "turn", "rate_dps": 9, "angle_deg": -90, "name": "turn"},
        {"kind": "hold", "duration_s": 5, "name": "cruise"}]},
    "calibrate": {"navigation_rate_hz": 25, "conventional_segments": 2},
}
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
    raise KeyError(command)


COMMANDS = ["simulate", "navigate", "align", "calibrate", "observability", "northfind",
            "realtime", "modulate"]


@pytest.mark.slow
@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_shows_a_bar_and_where_its_file_went(tmp_path, monkeypatch, command):
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    args = _args(tmp_path, command)
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    bar = ANSI.sub("", res.stderr).replace("\r", "\n")
    assert f"{command} running" in bar  # before the first kernel call (numba's compile)
    assert "100%" in bar, bar
    assert all(len(x) <= 80 for x in bar.splitlines() if "━" in x), bar
    assert "running" not in res.stdout  # the table's stream holds no bar
    assert f"wrote {args[-1]}\n" in res.stderr


def test_modulate_bar_counts_data_seconds_of_its_scheme(tmp_path, monkeypatch):
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    res = runner.invoke(app, _args(tmp_path, "modulate"))
    assert res.exit_code == 0, res.output
    bar = ANSI.sub("", res.stderr)
    assert "modulate seed-12 (data s)" in bar and "180/180" in bar  # 0.05 h = 180 s


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
    bar = ProgressBar("x", delay_s=0.05)
    bar.enabled = True  # as on a terminal
    try:
        bar(0, 1, "starting")
        assert bar.bar is None  # not yet: short runs stay quiet
        for _ in range(100):
            if "starting" in bar.tasks:
                break
            time.sleep(0.01)
        assert bar.bar is not None and "starting" in bar.tasks
    finally:
        bar.close()
    late = ProgressBar("y", delay_s=0.05)
    late.enabled = True
    late(0, 1, "starting")
    late.close()  # done before the delay: never drawn
    time.sleep(0.1)
    assert late.bar is None
