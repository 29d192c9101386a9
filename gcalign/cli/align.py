"""`gcalign align`: gyrocompass alignment (seed 000)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import typer

from gcalign.app import report
from gcalign.app.align.run import alignment_summary, run_alignment
from gcalign.app.data import scenario_data
from gcalign.cli import app, default_output, user_errors
from gcalign.cli.common import builtin_text, load_with_overrides, save_and_show
from gcalign.cli.data import JSON_HELP, OUT_HELP
from gcalign.errors import ScenarioError
from gcalign.io import results

BUILTIN = "seed000_moving_full_cycle.yaml"


def builtin_scenario_text() -> str:
    """The built-in seed 000 §5.3 moving-base full-cycle scenario (YAML text)."""
    return builtin_text(BUILTIN)


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


@app.command()
@user_errors
def align(
    scenario: Path | None = typer.Argument(
        None, help="Scenario YAML; without it, the built-in seed 000 §5.3 moving-base case."
    ),
    mode: str | None = typer.Option(None, "--mode", help="conventional | full-cycle | half-cycle"),
    compensation: str | None = typer.Option(
        None, "--compensation", help="none | one-off | continued"
    ),
    passes: int | None = typer.Option(None, "--passes", help="Forward and reverse passes in all."),
    t2: float | None = typer.Option(None, "--t2", help="End of the stored data block T2 (s)."),
    t3: str | None = typer.Option(None, "--t3", help="Result time T3 (s) or 'measured'."),
    seed: int | None = typer.Option(None, "--seed", help="Override imu.seed."),
    output: Path | None = typer.Option(None, "-o", "--output", help=OUT_HELP),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Gyrocompass fine alignment with forward/reverse passes and T2→T3 compensation."""
    overrides = {
        "mode": mode,
        "compensation": compensation,
        "passes": passes,
        "t2_s": t2,
        "t3_s": _t3(t3),
    }
    sc, text, _ = load_with_overrides(scenario, BUILTIN, "align", overrides)
    data = scenario_data(sc, seed)
    run = run_alignment(sc, data)
    summary = alignment_summary(run, data, sc.name)
    for line in summary["warnings"]:
        sys.stderr.write(f"warning: {line}\n")
    out = output or default_output(sc.name, "align", data.seed)
    save_and_show(
        out,
        "align",
        text,
        data.seed,
        summary,
        report.align_table,
        as_json,
        lambda f: results.write_alignment(f, run),
        data.truth,
    )
