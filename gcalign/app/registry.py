"""The command registry: one line per command; adding a capability is new files plus a line.

Each command's room is a subpackage of :mod:`gcalign.app` whose ``__init__`` offers, as
plain functions that import their heavy parts only when called (so ``gcalign show`` and
``gcalign validate`` never load numba):

* ``execute(sc, seed=None, cache_key=None, progress=None) -> Outcome`` -- run a scenario
  (not ``batch``); a room whose run can take longer than a second or two takes
  ``progress``, a plain callable ``progress(done, total, what)`` (any units; the command
  line draws a bar from it, the core never sees rich);
* ``table(summary) -> rich.table.Table`` -- the table the command prints (and ``show``);
* ``figures(f, name) -> dict[str, Figure]`` -- the figures of its results file (``plot``);
* optionally ``components(metric, k)`` -- names of a batch metric's vector components.

The registry itself imports nothing of them; :meth:`Command.room` loads the subpackage.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any


@dataclass(frozen=True)
class Outcome:
    """What one run of a command produced, ready to be written and shown.

    summary : plain numbers (degrees, seconds, ...): the JSON contract and ``summary_json``.
    write : writes the command's groups into an open results file (h5py.File).
    truth : the simulated truth to store under ``/truth``, if any.
    seed : the random seed the run used (None for recorded data).
    warnings : one line each, shown on stderr and kept in the summary.
    result : the capability's typed result (SI arrays), as its core function returns it.
    """

    summary: dict
    write: Callable[[Any], None]
    truth: Any = None
    seed: int | None = None
    warnings: tuple[str, ...] = ()
    result: Any = None  # the capability's typed result object (SI), for the Python API


@dataclass(frozen=True)
class Command:
    """A command: its name (also the ``kind`` of its results file) and its room."""

    name: str
    room: str  # subpackage of gcalign.app
    help: str
    section: str | None = None  # the scenario section it reads
    builtin: str | None = None  # built-in scenario (package data gcalign/scenarios)
    batch_metrics: tuple[str, ...] = field(default=())  # default metrics; () = not batchable
    streams: bool = False  # execute() writes its series into an open results file (sink=)
    recorded: bool = False  # can run on recorded data (the CLI adds --imu-file, --lat, ...)

    def load(self) -> ModuleType:
        return importlib.import_module(f"gcalign.app.{self.room}")

    def builtin_text(self) -> str:
        """YAML text of the built-in scenario (`gcalign example NAME`); KeyError if none."""
        if not self.builtin:
            raise KeyError(f"{self.name!r} has no built-in scenario")
        return builtin_text(self.builtin)

    def execute(self, sc, seed: int | None = None, *args, **options) -> Outcome:
        """The room's ``execute`` after the checks and the cost estimate of
        :func:`gcalign.app.preflight.preflight` (the same ones ``gcalign validate`` runs),
        with the seed checked to lie in [0, 2^63); the summary is checked to be finite."""
        from gcalign.app.preflight import check_seed, preflight
        from gcalign.io.results import finite_summary

        check_seed(seed)
        preflight(sc, self.name, read_recorded=False)
        outcome = self.load().execute(sc, seed, *args, **options)
        finite_summary(outcome.summary, self.name)
        return outcome


def builtin_text(name: str) -> str:
    """YAML text of a built-in scenario file (package data in gcalign/scenarios)."""
    from importlib import resources

    return resources.files("gcalign.scenarios").joinpath(name).read_text(encoding="utf-8")


COMMANDS: dict[str, Command] = {
    c.name: c
    for c in (
        Command("simulate", "simulate", "Simulate truth and IMU data.", streams=True),
        Command("navigate", "navigate", "Strapdown navigation of simulated or recorded data.",
                "navigation", streams=True, recorded=True),
        Command("align", "align", "Gyrocompass alignment (seed 000).", "align",
                "seed000_moving_full_cycle.yaml", ("error_t3_deg",), recorded=True),
        Command("northfind", "northfind", "Multi-position north-finding (seed 001).",
                "northfind", "seed001_simulation.yaml", ("methods.coordinate.rms_error_deg",)),
        Command("calibrate", "calibrate", "In-flight calibration, 21-state Kalman filter "
                "(seed 002).", "calibrate", "seed002_designed.yaml",
                ("nees.final", "normalized_error"), recorded=True),
        Command("observability", "observability", "PWCS/SVD observability table of a flight "
                "(seed 002).", "observability", "seed002_designed.yaml", ("rank_final",)),
        Command("realtime", "realtime", "Attitude at sync pulses: filter delay and prediction "
                "(seed 003).", "realtime", "seed003_table1.yaml",
                ("cases.0.after_max_arcsec.kalman-ls",)),
        Command("modulate", "modulate", "Rotation modulation: navigation on a turning IMU, "
                "schemes compared on the same data (seed 004).", "modulate",
                "seed004_modulation.yaml", ("max_horizontal_error_m",), streams=True),
        Command("batch", "batch", "Sweeps and Monte Carlo over any batchable command."),
    )
}


def command(name: str) -> Command:
    """The registered command `name`; KeyError names the ones that exist."""
    try:
        return COMMANDS[name]
    except KeyError:
        raise KeyError(f"unknown command {name!r}; commands: {', '.join(COMMANDS)}") from None


def batchable() -> dict[str, Command]:
    """Commands a sweep can run, with their default metrics."""
    return {n: c for n, c in COMMANDS.items() if c.batch_metrics}
