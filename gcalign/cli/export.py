"""`gcalign export`: a results file's series as CSV, MAT, KF-GINS or PSINS files."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from gcalign.choices import EXPORT_FORMATS, listed
from gcalign.cli.base import app, consoles, emit_json
from gcalign.cli.options import Json


@app.command()
def export(
    file: Path = typer.Argument(..., help="A gcalign results file (.h5)."),
    fmt: str = typer.Option(..., "--format", metavar="FORMAT",
                            help=listed(EXPORT_FORMATS)),
    output: Path | None = typer.Option(
        None, "-o", "--output", help="File to write; default FILE with the format's suffix "
        "(.csv, .mat, .nav, .avp.mat)."),
    group: str | None = typer.Option(
        None, "--group", help="Group of the series (default: the command's, e.g. navigate; "
        "an alignment's last pass, a calibration's first run)."),
    week: int = typer.Option(0, "--week", help="GNSS week written by i2nav-nav (the results "
                             "keep seconds only).", min=0, max=9999),
    as_json: Json = False,
):
    """Write the time series of a results file in another tool's format: csv (units in the
    header), mat (scipy.io.savemat, units in a struct), i2nav-nav (KF-GINS: NED, degrees),
    psins-avp (PSINS avp array in a MAT file)."""
    from gcalign.app.export import export as run

    out = run(file, fmt, output, group, week,
              note=lambda text: sys.stderr.write(text + "\n"))
    consoles(as_json).print(str(out), highlight=False, soft_wrap=True)
    if as_json:
        emit_json({"file": str(file), "format": fmt, "output": str(out)})
