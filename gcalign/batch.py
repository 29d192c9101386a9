"""Sweeps and Monte Carlo batches: a base scenario × a grid of overrides × seeds.

DESIGN.md "CLI" (``gcalign batch``), "Results file", "Performance"; the sweep format is
described in ``docs/batch.md``. This module is the engine; it never imports typer or rich
(the command line gives it a progress callback).

Model
-----
A *sweep* is a base scenario (a path relative to the sweep file, or an inline mapping), a
*grid* of overrides by dotted key (``align.stages.0.t_z_s: [100, 150, 200]``), a seed count
and the *metrics* to aggregate (dotted paths into the run summary, e.g. ``error_t3_deg``).
A *variant* is one point of the Cartesian product of the grid; a *run* is a variant and a
seed. Every variant runs the same seeds ``seed_start .. seed_start + seeds - 1`` (common
random numbers), so differences between variants are not masked by different noise.

Robustness
----------
Every finished run is appended to a journal next to the output
(``FILE.journal.jsonl``: one JSON line per run, flushed and fsync'd per batch of results).
The HDF5 file is rebuilt from the journal under a temporary name and renamed
(:func:`gcalign.results.atomic_h5`) every few seconds and at the end, so a SIGKILL never
leaves a corrupt file, and ``resume=True`` runs only what is missing (from the journal, or
from the HDF5 file if the journal is gone). Runs are identified by a hash of their
variant's scenario, command and metrics plus the seed, so a resumed sweep with more seeds
or more grid values reuses every run it already has. The aggregate is computed from the
records sorted by (variant, seed): the same sweep gives the same numbers whatever the
number of workers or the order in which runs finished.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import os
import signal
import sys
import threading
import time
import types
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Union, get_args, get_origin

import numpy as np

from gcalign.errors import GcalignError, ScenarioError

COMMANDS = ("align", "northfind")
DEFAULT_METRICS = {
    "align": ("error_t3_deg",),
    "northfind": ("methods.coordinate.rms_error_deg",),
}
SWEEP_KEYS = ("name", "base", "command", "grid", "seeds", "seed_start", "metrics")
STATS = ("mean", "std", "rms", "median", "p05", "p95")
ATT_COMPONENTS = ("pitch", "roll", "yaw")
SCHEDULER_TIMEOUT_S = 5.0  # connecting to a Dask scheduler; the message comes within 10 s
MAX_ATTEMPTS = 2  # a run in flight when a worker process died is retried once, alone
REBUILD_EVERY_S = 2.0  # HDF5 rebuilt from the journal at most this often while running
JOURNAL_SUFFIX = ".journal.jsonl"


# --------------------------------------------------------------------------------------
# Sweep model
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Variant:
    """One grid point: its overrides (dotted key -> value) and the resulting scenario."""

    index: int
    overrides: dict
    scenario: dict
    key: str  # hash of command, metrics and scenario: identifies its runs across resumes

    @property
    def label(self) -> str:
        if not self.overrides:
            return "base"
        return ", ".join(f"{k}={_short(v)}" for k, v in self.overrides.items())


@dataclass(frozen=True)
class Sweep:
    """A validated sweep: every variant's scenario has passed ``parse_scenario``."""

    name: str
    command: str
    source: str
    text: str
    base_source: str
    base_text: str
    grid: dict
    seeds: int
    seed_start: int
    metrics: tuple[str, ...]
    variants: tuple[Variant, ...]

    @property
    def seed_values(self) -> range:
        return range(self.seed_start, self.seed_start + self.seeds)

    def run_keys(self) -> list[tuple[int, int]]:
        """``(variant, seed)`` of every run, in canonical order."""
        return [(v.index, s) for v in self.variants for s in self.seed_values]

    @property
    def fingerprint(self) -> str:
        return _hash([v.key for v in self.variants], list(self.seed_values))


def _short(v) -> str:
    text = json.dumps(v) if not isinstance(v, str) else v
    return text if len(text) <= 40 else text[:37] + "..."


