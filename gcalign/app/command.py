"""What a command is: one object per command, written once in its folder's ``__init__``.

A command (:class:`Command`) says what it reads (its scenario section, its built-in
scenario), what it refuses (:meth:`~Command.check`, the one code path of ``gcalign
validate``, the preflight of every run and a batch's check of its variants), what a run
costs (:meth:`~Command.cost`, held against :mod:`gcalign.limits` before any work), how it
runs (:meth:`~Command.execute`) and how it shows and stores its results (table, figures,
results file, batch metrics). The registry (:mod:`gcalign.app.registry`) holds one object
per command; adding a command is a new folder with such an object and one registry line.

A command imports its heavy parts (numba kernels, scipy, matplotlib) inside its methods,
so that ``gcalign show`` and ``gcalign validate`` never load them.
"""

from __future__ import annotations

import gc
import inspect
import os
import typing
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from gcalign.errors import ScenarioError

if TYPE_CHECKING:
    from gcalign.app.data import Recording, Stream
    from gcalign.io.scenario import Scenario

#: The id of the process that runs one command and ends, set by the command line's ``main``
#: (:func:`gcalign.cli.main`): there, what :func:`loading` makes lives until the end. A
#: process it forks (a batch's workers, which run many runs) is not it.
ONE_SHOT: int | None = None


@contextmanager
def loading() -> Iterator[None]:
    """A stretch that loads modules (the scenario models, a command's kernels and numba with
    them) whose objects live as long as the process. In a one-shot process (:data:`ONE_SHOT`)
    Python's cyclic collector is paused during it and what it made is frozen afterwards
    (left out of every later collection): otherwise the collector walks those 10^5 objects
    again and again, a tenth of a warm ``gcalign align``. Elsewhere (the API, a test's
    CliRunner, a batch worker) nothing changes."""
    if ONE_SHOT != os.getpid() or not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.enable()


DOUBLE = 8  #: bytes of one float64
BLOCK = 1 << 16  #: samples a streaming run simulates and navigates at a time
#: Operations (multiply-adds) of one step, for the work of the cost models: a strapdown
#: update (quaternion, velocity, position and the earth terms), the simulation of one IMU
#: sample with its sensor errors, a 21-state Kalman predict + update (Φ P Φᵀ and the gain).
STRAPDOWN_OPS = 200.0
SIMULATE_OPS = 400.0
KALMAN_OPS = 4.0 * 21**3


@dataclass(frozen=True)
class Extent:
    """The data a scenario gives: sample count, interval (s), whether recorded, truth, and
    the site latitude (rad) where it is known (a recorded file's header)."""

    samples: int
    ts: float
    recorded: bool
    has_truth: bool
    lat: float | None = None


@dataclass(frozen=True)
class Inputs:
    """What a run reads, loaded once (:func:`gcalign.app.preflight.preflight`) and passed
    along: the scenario, its recorded file as read and validated (None for simulated data,
    or for a command that reads no recording), and the extent of its data (None: it has
    none). The checks and the cost take its scenario and extent, the run its recording, so
    that a recorded file is read once per run."""

    scenario: Scenario
    #: a :class:`~gcalign.app.data.Recording`, or what a command reads itself
    #: (:meth:`Command.read_own`)
    recording: Recording | Any = None
    extent: Extent | None = None


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

    summary: dict[str, Any]
    write: Callable[[Any], None]
    truth: Any = None
    seed: int | None = None
    warnings: tuple[str, ...] = ()
    result: Any = None


@dataclass(frozen=True)
class Cost:
    """What one run of a command costs, estimated before it starts.

    samples : IMU samples generated or read.
    memory_bytes : bytes held at once.
    output_bytes : bytes of the series stored in the results file.
    work : arithmetic, in operations (multiply-adds), as ``work_what`` counts them.
    work_what : how the work is counted, for the refusal (``"pieces × 21³ × 40"``).
    memory_what : what dominates the memory, for the refusal.
    """

    samples: float = 0.0
    memory_bytes: float = 0.0
    output_bytes: float = 0.0
    work: float = 0.0
    work_what: str = ""
    memory_what: str = ""


@dataclass(frozen=True)
class Options:
    """How a command runs.

    recorded : it can run on recorded data (the preflight reads the recording for it; its
        command line declares the recorded-data options of :mod:`gcalign.cli.options`).
    streams : its ``execute`` writes series into an open results file (``sink=``).
    self_contained : it simulates its own data from its section (no motion needed).
    batch_metrics : default metrics of a batch; () = not batchable.
    """

    recorded: bool = False
    streams: bool = False
    self_contained: bool = False
    batch_metrics: tuple[str, ...] = ()


