"""The command registry: one object per command that runs a scenario
(:class:`gcalign.app.command.Command`), one line each; adding a capability is a new folder
under ``gcalign/app`` plus a line here. ``batch`` runs these (so it is not among them); the
kinds of results files, batch's with them, are :func:`gcalign.app.readback.kinds`.

The objects import their heavy parts only when a method needs them, so ``gcalign show`` and
``gcalign validate`` never load numba.
"""

from __future__ import annotations

from gcalign.app.command import Command, builtin_text


def _registered() -> dict[str, Command]:
    from gcalign.app.align import COMMAND as align
    from gcalign.app.allan import COMMAND as allan
    from gcalign.app.calibrate import COMMAND as calibrate
    from gcalign.app.modulate import COMMAND as modulate
    from gcalign.app.navigate import COMMAND as navigate
    from gcalign.app.northfind import COMMAND as northfind
    from gcalign.app.observability import COMMAND as observability
    from gcalign.app.realtime import COMMAND as realtime
    from gcalign.app.simulate import COMMAND as simulate

    commands = (simulate, navigate, align, northfind, calibrate, observability, realtime,
                modulate, allan)
    return {c.name: c for c in commands}


COMMANDS: dict[str, Command] = _registered()
__all__ = ["COMMANDS", "batchable", "builtin_text", "command", "register"]


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
