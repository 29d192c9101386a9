"""The `gcalign` command line (Typer). It only translates: load the scenario, call a
pipeline, write the results file, render a table or JSON.

Exit codes: 0 success, 2 bad input (one line naming the field, the value and what is
allowed), 1 other failures; no traceback for user errors.
"""

from __future__ import annotations

import functools
import json
import math
import sys
from pathlib import Path

import typer
from rich.console import Console

from gcalign import __version__
from gcalign.app.registry import COMMANDS
from gcalign.errors import GcalignError


def _top_help() -> str:
    """What gcalign does, from the registry (so it never promises a command that is not
    there); the command list below it takes each command's line from the registry too."""
    seeds = sorted({c.help.rsplit("(seed ", 1)[1].rstrip(").") for c in COMMANDS.values()
                    if "(seed " in c.help})
    return ("Strapdown INS laboratory: write a scenario (YAML), run a command, read its "
            "table and its results file (HDF5). Algorithms of the seed papers "
            f"{', '.join(seeds)}; `gcalign example` lists the built-in scenarios. Exit "
            "codes: 0 success, 2 bad input, 1 other failures.")


app = typer.Typer(
    add_completion=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain click help: flags without <bool>, [dask] kept as written
    help=_top_help(),
)


def _version(value: bool) -> None:
    if value:
        sys.stdout.write(f"gcalign {__version__}\n")
        raise typer.Exit(0)


@app.callback(invoke_without_command=True)
def _root(
    ctx: typer.Context,
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                 help="Print the version and exit."),
) -> None:
    """Bare `gcalign` prints the help and succeeds (exit 0)."""
    if ctx.invoked_subcommand is None:
        typer.echo(ctx.get_help())
        raise typer.Exit(0)


def consoles(as_json: bool) -> Console:
    """Where tables go: stdout normally, stderr under --json (stdout then holds JSON only)."""
    return Console(stderr=as_json, highlight=False)


def _finite(x):
    """NaN and ±inf become null: bare NaN is not JSON, and jq and friends reject it."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    return x


def emit_json(obj: dict) -> None:
    sys.stdout.write(json.dumps(_finite(obj), allow_nan=False) + "\n")
    sys.stdout.flush()


def user_errors(fn):
    """Turn GcalignError into one line on stderr and its exit code; Ctrl-C into exit 130."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except GcalignError as err:
            for line in str(err).splitlines():
                sys.stderr.write(f"error: {line}\n")
            raise typer.Exit(err.exit_code) from None
        except KeyboardInterrupt:
            sys.stderr.write("interrupted\n")
            raise typer.Exit(130) from None

    return wrapper


def default_output(name: str, kind: str, seed: int | None, overrides=()) -> Path:
    """``runs/NAME-COMMAND[-OVERRIDES][-rngN].h5`` (:func:`gcalign.cli.common.output_name`)."""
    from gcalign.cli.common import output_name

    return output_name(name, kind, seed, list(overrides))


def main() -> None:
    app()


# Commands register themselves on `app`.
from gcalign.cli import align as _align  # noqa: E402,F401
from gcalign.cli import batch as _batch  # noqa: E402,F401
from gcalign.cli import calibrate as _calibrate  # noqa: E402,F401
from gcalign.cli import data as _data  # noqa: E402,F401
from gcalign.cli import example as _example  # noqa: E402,F401
from gcalign.cli import modulate as _modulate  # noqa: E402,F401
from gcalign.cli import northfind as _northfind  # noqa: E402,F401
from gcalign.cli import plot as _plot  # noqa: E402,F401
from gcalign.cli import realtime as _realtime  # noqa: E402,F401

# Last: the options every scenario command shares (--set, --imu-file, --lat/--lon/--height).
from gcalign.cli.common import install as _install  # noqa: E402

_install(app)
