"""The command line's application object and its habits: the Typer app, one-line errors
and exit codes (:func:`user_errors`), stdout that may be refused, JSON on stdout and tables
beside it (:func:`consoles`, :func:`emit_json`), and :func:`main`. The commands register
themselves on :data:`app` from their modules (:mod:`gcalign.cli` imports them all)."""

from __future__ import annotations

import errno
import functools
import gc
import json
import math
import os
import signal
import sys
import threading
import warnings
from typing import TYPE_CHECKING, NoReturn

import typer
from typer.core import TyperGroup

try:  # typer ≥ 0.2x carries its own copy of click
    from typer._click import exceptions as click_errors
except ImportError:  # pragma: no cover - older typer on the real click
    from click import exceptions as click_errors  # type: ignore[no-redef]

# First, before anything loads NumPy: its OpenBLAS under an address-space limit
from gcalign.cli import address_space  # noqa: F401

# isort: split
from gcalign._version import __version__
from gcalign.app.registry import COMMANDS
from gcalign.errors import TERMINATE_REQUESTED, GcalignError, Terminated, check_terminated

if TYPE_CHECKING:
    from rich.console import Console


def _top_help() -> str:
    """What gcalign does, from the registry (so it never promises a command that is not
    there); the command list below it takes each command's line from the registry too."""
    import re

    seeds = sorted({m for c in COMMANDS.values() for m in re.findall(r"\(seed (\d+)\)", c.help)})
    return ("Strapdown INS laboratory: write a scenario (YAML), run a command, read its "
            "table and its results file (HDF5). Algorithms of the seed papers "
            f"{', '.join(seeds)}; `gcalign example` lists the built-in scenarios. Exit "
            "codes: 0 success, 2 bad input, 1 other failures.")


MAX_LINE = 400  #: characters of an error line (values in it are cut at about 80)


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
    one line and exit 2, like every other bad input, instead of a usage box; what a command
    raises as :func:`user_errors` says."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True,
             **extra):
        try:
            rv = super().main(args=args, prog_name=prog_name, complete_var=complete_var,
                              standalone_mode=False, **extra)
        except click_errors.ClickException as err:
            where = f" (see '{err.ctx.command_path} --help')" if getattr(err, "ctx", None) \
                else ""
            _fail(f"{err.format_message()}{where}", err.exit_code)
        except typer.Abort:  # typer ≥ 0.2x: its own Abort, not in its click copy
            _fail("aborted", 1)
        if not standalone_mode:
            return rv
        sys.exit(rv if isinstance(rv, int) else 0)

    def invoke(self, ctx):
        """Every command's own errors as one line and an exit code (:func:`user_errors`)."""
        return user_errors(super().invoke)(ctx)


