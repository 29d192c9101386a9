"""The `gcalign allan` figure, as PSINS's ``avar``/``avarfit`` draw it: per triad, log-log
σ(τ) of each axis with its 1σ band from the number of clusters (dashed), each fitted term as
a dashed line of its slope labelled at its end (Q, N, B, K), drawn solid over the τ range it
was fitted on, and the sum of the terms (the model)."""

from __future__ import annotations

import numpy as np

from gcalign import units as u
from gcalign.allan import FLAT, AllanRecord, TriadRecord
from gcalign.app.plots import new_figure
from gcalign.io.stored import read_fields

AXES = ("x", "y", "z")
COLORS = ("tab:blue", "tab:orange", "tab:green")
LETTER = {"quantization": "Q", "white": "N", "instability": "B", "rate_rw": "K"}
BASIS = {"quantization": lambda t: np.sqrt(3.0) / t, "white": lambda t: 1.0 / np.sqrt(t),
         "instability": lambda t: FLAT + 0.0 * t, "rate_rw": lambda t: np.sqrt(t / 3.0)}
SCALE = {"gyro": (1.0 / u.DPH, "σ(τ) (°/h)", "gyros"),
         "accel": (1.0 / u.UG, "σ(τ) (µg)", "accelerometers")}


def figures(f, name: str) -> dict:
    """``{stem: Figure}`` of a results file holding ``/allan``, from its record read back
    (:class:`gcalign.allan.AllanRecord`)."""
    rec = read_fields(f["allan"], AllanRecord)
    span = None if rec.fit_tau_s is None else tuple(rec.fit_tau_s)
    fig, axes = new_figure(1, 2, width=13.0, height=5.6, sharex=False)
    for ax, triad in zip(axes, ("gyro", "accel"), strict=True):
        _panel(ax, getattr(rec, triad), triad, span)
    fig.suptitle(f"{name}: Allan deviation and fitted noise terms (1σ bands dashed)",
                 fontsize="medium")
    return {f"{name}-allan": fig}


def _panel(ax, g: TriadRecord, triad: str, span: tuple | None) -> None:
    scale, ylabel, title = SCALE[triad]
    tau = g.tau
    adev, lo, hi, model = (x * scale for x in (g.adev, g.adev_lo, g.adev_hi, g.model))
    if span is not None:  # the terms were fitted on span only: their sum is drawn there
        model[(tau < span[0] * (1 - 1e-9)) | (tau > span[1] * (1 + 1e-9))] = np.nan
        for a, b in ((tau[0], span[0]), (span[1], tau[-1])):
            if b > a:
                ax.axvspan(a, b, color="0.9", zorder=0, label="_not fitted")
    t_line = np.geomspace(tau[0], tau[-1], 200)
    ymin, ymax = np.nanmin(lo[lo > 0]) if (lo > 0).any() else adev.min(), np.nanmax(hi)
    for i, (axis, color) in enumerate(zip(AXES, COLORS, strict=True)):
        ax.loglog(tau, adev[:, i], "-+", color=color, lw=1.4, ms=4, label=f"{axis}")
        ax.loglog(tau, lo[:, i], "--", color=color, lw=0.6, alpha=0.6, label="_band")
        ax.loglog(tau, hi[:, i], "--", color=color, lw=0.6, alpha=0.6, label="_band")
        ax.loglog(tau, model[:, i], "-", color=color, lw=3.0, alpha=0.25,
                  label=f"{axis} fitted (sum)")
        for name, letter in LETTER.items():
            tg = g.terms[name]
            value = float(tg.value[i]) * scale
            if not np.isfinite(value) or value <= 0:
                continue
            line = value * BASIS[name](t_line)
            keep = (line > ymin / 2) & (line < ymax * 2)  # inside the axes: the label shows
            if not keep.any():
                continue
            ax.loglog(t_line[keep], line[keep], ":", color=color, lw=0.9, label="_term")
            a, b = tg.tau_range[i]
            seg = (t_line >= a) & (t_line <= b)
            ax.loglog(t_line[seg], line[seg], "-", color=color, lw=1.0, alpha=0.9,
                      label="_term range")
            last = np.flatnonzero(keep)[-1]
            ax.annotate(letter, (t_line[last], line[last]), color=color, fontsize=8,
                        xytext=(2, 0), textcoords="offset points")
    ax.set_ylim(ymin / 2, ymax * 2)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title if span is None else f"{title} (terms fitted on τ {span[0]:g}–"
                 f"{span[1]:g} s, unshaded)", fontsize="medium")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize="x-small", ncols=2, loc="best")
