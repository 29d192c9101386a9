"""`gcalign northfind`: multi-position gyro north-finding with tilt compensation (seed 001)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import typer
import yaml

from gcalign import report, results
from gcalign.cli import app, consoles, default_output, emit_json, user_errors
from gcalign.cli.data import JSON_HELP, OUT_HELP
from gcalign.config import parse_scenario
from gcalign.config.loader import read_yaml
from gcalign.errors import ScenarioError
from gcalign.pipelines.northfind import northfind_summary, run_northfind

BUILTIN = "seed001_simulation.yaml"


def builtin_scenario_text() -> str:
    """The built-in seed 001 §3.1 simulation scenario (YAML text)."""
    return resources.files("gcalign.scenarios").joinpath(BUILTIN).read_text(encoding="utf-8")


def parse_sweep(text: str | None) -> dict | None:
    """``START:STOP:STEP`` (degrees) -> the ``northfind.sweep`` mapping (values validated later)."""
    if text is None:
        return None
    parts = text.split(":")
    if len(parts) != 3 or not all(p.strip() for p in parts):
        raise ScenarioError(
            f"northfind.sweep: --sweep expects START:STOP:STEP in degrees (e.g. 0:360:5), "
            f"got {text!r}"
        )
    return dict(zip(("start_deg", "stop_deg", "step_deg"), (p.strip() for p in parts), strict=True))


def load_with_overrides(path: Path | None, overrides: dict):
    """Scenario and its text with command-line overrides of ``northfind.*`` applied before
    validation, so a bad option is reported like a bad key in the file (field, value, rule).

    ``azimuth_deg`` replaces a sweep of the file and ``sweep`` an azimuth; both given is the
    usual "not both" error.
    """
    if path is None:
        text, source = builtin_scenario_text(), f"<built-in {BUILTIN}>"
        data = yaml.safe_load(text)
    else:
        data, source = read_yaml(path), str(path)
        text = Path(path).read_text(encoding="utf-8")
    given = {k: v for k, v in overrides.items() if v is not None}
    if isinstance(data, dict) and given:
        section = data.get("northfind")
        section = dict(section) if isinstance(section, dict) else {}
        if "azimuth_deg" in given and "sweep" not in given:
            section.pop("sweep", None)
        if "sweep" in given and "azimuth_deg" not in given:
            section.pop("azimuth_deg", None)
        section.update(given)
        data["northfind"] = section
    sc = parse_scenario(data, source)
    if sc.northfind is not None:
        try:
            sc.northfind.check(sc)
        except ScenarioError as err:
            raise ScenarioError(f"{source}: {err}") from None
    if given:
        text += "\n# command-line overrides of northfind:\n" + yaml.safe_dump(
            {"northfind": given}, sort_keys=False)
    return sc, text


@app.command()
@user_errors
def northfind(
    scenario: Path | None = typer.Argument(
        None, help="Scenario YAML; without it, the built-in seed 001 §3.1 simulation (sweep "
                   "0…355°, 10° tilt)."),
    method: list[str] | None = typer.Option(
        None, "--method", help="coordinate | vector | naive | none | vector_literal (repeat "
                               "the option for several)."),
    positions: int | None = typer.Option(None, "--positions", help="Table positions per turn."),
    dwell: float | None = typer.Option(None, "--dwell", help="Dwell per position (s)."),
    tilt: float | None = typer.Option(None, "--tilt", help="Table tilt (deg)."),
    azimuth: float | None = typer.Option(None, "--azimuth",
                                         help="One true azimuth (deg); replaces a sweep."),
    sweep: str | None = typer.Option(None, "--sweep",
                                     help="START:STOP:STEP (deg); replaces azimuth_deg."),
    repeats: int | None = typer.Option(None, "--repeats",
                                       help="Independent determinations per azimuth."),
    seed: int | None = typer.Option(None, "--seed", help="Override imu.seed."),
    output: Path | None = typer.Option(None, "-o", "--output", help=OUT_HELP),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Multi-position north-finding on a tilted table: coordinate, vector, naive and none."""
    overrides = {"methods": list(method) if method else None, "positions": positions,
                 "dwell_s": dwell, "tilt_deg": tilt, "azimuth_deg": azimuth,
                 "sweep": parse_sweep(sweep), "repeats": repeats}
    sc, text = load_with_overrides(scenario, overrides)
    run = run_northfind(sc, seed)
    summary = northfind_summary(run, sc)
    out = output or default_output(sc.name, "northfind", run.seed)
    summary["output"] = str(out)
    with results.atomic_h5(out) as f:
        results.write_header(f, "northfind", text, run.seed, summary)
        results.write_northfind(f, run)
    consoles(as_json).print(report.northfind_table(summary))
    if as_json:
        emit_json(summary)
