"""Results files read back by the command that wrote them: its table (``gcalign show``) and
its figures (``gcalign plot``), found by the file's ``kind`` among the registry's commands
and ``batch`` (:func:`kinds`)."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gcalign.app.command import Command
from gcalign.app.report import with_warnings
from gcalign.errors import ScenarioError, check_terminated
from gcalign.io.paths import not_a_file

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from rich.console import RenderableType


def kinds() -> dict[str, Command]:
    """The commands whose results files are read back: the registry's and ``batch``."""
    from gcalign.app.batch import COMMAND as batch
    from gcalign.app.registry import COMMANDS

    return {**COMMANDS, batch.name: batch}


def summary_table(kind: str, summary: dict[str, Any]) -> RenderableType:
    """The table a command prints, from its summary (also for `gcalign show`), with the
    run's warnings."""
    commands = kinds()
    if kind not in commands:
        raise ScenarioError(f"kind: {kind!r} is not a gcalign command ({', '.join(commands)}); "
                            "a results file from another version, or a damaged one")
    try:
        table = commands[kind].table(summary)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as err:
        raise ScenarioError(f"summary_json: not the summary of a {kind!r} run "
                            f"({type(err).__name__}: {str(err)[:60]}); a damaged results "
                            "file, or one from another version") from None
    return with_warnings(table, summary.get("warnings") or [])


def figures_for(path: Path) -> dict[str, Figure]:
    """The figures of a results file, by name (file stem of the PNG), from the command
    that wrote it (its ``figures(f, name)``), else the truth and the IMU output if
    the file holds them; a recorded data file (``.imu``, CSV, compressed) gives its IMU
    figure."""
    from gcalign.io import results

    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: {not_a_file(path)}")
    if not results.is_hdf5(path):
        return {"imu": _recorded_imu_figure(path)}
    from gcalign.app.checked import layout, read_checked
    from gcalign.app.plots import truth_and_imu

    kind, summary, _ = read_checked(path)  # ScenarioError if kind, summary or groups are bad
    name = summary.get("scenario") or summary.get("sweep") or path.stem
    if not isinstance(name, str):
        name = path.stem
    with results.open_results(path) as f:
        try:
            commands = kinds()
            figs: dict[str, Figure] = (commands[kind].figures(f, name) if kind in commands
                                       else {})
        except ScenarioError:
            raise  # a figure's own check, naming its datasets
        except (ValueError, TypeError, IndexError, KeyError) as err:
            # the checks hold each dataset; these are datasets that do not fit together
            # (a series shorter than its time, a vector of the wrong width)
            raise ScenarioError(f"{path}: the {'/' + ', /'.join(layout(kind))} "
                                f"datasets of this {kind!r} file do not make its figures "
                                f"({type(err).__name__}: {str(err)[:120]})") from None
        if not figs:
            figs = truth_and_imu(f, name)
    if not figs:
        raise ScenarioError(f"{path}: nothing to plot: this {kind!r} results file holds "
                            "none of the groups its figures are drawn from")
    return figs


def _recorded_imu_figure(path: Path) -> Figure:
    from gcalign.app.data import read_data_file
    from gcalign.app.plots import imu_figure

    imu, _ = read_data_file(path)
    return imu_figure(imu.t, imu.dtheta, imu.dv, imu.ts, "body", f"{path.name}: IMU output")


def default_plot_dir(path: Path) -> Path:
    """``runs/x.h5`` -> ``runs/x_plots/``; ``data.imu.xz`` -> ``data_plots/``."""
    path = Path(path)
    return path.with_name(path.name.split(".")[0] + "_plots")


def plot_file(path: Path, out_dir: Path | str | None = None,
              progress: Callable[[int, int, str], None] | None = None) -> list[Path]:
    """Write every figure of a results file as PNG; the paths written. `progress(done,
    total, what)` hears of each figure written."""
    figs = figures_for(path)
    from gcalign.app.plots import DPI
    from gcalign.io.results import TMP_SUFFIX, check_output_dir, write_error

    out_dir = check_output_dir(out_dir if out_dir is not None else default_plot_dir(path))
    # Drawn into a temporary folder beside it, then renamed one by one: an interrupted
    # plot (SIGTERM, a full disk) leaves no truncated PNG under a figure's name.
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.{os.getpid()}.",
                                    suffix=TMP_SUFFIX, dir=out_dir.parent))
    except OSError as err:
        raise write_error(out_dir, err) from None
    written = []
    try:
        for i, (stem, fig) in enumerate(figs.items()):
            p = tmp / f"{stem}.png"
            try:
                fig.savefig(p, dpi=DPI)
            except OSError as err:  # a full disk: one line, not a traceback
                raise write_error(out_dir / p.name, err) from None
            if progress is not None:
                progress(i + 1, len(figs), "figures")
        check_terminated()  # a SIGTERM whose exception a finaliser swallowed
        for stem in figs:
            os.replace(tmp / f"{stem}.png", out_dir / f"{stem}.png")
            written.append(out_dir / f"{stem}.png")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return written
