"""The options several commands share, declared once (one help text each) as annotated
types: a command writes ``seed: Seed = None`` and Typer reads the option from the type.
The recorded-data options (``--imu-file``, ``--format``, ``--axes``, ``--reference``,
``--lat``, ``--lon``, ``--height``) are declared the same way; every command that runs on
recorded data names them and passes them on as one value
(:func:`gcalign.cli.common.recorded`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from gcalign.choices import RECORDING_FORMATS, listed

JSON_HELP = "Print one JSON object on stdout (tables go to stderr)."
OUT_HELP = ("Results file; default runs/NAME-COMMAND[-OVERRIDES][-rngN].h5, with every option "
            "that changes the result in the name and N the random seed.")
SEED_HELP = "Random seed of the simulated sensor noise (overrides imu.seed)."

SET_HELP = ("Set any scenario key, dotted as in a sweep grid; VALUE is YAML "
            "(--set align.stages.0.t_z_s=200 --set imu.gyro.bias_dph=0.01). Repeatable.")

Seed = Annotated[int | None, typer.Option("--seed", help=SEED_HELP)]
Output = Annotated[Path | None, typer.Option("-o", "--output", help=OUT_HELP)]
Json = Annotated[bool, typer.Option("--json", help=JSON_HELP)]
Sets = Annotated[list[str] | None, typer.Option("--set", metavar="KEY=VALUE", help=SET_HELP)]

IMU_FILE_HELP = ("Recorded IMU data (PSINS .imu, CSV/text, gcalign HDF5; .gz/.xz "
                 "compressed) instead of the scenario's simulation: it replaces the motion, "
                 "mechanism, imu and site sections; the site then comes from the file's "
                 "header or --lat/--lon/--height.")
FORMAT_HELP = (f"Layout of the --imu-file (or the scenario's imu_file): "
               f"{listed(RECORDING_FORMATS)} | auto (from the suffix); see "
               "docs/how-to/file-formats.md.")
REFERENCE_HELP = ("Reference solution of the recording (a master INS, a post-processed "
                  "trajectory): .mat psins-mat avp, .csv csv, else i2nav-nav (KF-GINS); "
                  "errors against it, and the initial state when the data have none.")
AXES_HELP = ("Body axes of the recording, the file's x, y, z: three of F/B, R/L, U/D, e.g. "
             "RFU (ours), FRD (KF-GINS), FLU (ROS).")

ImuFile = Annotated[Path | None, typer.Option("--imu-file", metavar="FILE", help=IMU_FILE_HELP)]
ImuFormat = Annotated[str | None, typer.Option("--format", metavar="FORMAT", help=FORMAT_HELP)]
ImuAxes = Annotated[str | None, typer.Option("--axes", metavar="AXES", help=AXES_HELP)]
Reference = Annotated[Path | None, typer.Option("--reference", metavar="FILE",
                                                help=REFERENCE_HELP)]
Lat = Annotated[float | None, typer.Option(
    "--lat", metavar="DEG", help="Site latitude (deg); with --lon (and --height) replaces the "
    "site of the scenario or of the data file's header.")]
Lon = Annotated[float | None, typer.Option("--lon", metavar="DEG", help="Site longitude (deg).")]
Height = Annotated[float | None, typer.Option("--height", metavar="M", help="Site height (m).")]