def _hash(*parts) -> str:
    text = json.dumps(parts, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_sweep(path: Path) -> Sweep:
    """Read and validate a sweep file (ScenarioError, exit 2, on any bad input)."""
    from gcalign.config.loader import read_yaml

    path = Path(path)
    data = read_yaml(path)
    return sweep_from_mapping(data, str(path), path.parent, path.read_text(encoding="utf-8"),
                              default_name=path.stem)


def sweep_from_mapping(data, source: str = "sweep", base_dir: Path | None = None,
                       text: str | None = None, default_name: str = "sweep") -> Sweep:
    """Validate a parsed sweep mapping; every variant is parsed before anything runs.

    Raises ScenarioError with one line naming the key and the value that is wrong.
    """
    import yaml

    from gcalign.config import parse_scenario
    from gcalign.config.loader import read_yaml

    base_dir = Path(base_dir or ".")
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: a sweep must be a YAML mapping, got {type(data).__name__}")
    for k in data:
        if k not in SWEEP_KEYS:
            raise ScenarioError(f"{source}: {k}: unknown key (a sweep has: "
                                f"{', '.join(SWEEP_KEYS)})")
    text = text if text is not None else yaml.safe_dump(data, sort_keys=False)

    name = data.get("name", default_name)
    if not isinstance(name, str) or not name or any(c in name for c in "/\\ \t"):
        raise ScenarioError(f"{source}: name: must be a non-empty word (used in file names), "
                            f"got {name!r}")

    # Base scenario: a file relative to the sweep, or an inline mapping.
    if "base" not in data:
        raise ScenarioError(f"{source}: base: missing; give a scenario file (relative to the "
                            "sweep file) or an inline scenario mapping")
    base = data["base"]
    if isinstance(base, str):
        base_path = (base_dir / base) if not Path(base).is_absolute() else Path(base)
        if not base_path.is_file():
            raise ScenarioError(f"{source}: base: {base!r}: file not found ({base_path})")
        base_data = read_yaml(base_path)
        base_source, base_text = str(base_path), base_path.read_text(encoding="utf-8")
        imu_dir = base_path.parent
    elif isinstance(base, dict):
        base_data, base_source = copy.deepcopy(base), f"{source}: base"
        base_text, imu_dir = yaml.safe_dump(base, sort_keys=False), base_dir
    else:
        raise ScenarioError(f"{source}: base: must be a scenario file name or a mapping, "
                            f"got {type(base).__name__} {base!r}")
    if isinstance(base_data, dict) and isinstance(base_data.get("imu_file"), str):
        p = Path(base_data["imu_file"])  # workers may run elsewhere: make it absolute
        base_data["imu_file"] = str(p if p.is_absolute() else (imu_dir / p).resolve())
    base_model = parse_scenario(base_data, base_source)

    command = data.get("command")
    if command is None:
        has = [c for c in COMMANDS if isinstance(base_data, dict) and c in base_data]
        if len(has) > 1:
            raise ScenarioError(f"{source}: command: the base has both 'align' and 'northfind' "
                                "sections; say which to run (command: align | northfind)")
        command = has[0] if has else "align"
    if command not in COMMANDS:
        raise ScenarioError(f"{source}: command: must be one of {', '.join(COMMANDS)}, "
                            f"got {command!r}")

    seeds = data.get("seeds", 1)
    if isinstance(seeds, bool) or not isinstance(seeds, int) or seeds < 1:
        raise ScenarioError(f"{source}: seeds: must be a whole number ≥ 1 (the seed count), "
                            f"got {seeds!r}")
    seed_start = data.get("seed_start", 1)
    if isinstance(seed_start, bool) or not isinstance(seed_start, int) or seed_start < 0:
        raise ScenarioError(f"{source}: seed_start: must be a whole number ≥ 0, got {seed_start!r}")

    metrics = data.get("metrics", list(DEFAULT_METRICS[command]))
    if isinstance(metrics, str):
        metrics = [metrics]
    if not isinstance(metrics, list) or not metrics:
        raise ScenarioError(f"{source}: metrics: must be a non-empty list of dotted paths into "
                            f"the run summary (e.g. [error_t3_deg]), got {metrics!r}")
    for m in metrics:
        if not isinstance(m, str) or not m or "/" in m or any(p == "" for p in m.split(".")):
            raise ScenarioError(f"{source}: metrics: {m!r} is not a dotted path "
                                "(e.g. error_t3_deg, passes.2.error_deg)")
    if len(set(metrics)) != len(metrics):
        raise ScenarioError(f"{source}: metrics: {metrics!r} names a metric twice")

    grid = data.get("grid") or {}
    if not isinstance(grid, dict):
        raise ScenarioError(f"{source}: grid: must be a mapping of dotted key -> list of values, "
                            f"got {type(grid).__name__}")
    axes: dict[str, list] = {}
    for key, values in grid.items():
        if not isinstance(key, str) or not key:
            raise ScenarioError(f"{source}: grid: {key!r}: keys must be dotted paths "
                                "(e.g. align.mode)")
        if not isinstance(values, list):
            values = [values]  # one fixed value
        if not values:
            raise ScenarioError(f"{source}: grid: {key} = []: empty list of values; give at "
                                "least one value")
        seen = [json.dumps(v, sort_keys=True, default=str) for v in values]
        for i, s in enumerate(seen):
            if s in seen[:i]:
                raise ScenarioError(f"{source}: grid: {key}: value {values[i]!r} appears twice")
        axes[key] = values

    # Each key and value alone against the base: a message that names exactly that pair.
    for key, values in axes.items():
        for value in values:
            trial = copy.deepcopy(base_data)
            try:
                apply_override(trial, key, value, base_model)
            except ScenarioError as err:
                raise ScenarioError(f"{source}: grid: {key} = {value!r}: {err}") from None
            where = f"{source}: grid: {key} = {value!r}"
            _check_section(parse_scenario(trial, where), command, where)

    # Then every combination (a value may be valid alone but not with another one).
    keys = list(axes)
    variants = []
    for i, combo in enumerate(itertools.product(*(axes[k] for k in keys))):
        overrides = dict(zip(keys, combo, strict=True))
        scenario = copy.deepcopy(base_data)
        label = ", ".join(f"{k} = {v!r}" for k, v in overrides.items())
        try:
            for k, v in overrides.items():
                apply_override(scenario, k, v, base_model)
        except ScenarioError as err:
            raise ScenarioError(f"{source}: grid: variant {label}: {err}") from None
        where = f"{source}: grid: variant {label}"
        _check_section(parse_scenario(scenario, where), command, where)
        variants.append(Variant(i, overrides, scenario,
                                _hash(command, list(metrics), scenario)))
    return Sweep(name=name, command=command, source=source, text=text,
                 base_source=base_source, base_text=base_text, grid=axes, seeds=seeds,
                 seed_start=seed_start, metrics=tuple(metrics), variants=tuple(variants))


def _check_section(sc, command: str, where: str) -> None:
    """The command's own checks that need the whole scenario (e.g. ``northfind.check``)."""
    section = getattr(sc, command, None)
    if section is None and command != "align":
        raise ScenarioError(f"{where}: {command}: missing; command {command!r} needs a "
                            f"'{command}' section in the base scenario")
    check = getattr(section, "check", None)
    if callable(check):
        try:
            check(sc)
        except ScenarioError as err:
            raise ScenarioError(f"{where}: {err}") from None


# Dotted keys -----------------------------------------------------------------------------


def _unwrap(tp):
    """Strip Annotated[...] and Optional[...] from a pydantic field annotation."""
    while True:
        origin = get_origin(tp)
        if origin is Annotated:
            tp = get_args(tp)[0]
        elif origin in (Union, types.UnionType):
            args = [a for a in get_args(tp) if a is not type(None)]
            if len(args) != 1:
                return tp  # e.g. float | Literal["measured"]: a single value
            tp = args[0]
        else:
            return tp


def _is_model(tp) -> bool:
    from pydantic import BaseModel

    return isinstance(tp, type) and issubclass(tp, BaseModel)


def _dump(value):
    """A model value as plain YAML types (only what the user set, so defaults stay defaults)."""
    from pydantic import BaseModel

    if isinstance(value, BaseModel):
        return value.model_dump(mode="json", exclude_unset=True)
    if isinstance(value, (list, tuple)):
        return [_dump(v) for v in value]
    return value


def apply_override(data: dict, key: str, value, base_model=None) -> None:
    """Set ``data[a][b][0][c] = value`` for ``key = "a.b.0.c"``, in place.

    The path is checked against the scenario schema (:class:`gcalign.config.Scenario`), not
    only against `data`: a key the schema does not have is an error even where the parent
    section is optional, and a list index must exist (``align.stages.5`` with one stage is
    an error that says which indices exist). A section or list the base leaves to its
    default is filled in from the validated `base_model` (``align.stages.0.t_z_s`` works on
    a base that gives no stages). ScenarioError on a bad path.
    """
    from gcalign.config import Scenario

    parts = key.split(".")
    if any(not p for p in parts):
        raise ScenarioError(f"{key}: not a dotted key (e.g. align.stages.0.t_z_s)")
    node: Any = data
    tp: Any = Scenario
    model_val = base_model
    for depth, part in enumerate(parts):
        here = ".".join(parts[:depth]) or "the scenario"
        path = ".".join(parts[: depth + 1])
        if _is_model(tp):
            fields = tp.model_fields
            if part not in fields:
                raise ScenarioError(f"{path}: unknown key; {here} has: {', '.join(fields)}")
            if not isinstance(node, dict):
                raise ScenarioError(f"{path}: {here} is {node!r}, not a mapping")
            child_tp = _unwrap(fields[part].annotation)
            child_val = getattr(model_val, part, None) if model_val is not None else None
            slot: Any = part
            child = node.get(part)
        elif get_origin(tp) in (list, tuple):
            if not isinstance(node, list):
                raise ScenarioError(f"{path}: {here} is {node!r}, not a list")
            n = len(node)
            have = "no items" if n == 0 else (
                f"{n} item(s): index 0" + (f" .. {n - 1}" if n > 1 else ""))
            if not part.isdigit():
                raise ScenarioError(f"{path}: {here} is a list; address an item by its index "
                                    f"({have})")
            slot = int(part)
            if slot >= n:
                raise ScenarioError(f"{path}: no item {slot}; {here} has {have}")
            args = get_args(tp)
            child_tp = _unwrap(args[0]) if args else Any
            child_val = (model_val[slot] if isinstance(model_val, (list, tuple))
                         and slot < len(model_val) else None)
            child = node[slot]
        elif get_origin(tp) is dict:
            if not isinstance(node, dict):
                raise ScenarioError(f"{path}: {here} is {node!r}, not a mapping")
            args = get_args(tp)
            child_tp = _unwrap(args[1]) if len(args) == 2 else Any
            child_val = model_val.get(part) if isinstance(model_val, dict) else None
            slot, child = part, node.get(part)
        else:
            raise ScenarioError(f"{path}: {here} is a single value, it has no keys or items")
        if depth == len(parts) - 1:
            node[slot] = value
            return
        if child is None:
            if isinstance(child_val, (list, tuple, dict)) or _is_model(type(child_val)):
                child = _dump(child_val)
            elif _is_model(child_tp) or get_origin(child_tp) is dict:
                child = {}
            elif get_origin(child_tp) in (list, tuple):
                child = []
            else:
                raise ScenarioError(f"{path + '.' + parts[depth + 1]}: {path} is a single "
                                    "value, it has no keys or items")
            node[slot] = child
        node, tp, model_val = child, child_tp, child_val


# --------------------------------------------------------------------------------------
# One run (executes in a worker process: top-level, picklable, no rich)
# --------------------------------------------------------------------------------------


class MetricError(Exception):
    """A metric path that the run summary does not have (the sweep is wrong, not the run)."""


_PARSED: dict[str, Any] = {}


def _scenario(task: dict):
    from gcalign.config import parse_scenario

    sc = _PARSED.get(task["vkey"])
    if sc is None:
        if len(_PARSED) > 256:
            _PARSED.clear()
        sc = _PARSED[task["vkey"]] = parse_scenario(copy.deepcopy(task["scenario"]),
                                                    task["source"])
    return sc


_NOISE_FREE: dict = {}  # cache key -> noise-free RunData (truth, ideal IMU) in this worker


def run_data(sc, seed: int, cache_key: str | None = None):
    """:func:`gcalign.pipelines.data.scenario_data` with the noise-free simulation (truth
    and ideal increments: about 2/3 of a seed 000 run) computed once per variant in each
    worker; only the sensor errors depend on the seed. Same numbers, bit for bit (tested).
    The cached arrays are made read-only, so code that would modify them fails loudly.
    """
    from gcalign.pipelines.data import noise_free, scenario_data, with_errors

    if cache_key is None or sc.imu_file is not None or sc.motion is None or sc.site is None:
        return scenario_data(sc, seed)
    hit = _NOISE_FREE.get(cache_key)
    if hit is None:
        if len(_NOISE_FREE) >= 4:
            _NOISE_FREE.pop(next(iter(_NOISE_FREE)))
        hit = _NOISE_FREE[cache_key] = noise_free(sc)
        for obj in (hit.truth, hit.imu):
            for value in vars(obj).values():
                if isinstance(value, np.ndarray):
                    value.flags.writeable = False
    return with_errors(sc, hit, seed)


def run_summary(command: str, sc, seed: int, cache_key: str | None = None) -> dict:
    """The summary dict a single ``gcalign align`` / ``gcalign northfind`` run would print.

    `cache_key` (the variant) lets successive seeds share the noise-free simulation.
    """
    if command == "align":
        from gcalign.pipelines.align import alignment_summary, run_alignment

        data = run_data(sc, seed, cache_key)
        return alignment_summary(run_alignment(sc, data), data, sc.name)
    if command == "northfind":
        try:
            from gcalign.pipelines.northfind import northfind_summary, run_northfind
        except ImportError as err:  # pragma: no cover - until the pipeline lands
            raise GcalignError(f"northfind pipeline not available: {err}") from None
        return northfind_summary(run_northfind(sc, seed), sc)
    raise GcalignError(f"unknown command {command!r}")


def metric_value(summary: dict, path: str):
    """The value at a dotted path of a run summary: a float or a list of floats."""
    node: Any = summary
    parts = path.split(".")
    for depth, part in enumerate(parts):
        here = ".".join(parts[:depth]) or "the run summary"
        if isinstance(node, dict):
            if part not in node:
                raise MetricError(f"metric {path!r}: {here} has no {part!r}; it has: "
                                  f"{', '.join(map(str, node))}")
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
    rec = {"variant": task["variant"], "vkey": task["vkey"], "seed": task["seed"],
           "status": "ok", "metrics": {}, "error": ""}
    try:
        summary = run_summary(task["command"], _scenario(task), task["seed"], task["vkey"])
        rec["metrics"] = {m: metric_value(summary, m) for m in task["metrics"]}
    except MetricError as err:
        rec.update(status="bad-metric", error=str(err), metrics={})
    except Exception as err:  # a failing run is recorded, the others go on
        msg = str(err).strip().replace("\n", "; ")
        rec.update(status="failed", metrics={},
                   error=msg if isinstance(err, GcalignError) else f"{type(err).__name__}: {msg}")
    rec["wall_s"] = time.perf_counter() - t0
    return rec


def run_chunk(tasks: list[dict]) -> list[dict]:
    """Several runs in one worker call (amortises the per-call overhead)."""
    return [run_task(t) for t in tasks]


def kernel_cache_stats() -> dict:
    """Numba dispatchers of gcalign loaded in this process: cache hits and misses.

    A miss means the kernel was compiled here instead of loaded from the on-disk cache.
    """
    hits = misses = 0
    for name in ("gcalign.kernels", "gcalign.align.kernel", "gcalign.northfind"):
        mod = sys.modules.get(name)
        for obj in vars(mod).values() if mod else ():
            stats = getattr(obj, "stats", None)
            if stats is not None and hasattr(stats, "cache_misses"):
                hits += sum(stats.cache_hits.values())
                misses += sum(stats.cache_misses.values())
    return {"pid": os.getpid(), "cache_hits": hits, "cache_misses": misses}


WARM_SCENARIO = {
    "name": "warm-up",
    "site": {"lat_deg": 45.0, "lon_deg": 126.0},
    "imu": {"gyro": {"bias_dph": [0.01, 0.01, 0.01]}, "accel": {"bias_ug": [50, 50, 50]}},
    "motion": {"kind": "moving", "attitude_deg": [0, 0, 30], "duration_s": 3,
               "segments": [{"duration_s": 1}, {"duration_s": 2, "accel_mps2": 0.5}]},
    "align": {"t1_s": 1, "t2_s": 2, "t3_s": 2.5, "passes": 3, "level_s": 0.1,
              "aiding": {"source": "odometer"}},
}


def warm_up(command: str = "align") -> dict:
    """Load the numba kernels (from the on-disk JIT cache) with a tiny run, once per process."""
    if command == "align":
        from gcalign.config import parse_scenario

        try:
            run_summary("align", parse_scenario(copy.deepcopy(WARM_SCENARIO), "warm-up"), 1)
        except Exception:  # noqa: BLE001 - warming is an optimisation only
            pass
    return kernel_cache_stats()


def _watch_parent(parent: int) -> None:  # pragma: no cover - runs in workers
    while True:
        time.sleep(0.5)
        if os.getppid() != parent:
            os._exit(1)  # the batch process died (SIGKILL): do not linger as an orphan


def _init_worker(command: str) -> None:  # pragma: no cover - runs in workers
    """Process-pool initializer: Ctrl-C is the parent's business; exit with the parent;
    load the JIT cache once."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch_parent, args=(os.getppid(),), daemon=True).start()
    warm_up(command)


# --------------------------------------------------------------------------------------
# Aggregation (canonical order: variant, seed)
# --------------------------------------------------------------------------------------


def _finite(x):
    """JSON-safe numbers: NaN -> None."""
    if isinstance(x, list):
        return [_finite(v) for v in x]
    return None if x is None or not math.isfinite(x) else float(x)


def components(command: str, metric: str, k: int | None) -> list[str] | None:
    if k is None:
        return None
    if command == "align" and k == 3 and metric.endswith("_deg"):
        return list(ATT_COMPONENTS)
    return [str(i) for i in range(k)]


def metric_units(metric: str) -> str:
    last = metric.rsplit(".", 1)[-1]
    for suffix, units in (("_deg", "deg"), ("_s", "s"), ("_dph", "deg/h"), ("_m", "m"),
                          ("_mps", "m/s"), ("_arcsec", "arcsec")):
        if last.endswith(suffix):
            return units
    return ""


def stats_of(values: np.ndarray) -> dict:
    """mean, std (ddof 1), RMS, median, 5 and 95 % percentiles along axis 0."""
    n = values.shape[0]
    if n == 0:
        nan = np.full(values.shape[1:], np.nan)
        return {s: nan for s in STATS}
    return {
        "mean": values.mean(0),
        "std": values.std(0, ddof=1) if n > 1 else np.full(values.shape[1:], np.nan),
        "rms": np.sqrt(np.mean(values * values, 0)),
        "median": np.median(values, 0),
        "p05": np.percentile(values, 5, axis=0),
        "p95": np.percentile(values, 95, axis=0),
    }


def _as_py(a):
    a = np.asarray(a, dtype=float)
    return _finite(a.tolist()) if a.ndim else _finite(float(a))


def aggregate(sweep: Sweep, records: dict[tuple[int, int], dict]) -> list[dict]:
    """Per-variant statistics of every metric, per vector component, from the records of
    finished runs (keyed by (variant, seed)); canonical order, so reproducible."""
    out = []
    for v in sweep.variants:
        recs = [records[(v.index, s)] for s in sweep.seed_values if (v.index, s) in records]
        ok = [r for r in recs if r["status"] == "ok"]
        stats: dict[str, dict] = {}
        entry = {"index": v.index, "label": v.label, "overrides": v.overrides,
                 "ok": len(ok), "failed": len(recs) - len(ok), "stats": stats}
        for m in sweep.metrics:
            vals = [r["metrics"][m] for r in ok]
            lengths = {len(x) if isinstance(x, list) else None for x in vals}
            if len(lengths) > 1:
                stats[m] = {"n": len(vals), "components": None,
                            "note": "runs gave values of different lengths",
                            **{s: None for s in STATS}}
                continue
            k = lengths.pop() if lengths else None
            arr = np.asarray(vals, dtype=float)
            if arr.size == 0:
                arr = np.zeros((0, k) if k else (0,))
            st = stats_of(arr)
            stats[m] = {"n": len(vals), "components": components(sweep.command, m, k),
                        "units": metric_units(m), **{s: _as_py(st[s]) for s in STATS}}
        out.append(entry)
    return out


def batch_summary(sweep: Sweep, records: dict, *, output: Path | None = None,
                  extra: dict | None = None) -> dict:
    """The summary stored in ``summary_json`` and printed by ``--json``."""
    keys = sweep.run_keys()
    finished = [records[k] for k in keys if k in records]
    failed = [r for r in finished if r["status"] != "ok"]
    return {
        "sweep": sweep.name,
        "command": sweep.command,
        "source": sweep.source,
        "base": sweep.base_source,
        "seeds": sweep.seeds,
        "seed_start": sweep.seed_start,
        "metrics": list(sweep.metrics),
        "grid": sweep.grid,
        "runs": len(keys),
        "finished": len(finished),
        "ok": len(finished) - len(failed),
        "failed": len(failed),
        "complete": len(finished) == len(keys),
        "variants": aggregate(sweep, records),
        "failures": [{"variant": r["variant"], "seed": r["seed"], "error": r["error"]}
                     for r in failed[:20]],
        **(extra or {}),
        "output": None if output is None else str(output),
    }


# --------------------------------------------------------------------------------------
# Journal and HDF5
# --------------------------------------------------------------------------------------


def journal_path(output: Path) -> Path:
    output = Path(output)
    return output.with_name(output.name + JOURNAL_SUFFIX)


class Journal:
    """Append-only JSON lines; each batch of lines is flushed and fsync'd."""

    def __init__(self, path: Path, header: dict, keep: Iterable[dict] = ()):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # Start from a clean file (a torn last line from a SIGKILL must not be appended to):
        # header + the records kept, written under a temporary name and renamed.
        tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        with open(tmp, "w", encoding="utf-8") as f:
            for obj in (header, *keep):
                f.write(json.dumps(obj) + "\n")
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, self.path)
        self._f = open(self.path, "a", encoding="utf-8")  # noqa: SIM115

    def append(self, records: Iterable[dict]) -> None:
        for r in records:
            self._f.write(json.dumps({"type": "run", **r}) + "\n")
        self._f.flush()
        os.fsync(self._f.fileno())

    def close(self) -> None:
        self._f.close()


