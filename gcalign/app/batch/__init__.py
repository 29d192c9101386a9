"""Sweeps and Monte Carlo batches: a base scenario × a grid of overrides × seeds.

DESIGN.md "CLI" (``gcalign batch``), "Results file", "Performance"; the sweep format is
described in ``docs/batch.md``. This package is the engine; it never imports typer or rich
(the command line gives it a progress callback).

Modules
-------
:mod:`~gcalign.app.batch.sweep`
    The sweep model (:class:`Sweep`, :class:`Variant`): reading and validating a sweep file.
:mod:`~gcalign.app.batch.overrides`
    Dotted-key overrides (:func:`apply_override`) checked against the scenario schema.
:mod:`~gcalign.app.batch.runs`
    What one run does in a worker process: the run summary, its metrics, the JIT warm-up.
:mod:`~gcalign.app.batch.backends`
    Where runs execute: a local process pool or an existing Dask cluster.
:mod:`~gcalign.app.batch.engine`
    :func:`run_batch`: resume, submit, retry, journal, progress, rebuild the file.
:mod:`~gcalign.app.batch.store`
    The journal, the HDF5 results file and the records a resume reads back.
:mod:`~gcalign.app.batch.aggregate`
    Per-variant statistics over seeds and the batch summary.
"""

import importlib
from typing import TYPE_CHECKING, Any

from gcalign.app.command import Command

if TYPE_CHECKING:
    from gcalign.app.batch.aggregate import (
        STATS,
        batch_summary,
        components,
        metric_units,
        stats_of,
    )
    from gcalign.app.batch.backends import (
        SCHEDULER_TIMEOUT_S,
        WorkerLost,
        Workers,
        dask_client,
        dask_workers,
        local_workers,
        make_backend,
    )
    from gcalign.app.batch.engine import (
        MAX_ATTEMPTS,
        REBUILD_EVERY_S,
        BatchResult,
        Progress,
        run_batch,
    )
    from gcalign.app.batch.engine import _tasks as _tasks  # the tests build tasks with it
    from gcalign.app.batch.overrides import apply_override
    from gcalign.app.batch.runs import (
        MetricError,
        kernel_cache_stats,
        metric_value,
        run_chunk,
        run_summary,
        run_task,
        warm_up,
    )
    from gcalign.app.batch.store import (
        JOURNAL_SUFFIX,
        Journal,
        journal_path,
        previous_records,
        read_batch,
        read_journal,
        read_runs_h5,
        write_batch_h5,
    )
    from gcalign.app.batch.sweep import (
        SWEEP_KEYS,
        Sweep,
        Variant,
        batchable,
        load_sweep,
        sweep_from_mapping,
    )

#: The engine's names and their modules, imported on first use (PEP 562): the registry
#: imports this package for :data:`COMMAND`, and every command would otherwise load the
#: sweep models, the backends and the store at start-up.
_LAZY = {
    # (not ``aggregate``, the function: importing its module binds that name to the module)
    **dict.fromkeys(("STATS", "batch_summary", "components", "metric_units", "stats_of"),
                    "aggregate"),
    **dict.fromkeys(("SCHEDULER_TIMEOUT_S", "WorkerLost", "Workers", "dask_client",
                     "dask_workers", "local_workers", "make_backend"), "backends"),
    **dict.fromkeys(("MAX_ATTEMPTS", "REBUILD_EVERY_S", "BatchResult", "Progress",
                     "run_batch", "_tasks"), "engine"),
    "apply_override": "overrides",
    **dict.fromkeys(("MetricError", "kernel_cache_stats", "metric_value", "run_chunk",
                     "run_summary", "run_task", "warm_up"), "runs"),
    **dict.fromkeys(("JOURNAL_SUFFIX", "Journal", "journal_path", "previous_records",
                     "read_batch", "read_journal", "read_runs_h5", "write_batch_h5"), "store"),
    **dict.fromkeys(("SWEEP_KEYS", "Sweep", "Variant", "batchable", "load_sweep",
                     "sweep_from_mapping"), "sweep"),
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


class Batch(Command):
    """``gcalign batch`` as a kind of results file: its table and figures (``show``,
    ``plot``); a batch runs sweeps of the registry's commands, not a scenario
    (:func:`run_batch`)."""

    name = "batch"
    help = "Sweeps and Monte Carlo over any batchable command."

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.batch.tables import batch_table

        return batch_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.batch.plots import figures

        return figures(f, name)


COMMAND = Batch()


__all__ = [
    "JOURNAL_SUFFIX",
    "MAX_ATTEMPTS",
    "REBUILD_EVERY_S",
    "SCHEDULER_TIMEOUT_S",
    "STATS",
    "SWEEP_KEYS",
    "COMMAND",
    "Batch",
    "BatchResult",
    "Journal",
    "MetricError",
    "Progress",
    "Sweep",
    "Variant",
    "WorkerLost",
    "Workers",
    "apply_override",
    "batch_summary",
    "batchable",
    "components",
    "dask_client",
    "dask_workers",
    "journal_path",
    "kernel_cache_stats",
    "load_sweep",
    "local_workers",
    "make_backend",
    "metric_units",
    "metric_value",
    "previous_records",
    "read_batch",
    "read_journal",
    "read_runs_h5",
    "run_batch",
    "run_chunk",
    "run_summary",
    "run_task",
    "stats_of",
    "sweep_from_mapping",
    "warm_up",
    "write_batch_h5",
]
