"""The command registry: one object per command (:class:`gcalign.app.command.Command`), one
line each; adding a capability is a new folder under ``gcalign/app`` plus a line here.

The objects import their heavy parts only when a method needs them, so ``gcalign show`` and
``gcalign validate`` never load numba.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from gcalign.app.command import Command, builtin_text


@dataclass(frozen=True)
class Outcome:
    """What one run of a command produced, ready to be written and shown.

    summary : plain numbers (degrees, seconds, ...): the JSON contract and ``summary_json``.
    write : writes the command's groups into an open results file (h5py.File).
    truth : the simulated truth to store under ``/truth``, if any.
    seed : the random seed the run used (None for recorded data).
    warnings : one line each, shown on stderr and kept in the summary.
    result : the capability's typed result in SI (e.g.
        :class:`gcalign.align.gyrocompass.Alignment`), or None.
    """

    summary: dict
    write: Callable[[Any], None]
    truth: Any = None
    seed: int | None = None
    warnings: tuple[str, ...] = ()
    result: Any = None


def _registered() -> dict[str, Command]:
    from gcalign.app.align import COMMAND as align
    from gcalign.app.allan import COMMAND as allan
    from gcalign.app.batch import COMMAND as batch
    from gcalign.app.calibrate import COMMAND as calibrate
    from gcalign.app.modulate import COMMAND as modulate
    from gcalign.app.navigate import COMMAND as navigate
    from gcalign.app.northfind import COMMAND as northfind
    from gcalign.app.observability import COMMAND as observability
    from gcalign.app.realtime import COMMAND as realtime
    from gcalign.app.simulate import COMMAND as simulate

    commands = (simulate, navigate, align, northfind, calibrate, observability, realtime,
                modulate, allan, batch)
    return {c.name: c for c in commands}


COMMANDS: dict[str, Command] = _registered()
__all__ = ["COMMANDS", "Outcome", "batchable", "builtin_text", "command", "register"]


def command(name: str) -> Command:
    """The registered command `name`; KeyError names the ones that exist."""
    try:
        return COMMANDS[name]
    except KeyError:
        raise KeyError(f"unknown command {name!r}; commands: {', '.join(COMMANDS)}") from None


def batchable() -> dict[str, Command]:
    """Commands a sweep can run, with their default metrics."""
    return {n: c for n, c in COMMANDS.items() if c.options.batch_metrics}


def register(cmd: Command) -> None:
    """Add (or replace) a command at run time, before the command line is built: how a
    test, or a plug-in, adds one without a line above."""
    COMMANDS[cmd.name] = cmd