def read_journal(path: Path) -> list[dict]:
    """Run records of a journal; a torn line (the process was killed mid-write) is skipped."""
    out = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            try:
                obj = json.loads(line)
            except json.JSONDecodeError:
                continue
            if isinstance(obj, dict) and obj.get("type") == "run":
                out.append(obj)
    return out


def read_runs_h5(path: Path) -> list[dict]:
    """Run records from a batch results file (``/batch/runs``)."""
    from gcalign import results

    with results.open_results(path) as f:
        if "batch/runs" not in f:
            raise ScenarioError(f"{path}: not a batch results file (no /batch/runs)")
        g = f["batch/runs"]
        metrics = {m: g["metrics"][m][()] for m in g["metrics"]}
        lengths = g["metrics"].attrs
        recs = []
        for i in range(g["seed"].shape[0]):
            status = _s(g["status"][i])
            vals = {}
            if status == "ok":
                for m, arr in metrics.items():
                    x = arr[i]
                    n = int(lengths.get(m + ".length", -1))
                    vals[m] = float(x) if n < 0 else [float(v) for v in x[:n]]
            recs.append({"variant": int(g["variant"][i]), "vkey": _s(g["vkey"][i]),
                         "seed": int(g["seed"][i]), "status": status, "metrics": vals,
                         "error": _s(g["error"][i]), "wall_s": float(g["wall_s"][i])})
    return recs


