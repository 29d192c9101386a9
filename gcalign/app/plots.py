"""PNG figures from results files (matplotlib, Agg canvas, no pyplot state).

One function per figure; each returns a :class:`matplotlib.figure.Figure` so that tests can
inspect ``fig.axes`` and ``ax.lines``. :func:`figures_for` picks the figures of a results
file by its ``kind``; :func:`plot_file` writes them as PNG.

Each command's figures live in its room (``gcalign/app/<command>/plots.py``, reached
through the registry); this module holds what they share: linear axes in the unit the
values need (:func:`angle_scale`, :func:`time_axis`), legends beside or below the panels
so that they never cover data (:func:`legend_right`, :func:`legend_below`), titles wrapped
to the figure (:func:`suptitle`), long series drawn as bins (:func:`envelope`), and the
figures any file can have: the truth (``/truth``) and the IMU output (``/imu``, or a
recorded data file itself).

Series that are data carry a label; pass boundaries and other guides are labelled with a
leading underscore (matplotlib's "not in the legend"), so ``[l for l in ax.lines if not
l.get_label().startswith("_")]`` are the data series.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import h5py
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from gcalign import units

ANGLES = ("pitch", "roll", "yaw")
ENU = ("east", "north", "up")
AXES = ("x", "y", "z")

DPI = 120
#: Points per line above which a series is drawn as its min/max envelope per bin.
MAX_POINTS = 4000


def new_figure(rows: int, cols: int = 1, *, width: float = 9.0, height: float | None = None,
               sharex: bool | Literal["none", "all", "row", "col"] = True
               ) -> tuple[Figure, list[Axes]]:
    """A Figure on the Agg canvas (no global pyplot state) and its axes, flattened."""
    fig = Figure(figsize=(width, height or 2.4 * rows + 1.0), dpi=DPI, layout="constrained")
    axes = fig.subplots(rows, cols, sharex=sharex, squeeze=False)
    return fig, list(axes.ravel())


def legend_below(fig: Figure, ax: Axes, ncols: int | None = None) -> None:
    """One legend for the figure, below the panels (it never covers a curve; above them,
    constrained layout would put it over the title), from the labelled series of `ax`."""
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", fontsize="small",
                   ncols=ncols or min(len(handles), 4), frameon=False)


def suptitle(fig: Figure, text: str) -> None:
    """The figure's title, wrapped to the figure's width (a long title is not cut off)."""
    import textwrap

    width = max(40, int(fig.get_figwidth() * 10.5))
    fig.suptitle("\n".join(textwrap.wrap(text, width)) if len(text) > width else text)


def legend_right(ax: Axes) -> None:
    """The panel's legend outside it, on the right (constrained layout makes room)."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False,
              borderaxespad=0.0)


def plain_numbers(ax: Axes) -> None:
    """y tick labels that read as values in the axis's unit: no offset ("−2.88e2" at the end
    of the axis, to be added to every label) and no power of ten."""
    ax.ticklabel_format(axis="y", useOffset=False, style="plain")


def steady(ax: Axes) -> None:
    """A panel whose values agree to 1e-6 of their size (a noise-free sensor's output) drawn
    as matplotlib draws a constant, ±5 % about it: fitted to them, its labels would read the
    round-off ("1e−10+5.244972887" above the axis)."""
    lo, hi = ax.dataLim.intervaly
    mid = 0.5 * (lo + hi)
    if 0.0 < hi - lo < 1e-6 * abs(mid):
        ax.set_ylim(mid - 0.05 * abs(mid), mid + 0.05 * abs(mid))


def finish(fig: Figure, axes: Sequence[Axes], xlabel: str | Sequence[str], title: str,
           ylabels: Sequence[str] | None = None, *,
           legend: Literal["right", "below"] | None = "right", ncols: int | None = None
           ) -> Figure:
    """The common ending of a figure of panels: each panel gridded (with its y label, if
    given), the x label under the last panel (a list: one under each of the last panels,
    the bottom row), each panel's legend on its right, or one legend below the panels from the first
    panel's series (:func:`legend_below`, `ncols`), or none; the title."""
    xlabels = [xlabel] if isinstance(xlabel, str) else list(xlabel)
    for i, ax in enumerate(axes):
        if ylabels is not None:
            ax.set_ylabel(ylabels[i])
        ax.grid(True, alpha=0.3)
        if legend == "right":
            legend_right(ax)
    for ax, text in zip(axes[len(axes) - len(xlabels):], xlabels, strict=True):
        ax.set_xlabel(text)
    if legend == "below":
        legend_below(fig, axes[0], ncols)
    suptitle(fig, title)
    return fig


def time_axis(t: np.ndarray) -> tuple[np.ndarray, str]:
    """Time from the first sample in s, min or h, whichever reads best."""
    span = float(t[-1] - t[0]) if len(t) else 0.0
    x = t - t[0] if len(t) else t
    if span > 3 * 3600:
        return x / 3600.0, "time from the start (h)"
    if span > 20 * 60:
        return x / 60.0, "time from the start (min)"
    return x, "time from the start (s)"


