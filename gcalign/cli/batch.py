"""`gcalign batch`: sweeps and Monte Carlo over seeds, on local processes or a Dask cluster.

The engine is :mod:`gcalign.app.batch`; this module only loads the sweep, shows progress,
prints the table (or JSON) and maps failures to exit codes (0 all runs ok, 1 some run
failed or the cluster is unreachable, 2 bad sweep, 130 interrupted).
"""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

import typer

from gcalign.app.batch import COMMAND
from gcalign.cli.base import app, consoles, emit_json
from gcalign.cli.options import Json, Sets
from gcalign.errors import ScenarioError


def _progress_bar(total_hint: str):
    """A rich progress bar with ETA on stderr, or None when stderr is not a terminal;
    ``GCALIGN_PROGRESS=always`` forces it (into a pipe or a log too), ``never`` turns it
    off, as for the other commands (:class:`gcalign.cli.common.ProgressBar`)."""
    import os

    mode = os.environ.get("GCALIGN_PROGRESS", "auto").lower()
    if mode == "never" or (mode != "always" and not sys.stderr.isatty()):
        return None
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return Progress(
        TextColumn(f"[bold]{total_hint}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[failed]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=Console(stderr=True, force_terminal=mode == "always" or None),
        transient=False,
    )


def load_batch(files: list[Path], command: str | None, seeds: int | None,
               seed_start: int | None, metrics: list[str] | None,
               sets: list[str] | None = None, notes: list[str] | None = None):
    """One sweep file, or a plain list of scenario files (each file a variant). On a sweep
    file, --seeds and --seed-start replace the file's (said in `notes`); --set changes the
    base scenario of a sweep, or every file of a list."""
    from gcalign.app.batch.sweep import sweep_from_files, sweep_from_mapping
    from gcalign.io.scenario.loader import parse_override, read_yaml

    pairs = [parse_override(item) for item in sets or []]
    list_options = {"--command": command, "--metric": metrics or None}
    if len(files) == 1:
        data = read_yaml(files[0])
        if isinstance(data, dict) and "base" in data:
            given = [k for k, v in list_options.items() if v is not None]
            if given:
                raise ScenarioError(f"{given[0]}: applies to a list of scenario files; the "
                                    f"sweep file {files[0]} says it (command, metrics)")
            text = files[0].read_text(encoding="utf-8")
            for option, key, value in (("--seeds", "seeds", seeds),
                                       ("--seed-start", "seed_start", seed_start)):
                if value is not None:
                    if notes is not None:
                        notes.append(f"{option} {value} replaces the sweep's {key} "
                                     f"({data.get(key, 1)})")
                    data[key] = value
                    text += f"\n# command line: {option} {value}\n"
            return sweep_from_mapping(data, str(files[0]), files[0].parent, text,
                                      default_name=files[0].stem, sets=pairs)
    return sweep_from_files(files, command, 1 if seeds is None else seeds,
                            1 if seed_start is None else seed_start, metrics or None, pairs)


def _named(sw, seeds: int | None, seed_start: int | None, sets: list[str] | None) -> list:
    """The options that change a batch's results beside its sweep file, for its default
    file name: --set, and --seeds/--seed-start on a sweep file."""
    from gcalign.app.batch.sweep import FILE_KEY
    from gcalign.io.scenario.loader import parse_override

    sweep = FILE_KEY not in sw.grid
    return [*((k, v) for k, v in (("seeds", seeds), ("seed_start", seed_start))
              if sweep and v is not None), *(parse_override(x) for x in sets or [])]


def bar_label(sw) -> str:
    """The batch's short name for its progress bar (within 30 characters): a list of files
    by its count, a sweep by its name and its variants."""
    from gcalign.app.batch.sweep import FILE_KEY

    seeds = f"{sw.seeds} seed{'s' if sw.seeds != 1 else ''}"
    n = len(sw.variants)
    if FILE_KEY in sw.grid:
        return f"{n} scenario{'s' if n != 1 else ''} × {seeds}"
    what = f" {n} variants × {seeds}"
    name = sw.name if len(sw.name) + len(what) <= 30 else sw.name[:29 - len(what)] + "…"
    return name + what


@app.command()
def batch(
    files: list[Path] = typer.Argument(
        ..., help="A sweep YAML (base scenario, grid of overrides, seeds, metrics: "
        "docs/batch.md), or one or more scenario files: each file is a variant, run for "
        "--seeds seeds."
    ),
    workers: int | None = typer.Option(
        None, "--workers", "-w", help="Local worker processes (default: all cores)."
    ),
    scheduler: str | None = typer.Option(
        None,
        "--scheduler",
        help='Run on an existing Dask cluster, e.g. tcp://host:8786 (pip install -e ".[dask]").',
    ),
    command: str | None = typer.Option(
        None, "--command", help="Scenario files: the command to run (default: the one whose "
        "section the files have; align)."),
    seeds: int | None = typer.Option(
        None, "--seeds", help="Seeds per variant (scenario files: default 1; a sweep file: "
        "replaces its seeds)."),
    seed_start: int | None = typer.Option(
        None, "--seed-start", help="The first seed (scenario files: default 1; a sweep "
        "file: replaces its seed_start)."),
    metric: list[str] | None = typer.Option(
        None, "--metric", help="Scenario files: a metric, a dotted path into the run "
        "summary (repeatable; default: the command's)."),
    output: Path | None = typer.Option(
        None,
        "-o",
        "--output",
        help="Results file (default runs/SWEEP-batch.h5); the journal "
        "FILE.journal.jsonl sits next to it while runs are missing.",
    ),
    resume: bool = typer.Option(
        False, "--resume", help="Run only what an earlier, interrupted batch did not finish."
    ),
    as_json: Json = False,
    set_: Sets = None,
):
    """Run a sweep (variants × seeds), or the same seeds on several scenario files; aggregate
    each metric per variant into one HDF5 file. One batch starts Python once: far cheaper
    than a shell loop over `gcalign align` (docs/batch.md)."""
    if workers is not None and workers < 1:
        raise ScenarioError(f"--workers: must be at least 1, got {workers}")
    if scheduler is not None:  # a bad address at once, before the sweep is loaded
        from gcalign.app.batch.backends import check_address

        scheduler = check_address(scheduler)
    if workers is not None and scheduler:
        raise ScenarioError(
            "--workers: applies to the local process pool; with --scheduler "
            "the cluster's workers run the batch (give one or the other)"
        )
    from gcalign.app.batch.engine import run_batch
    from gcalign.cli.common import output_name

    notes: list[str] = []
    sw = load_batch(files, command, seeds, seed_start, metric, set_, notes)
    out = output or output_name(sw.name, "batch", None,
                                list(_named(sw, seeds, seed_start, set_)))
    err = consoles(True)  # notes always on stderr
    for line in notes:
        sys.stderr.write(f"note: {line}\n")
    for line in sw.warnings:  # before the runs: a grid key that cannot matter wastes them
        sys.stderr.write(f"warning: {line}\n")

    bar = _progress_bar(bar_label(sw))

    def progress(done: int, total: int, failed: int) -> None:
        assert bar is not None
        if not bar.task_ids:
            bar.add_task("runs", total=total, completed=done, failed="")
        bar.update(bar.task_ids[0], completed=done,
                   failed=f"[red]{failed} failed" if failed else "")

    with bar or contextlib.nullcontext():
        result = run_batch(sw, out, workers=workers, scheduler=scheduler, resume=resume,
                           progress=progress if bar else None,
                           log=lambda msg: err.print(f"[dim]{msg}[/dim]", soft_wrap=True))
    summary = result.summary
    sys.stderr.write(f"wrote {out}\n")
    consoles(as_json).print(COMMAND.table(summary))
    if as_json:
        emit_json({**summary, "warnings": list(sw.warnings)})
    if summary["failed"]:  # the file records them: a result, but not a success
        sys.stderr.write(f"error: {summary['failed']} of {summary['runs']} run(s) failed "
                         f"(each recorded with its message in {out})\n")
        raise typer.Exit(1)