def _s(x) -> str:
    return x.decode() if isinstance(x, bytes) else str(x)


def write_batch_h5(output: Path, sweep: Sweep, records: dict, summary: dict) -> None:
    """(Re)build the whole results file from the run records, atomically."""
    import h5py

    from gcalign import results

    keys = [k for k in sweep.run_keys() if k in records]
    recs = [records[k] for k in keys]
    by_index = {v.index: v for v in sweep.variants}
    scenario_text = sweep.text + f"\n# base scenario: {sweep.base_source}\n" + "".join(
        f"# {line}\n" for line in sweep.base_text.splitlines())
    with results.atomic_h5(output) as f:
        results.write_header(f, "batch", scenario_text, None, summary)
        b = f.create_group("batch")
        b.attrs["command"] = sweep.command
        b.attrs["sweep"] = sweep.name
        b.attrs["seeds"], b.attrs["seed_start"] = sweep.seeds, sweep.seed_start
        b.attrs["metrics"] = json.dumps(list(sweep.metrics))
        b.attrs["grid_json"] = json.dumps(sweep.grid, default=str)
        b.attrs["base_yaml"] = sweep.base_text
        b.attrs["fingerprint"] = sweep.fingerprint
        b.attrs["complete"] = bool(summary["complete"])
        r = b.create_group("runs")
        r.attrs["description"] = ("one row per finished run, sorted by (variant, seed); "
                                  "metric values NaN where the run failed")
        str_dt = h5py.string_dtype()
        results.put(r, "variant", np.array([k[0] for k in keys], dtype=np.int32), "1")
        results.put(r, "seed", np.array([k[1] for k in keys], dtype=np.int64), "1")
        for name, what in (("status", "ok | failed"), ("error", "error message ('' if ok)"),
                           ("vkey", "hash of the variant's command, metrics and scenario")):
            ds = r.create_dataset(name, data=np.array([x[name] for x in recs], dtype=object),
                                  dtype=str_dt)
            ds.attrs["units"], ds.attrs["description"] = "none", what
        results.put(r, "wall_s", np.array([x.get("wall_s", np.nan) for x in recs]), "s")
        mg = r.create_group("metrics")
        for m in sweep.metrics:
            vals = [x["metrics"].get(m) if x["status"] == "ok" else None for x in recs]
            lens = {len(v) for v in vals if isinstance(v, list)}
            if lens:
                k = max(lens)
                arr = np.full((len(recs), k), np.nan)
                for i, v in enumerate(vals):
                    if isinstance(v, list):
                        arr[i, : len(v)] = v
                mg.attrs[m + ".length"] = k
            else:
                arr = np.array([np.nan if v is None else v for v in vals], dtype=float)
            ds = results.put(mg, m, arr, metric_units(m))
            comps = components(sweep.command, m, arr.shape[1] if arr.ndim == 2 else None)
            if comps:
                ds.attrs["components"] = ", ".join(comps)
        a = b.create_group("aggregate")
        for entry in summary["variants"]:
            v = by_index[entry["index"]]
            g = a.create_group(f"v{v.index:03d}")
            g.attrs["index"], g.attrs["label"] = v.index, v.label
            g.attrs["overrides_json"] = json.dumps(v.overrides, default=str)
            g.attrs["ok"], g.attrs["failed"] = entry["ok"], entry["failed"]
            for key, value in v.overrides.items():
                g.attrs[key] = _attr(value)
            for m, st in entry["stats"].items():
                mg = g.create_group(m)
                mg.attrs["n"] = st["n"]
                if st.get("components"):
                    mg.attrs["components"] = ", ".join(st["components"])
                for s in STATS:
                    val = st[s]
                    if val is None:
                        val = np.nan
                    results.put(mg, s, np.array(val, dtype=float) if not isinstance(val, list)
                                else np.array([np.nan if x is None else x for x in val]),
                                metric_units(m))


