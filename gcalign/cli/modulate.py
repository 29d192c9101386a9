"""`gcalign modulate`: rotation modulation, schemes compared on the same data (seed 004)."""

from __future__ import annotations

from pathlib import Path

import typer

from gcalign.app.registry import COMMANDS
from gcalign.cli.base import app
from gcalign.cli.common import load_with_overrides, read_source, run_and_show
from gcalign.cli.options import Json, Output, Seed, Sets


def load_modulate(path: Path | None, overrides: dict, scheme: str | None,
                  dwell: float | None, sets: list[str] | None = None):
    """The scenario (:class:`~gcalign.cli.common.Loaded`) with --scheme/--dwell written
    into ``mechanism`` and the other options into ``modulate`` before validation. --scheme
    replaces the scenario's mechanism (a table too; its timing keys stay) and, without
    --compare, is the one scheme run."""
    from gcalign.io.scenario.loader import with_overrides

    data, text, _ = read_source(path, COMMANDS["modulate"].builtin or "")
    given = {k: v for k, v in (("scheme", scheme), ("dwell_s", dwell)) if v is not None}
    if given and isinstance(data, dict):
        mech = data.get("mechanism")
        mech = dict(mech) if isinstance(mech, dict) else {}
        if scheme is not None:
            for key in ("steps", "name", "reference", "repeat"):
                mech.pop(key, None)
            if overrides.get("compare") is None:
                overrides["compare"] = [scheme]
        mech.update(given)
        data["mechanism"] = mech
        text = with_overrides(text, " of mechanism",
                              {f"mechanism.{k}": v for k, v in given.items()})
    return load_with_overrides("modulate", path, overrides, data=data, text=text, sets=sets)


@app.command()
def modulate(
    scenario: Path | None = typer.Argument(
        None, help="Scenario YAML; without it, the built-in seed 004 case (static, 72 h, "
        "fixed, seed-12, four-position-12, dual-16-improved)."),
    scheme: str | None = typer.Option(
        None, "--scheme", help="Run this built-in scheme (replaces mechanism; alone unless "
        "--compare)."),
    compare: str | None = typer.Option(
        None, "--compare", help="Schemes on the same data, comma-separated "
        "(e.g. fixed,seed-12,four-position-12)."),
    hours: float | None = typer.Option(None, "--hours", help="How long to navigate (h)."),
    dwell: float | None = typer.Option(None, "--dwell", help="Dwell after each turn (s)."),
    seed: Seed = None,
    output: Output = None,
    as_json: Json = False,
    set_: Sets = None,
):
    """Strapdown navigation with the IMU on a rotation mechanism: per scheme the horizontal
    error at 1, 4, 12, 24, 72 h, the attitude-error maxima, the linear model beside it and
    the invariant report (mean C over the cycle, residual biases, Schuler warning)."""
    names = None if compare is None else [x.strip() for x in compare.split(",") if x.strip()]
    overrides = {"compare": names, "hours": hours}
    run_and_show("modulate", load_modulate(scenario, overrides, scheme, dwell, set_), seed,
                 output, as_json)
