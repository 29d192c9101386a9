"""`gcalign allan`: the Allan deviation of IMU data and the noise terms fitted to it."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from gcalign.cli import options as opt
from gcalign.cli.base import app
from gcalign.cli.common import load_with_overrides, recorded, run_and_show
from gcalign.errors import ScenarioError
from gcalign.io.paths import not_a_file

SCENARIO_HELP = ("Write a static scenario with the fitted noise as its imu section (site and "
                 "duration of the data), to run as it is; '-' prints it on stdout (the table "
                 "then goes to stderr).")


@app.command()
def allan(
    source: Path | None = typer.Argument(
        None, help="A recording (PSINS .imu, CSV/text, PSINS MAT, KF-GINS; .gz/.xz "
        "compressed too), a `gcalign simulate` results file, or a scenario YAML (simulated "
        "at rest, or naming its imu_file). Or none, with --imu-file FILE."),
    start: float | None = typer.Option(None, "--start", help="Data time the window starts at "
                                       "(s)."),
    duration: float | None = typer.Option(None, "--duration", help="Window length (s)."),
    scenario_out: str | None = typer.Option(None, "--scenario", metavar="FILE",
                                            help=SCENARIO_HELP),
    output: opt.Output = None,
    seed: opt.Seed = None,
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
    """Overlapping Allan deviation of every gyro and accelerometer axis (allantools), its 1σ
    interval from the number of clusters, and the IEEE Std 952 terms fitted to it:
    quantization (slope −1), ARW/VRW (−½), bias instability (flat / 0.664) and rate random
    walk (+½), each with its τ range and interval, named as the scenario's imu keys."""
    import yaml

    from gcalign.cli.data import data_file
    from gcalign.io import results

    if source is not None and not source.is_file():
        raise ScenarioError(f"{source}: {not_a_file(source)}")
    given = recorded(imu_file, imu_format, imu_axes, reference, lat, lon, height)
    if source is None and given.imu_file is None:
        raise ScenarioError("allan: give a recording, a results file or a scenario (SOURCE), "
                            "or --imu-file FILE")
    if scenario_out not in (None, "-"):  # a file
        if output is not None and Path(scenario_out).resolve() == Path(output).resolve():
            raise ScenarioError(f"--scenario: {scenario_out} is also the results file (-o)")
        results.check_output(scenario_out, "--scenario")
    data, _ = data_file(source, ("earth",))
    text = None if data is None else yaml.safe_dump(data)
    overrides = {"start_s": start, "duration_s": duration}
    loaded = load_with_overrides("allan", source, overrides, data=data, text=text,
                                 sets=set_, recorded=given)
    if as_json and scenario_out == "-":
        raise ScenarioError("--scenario: '-' prints the scenario on stdout, where --json "
                            "prints its JSON; give --scenario FILE, or leave out --json")
    captured: dict = {}
    run_and_show("allan", loaded, seed, output, as_json, on_summary=captured.update,
                 stdout_free=scenario_out == "-")
    if scenario_out is not None:
        from gcalign.app.allan.scenario import scenario_text

        out = scenario_text(captured)
        if scenario_out == "-":
            sys.stdout.write(out)
        else:
            with results.atomic_file(scenario_out, "w") as f:  # whole or not at all
                f.write(out)
            sys.stderr.write(f"wrote {scenario_out}\n")

