"""Per-variant statistics of the metrics over seeds, and the batch summary.

The aggregate is computed from the records sorted by (variant, seed): the same sweep gives
the same numbers whatever the number of workers or the order in which runs finished.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gcalign.app.batch.sweep import Sweep
from gcalign.schema import plain

STATS = ("mean", "std", "rms", "median", "p05", "p95")


def components(command: str, metric: str, k: int | None) -> list[str] | None:
    """Names of a vector metric's components, as the command's ``components`` gives them
    (attitude triples are pitch, roll, yaw in align; else their indices)."""
    from gcalign.app.registry import COMMANDS

    return None if k is None else COMMANDS[command].components(metric, k)


def metric_label(command: str, metric: str) -> str:
    """A metric's name for figures: the command's ``label`` may name a picked component
    (``error_t3_deg.2`` -> ``error_t3_deg yaw`` in align)."""
    from gcalign.app.registry import COMMANDS

    return COMMANDS[command].label(metric) if command in COMMANDS else metric


def metric_units(metric: str) -> str:
    """Units from the name's suffix; a trailing index (``error_t3_deg.2``, one component of
    a vector metric) has the units of its vector."""
    parts = metric.split(".")
    while len(parts) > 1 and parts[-1].isdigit():
        parts.pop()
    last = parts[-1]
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
                        "units": metric_units(m), **{s: plain(st[s]) for s in STATS}}
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
        "cases": sweep.cases,
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
