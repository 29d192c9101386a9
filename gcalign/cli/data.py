"""Foundation commands: simulate, navigate, show, validate."""

from __future__ import annotations

import re
from pathlib import Path

import typer
import yaml

from gcalign.app.report import kv_table, summary_table
from gcalign.cli import app, consoles, emit_json, user_errors
from gcalign.cli.common import run_and_show
from gcalign.io import results
from gcalign.io.results import HDF5_SUFFIXES
from gcalign.io.scenario import load_scenario, parse_scenario
from gcalign.io.scenario.resolve import resolved_rows

DATA_SUFFIXES = {".imu", ".csv", ".txt"}
JSON_HELP = "Print one JSON object on stdout (tables go to stderr)."
OUT_HELP = "Results file (default runs/NAME-COMMAND[-seedN].h5)."


@app.command()
@user_errors
def simulate(
    scenario: Path = typer.Argument(..., help="Scenario YAML."),
    output: Path | None = typer.Option(None, "-o", "--output", help=OUT_HELP),
    seed: int | None = typer.Option(None, "--seed", help="Override imu.seed."),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Simulate truth and IMU data; write /truth and /imu."""
    sc, text = load_scenario(scenario)
    run_and_show("simulate", sc, text, seed, output, as_json)


@app.command()
@user_errors
def navigate(
    source: Path = typer.Argument(
        ..., help="Scenario YAML, a results file with /imu, or a PSINS .imu / CSV data file."
    ),
    output: Path | None = typer.Option(None, "-o", "--output", help=OUT_HELP),
    seed: int | None = typer.Option(None, "--seed", help="Override imu.seed."),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Free inertial navigation from the true initial state; errors against truth.

    Recorded data have no truth: the run starts from the file header's state and the
    table shows the final state instead of errors (`final_error` is null in the JSON).
    """
    suffix = source.suffix.lower()
    if suffix in DATA_SUFFIXES | HDF5_SUFFIXES:
        # A bare data file stands for the scenario `imu_file: SOURCE`; our own results
        # file keeps the name and text of the scenario that made it.
        text = results.read_scenario_yaml(source) if suffix in HDF5_SUFFIXES else ""
        stored = yaml.safe_load(text) if text else None
        name = stored.get("name") if isinstance(stored, dict) else None
        name = name or re.sub(r"[^A-Za-z0-9_.+-]", "_", source.stem) or "data"
        scenario = {"name": name, "imu_file": str(source.resolve())}
        text = text or yaml.safe_dump(scenario)
        sc = parse_scenario(scenario, str(source))
    else:
        sc, text = load_scenario(source)
    run_and_show("navigate", sc, text, seed, output, as_json)


@app.command()
@user_errors
def show(
    file: Path = typer.Argument(..., help="A gcalign results file."),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Print the summary of a results file again, from the file alone."""
    kind, summary, attrs = results.read_summary(file)
    console = consoles(as_json)
    console.print(summary_table(kind, summary))
    console.print(
        f"[dim]{attrs.get('command_line', '')}  ({attrs.get('created_utc', '')}, "
        f"gcalign {attrs.get('gcalign_version', '?')})[/dim]"
    )
    if as_json:
        emit_json({"kind": kind, **summary})


@app.command()
@user_errors
def validate(
    scenario: Path = typer.Argument(..., help="Scenario YAML."),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Check a scenario and print its resolved values in user units and SI."""
    sc, _ = load_scenario(scenario)
    rows = resolved_rows(sc)
    consoles(as_json).print(kv_table(f"{scenario}: valid", rows, ("field", "value", "SI")))
    if as_json:
        emit_json({"valid": True, "values": {k: {"value": v, "si": s} for k, v, s in rows}})
