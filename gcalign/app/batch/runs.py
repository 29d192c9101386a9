"""One run of a batch, as it executes in a worker process (local pool or Dask worker).

Everything here is a top-level, picklable function that never imports rich: a task
(a plain dict) goes in, a record (a plain dict) comes out, and a failing run is recorded,
never raised. Each worker process caches the parsed scenario of a variant and the
noise-free simulation of a site and motion, so successive runs only add their sensor
errors (and variants that differ only in errors or algorithm settings share it).
"""

from __future__ import annotations

import copy
import difflib
import os
import sys
import time
from typing import Any

from gcalign.errors import GcalignError


class MetricError(Exception):
    """A metric path that the run summary does not have (the sweep is wrong, not the run)."""


_PARSED: dict[str, Any] = {}
#: the recorded file of the variant run last, as its first run read it (vkey -> Recording):
#: the variant's later seeds pass it along instead of reading the file again
_RECORDING: dict[str, Any] = {}


def _scenario(task: dict):
    from gcalign.io.scenario import parse_scenario

    sc = _PARSED.get(task["vkey"])
    if sc is None:
        if len(_PARSED) > 256:
            _PARSED.clear()
        sc = _PARSED[task["vkey"]] = parse_scenario(copy.deepcopy(task["scenario"]),
                                                    task["source"])
    return sc


def noise_free_key(sc) -> str | None:
    """What the noise-free part of a simulation depends on (site, earth, motion, mechanism,
    IMU rate: :func:`gcalign.app.data.noise_free`), as a cache key: variants that differ only
    in sensor errors or algorithm settings (a T_z × mode sweep) share one simulation."""
    if sc.motion is None or sc.site is None:
        return None
    mech = "" if sc.mechanism is None else sc.mechanism.model_dump_json()
    return "|".join((sc.site.model_dump_json(), sc.earth, sc.motion.model_dump_json(), mech,
                     repr(float(sc.imu.rate_hz))))


def run_summary(command: str, sc, seed: int, cache_key: str | None = None,
                vkey: str | None = None) -> dict:
    """The summary dict a single run of `command` would print (through its room).

    `cache_key` (:func:`noise_free_key`) lets successive runs share the noise-free
    simulation; `vkey` (the variant) lets them share the recorded file as read.
    """
    from gcalign.app.preflight import checked_run
    from gcalign.app.registry import COMMANDS

    if command not in COMMANDS:
        raise GcalignError(f"unknown command {command!r}; commands: {', '.join(COMMANDS)}")
    held = _RECORDING.get(vkey) if vkey is not None else None
    outcome, inputs = checked_run(command, sc, seed, cache_key, recording=held)
    if vkey is not None and held is None and inputs.recording is not None:
        _RECORDING.clear()  # one variant's file at a time
        _RECORDING[vkey] = inputs.recording
    return outcome.summary


def metric_value(summary: dict, path: str):
    """The value at a dotted path of a run summary: a float or a list of floats."""
    node: Any = summary
    parts = path.split(".")
    for depth, part in enumerate(parts):
        here = ".".join(parts[:depth]) or "the run summary"
        if isinstance(node, dict):
            if part not in node:
                names = [str(k) for k in node]
                # the closest names first: the list is cut, and a typo's fix should show
                close = difflib.get_close_matches(part, names, n=3, cutoff=0.6)
                names = close + [n for n in names if n not in close]
                more = f", … ({len(names) - 12} more)" if len(names) > 12 else ""
                raise MetricError(f"metric {path[:60]!r}: {here} has no {part[:40]!r}; it has: "
                                  f"{', '.join(names[:12])}{more}")
            node = node[part]
        elif isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise MetricError(f"metric {path!r}: {here} is a list of {len(node)} item(s); "
                                  f"{part!r} is not one of its indices")
            node = node[int(part)]
        else:
            raise MetricError(f"metric {path!r}: {here} is a single value, it has no {part!r}")
    if node is None:
        raise ValueError(f"metric {path!r} is empty in this run (no truth to compare with?)")
    if isinstance(node, bool) or not isinstance(node, (int, float, list)):
        raise MetricError(f"metric {path!r}: not a number or a list of numbers, "
                          f"got {type(node).__name__}")
    if isinstance(node, list):
        if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in node):
            raise MetricError(f"metric {path!r}: a list, but not of numbers")
        return [float(x) for x in node]
    return float(node)


def run_task(task: dict) -> dict:
    """One run: ``task`` = command, variant, vkey, seed, scenario (mapping), source, metrics.

    Never raises for a failing run: the record says ``status: failed`` and the error.
    """
    t0 = time.perf_counter()
    outcome: dict | Exception
    try:
        sc = _scenario(task)
        outcome = run_summary(task["command"], sc, task["seed"], noise_free_key(sc),
                              task["vkey"])
    except Exception as err:  # a failing run is recorded, the others go on
        outcome = err
    rec = _record(task, outcome)
    rec["wall_s"] = time.perf_counter() - t0
    return rec


def _record(task: dict, outcome: dict | Exception) -> dict:
    """The record of a task's run from its summary, or from the error that ended it."""
    rec = {"variant": task["variant"], "vkey": task["vkey"], "seed": task["seed"],
           "status": "ok", "metrics": {}, "error": ""}
    try:
        if isinstance(outcome, Exception):
            raise outcome
        rec["metrics"] = {m: metric_value(outcome, m) for m in task["metrics"]}
    except MetricError as err:
        rec.update(status="bad-metric", error=str(err))
    except Exception as err:  # noqa: BLE001 - a failing run is recorded, the others go on
        msg = str(err).strip().replace("\n", "; ")
        rec.update(status="failed",
                   error=msg if isinstance(err, GcalignError) else f"{type(err).__name__}: {msg}")
    return rec


