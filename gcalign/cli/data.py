"""Foundation commands: simulate, navigate, show, validate."""

from __future__ import annotations

import re
from pathlib import Path

import typer

from gcalign.app.registry import COMMANDS
from gcalign.choices import VERTICAL_CHOICES, listed
from gcalign.cli import options as opt
from gcalign.cli.base import app, consoles, emit_json
from gcalign.cli.common import load_with_overrides, recorded, run_and_show, warn
from gcalign.errors import ScenarioError
from gcalign.io.paths import not_a_file

DATA_SUFFIXES = {".imu", ".csv", ".txt", ".mat"}


def data_file(source: Path | None, keep: tuple[str, ...]) -> tuple[dict | None, str]:
    """A data file given as SOURCE stands for the scenario ``imu_file: SOURCE``, and its
    scenario text ("" but for our own results file); (None, "") for anything else. Our own
    results file keeps the name of the scenario that made it and its sections `keep`."""
    import yaml

    from gcalign.io.imu_files import data_suffix
    from gcalign.io.results import HDF5_SUFFIXES, read_scenario_yaml

    suffix = "" if source is None else data_suffix(source)
    if source is None or suffix not in DATA_SUFFIXES | HDF5_SUFFIXES:
        return None, ""
    text = read_scenario_yaml(source) if suffix in HDF5_SUFFIXES else ""
    stored = yaml.safe_load(text) if text else None
    name = stored.get("name") if isinstance(stored, dict) else None
    name = name or re.sub(r"[^A-Za-z0-9_.+-]", "_", source.name.split(".")[0]) or "data"
    data = {"name": name, "imu_file": str(source.resolve())}
    if isinstance(stored, dict):
        data |= {key: stored[key] for key in keep if key in stored}
    return data, text


@app.command()
def simulate(
    scenario: Path = typer.Argument(..., help="Scenario YAML."),
    output: opt.Output = None,
    seed: opt.Seed = None,
    as_json: opt.Json = False,
    set_: opt.Sets = None,
):
    """Simulate truth and IMU data; write /truth and /imu."""
    run_and_show("simulate", load_with_overrides("simulate", scenario, sets=set_), seed, output,
                 as_json)


