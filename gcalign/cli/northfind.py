"""`gcalign northfind`: multi-position gyro north-finding with tilt compensation (seed 001)."""

from __future__ import annotations

from pathlib import Path

import typer

from gcalign.choices import AZIMUTH_METHODS_ALL, listed
from gcalign.cli.base import app
from gcalign.cli.common import load_with_overrides, run_and_show
from gcalign.cli.options import Json, Output, Seed, Sets
from gcalign.errors import ScenarioError


def parse_sweep(text: str | None) -> dict | None:
    """``START:STOP:STEP`` (degrees) -> the ``northfind.sweep`` mapping (values validated later)."""
    if text is None:
        return None
    parts = text.split(":")
    try:
        values = [float(p) for p in parts]  # an option's text read as numbers, as typer does
    except ValueError:
        values = []
    if len(values) != 3:
        raise ScenarioError(
            f"northfind.sweep: --sweep expects START:STOP:STEP in degrees (e.g. 0:360:5), "
            f"got {text!r}"
        )
    return dict(zip(("start_deg", "stop_deg", "step_deg"), values, strict=True))


def _one_azimuth_source(section: dict, given: dict) -> None:
    """An --azimuth option replaces the file's sweep and --sweep its azimuth (both given
    stays the usual "not both" error)."""
    if "azimuth_deg" in given and "sweep" not in given:
        section.pop("sweep", None)
    if "sweep" in given and "azimuth_deg" not in given:
        section.pop("azimuth_deg", None)


@app.command()
def northfind(
    scenario: Path | None = typer.Argument(
        None, help="Scenario YAML; without it, the built-in seed 001 §3.1 simulation (sweep "
        "0…355°, 10° tilt)."),
    method: list[str] | None = typer.Option(
        None, "--method", help=f"{listed(AZIMUTH_METHODS_ALL)} (repeat the option for several)."),
    positions: int | None = typer.Option(None, "--positions", help="Table positions per turn."),
    dwell: float | None = typer.Option(None, "--dwell", help="Dwell per position (s)."),
    tilt: float | None = typer.Option(None, "--tilt", help="Table tilt (deg)."),
    azimuth: float | None = typer.Option(
        None, "--azimuth", help="One true azimuth (deg); replaces a sweep."),
    sweep: str | None = typer.Option(
        None, "--sweep", help="START:STOP:STEP (deg); replaces azimuth_deg."),
    repeats: int | None = typer.Option(
        None, "--repeats", help="Independent determinations per azimuth."),
    seed: Seed = None,
    output: Output = None,
    as_json: Json = False,
    set_: Sets = None,
):
    """Multi-position north-finding on a tilted table: coordinate, vector, naive and none."""
    overrides = {"methods": list(method) if method else None, "positions": positions,
                 "dwell_s": dwell, "tilt_deg": tilt, "azimuth_deg": azimuth,
                 "sweep": parse_sweep(sweep), "repeats": repeats}
    loaded = load_with_overrides("northfind", scenario, overrides, _one_azimuth_source,
                                 sets=set_)
    run_and_show("northfind", loaded, seed, output, as_json)
