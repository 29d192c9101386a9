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

The package itself holds only :data:`COMMAND`, which the registry imports: the engine's
names are imported from their modules, so that no command loads the sweep models, the
backends and the store at start-up.
"""

from typing import Any

from gcalign.app.command import Command


class Batch(Command):
    """``gcalign batch`` as a kind of results file: its table and figures (``show``,
    ``plot``); a batch runs sweeps of the registry's commands, not a scenario
    (:func:`~gcalign.app.batch.engine.run_batch`)."""

    name = "batch"
    help = "Sweeps and Monte Carlo over any batchable command."

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.batch.tables import batch_table

        return batch_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.batch.plots import figures

        return figures(f, name)


COMMAND = Batch()

__all__ = ["COMMAND", "Batch"]
