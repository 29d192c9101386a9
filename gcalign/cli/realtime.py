"""`gcalign realtime`: attitude at external sync pulses, filter delay and prediction
(seed 003)."""

from __future__ import annotations

from pathlib import Path

import typer

from gcalign.choices import PREDICTORS, listed
from gcalign.cli.base import app
from gcalign.cli.common import load_with_overrides, run_and_show
from gcalign.cli.options import Json, Output, Seed, Sets


@app.command()
def realtime(
    scenario: Path | None = typer.Argument(
        None, help="Scenario YAML; without it, the seed's Table 1 (12 cases) in its "
        "semi-physical setting and a 13th case with asynchronous pulses."),
    predictor: list[str] | None = typer.Option(
        None, "--predictor", help=f"{listed(PREDICTORS)} (repeat the option for several; "
        "default all three)."),
    seed: Seed = None,
    output: Output = None,
    as_json: Json = False,
    set_: Sets = None,
):
    """Attitude at sync pulses: filter delay T + Δt, and prediction to the pulse time."""
    overrides = {"predictors": list(predictor) if predictor else None}
    loaded = load_with_overrides("realtime", scenario, overrides, sets=set_)
    run_and_show("realtime", loaded, seed, output, as_json)
