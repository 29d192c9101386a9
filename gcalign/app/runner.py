"""Run a registered command on a scenario and write its results file: what the command line
(:func:`gcalign.cli.common.run_and_show`) and the Python API (:func:`gcalign.run`) share.

No typer, no rich: progress is a plain callable and warnings are strings.
"""

from __future__ import annotations

import errno
import time
from collections.abc import Callable, Sequence
from pathlib import Path

from gcalign.app.command import Outcome
from gcalign.app.preflight import checked_run
from gcalign.app.registry import command
from gcalign.errors import GcalignError, ScenarioError
from gcalign.io import results
from gcalign.io.scenario import Scenario


def run_command(name: str, sc: Scenario, text: str, seed: int | None, out: Path, *,
                progress: Callable | None = None, notes: Sequence[str] = (),
                before_write: Callable[[], None] | None = None,
                on_outcome: Callable[[Outcome], None] | None = None, **options) -> dict:
    """Run command `name` (its preflight, then its ``execute``), write the results file
    `out` (atomically: an interrupted run leaves no file) and return the summary it stored.

    The summary gets ``warnings`` (`notes`, the scenario's keys that cannot matter, and the
    run's own), ``wall_s`` (the whole call) and ``output``. `progress(done, total, what)`
    goes to a command whose ``execute`` takes it, after a first stage ``running`` from the
    start (a first run's kernel compile falls in it); `before_write` is called when the run is
    done, before the file is finished (the command line closes its progress bar there);
    `on_outcome` hears of the command's :class:`Outcome` (the Python API keeps its typed
    result).
    """
    from gcalign.app.data import recording_record
    from gcalign.io.stored import write_fields

    cmd = command(name)
    kwargs = dict(options, progress=progress)
    t0 = time.perf_counter()
    if progress is not None:  # a bar before the first kernel call (numba compiles it once)
        progress(0.0, 1.0, "running")
    try:
        with results.atomic_h5(out) as f:
            # preflight checks, the seed's range, a finite summary
            if cmd.options.streams:
                kwargs["sink"] = f
            outcome, inputs = checked_run(name, sc, seed, **kwargs)
            if progress is not None:
                progress(1.0, 1.0, "running")
            if on_outcome is not None:
                on_outcome(outcome)
            if before_write is not None:
                before_write()
            summary = outcome.summary
            # what the reader of the recorded file assumed
            record = recording_record(sc, inputs.recording)
            summary["warnings"] = list(dict.fromkeys(
                [*notes, *sc.unused(cmd.section), *outcome.warnings,
                 *summary.get("warnings", []), *(record or {}).get("warnings", [])]))
            summary["wall_s"] = time.perf_counter() - t0
            summary["output"] = str(out)
            results.write_header(f, name, text, outcome.seed, summary)
            if record is not None:
                results.write_recording(f, record)
            if outcome.truth is not None:
                write_fields(f.create_group("truth"), outcome.truth)
            outcome.write(f)
            results.add_dimension_scales(f)
    except OSError as err:
        if out_of_memory(err):
            raise GcalignError(OUT_OF_MEMORY) from None
        raise ScenarioError(f"--output: cannot write {out}: {err.strerror or err}") from None
    return summary


OUT_OF_MEMORY = ("out of memory; a smaller run, or lower GCALIGN_MAX_MEMORY_MB so that gcalign "
                 "refuses it up front (docs/reference: Limits)")


def out_of_memory(err: BaseException) -> bool:
    """Is `err` the address space running out (``ulimit -v``): MemoryError, ENOMEM, or a
    shared library (numba's llvmlite, OpenBLAS) that could not be mapped?"""
    text = str(err)
    return (isinstance(err, MemoryError) or getattr(err, "errno", None) == errno.ENOMEM
            or "shared object" in text or "cannot allocate memory" in text.lower())
