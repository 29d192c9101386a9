"""The options several commands share, declared once (one help text each) as annotated
types: a command writes ``seed: Seed = None`` and Typer reads the option from the type."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

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