app = typer.Typer(
    cls=OneLineErrors,
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
    from rich.console import Console

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
    TERMINATE_REQUESTED[0] = True
    raise Terminated()


def _unraisable(info) -> None:
    """A SIGTERM's exception raised in a finaliser or a weakref callback cannot propagate:
    no "Exception ignored" traceback for it; the flag it set ends the run at the next
    check (errors.check_terminated)."""
    if not isinstance(info.exc_value, Terminated):
        sys.__unraisablehook__(info)


def _terminated() -> NoReturn:
    sys.stderr.write("error: terminated (SIGTERM)\n")
    raise typer.Exit(143) from None


def user_errors(fn):
    """Turn GcalignError into one line on stderr and its exit code; Ctrl-C into exit 130,
    SIGTERM into 143 (both after the temporary files are gone); anything unexpected into
    one line and exit 1 (a bug: GCALIGN_TRACEBACK=1 shows where)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        main_thread = threading.current_thread() is threading.main_thread()
        previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
        hook = sys.unraisablehook
        if main_thread:
            TERMINATE_REQUESTED[0] = False
            sys.unraisablehook = _unraisable
        try:
            with warnings.catch_warnings():
                # NumPy's overflow/invalid-value warnings would print lines before the one
                # error line; a result that is not finite is refused by name anyway
                # (results.finite_summary)
                warnings.simplefilter("ignore", RuntimeWarning)
                out = fn(*args, **kwargs)
            check_terminated()  # one whose exception a finaliser swallowed (_unraisable)
            return out
        except GcalignError as err:
            if TERMINATE_REQUESTED[0]:
                # The SIGTERM's exception landed inside a library, which turned it into an
                # error of its own (h5py: a TypeError or an OSError; a writer turns that into
                # a GcalignError): what failed after it is its consequence, not a bug.
                _terminated()
            sys.stderr.write(f"error: {error_line(str(err))}\n")
            raise typer.Exit(err.exit_code) from None
        except KeyboardInterrupt:
            sys.stderr.write("error: interrupted\n")
            raise typer.Exit(130) from None
        except Terminated:
            _terminated()
        except (typer.Exit, typer.Abort, click_errors.ClickException):
            raise
        except Exception as err:
            if TERMINATE_REQUESTED[0]:  # as above
                _terminated()
            from gcalign.app.runner import OUT_OF_MEMORY, out_of_memory

            if isinstance(err, StdoutError):
                _stdout_failed(err)
            if out_of_memory(err):
                sys.stderr.write(f"error: {OUT_OF_MEMORY}\n")
                raise typer.Exit(1) from None
            if os.environ.get("GCALIGN_TRACEBACK"):
                raise
            sys.stderr.write(f"error: internal error, {type(err).__name__}: "
                             f"{error_line(str(err))[:200]} (a bug in gcalign; "
                             "GCALIGN_TRACEBACK=1 shows where)\n")
            raise typer.Exit(1) from None
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)
                sys.unraisablehook = hook

    return wrapper


def _stdout_failed(err: OSError) -> None:
    """A write to stdout refused (``> /dev/full``, a closed stdout, a reader that went
    away): one line, exit 1; what is still buffered goes to /dev/null, so that Python's own
    flush at exit cannot print a traceback."""
    reason = (err.strerror or os.strerror(err.errno)) if err.errno else str(err)
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    except OSError:
        pass
    sys.stderr.write(f"error: cannot write to stdout: {reason}\n")
    sys.stderr.flush()
    os._exit(1)  # the buffered text would only fail again


class StdoutError(OSError):
    """A write to stdout that was refused."""


class _Stdout:
    """stdout as the commands write it: a refused write (``> /dev/full``, a closed stdout, a
    reader that went away) raises :class:`StdoutError`, which no other write raises, so that
    it is told apart from a results file that cannot be written."""

    def __init__(self, raw):
        self._raw = raw

    def write(self, s: str) -> int:
        if self._raw is None:  # the process started with stdout closed (>&-)
            raise StdoutError(errno.EBADF, "it is closed")
        try:
            return self._raw.write(s)  # type: ignore[no-any-return]
        except OSError as err:
            raise StdoutError(err.errno, err.strerror) from None

    def flush(self) -> None:
        if self._raw is not None:
            try:
                self._raw.flush()
            except OSError as err:
                raise StdoutError(err.errno, err.strerror) from None

    def isatty(self) -> bool:
        return self._raw is not None and self._raw.isatty()

    def __getattr__(self, name: str):
        return getattr(self._raw, name)


def main() -> None:
    """The command line as the ``gcalign`` script runs it (:mod:`gcalign.__main__`)."""
    from gcalign.app import command

    command.ONE_SHOT = os.getpid()  # one command, then this process ends (command.loading)
    sys.stdout = _Stdout(sys.stdout)  # type: ignore[assignment]
    try:
        app()
    finally:
        try:
            sys.stdout.flush()
        except OSError as err:
            _stdout_failed(err)
        if TERMINATE_REQUESTED[0]:
            # A SIGTERM that landed inside h5py leaves HDF5 objects half made; freeing them
            # in the interpreter's finalisation crashed the process (SIGSEGV after the error
            # line). The temporary files are gone by now: end without finalisation.
            sys.stderr.flush()
            os._exit(143)
        # The process ends here: what is alive now needs no collection, and the
        # interpreter's finalisation would otherwise walk it all (a third of a second).
        gc.freeze()
