"""PNG figures from results files (matplotlib, Agg canvas, no pyplot state).

One function per figure; each returns a :class:`matplotlib.figure.Figure` so that tests can
inspect ``fig.axes`` and ``ax.lines``. :func:`figures_for` picks the figures of a results
file by its ``kind``; :func:`plot_file` writes them as PNG.

Each command's figures live in its room (``gcalign/app/<command>/figures.py``, reached
through the registry); this module holds what they share and the truth figure that any
file with ``/truth`` can show.

Series that are data carry a label; pass boundaries and other guides are labelled with a
leading underscore (matplotlib's "not in the legend"), so ``[l for l in ax.lines if not
l.get_label().startswith("_")]`` are the data series.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from gcalign.errors import ScenarioError

ANGLES = ("pitch", "roll", "yaw")
ENU = ("east", "north", "up")

DPI = 120


def new_figure(rows: int, cols: int = 1, *, width: float = 9.0, height: float | None = None,
               sharex: bool = True) -> tuple[Figure, list]:
    """A Figure on the Agg canvas (no global pyplot state) and its axes, flattened."""
    fig = Figure(figsize=(width, height or 2.4 * rows + 1.0), dpi=DPI, layout="constrained")
    axes = fig.subplots(rows, cols, sharex=sharex, squeeze=False)
    return fig, list(axes.ravel())


def truth_figure(t: np.ndarray, att: np.ndarray, v_n: np.ndarray,
                 title: str = "truth") -> Figure:
    """True attitude (deg) and velocity (m/s, ENU) against time."""
    fig, axes = new_figure(2)
    for j, name in enumerate(ANGLES):
        y = np.unwrap(att[:, j]) if j == 2 else att[:, j]
        axes[0].plot(t, np.degrees(y), label=name)
    for j, name in enumerate(ENU):
        axes[1].plot(t, v_n[:, j], label=name)
    axes[0].set_ylabel("attitude (deg)")
    axes[1].set_ylabel("velocity (m/s)")
    axes[1].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    fig.suptitle(title)
    return fig


def _s(x) -> str:
    return x.decode() if isinstance(x, bytes) else str(x)


def figures_for(path: Path) -> dict[str, Figure]:
    """The figures of a results file, by name (file stem of the PNG), from the room of the
    command that wrote it (its ``figures(f, name)``); the truth when it has no others."""
    from gcalign.app.registry import COMMANDS
    from gcalign.io import results

    path = Path(path)
    with results.open_results(path) as f:
        kind = _s(f.attrs.get("kind", ""))
        summary = json.loads(_s(f.attrs.get("summary_json", "{}")))
        name = summary.get("scenario") or summary.get("sweep") or path.stem
        figs: dict[str, Figure] = COMMANDS[kind].load().figures(f, name) if kind in COMMANDS else {}
        if not figs and "truth" in f:
            figs["truth"] = truth_figure(f["truth/t"][()], f["truth/att"][()],
                                         f["truth/v_n"][()], title=f"{name}: truth")
    if not figs:
        raise ScenarioError(f"{path}: nothing to plot in a {kind!r} results file")
    return figs


def default_plot_dir(path: Path) -> Path:
    """``runs/x.h5`` -> ``runs/x_plots/``."""
    path = Path(path)
    return path.with_name(path.stem + "_plots")


def plot_file(path: Path, out_dir: Path | None = None) -> list[Path]:
    """Write every figure of a results file as PNG; the paths written."""
    figs = figures_for(path)
    from gcalign.io.results import check_output_dir, write_error

    out_dir = check_output_dir(out_dir if out_dir is not None else default_plot_dir(path))
    written = []
    for stem, fig in figs.items():
        p = out_dir / f"{stem}.png"
        try:
            fig.savefig(p, dpi=DPI)
        except OSError as err:  # a full disk: one line, not a traceback
            p.unlink(missing_ok=True)
            raise write_error(p, err) from None
        written.append(p)
    return written
