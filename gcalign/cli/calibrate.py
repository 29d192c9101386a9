"""`gcalign calibrate` and `gcalign observability`: in-flight calibration (seed 002)."""

from __future__ import annotations

from pathlib import Path

import typer

from gcalign.choices import MATCHINGS, MEASUREMENTS, TRUTH_SOURCES, listed
from gcalign.cli import options as opt
from gcalign.cli.base import app
from gcalign.cli.common import load_with_overrides, recorded, run_and_show
from gcalign.errors import ScenarioError

SCENARIO_HELP = "Scenario YAML; without it, the built-in seed 002 designed 590 s take-off."
MEASURE_HELP = f"DGNSS measurement: {listed(MEASUREMENTS)}."
MATCHING_HELP = (f"Transfer alignment (align.mode: transfer): {listed(MATCHINGS)} (sets "
                 "align.transfer.matching).")


@app.command()
def calibrate(
    scenario: Path | None = typer.Argument(None, help=SCENARIO_HELP),
    measure: str | None = typer.Option(None, "--measure", help=MEASURE_HELP),
    compare: bool = typer.Option(
        False, "--compare", help="Velocity, position and both on the flight and on its first "
        "calibrate.conventional_segments segments (the seed's Table 3)."),
    smoother: bool | None = typer.Option(
        None, "--smoother/--no-smoother", help="Also run the RTS smoother (post-flight)."),
    truth: str | None = typer.Option(
        None, "--truth", help=f"Injected errors: {listed(TRUTH_SOURCES)} (from P0 with the seed)."),
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
    """In-flight calibration: the 21-state Kalman filter aided by DGNSS (or zero velocity
    on recorded data); per state the injected truth, estimate, error and final σ."""
    given = recorded(imu_file, imu_format, imu_axes, reference, lat, lon, height)
    overrides = {"measure": measure, "smoother": smoother, "truth": truth}
    loaded = load_with_overrides("calibrate", scenario, overrides, sets=set_, recorded=given)
    run_and_show("calibrate", loaded, seed, output, as_json, compare=compare)


@app.command()
def observability(
    scenario: Path | None = typer.Argument(None, help=SCENARIO_HELP),
    measure: str | None = typer.Option(None, "--measure", help=MEASURE_HELP),
    scaling: str | None = typer.Option(
        None, "--scaling",
        help="p0 (default: columns × initial σ, unit-free ranks) | none (the paper: unscaled)."),
    matching: str | None = typer.Option(None, "--matching", help=MATCHING_HELP),
    output: opt.Output = None,
    as_json: opt.Json = False,
    set_: opt.Sets = None,
):
    """Observability of the flight's manoeuvres: PWCS pieces, SOM/TOM ranks and the seed's
    SVD degree η per segment and cumulative (Table 1 analogue); on a transfer-alignment
    scenario, of the transfer filter's run per window and per state."""
    overrides = {"measure": measure, "scaling": scaling}
    sets = list(set_ or [])
    if matching is not None:
        sc = load_with_overrides("observability", scenario, overrides, sets=set_).scenario
        if sc.align is None or sc.align.mode != "transfer":
            raise ScenarioError(f"--matching: {matching!r} applies to a transfer-alignment "
                                "scenario (align.mode: transfer); a flight takes --measure")
        sets.append(f"align.transfer.matching={matching}")
    loaded = load_with_overrides("observability", scenario, overrides, sets=sets)
    run_and_show("observability", loaded, None, output, as_json)