def _attr(value):
    """An override value as an HDF5 attribute (JSON text where HDF5 has no type for it)."""
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                       for x in value):
        return np.asarray(value, dtype=float)
    return json.dumps(value, default=str)


def _clean_stale_tmp(output: Path) -> None:
    """Remove temporary files of our output left by a killed batch (dead pid only)."""
    for p in output.parent.glob(f".{output.name}.*.tmp"):
        try:
            pid = int(p.name.rsplit(".", 2)[-2])
        except ValueError:
            continue
        if pid != os.getpid() and not _alive(pid):
            p.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


# --------------------------------------------------------------------------------------
# Executors: local process pool, or an existing Dask cluster
# --------------------------------------------------------------------------------------


class WorkerLost(Exception):
    """The process running a chunk died (killed, crashed, out of memory)."""


class LocalBackend:
    """``concurrent.futures.ProcessPoolExecutor`` of `workers` processes, each warming the
    JIT cache once (initializer).

    Start method: ``fork`` when this process has no other thread (the workers then start
    with every module already imported: no interpreter start, no re-import), else the fork
    server (forking a multi-threaded process can deadlock the child). The processes are
    started here, before the caller starts a progress-bar thread.
    """

    def __init__(self, workers: int, command: str):
        self.workers = workers
        self.command = command
        self.description = f"local pool, {workers} worker(s)"
        self._pool = self._new_pool()

    def _new_pool(self):
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        methods = mp.get_all_start_methods()
        if "fork" in methods and threading.active_count() == 1:
            ctx = mp.get_context("fork")
        elif "forkserver" in methods:
            ctx = mp.get_context("forkserver")
            # The fork server imports the engine (numpy, numba, pipelines) once; every
            # worker forked from it starts with those modules loaded.
            ctx.set_forkserver_preload(["gcalign.batch", "gcalign.pipelines.align"])
        else:
            ctx = mp.get_context("spawn")
        self.start_method = ctx.get_start_method()
        pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=ctx,
                                   initializer=_init_worker, initargs=(self.command,))
        if self.start_method == "fork":
            pool.submit(os.getpid).result()  # forks every worker now (all at once for fork)
        return pool

    def submit(self, chunk):
        return self._pool.submit(run_chunk, chunk)

    def wait(self, futures, timeout: float):
        from concurrent.futures import FIRST_COMPLETED, wait

        return wait(futures, timeout=timeout, return_when=FIRST_COMPLETED)[0]

    def result(self, fut) -> list[dict]:
        from concurrent.futures.process import BrokenProcessPool

        try:
            return fut.result()
        except BrokenProcessPool as err:
            raise WorkerLost(str(err) or "a worker process died") from None

    def restart(self) -> None:
        self.close(cancel=True)
        self._pool = self._new_pool()

    def run_on_workers(self, fn) -> list:
        return [f.result() for f in [self._pool.submit(fn) for _ in range(self.workers)]]

    def close(self, cancel: bool = False) -> None:
        if cancel:
            procs = list((getattr(self._pool, "_processes", None) or {}).values())
            self._pool.shutdown(wait=False, cancel_futures=True)
            for p in procs:  # do not wait for chunks in flight after Ctrl-C
                if p.is_alive():
                    p.terminate()
        else:
            self._pool.shutdown(wait=True)


