"""The batch engine: run every unfinished (variant, seed) of a sweep and keep the results.

DESIGN.md "CLI" (``gcalign batch``), "Performance". :func:`run_batch` resumes what it can
(:mod:`gcalign.app.batch.store`), submits chunks of runs to a backend
(:mod:`gcalign.app.batch.backends`) through a bounded window, journals every result, retries
once, alone, each run lost with a dying worker, reports progress through a callback and
rebuilds the results file every few seconds and at the end.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gcalign.app.batch.aggregate import batch_summary
from gcalign.app.batch.backends import WorkerLost, check_address, dask_workers, local_workers
from gcalign.app.batch.store import (
    Journal,
    OutputLock,
    journal_path,
    previous_records,
    read_journal,
    write_batch_h5,
)
from gcalign.app.batch.sweep import Sweep
from gcalign.errors import ScenarioError

MAX_ATTEMPTS = 2  # a run in flight when a worker process died is retried once, alone
REBUILD_EVERY_S = 2.0  # HDF5 rebuilt from the journal at most this often while running
#: Runs in a chunk at most: the seeds an align variant steps in lockstep
#: (:data:`gcalign.align.kernel.LANES`), few enough for progress and resume.
CHUNK_MAX = 16


@dataclass
class BatchResult:
    summary: dict
    records: dict = field(repr=False)
    reused: int = 0  # runs taken from an earlier (resumed) batch

    @property
    def failed(self) -> int:
        return self.summary["failed"]


Progress = Callable[[int, int, int], None]  # (finished, total, failed)


def _tasks(sweep: Sweep, keys: list[tuple[int, int]]) -> list[dict]:
    return [{"command": sweep.command, "variant": vi, "vkey": sweep.keys[vi], "seed": seed,
             "scenario": sweep.variants[vi].scenario,
             "source": f"{sweep.source}: variant {sweep.variants[vi].label}",
             "metrics": list(sweep.metrics)} for vi, seed in keys]


def _chunks(tasks: list[dict], workers: int, size: int | None) -> list[list[dict]]:
    if size is None:  # ≥ 4 chunks per worker (load balance), ≤ CHUNK_MAX runs each
        size = max(1, min(CHUNK_MAX, math.ceil(len(tasks) / (4 * workers))))
    return [tasks[i:i + size] for i in range(0, len(tasks), size)]


def run_batch(sweep: Sweep, output: Path, *, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False,
              progress: Progress | None = None, log: Callable[[str], None] | None = None,
              chunk_size: int | None = None, rebuild_every_s: float = REBUILD_EVERY_S,
              backend=None) -> BatchResult:
    """Run every (variant, seed) of `sweep` not yet finished, journal and write `output`.

    Parameters
    ----------
    workers : local worker processes (default: all cores). Ignored with `scheduler`.
    scheduler : address of a Dask scheduler (``tcp://host:port``) to run on instead.
    resume : reuse the finished runs recorded in the journal (or in `output`).
    progress : called with (finished, total, failed) as results arrive.
    log : called with one-line notes (resume counts, discarded journal).

    Returns the summary (also in the file) and the records. A failing run never raises;
    a worker process that dies takes its runs with it, and each is retried once alone.
    """
    from gcalign.io.results import check_output, clean_stale_temps

    if scheduler is not None:  # "" is refused too: it ran locally in silence
        scheduler = check_address(scheduler)
    output = check_output(output)
    jpath = journal_path(output)
    if jpath.exists() and not jpath.is_file():
        raise ScenarioError(f"--output: the journal {jpath} exists and is not a regular file")
    log = log or (lambda msg: None)
    t_start = time.perf_counter()
    keys = sweep.run_keys()
    n_workers = worker_count(workers, scheduler, len(keys))
    with OutputLock(output):
        clean_stale_temps(output.parent)
        records: dict[tuple[int, int], dict] = {}
        reused = 0
        notes: list[str] = []  # shown once the scheduler has answered: a failure is one line
        if resume:
            records, where = previous_records(sweep, output, notes.append)
            reused = len(records)
            if where:
                notes.append(f"resuming from {where}: {reused} of {len(keys)} run(s) already "
                             "finished")
            else:
                notes.append(f"nothing to resume at {output}: starting afresh")
        todo = [k for k in keys if k not in records]
        budget_check(sweep, n_workers)

        # Connect before touching the journal: an unreachable scheduler loses nothing, and
        # a new batch leaves no file behind.
        if backend is None and todo:
            backend = (dask_workers(scheduler, sweep.command) if scheduler else
                       local_workers(min(n_workers, len(todo)), sweep.command))
        for note in notes:
            log(note)
        if not resume and jpath.is_file():
            n_old = len(read_journal(jpath))
            if n_old:
                log(f"discarding {jpath} ({n_old} finished run(s)); use --resume to continue "
                    "it")
        return _run(sweep, output, jpath, records, reused, todo, backend, progress, keys,
                    chunk_size, rebuild_every_s, t_start, resume)


def worker_count(workers: int | None, scheduler: str | None, runs: int) -> int:
    """The local worker processes a batch of `runs` starts (1 on a scheduler)."""
    from gcalign import limits

    if scheduler:
        return 1
    n = workers or os.cpu_count() or 1
    if workers is not None:
        limits.MAX_WORKERS.check(workers, "--workers",
                                 f"this machine has {os.cpu_count()} core(s)")
    return max(1, min(n, runs))


def budget_check(sweep: Sweep, workers: int) -> None:
    """The memory of `workers` runs held at once (each worker keeps its variant's
    noise-free simulation) against the limit, before anything runs."""
    from gcalign.app.preflight import budget, load
    from gcalign.app.registry import command
    from gcalign.io.scenario import parse_scenario

    v = max(sweep.variants, key=lambda v: _duration(v.scenario))
    sc = parse_scenario(v.scenario, f"{sweep.source}: variant {v.label}")
    inputs = load(sc, read_recorded=False)
    if inputs.extent is not None:
        budget(inputs, command(sweep.command), workers,
               where=f"{sweep.source}: variant {v.label}", batch=True)


def _duration(scenario: dict) -> float:
    """The samples of a variant's simulation (a validated scenario: sections are mappings)."""
    motion, imu = scenario.get("motion") or {}, scenario.get("imu") or {}
    return float(motion.get("duration_s") or 0.0) * float(imu.get("rate_hz", 100.0) or 0.0)


def _run(sweep, output, jpath, records, reused, todo, backend, progress, keys, chunk_size,
         rebuild_every_s, t_start, resume) -> BatchResult:
    header = {"type": "header", "sweep": sweep.name, "source": sweep.source,
              "fingerprint": sweep.fingerprint, "runs": len(keys)}
    journal = Journal(jpath, header, [{"type": "run", **r} for r in records.values()])
    existed = output.exists()

    extra = {"workers": None if backend is None else backend.workers,
             "executor": None if backend is None else backend.description}

    def rebuild() -> dict:
        summary = batch_summary(sweep, records, output=output,
                                extra={**extra, "wall_s": time.perf_counter() - t_start})
        write_batch_h5(output, sweep, records, summary)
        return summary

    if progress:
        progress(len(records), len(keys), 0)
    try:
        if todo:
            _drive(backend, sweep, todo, records, journal, progress, len(keys),
                   chunk_size, rebuild, rebuild_every_s)
        summary = rebuild()
    except BaseException as err:
        # Ctrl-C, a full disk, ...: keep what finished (journal + a consistent file). A bad
        # metric is a bad sweep: a new batch then leaves nothing behind.
        if backend is not None:
            backend.close(cancel=True)
            backend = None
        journal.close()
        if isinstance(err, ScenarioError) and not resume:
            jpath.unlink(missing_ok=True)
            if not existed:
                output.unlink(missing_ok=True)
            raise
        if journal.exists:
            try:
                rebuild()
            except Exception:  # noqa: BLE001 - the journal still holds every finished run
                pass
        raise
    finally:
        if backend is not None:
            backend.close()
    journal.close()
    if summary["complete"]:
        jpath.unlink(missing_ok=True)  # the file holds everything; resume reads it
    return BatchResult(summary=summary, records=records, reused=reused)


def _drive(backend, sweep, todo, records, journal, progress, total, chunk_size, rebuild,
           rebuild_every_s) -> None:
    """Submit chunks (a bounded window), collect results, journal them, rebuild the file."""
    queue = _chunks(_tasks(sweep, todo), backend.workers, chunk_size)
    queue.reverse()  # pop() from the end = canonical order
    attempts: dict[tuple[int, int], int] = {}
    in_flight: dict[Any, list[dict]] = {}
    window = 2 * backend.workers
    failed = 0
    last_rebuild = time.monotonic()
    while queue or in_flight:
        while queue and len(in_flight) < window:
            chunk = queue.pop()
            in_flight[backend.submit(chunk)] = chunk
        done = backend.wait(list(in_flight), timeout=0.5)
        for fut in done:
            chunk = in_flight.pop(fut)
            try:
                recs = backend.result(fut)
            except WorkerLost as err:  # its runs retried alone: a crasher only takes itself down
                recs = []
                for t in chunk:
                    k = (t["variant"], t["seed"])
                    attempts[k] = attempts.get(k, 0) + 1
                    if attempts[k] < MAX_ATTEMPTS:
                        queue.append([t])
                    else:
                        recs.append({"variant": t["variant"], "vkey": t["vkey"], "seed": t["seed"],
                                     "status": "failed", "metrics": {}, "wall_s": float("nan"),
                                     "error": f"worker process died while running it ({err})"})
            for r in recs:
                if r["status"] == "bad-metric":
                    raise ScenarioError(f"{sweep.source}: metrics: {r['error']}")
            journal.append(recs)
            for r in recs:
                records[(r["variant"], r["seed"])] = r
                failed += r["status"] != "ok"
        if progress and done:
            progress(len(records), total, failed)
        if time.monotonic() - last_rebuild >= rebuild_every_s and (queue or in_flight):
            rebuild()
            last_rebuild = time.monotonic()
