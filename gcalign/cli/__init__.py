"""The `gcalign` command line (Typer). It only translates: load the scenario, call a
pipeline, write the results file, render a table or JSON.

Exit codes: 0 success, 2 bad input (one line naming the field, the value and what is
allowed), 1 other failures, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM); every
failure is one line on stderr and never a traceback (``GCALIGN_TRACEBACK=1`` shows the
traceback of an unexpected error, which is a bug).
"""

from __future__ import annotations

import functools
import json
import math
import os
import signal
import sys
import threading
from pathlib import Path

import typer
from rich.console import Console
from typer.core import TyperGroup

try:  # typer ≥ 0.2x carries its own copy of click
    from typer._click import exceptions as click_errors
except ImportError:  # pragma: no cover - older typer on the real click
    from click import exceptions as click_errors  # type: ignore[no-redef]

from gcalign.errors import GcalignError

MAX_LINE = 400  #: characters of an error line (values in it are cut at about 80)


class Terminated(BaseException):
    """SIGTERM: unwinds like Ctrl-C, so that temporary files are removed."""


def error_line(message: str) -> str:
    """One line for stderr: the lines of a message joined, cut at MAX_LINE characters."""
    parts = [p.strip() for p in str(message).splitlines() if p.strip()] or ["failed"]
    line = "; ".join(parts)
    return line if len(line) <= MAX_LINE else line[:MAX_LINE - 3] + "..."


def _fail(message: str, code: int):
    sys.stderr.write(f"error: {error_line(message)}\n")
    sys.stderr.flush()
    sys.exit(code)


class OneLineErrors(TyperGroup):
    """Click's usage errors (a bad option value, an unknown option, a missing argument) as
    one line and exit 2, like every other bad input, instead of a usage box."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True,
             **extra):
        try:
            rv = super().main(args=args, prog_name=prog_name, complete_var=complete_var,
                              standalone_mode=False, **extra)
        except click_errors.NoArgsIsHelpError as err:
            print(err.ctx.get_help() if err.ctx else "")
            sys.exit(0)
        except click_errors.ClickException as err:
            where = f" (see '{err.ctx.command_path} --help')" if getattr(err, "ctx", None) \
                else ""
            _fail(f"{err.format_message()}{where}", err.exit_code)
        except typer.Abort:  # typer ≥ 0.2x: its own Abort, not in its click copy
            _fail("aborted", 1)
        if not standalone_mode:
            return rv
        sys.exit(rv if isinstance(rv, int) else 0)


app = typer.Typer(
    cls=OneLineErrors,
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


def _terminate(signum, frame):
    raise Terminated()


def user_errors(fn):
    """Turn GcalignError into one line on stderr and its exit code; Ctrl-C into exit 130,
    SIGTERM into 143 (both after the temporary files are gone); anything unexpected into
    one line and exit 1 (a bug: GCALIGN_TRACEBACK=1 shows where)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        main_thread = threading.current_thread() is threading.main_thread()
        previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
        try:
            return fn(*args, **kwargs)
        except GcalignError as err:
            sys.stderr.write(f"error: {error_line(str(err))}\n")
            raise typer.Exit(err.exit_code) from None
        except KeyboardInterrupt:
            sys.stderr.write("error: interrupted\n")
            raise typer.Exit(130) from None
        except Terminated:
            sys.stderr.write("error: terminated (SIGTERM)\n")
            raise typer.Exit(143) from None
        except (typer.Exit, typer.Abort, click_errors.ClickException):
            raise
        except MemoryError:
            sys.stderr.write("error: out of memory; a smaller run, or lower GCALIGN_MAX_MEMORY_MB "
                             "so that gcalign refuses it up front (README 'Limits')\n")
            raise typer.Exit(1) from None
        except Exception as err:
            if os.environ.get("GCALIGN_TRACEBACK"):
                raise
            sys.stderr.write(f"error: internal error, {type(err).__name__}: "
                             f"{error_line(str(err))[:200]} (a bug in gcalign; "
                             "GCALIGN_TRACEBACK=1 shows where)\n")
            raise typer.Exit(1) from None
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)

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
from gcalign.cli import northfind as _northfind  # noqa: E402,F401
from gcalign.cli import plot as _plot  # noqa: E402,F401
from gcalign.cli import realtime as _realtime  # noqa: E402,F401