def dask_client(address: str, timeout: float = SCHEDULER_TIMEOUT_S):
    """A ``distributed.Client`` connected to `address`; GcalignError if Dask is missing or
    the scheduler does not answer within `timeout` seconds."""
    try:
        import distributed
    except ImportError:
        raise GcalignError('--scheduler needs Dask distributed, which is not installed: '
                           'pip install -e ".[dask]"') from None
    try:
        return distributed.Client(address, timeout=timeout, set_as_default=False)
    except Exception as err:  # OSError, TimeoutError, ValueError (bad address), ...
        msg = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise GcalignError(f"cannot reach the Dask scheduler at {address} "
                           f"(waited {timeout:g} s): {msg}") from None


class DaskBackend:
    """Runs chunks on an existing Dask distributed cluster (``client.submit``)."""

    def __init__(self, address: str, command: str, timeout: float = SCHEDULER_TIMEOUT_S):
        self.client = dask_client(address, timeout)
        self.address = address
        nthreads = self.client.nthreads()
        self.workers = max(1, sum(nthreads.values()))
        self.description = f"Dask scheduler {address}, {len(nthreads)} worker(s)"
        self.command = command
        try:  # load the JIT cache on every worker, in parallel; checks gcalign is there
            self.client.run(warm_up, command)
        except Exception as err:
            self.close()
            raise GcalignError(f"the Dask workers of {address} cannot run gcalign "
                               f"({type(err).__name__}: {err}); install gcalign where the "
                               "workers run") from None

    def _check_connected(self) -> None:
        if self.client.status not in ("running", "connecting"):
            raise GcalignError(f"lost the Dask scheduler at {self.address} (client "
                               f"{self.client.status}); the finished runs are kept: rerun "
                               "with --resume")

    def submit(self, chunk):
        self._check_connected()
        return self.client.submit(run_chunk, chunk, pure=False)

    def wait(self, futures, timeout: float):
        # distributed.wait needs a default client; polling the futures does not.
        deadline = time.monotonic() + timeout
        while True:
            done = {f for f in futures if f.done()}
            if done or time.monotonic() >= deadline:
                return done
            time.sleep(0.02)

    def result(self, fut) -> list[dict]:
        try:
            return fut.result()
        except Exception as err:  # KilledWorker, CancelledError, CommClosedError, ...
            self._check_connected()
            raise WorkerLost(f"{type(err).__name__}: {err}") from None

    def restart(self) -> None:
        pass  # the scheduler replaces lost workers itself

    def run_on_workers(self, fn) -> list:
        return list(self.client.run(fn).values())

    def close(self, cancel: bool = False) -> None:
        try:
            self.client.close(timeout=SCHEDULER_TIMEOUT_S)
        except Exception:  # noqa: BLE001 - closing a broken connection
            pass


