"""Foundation commands: simulate, navigate, show, validate."""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np
import typer
import yaml

from gcalign.app import report
from gcalign.app.data import HDF5_SUFFIXES, RunData, scenario_data
from gcalign.app.navigate.run import navigation_summary, run_navigation
from gcalign.cli import app, consoles, default_output, emit_json, user_errors
from gcalign.cli.common import save_and_show
from gcalign.io import results
from gcalign.io.scenario import load_scenario, parse_scenario
from gcalign.io.scenario.resolve import resolved_rows

DATA_SUFFIXES = {".imu", ".csv", ".txt"}
JSON_HELP = "Print one JSON object on stdout (tables go to stderr)."
OUT_HELP = "Results file (default runs/NAME-COMMAND[-seedN].h5)."


def simulation_summary(data: RunData, name: str, compute_s: float) -> dict:
    imu = data.imu
    s = {
        "scenario": name,
        "seed": data.seed,
        "samples": len(imu),
        "rate_hz": 1.0 / imu.ts,
        "duration_s": float(len(imu) * imu.ts),
        "compute_s": compute_s,
        "initial_attitude_deg": None,
        "final_attitude_deg": None,
        "final_velocity_mps": None,
        "distance_m": None,
    }
    if data.truth is not None:
        tr = data.truth
        step = np.linalg.norm(np.diff(tr.t)[:, None] * 0.5 * (tr.v_n[1:] + tr.v_n[:-1]), axis=1)
        s.update(
            initial_attitude_deg=np.degrees(tr.att[0]).tolist(),
            final_attitude_deg=np.degrees(tr.att[-1]).tolist(),
            final_velocity_mps=tr.v_n[-1].tolist(),
            distance_m=float(step.sum()),
        )
    return s


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
    t0 = time.perf_counter()
    data = scenario_data(sc, seed)
    summary = simulation_summary(data, sc.name, time.perf_counter() - t0)
    out = output or default_output(sc.name, "simulate", data.seed)
    save_and_show(
        out,
        "simulate",
        text,
        data.seed,
        summary,
        report.simulate_table,
        as_json,
        lambda f: results.write_imu(f, data.imu),
        data.truth,
    )


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
    data = scenario_data(sc, seed)
    run = run_navigation(data)
    summary = navigation_summary(run, data, sc.name)
    out = output or default_output(sc.name, "navigate", data.seed)
    save_and_show(
        out,
        "navigate",
        text,
        data.seed,
        summary,
        report.navigate_table,
        as_json,
        lambda f: results.write_navigation(f, run),
        data.truth,
    )


@app.command()
@user_errors
def show(
    file: Path = typer.Argument(..., help="A gcalign results file."),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Print the summary of a results file again, from the file alone."""
    kind, summary, attrs = results.read_summary(file)
    console = consoles(as_json)
    console.print(report.summary_table(kind, summary))
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
    consoles(as_json).print(report.kv_table(f"{scenario}: valid", rows, ("field", "value", "SI")))
    if as_json:
        emit_json({"valid": True, "values": {k: {"value": v, "si": s} for k, v, s in rows}})