def angle_scale(values_rad: np.ndarray) -> tuple[float, str]:
    """Multiplier from rad and the unit: the rule of :func:`gcalign.units.angle_unit` (deg
    from 1°, arc-minutes from 1′, else ″), applied to the largest finite |value|."""
    v = np.asarray(values_rad, float)
    v = v[np.isfinite(v)]
    unit = units.angle_unit(float(np.max(np.abs(v))) if v.size else 0.0)
    return 1.0 / units.ANGLE_UNITS[unit][0], unit


def rate_scale(values_rad_s: np.ndarray) -> tuple[float, str]:
    """Multiplier from rad/s and the unit: °/s from 1°/s, else °/h."""
    v = np.asarray(values_rad_s, float)
    peak = float(np.nanmax(np.abs(v))) if v.size else 0.0
    if math.degrees(peak) >= 1.0:
        return math.degrees(1.0), "deg/s"
    return math.degrees(1.0) * 3600.0, "deg/h"


def envelope(x: np.ndarray, y: np.ndarray, max_points: int = MAX_POINTS
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A long series as bins: centre times, mean, min and max of each bin (all (n,));
    short series come back as they are (min = max = mean = y)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) <= max_points:
        return x, y, y, y
    k = math.ceil(len(x) / max_points)
    n = len(x) // k * k
    xs, ys = x[:n].reshape(-1, k), y[:n].reshape(-1, k)
    return xs.mean(1), ys.mean(1), ys.min(1), ys.max(1)


def plot_series(ax: Axes, x: np.ndarray, y: np.ndarray, label: str, **style: Any) -> None:
    """A line, or for a long series its bin means and a band from min to max (a peak
    stays visible however many samples it stands for)."""
    xc, mean, lo, hi = envelope(x, y)
    (line,) = ax.plot(xc, mean, label=label, linewidth=style.pop("linewidth", 1.0), **style)
    if len(xc) < len(x):
        ax.fill_between(xc, lo, hi, color=line.get_color(), alpha=0.25, linewidth=0,
                        label="_envelope")


def truth_figure(t: np.ndarray, att: np.ndarray, v_n: np.ndarray,
                 title: str = "truth") -> Figure:
    """True attitude (deg) and velocity (m/s, ENU) against time."""
    x, xlabel = time_axis(t)
    fig, axes = new_figure(2)
    for j, name in enumerate(ANGLES):
        y = np.unwrap(att[:, j]) if j == 2 else att[:, j]
        plot_series(axes[0], x, np.degrees(y), name)
    for j, name in enumerate(ENU):
        plot_series(axes[1], x, v_n[:, j], name)
    return finish(fig, axes, xlabel, title, ("attitude (deg)\npitch, roll, yaw",
                                            "velocity (m/s)\neast, north, up"))


def imu_figure(t: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, ts: float,
               frame: str = "body", title: str = "IMU output") -> Figure:
    """The IMU output as rates: angular rate (°/h, or °/s for a turning base) and specific
    force (m/s²) per sensor axis against time; long records as min/max bands."""
    x, xlabel = time_axis(t)
    w, f = np.asarray(dtheta) / ts, np.asarray(dv) / ts
    scale, unit = rate_scale(w)
    fig, axes = new_figure(2, 3, width=11.0, height=5.6)
    for j, name in enumerate(AXES):
        plot_series(axes[j], x, w[:, j] * scale, f"gyro {name}", color=f"C{j}")
        plot_series(axes[3 + j], x, f[:, j], f"accel {name}", color=f"C{j}")
        axes[j].set_title(f"{name} axis", fontsize="medium")
    axes[0].set_ylabel(f"angular rate ({unit})")
    axes[3].set_ylabel("specific force (m/s²)")
    for ax in axes:
        steady(ax)
    bins = (f"; bins of {math.ceil(len(t) / MAX_POINTS)} samples: mean line, min-max band"
            if len(t) > MAX_POINTS else "")
    return finish(fig, axes, [xlabel] * 3,
                  f"{title}: increments / {ts * 1e3:g} ms, {frame} frame{bins}", legend=None)


def _s(x: object) -> str:
    return x.decode() if isinstance(x, bytes) else str(x)


def truth_and_imu(f: h5py.File, name: str) -> dict[str, Figure]:
    """The truth (``/truth`` with velocities) and IMU output (``/imu``; its increments are
    sums over each stored interval when decimated: rates over that interval) figures of
    the open file `f`, read through the checked readers (a damaged file: one line)."""
    from gcalign.io.results import imu_series, read_truth

    path = Path(f.filename)
    figs: dict[str, Figure] = {}
    if "truth" in f and "v_n" in f["truth"]:
        truth = read_truth(path)
        assert truth is not None
        figs["truth"] = truth_figure(truth.t, truth.att, truth.v_n, title=f"{name}: truth")
    if "imu" in f and "dtheta" in f["imu"]:
        t, dtheta, dv, ts, frame = imu_series(path)
        figs["imu"] = imu_figure(t, dtheta, dv, ts, frame, f"{name}: IMU output")
    return figs