@app.command()
def navigate(
    source: Path | None = typer.Argument(
        None, help="Scenario YAML, a results file with /imu, or a PSINS .imu / CSV data file "
        "(.gz/.xz compressed too); a CSV has no site: give --lat/--lon/--height. Or none, "
        "with --imu-file FILE."
    ),
    init: str | None = typer.Option(
        None, "--init", help="Start from: truth | header | an alignment results file (its "
        "attitude at T3, at T3's data time). Default: truth, or the header of recorded data."),
    vertical: str | None = typer.Option(
        None, "--vertical", help=f"Vertical channel: {listed(VERTICAL_CHOICES)}."),
    start: float | None = typer.Option(None, "--start", help="Data time to start at (s)."),
    duration: float | None = typer.Option(None, "--duration", help="How long to navigate (s)."),
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
    """Strapdown navigation, streamed block by block; errors against truth at every sample.

    The vertical channel is held for bases whose height cannot change and for recorded
    data, damped to the true height on moving bases (navigation.vertical, --vertical).
    Recorded data have no truth: the table shows the final state and its drift from the
    start (`final_error` is null in the JSON).
    """
    import yaml

    given_options = recorded(imu_file, imu_format, imu_axes, reference, lat, lon, height)
    overrides = {"vertical": vertical, "start_s": start, "duration_s": duration}
    for what, given in (("--init", init), ("the source", source)):
        if output is not None and given not in (None, "truth", "header") and \
                Path(given).resolve() == Path(output).resolve():
            raise ScenarioError(f"--output: {output} is {what} of this run; write the result "
                                "under another name (it would replace its own input)")
    if source is not None and not source.is_file():
        raise ScenarioError(f"{source}: {not_a_file(source)}")
    if source is None and given_options.imu_file is None:
        raise ScenarioError("navigate: give a scenario or a data file (SOURCE), or "
                            "--imu-file FILE")
    data, stored = data_file(source, ("earth", "navigation", "output"))
    text = None if data is None else stored or yaml.safe_dump(data)
    loaded = load_with_overrides("navigate", source, overrides, data=data, text=text,
                                 sets=set_, recorded=given_options)
    run_and_show("navigate", loaded, seed, output, as_json, init=init)


@app.command()
def show(
    file: Path = typer.Argument(..., help="A gcalign results file."),
    as_json: opt.Json = False,
):
    """Print the summary of a results file again, from the file alone."""
    from gcalign.app.checked import read_checked
    from gcalign.app.readback import summary_table

    kind, summary, attrs = read_checked(file)
    console = consoles(as_json)
    try:
        table = summary_table(kind, summary)
    except ScenarioError as err:  # a summary the file's command cannot read: name the file
        raise ScenarioError(f"{file}: {err}") from None
    console.print(table)
    console.print(
        f"[dim]{attrs.get('command_line', '')}  ({attrs.get('created_utc', '')}, "
        f"gcalign {attrs.get('gcalign_version', '?')})[/dim]"
    )
    if as_json:
        emit_json({"kind": kind, **summary})


@app.command()
def validate(
    scenario: Path = typer.Argument(..., help="Scenario YAML, or a sweep YAML."),
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
    """Check a scenario and print its resolved values in user units and SI, and the keys
    that cannot matter (as warnings). A sweep file (docs/batch.md): every variant checked
    as `gcalign batch` checks it, and what the batch would run."""
    from gcalign.app.preflight import preflight
    from gcalign.app.report import kv_table
    from gcalign.io.scenario.loader import read_yaml
    from gcalign.io.scenario.resolve import resolved_rows

    given = recorded(imu_file, imu_format, imu_axes, reference, lat, lon, height)
    data = read_yaml(scenario)
    if isinstance(data, dict) and "base" in data:
        return _validate_sweep(scenario, set_, as_json)
    sc = load_with_overrides(None, scenario, sets=set_, recorded=given).scenario
    inputs = preflight(sc)  # the checks every command runs first, for every section
    rows = resolved_rows(sc, None if inputs.recording is None else inputs.recording.imu)
    sections = [c.section for c in COMMANDS.values() if c.section]
    warnings = list(dict.fromkeys(w for sec in sections for w in sc.unused(sec)))
    table = kv_table(f"{scenario}: valid", rows, ("field", "value", "SI"),
                     ("left", "right", "left"))
    table.columns[0].no_wrap = True  # the keys whole, on one line
    _answer(table, warnings, as_json,
            {"values": {k: {"value": v, "si": s} for k, v, s in rows}})


def _answer(table, warnings: list[str], as_json: bool, answer: dict) -> None:
    """validate's answer: the warnings (:func:`~gcalign.cli.common.warn`), the table, where
    a long name or value folds onto the next line, whole, and under --json
    ``{"valid": true, **answer, "warnings": [...]}``."""
    from gcalign.app.report import with_warnings

    warn(warnings, as_json)
    for column in table.columns:
        column.overflow = "fold"
    consoles(as_json).print(table if as_json else with_warnings(table, warnings))
    if as_json:
        emit_json({"valid": True, **answer, "warnings": warnings})


def _validate_sweep(path: Path, sets: list[str] | None, as_json: bool) -> None:
    """`gcalign validate` of a sweep file: the checks `gcalign batch` makes before any run
    (every case, grid value and variant parsed and preflighted; the memory of the runs
    held at once on this machine's cores), then what it would run."""
    import os

    from gcalign.app.batch.engine import budget_check, worker_count
    from gcalign.app.report import kv_table
    from gcalign.cli.batch import load_batch

    sw = load_batch([path], None, None, None, None, sets)
    runs = len(sw.variants) * sw.seeds
    budget_check(sw, worker_count(None, None, runs))
    seeds = (f"seed {sw.seed_start}" if sw.seeds == 1 else
             f"seeds {sw.seed_start}–{sw.seed_start + sw.seeds - 1}")
    base = os.path.normpath(sw.base_source)
    info = {"sweep": sw.name, "command": sw.command, "base": base,
            "variants": len(sw.variants), "seeds": f"{sw.seeds} ({seeds})", "runs": runs,
            "metrics": ", ".join(sw.metrics)}
    info |= {f"grid: {k}": ", ".join(map(str, v)) for k, v in sw.grid.items()}
    table = kv_table(f"{path}: valid sweep", [(k, str(v)) for k, v in info.items()],
                     ("key", "value"), ("left", "left"))
    _answer(table, list(sw.warnings), as_json, {"sweep": {
        "name": sw.name, "command": sw.command, "base": base,
        "variants": [v.label for v in sw.variants], "seeds": list(sw.seed_values),
        "runs": runs, "metrics": list(sw.metrics), "grid": sw.grid}})
