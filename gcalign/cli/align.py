"""`gcalign align`: gyrocompass alignment (seed 000)."""

from __future__ import annotations

import math
from pathlib import Path

import typer

from gcalign.choices import ALIGN_MODES_ALL, COMPENSATIONS, listed
from gcalign.cli import options as opt
from gcalign.cli.base import app
from gcalign.cli.common import load_with_overrides, recorded, run_and_show
from gcalign.errors import ScenarioError


def _t3(value: str | None):
    """--t3: seconds or 'measured' (validated here: a union would give two messages)."""
    if value is None or value == "measured":
        return value
    try:
        seconds = float(value)
    except ValueError:
        seconds = math.nan
    if not math.isfinite(seconds):
        msg = f"align.t3_s: --t3 takes seconds or 'measured', got {value!r}"
        raise ScenarioError(msg)
    return seconds


def passes_into_stages(section: dict, given: dict) -> None:
    """--passes N (passes in all) sets the last stage's count to N minus the earlier
    stages' (the pass count is the sum of the stages' passes)."""
    n = given.pop("passes", None)
    if n is None:
        return
    stages = section.get("stages")
    stages = [dict(x) if isinstance(x, dict) else x for x in stages] if isinstance(
        stages, list) and stages else [{}]
    earlier = sum(int(x.get("passes") or 0) for x in stages[:-1] if isinstance(x, dict))
    if n - earlier < 1:
        raise ScenarioError(f"align.stages: --passes {n} leaves no pass for the last stage "
                            f"(the earlier stages take {earlier})")
    if isinstance(stages[-1], dict):
        stages[-1]["passes"] = n - earlier
    section["stages"] = stages


@app.command()
def align(
    scenario: Path | None = typer.Argument(
        None, help="Scenario YAML; without it, the built-in seed 000 §5.3 moving-base case "
        "(`gcalign example align` prints it)."
    ),
    mode: str | None = typer.Option(
        None, "--mode", help=listed(ALIGN_MODES_ALL)),
    compensation: str | None = typer.Option(
        None, "--compensation", help=f"{listed(COMPENSATIONS)} (T2 -> T3)"
    ),
    passes: int | None = typer.Option(
        None, "--passes", help="Forward and reverse passes in all (sets the last stage's "
        "align.stages.N.passes)."),
    t1: float | None = typer.Option(
        None, "--t1", help="End of the coarse window T1 (s); the fine block starts there."),
    t2: float | None = typer.Option(None, "--t2", help="End of the stored data block T2 (s)."),
    t3: str | None = typer.Option(None, "--t3", help="Result time T3 (s) or 'measured'."),
    seed: opt.Seed = None,
    output: opt.Output = None,
    as_json: opt.Json = False,
    set_: opt.Sets = None,
    imu_file: opt.ImuFile = None,
    imu_format: opt.ImuFormat = None,
    imu_axes: opt.ImuAxes = None,
    reference: opt.Reference = None,
    lat: opt.Lat = None,
    lon: opt.Lon = None,
    height: opt.Height = None,
):
    """Gyrocompass fine alignment with forward/reverse passes and T2 -> T3 compensation."""
    given = recorded(imu_file, imu_format, imu_axes, reference, lat, lon, height)
    overrides = {"mode": mode, "compensation": compensation, "passes": passes, "t1_s": t1,
                 "t2_s": t2, "t3_s": _t3(t3)}
    loaded = load_with_overrides("align", scenario, overrides, passes_into_stages, sets=set_,
                                 recorded=given)
    run_and_show("align", loaded, seed, output, as_json)