class Command:
    """One command: what it reads, refuses, costs, runs, shows and stores. A command folder
    subclasses it once (its name is also the ``kind`` of its results file); its methods
    import the folder's modules when called (heavy ones load numba), and the default check
    runs the section's own ``check(sc)``."""

    name: str = ""
    help: str = ""
    section: str | None = None  #: the scenario section it reads
    #: the keys of a section the command cannot run without, for the refusal when it is
    #: missing (None: the section is optional)
    section_keys: str | None = None
    builtin: str | None = None  #: its built-in scenario (package data gcalign/scenarios)
    options: Options = Options()

    # ------------------------------------------------------------------ checks and cost

    def check(self, inputs: Inputs) -> None:
        """Refuse (ScenarioError, one line naming the field) what the run would refuse;
        ``inputs.extent`` is the scenario's data (None: it has none, or a recorded file not
        read). By default: a section the command cannot run without, missing, and the
        section's own ``check(sc)`` (of its defaults where the scenario has none)."""
        sc = inputs.scenario
        if self.section is None:
            return
        if getattr(sc, self.section) is None and self.section_keys is not None:
            raise ScenarioError(f"{self.section}: missing; the scenario needs a "
                                f"'{self.section}' section ({self.section_keys})")
        check = getattr(config(sc, self.section), "check", None)
        if callable(check):
            check(sc)

    def cost(self, inputs: Inputs) -> Cost:
        """What a run costs, checked against :mod:`gcalign.limits` before any work."""
        ext = inputs.extent
        return Cost(samples=0.0 if ext is None else float(ext.samples))

    def read_own(self, sc: Scenario) -> Any:
        """What a run of `sc` reads from its files itself, where the generic reader does not
        (``sc.reads_own_recording``: transfer alignment's slave and master), read once by
        the preflight for the checks and the run (:attr:`Inputs.recording`); None: nothing."""
        return None

    # ------------------------------------------------------------------ run

    def runner(self) -> Callable[..., Outcome]:
        """Its ``execute(sc, seed, cache_key, **options)`` (imported when asked: it loads
        the kernels)."""
        raise NotImplementedError(f"{self.name} runs no scenario")

    def execute(self, sc: Scenario, seed: int | None = None, cache_key: str | None = None,
                *, recording: Recording | None = None, **options: Any) -> Outcome:
        """Run the scenario (after its preflight: :func:`gcalign.app.preflight.checked_run`):
        the summary and the writer of its results. `recording`: the scenario's recorded file
        as the preflight read it (:class:`Inputs`), for a command that reads recordings
        (``options.recorded``); without it such a command reads the file itself."""
        if recording is not None:
            options["recording"] = recording
        return self.runner()(sc, seed, cache_key, **options)

    def accepts(self, option: str) -> bool:
        """Does :meth:`execute` take keyword `option` (``progress``, ``sink``, ...)?"""
        return option in inspect.signature(self.runner()).parameters

    # ------------------------------------------------------------------ show and store

    def table(self, summary: dict[str, Any]) -> Any:
        """The table the command prints (and ``gcalign show``): a rich renderable."""
        raise NotImplementedError(f"{self.name} has no table")

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        """The figures of its results file (an open h5py.File), by file stem."""
        return {}

    def components(self, metric: str, k: int) -> list[str]:
        """Names of the `k` components of a vector batch metric."""
        return [str(i) for i in range(k)]

    def label(self, metric: str) -> str:
        """A metric's name in batch tables and figures."""
        return metric

    def warm_up(self) -> None:
        """Load the kernels a run uses (a tiny run), before a batch's workers start."""
        return None

    def builtin_text(self) -> str:
        """YAML text of the built-in scenario (`gcalign example NAME`); KeyError if none."""
        if not self.builtin:
            raise KeyError(f"{self.name!r} has no built-in scenario")
        return builtin_text(self.builtin)


def builtin_text(name: str) -> str:
    """YAML text of a built-in scenario file (package data in gcalign/scenarios)."""
    from importlib import resources

    return resources.files("gcalign.scenarios").joinpath(name).read_text(encoding="utf-8")


def config(sc: Scenario, section: str, values: dict[str, Any] | None = None) -> Any:
    """Scenario section `section` of `sc` (``align``, ``calibrate``, ...); where the scenario
    has none, the section's model built from `values` (default: the model's defaults)."""
    given = getattr(sc, section)
    if given is not None:
        return given
    kinds = typing.get_args(type(sc).model_fields[section].annotation)  # Model | None
    return next(t for t in kinds if t is not type(None)).model_validate(values or {})


def stride(sc: Scenario, ext: Extent | Stream) -> int:
    """Samples per stored row (``output.rate_hz``) of the data `ext` (its extent, or the
    stream itself); ScenarioError naming the field."""
    return sc.output.stride(1.0 / ext.ts, ext.samples * ext.ts)


def streamed(inputs: Inputs, row_doubles: int, ops: float, what: str) -> Cost:
    """The cost of a run that streams its data in blocks (:data:`BLOCK` samples held at
    once), `ops` operations a sample (and a sample's simulation where the data are
    simulated), and stores `row_doubles` per row at ``output.rate_hz``; nothing without
    data."""
    ext = inputs.extent
    if ext is None:
        return Cost()
    n = float(ext.samples)
    return Cost(samples=n, memory_bytes=min(n, BLOCK) * row_doubles * DOUBLE,
                output_bytes=n / stride(inputs.scenario, ext) * row_doubles * DOUBLE,
                work=n * (ops + (0.0 if ext.recorded else SIMULATE_OPS)), work_what=what)


def warm_scenario(scenario: dict[str, Any]) -> Scenario:
    """`scenario` (a mapping) parsed afresh, for a tiny run that loads a command's kernels
    (:meth:`Command.warm_up`)."""
    import copy

    from gcalign.io.scenario import parse_scenario

    return parse_scenario(copy.deepcopy(scenario), "warm-up")