def make_backend(command: str, workers: int | None = None, scheduler: str | None = None):
    if scheduler:
        return DaskBackend(scheduler, command)
    return LocalBackend(workers or os.cpu_count() or 1, command)


# --------------------------------------------------------------------------------------
# The engine
# --------------------------------------------------------------------------------------


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
    by_index = {v.index: v for v in sweep.variants}
    out = []
    for vi, seed in keys:
        v = by_index[vi]
        out.append({"command": sweep.command, "variant": vi, "vkey": v.key, "seed": seed,
                    "scenario": v.scenario, "source": f"{sweep.source}: variant {v.label}",
                    "metrics": list(sweep.metrics)})
    return out


def _chunks(tasks: list[dict], workers: int, size: int | None) -> list[list[dict]]:
    if size is None:  # ≥ 4 chunks per worker (load balance), ≤ 8 runs each (progress, resume)
        size = max(1, min(8, math.ceil(len(tasks) / (4 * workers))))
    return [tasks[i:i + size] for i in range(0, len(tasks), size)]


def previous_records(sweep: Sweep, output: Path) -> tuple[dict, str]:
    """Finished runs of an earlier batch into `output` that this sweep still contains:
    from the journal, else from the HDF5 file. Failed runs are not kept (they run again)."""
    jpath = journal_path(output)
    if jpath.is_file():
        recs, where = read_journal(jpath), str(jpath)
    elif Path(output).is_file():
        recs, where = read_runs_h5(output), str(output)
    else:
        return {}, ""
    index = {v.key: v.index for v in sweep.variants}
    seeds = set(sweep.seed_values)
    kept: dict[tuple[int, int], dict] = {}
    for r in recs:  # a later record of the same run wins
        vi = index.get(str(r.get("vkey")))
        if vi is None or r.get("seed") not in seeds or r.get("status") != "ok":
            continue
        r = {k: v for k, v in r.items() if k != "type"}
        r["variant"] = vi
        kept[(vi, r["seed"])] = r
    return kept, where


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
    output = Path(output)
    log = log or (lambda msg: None)
    t_start = time.perf_counter()
    _clean_stale_tmp(output)
    keys = sweep.run_keys()
    records: dict[tuple[int, int], dict] = {}
    reused = 0
    if resume:
        records, where = previous_records(sweep, output)
        reused = len(records)
        if where:
            log(f"resuming from {where}: {reused} of {len(keys)} run(s) already finished")
        else:
            log(f"nothing to resume at {output}: starting afresh")
    todo = [k for k in keys if k not in records]

    # Connect before touching the journal: an unreachable scheduler loses nothing.
    if backend is None and todo:
        backend = make_backend(sweep.command, min(workers or os.cpu_count() or 1, len(todo)),
                               scheduler)
    jpath = journal_path(output)
    if not resume and jpath.is_file():
        n_old = len(read_journal(jpath))
        if n_old:
            log(f"discarding {jpath} ({n_old} finished run(s)); use --resume to continue it")
    header = {"type": "header", "sweep": sweep.name, "source": sweep.source,
              "fingerprint": sweep.fingerprint, "runs": len(keys)}
    journal = Journal(jpath, header, [{"type": "run", **r} for r in records.values()])

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
    except BaseException:
        # Ctrl-C, a bad metric, ...: keep what finished (journal + a consistent file).
        if backend is not None:
            backend.close(cancel=True)
            backend = None
        journal.close()
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
           rebuild_every_s) -> int:
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
        lost: list[dict] = []
        broken = None
        for fut in done:
            chunk = in_flight.pop(fut)
            try:
                recs = backend.result(fut)
            except WorkerLost as err:
                lost.extend(chunk)
                broken = err
                continue
            for r in recs:
                if r["status"] == "bad-metric":
                    raise ScenarioError(f"{sweep.source}: metrics: {r['error']}")
            journal.append(recs)
            for r in recs:
                records[(r["variant"], r["seed"])] = r
                failed += r["status"] != "ok"
        if broken is not None:
            if isinstance(backend, LocalBackend):
                # A broken pool fails every chunk in flight: take them all, start a new pool.
                for chunk in in_flight.values():
                    lost.extend(chunk)
                in_flight.clear()
                backend.restart()
            dead = []
            for t in lost:
                k = (t["variant"], t["seed"])
                attempts[k] = attempts.get(k, 0) + 1
                if attempts[k] >= MAX_ATTEMPTS:
                    dead.append({"variant": t["variant"], "vkey": t["vkey"], "seed": t["seed"],
                                 "status": "failed", "metrics": {}, "wall_s": float("nan"),
                                 "error": f"worker process died while running it ({broken})"})
                else:
                    queue.append([t])  # retried alone: a crasher only takes itself down
            if dead:
                journal.append(dead)
                for r in dead:
                    records[(r["variant"], r["seed"])] = r
                failed += len(dead)
        if progress and done:
            progress(len(records), total, failed)
        if time.monotonic() - last_rebuild >= rebuild_every_s and (queue or in_flight):
            rebuild()
            last_rebuild = time.monotonic()
    return failed


def read_batch(path: Path) -> tuple[dict, list[dict]]:
    """Summary and run records of a batch results file."""
    from gcalign import results

    kind, summary, _ = results.read_summary(path)
    if kind != "batch":
        raise ScenarioError(f"{path}: a {kind!r} results file, not a batch")
    return summary, read_runs_h5(path)
