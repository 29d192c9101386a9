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

from gcalign.errors import GcalignError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="Strapdown INS alignment and north-finding laboratory (seeds 000-004).",
)


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


def default_output(name: str, kind: str, seed: int | None) -> Path:
    suffix = f"-seed{seed}" if seed is not None else ""
    return Path("runs") / f"{name}-{kind}{suffix}.h5"


def main() -> None:
    app()


# Commands register themselves on `app`.
from gcalign.cli import align as _align  # noqa: E402,F401
from gcalign.cli import batch as _batch  # noqa: E402,F401
from gcalign.cli import calibrate as _calibrate  # noqa: E402,F401
from gcalign.cli import data as _data  # noqa: E402,F401
from gcalign.cli import modulate as _modulate  # noqa: E402,F401
from gcalign.cli import northfind as _northfind  # noqa: E402,F401
from gcalign.cli import plot as _plot  # noqa: E402,F401
from gcalign.cli import realtime as _realtime  # noqa: E402,F401
