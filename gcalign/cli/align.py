"""`gcalign align`: gyrocompass alignment (seed 000)."""

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
from gcalign.pipelines.align import alignment_summary, run_alignment
from gcalign.pipelines.data import scenario_data

BUILTIN = "seed000_moving_full_cycle.yaml"


def builtin_scenario_text() -> str:
    """The built-in seed 000 §5.3 moving-base full-cycle scenario (YAML text)."""
    return resources.files("gcalign.scenarios").joinpath(BUILTIN).read_text(encoding="utf-8")


def load_with_overrides(path: Path | None, overrides: dict):
    """Scenario and its text with CLI overrides of `align.*` applied before validation,
    so that a bad override is reported like a bad key in the file."""
    if path is None:
        text, source = builtin_scenario_text(), f"<built-in {BUILTIN}>"
        data = yaml.safe_load(text)
    else:
        data, source = read_yaml(path), str(path)
        text = Path(path).read_text(encoding="utf-8")
    align = dict(data.get("align") or {}) if isinstance(data, dict) else {}
    align.update({k: v for k, v in overrides.items() if v is not None})
    if isinstance(data, dict):
        data["align"] = align
    sc = parse_scenario(data, source)
    if sc.imu_file is not None and path is not None and not sc.imu_file.is_absolute():
        sc.imu_file = (Path(path).parent / sc.imu_file).resolve()
    if any(v is not None for v in overrides.values()):
        text += "\n# command-line overrides of align:\n" + yaml.safe_dump(
            {"align": {k: v for k, v in overrides.items() if v is not None}}
        )
    return sc, text


def _t3(value: str | None):
    if value is None or value == "measured":
        return value
    try:
        return float(value)
    except ValueError:
        return value  # pydantic names the field and what is allowed


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
    sc, text = load_with_overrides(scenario, overrides)
    data = scenario_data(sc, seed)
    run = run_alignment(sc, data)
    summary = alignment_summary(run, data, sc.name)
    out = output or default_output(sc.name, "align", data.seed)
    summary["output"] = str(out)
    with results.atomic_h5(out) as f:
        results.write_header(f, "align", text, data.seed, summary)
        if data.truth is not None:
            results.write_truth(f, data.truth)
        results.write_alignment(f, run)
    consoles(as_json).print(report.align_table(summary))
    if as_json:
        emit_json(summary)
