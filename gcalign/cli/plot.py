"""`gcalign plot`: PNG figures from a results file (alignment, north-finding, batch, ...)."""

from __future__ import annotations

from pathlib import Path

import typer

from gcalign.cli import app, consoles, emit_json, user_errors
from gcalign.cli.data import JSON_HELP


@app.command()
@user_errors
def plot(
    file: Path = typer.Argument(..., help="A gcalign results file (.h5)."),
    out_dir: Path | None = typer.Option(
        None,
        "-o",
        "--output",
        help="Folder for the PNG files (default: FILE without its "
        "suffix + '_plots/', next to the file).",
    ),
    as_json: bool = typer.Option(False, "--json", help=JSON_HELP),
):
    """Write PNG figures: alignment error and attitude per pass (equivalent time),
    north-finding error against true azimuth, batch distributions per variant."""
    from gcalign.app import plots
    from gcalign.io import results

    kind, _, _ = results.read_summary(file)
    written = plots.plot_file(file, out_dir)
    console = consoles(as_json)
    for p in written:
        console.print(str(p), highlight=False, soft_wrap=True)
    if as_json:
        emit_json({"file": str(file), "kind": kind, "figures": [str(p) for p in written]})