#: the commands whose room steps a variant's seeds together: ``lockstep_ok(sc)`` and
#: ``summaries_of_seeds(sc, seeds, cache_key)`` in the module
LOCKSTEP = {"align": "gcalign.app.align.run", "calibrate": "gcalign.app.calibrate.run"}


def run_chunk(tasks: list[dict]) -> list[dict]:
    """Several runs in one worker call (amortises the per-call overhead). The seeds of a
    variant that allows it (align, calibrate) run in lockstep (:func:`run_seeds`), the rest
    one by one; the records come back in the order of `tasks`."""
    out: list[dict | None] = [None] * len(tasks)
    groups: dict[tuple[str, str], list[int]] = {}
    for i, t in enumerate(tasks):
        groups.setdefault((t["command"], t["vkey"]), []).append(i)
    for (command, _), idx in groups.items():
        recs = run_seeds([tasks[i] for i in idx]) if command in LOCKSTEP and len(idx) > 1 \
            else None
        if recs is None:
            recs = [run_task(tasks[i]) for i in idx]
        for i, r in zip(idx, recs, strict=True):
            out[i] = r
    return [r for r in out if r is not None]


_HEAP_KEPT = False


def keep_freed_memory() -> None:
    """Let this process keep the memory it frees for its next arrays (glibc: arrays below
    64 MB from the heap, not from fresh mappings, and up to 256 MB of freed heap kept).
    A lockstep group holds its runs' data at once and frees it together; returned to the
    system, the next group's arrays fault every page in again (2 500 page faults and 5 ms
    of system time a run). Once per process; a no-op where the C library is not glibc."""
    global _HEAP_KEPT
    if _HEAP_KEPT:
        return
    _HEAP_KEPT = True
    try:
        import ctypes

        libc = ctypes.CDLL(None)
        libc.mallopt(-1, 256 << 20)  # M_TRIM_THRESHOLD
        libc.mallopt(-3, 64 << 20)  # M_MMAP_THRESHOLD
    except (OSError, AttributeError):
        pass


def run_seeds(tasks: list[dict]) -> list[dict] | None:
    """The records of several seeds of one variant of a :data:`LOCKSTEP` command, run in
    lockstep (the room's ``summaries_of_seeds``, e.g. :func:`gcalign.app.align.run.
    summaries_of_seeds`: each seed's summary and metrics those of its own run, to the bit),
    or None when the variant cannot share a lockstep (then each runs alone). ``wall_s`` of
    each is the group's wall time per run."""
    import importlib

    from gcalign.app.preflight import check_seed, preflight

    command = tasks[0]["command"]
    room = importlib.import_module(LOCKSTEP[command])

    t0 = time.perf_counter()
    try:
        sc = _scenario(tasks[0])
    except Exception:  # noqa: BLE001 - each run records its own failure
        return None
    if not room.lockstep_ok(sc):
        return None
    keep_freed_memory()
    results: list[Any] = [None] * len(tasks)
    todo = []
    for i, t in enumerate(tasks):  # in checked_run's order: the seed, the preflight
        try:
            check_seed(t["seed"])
            todo.append(i)
        except Exception as err:  # noqa: BLE001
            results[i] = err
    try:
        preflight(sc, command)
    except Exception as err:  # noqa: BLE001 - the variant's runs fail alike
        for i in todo:
            results[i] = err
    else:
        for i, res in zip(todo, room.summaries_of_seeds(sc, [tasks[i]["seed"] for i in todo],
                                                        noise_free_key(sc)), strict=True):
            results[i] = res
    recs = [_record(t, res) for t, res in zip(tasks, results, strict=True)]
    wall = (time.perf_counter() - t0) / len(tasks)
    for rec in recs:
        rec["wall_s"] = wall
    return recs


def kernel_cache_stats() -> dict:
    """Numba dispatchers of gcalign loaded in this process: cache hits and misses, and the
    dispatchers that missed (a miss means the kernel was compiled here instead of loaded
    from the on-disk cache)."""
    hits = misses = 0
    missed = []
    for name, mod in list(sys.modules.items()):
        if not name.startswith("gcalign.") or mod is None:
            continue
        for attr, obj in vars(mod).items():
            stats = getattr(obj, "stats", None)
            if stats is not None and hasattr(stats, "cache_misses"):
                hits += sum(stats.cache_hits.values())
                m = sum(stats.cache_misses.values())
                misses += m
                if m:
                    missed.append(f"{name}.{attr}")
    return {"pid": os.getpid(), "cache_hits": hits, "cache_misses": misses,
            "missed": sorted(set(missed))}


def warm_up(command: str = "align") -> dict:
    """Load the numba kernels a command runs (from the on-disk JIT cache) with a tiny run of
    its room's ``warm_up()``, if it has one; once per process."""
    from gcalign.app.registry import COMMANDS

    if command in COMMANDS:
        try:
            COMMANDS[command].warm_up()
        except Exception:  # noqa: BLE001 - warming is an optimisation only
            pass
    return kernel_cache_stats()
