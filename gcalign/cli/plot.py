"""`gcalign plot`: PNG figures from a results file (alignment, north-finding, navigation,
batch, ...) or of a recorded IMU data file."""

from __future__ import annotations

from pathlib import Path

import typer

from gcalign.cli.base import app, consoles, emit_json
from gcalign.cli.options import Json


@app.command()
def plot(
    file: Path = typer.Argument(..., help="A gcalign results file (.h5), or recorded IMU "
                                "data (PSINS .imu, CSV; .gz/.xz): its IMU output."),
    out_dir: str | None = typer.Option(  # a str: a Path would turn '' into '.'
        None, "-o", "--output", help="Folder for the PNG files (default: FILE without its "
        "suffixes + '_plots/', next to the file)."),
    as_json: Json = False,
):
    """Write PNG figures: every figure the command that wrote FILE draws (alignment error
    and attitude per pass, navigation errors, north-finding error against azimuth, batch
    distributions, truth and IMU output, ...)."""
    from gcalign.app import readback
    from gcalign.cli.common import ProgressBar

    with ProgressBar("plot") as bar:
        written = readback.plot_file(file, out_dir, progress=bar)
    console = consoles(as_json)
    for p in written:
        console.print(str(p), highlight=False, soft_wrap=True)
    if as_json:
        kind = "data"
        if file.suffix.lower() in (".h5", ".hdf5", ".hdf"):
            from gcalign.io import results

            kind = results.read_summary(file)[0]
        emit_json({"file": str(file), "kind": kind, "figures": [str(p) for p in written]})
