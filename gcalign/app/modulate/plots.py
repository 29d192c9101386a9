"""Figures of a modulate results file: the horizontal position error of every scheme on one
log-scale figure (seed 004 Fig. 4, with the linear model dashed beside each), the attitude
errors (misalignment φ, ENU), and the mechanism over one cycle (angle turned about each
sensor axis, and the diagonal of C_s^r: where each sensor axis points)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MultipleLocator

from gcalign.app.plots import AXES, ENU, _s, angle_scale, finish, new_figure
from gcalign.modulate.linear import REPORT_HOURS

COLOURS = ("tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown",
           "tab:pink", "tab:gray", "tab:olive", "tab:cyan")


def _names(g) -> list[str]:
    return [_s(n) for n in g.attrs.get("compare", list(g))]


def hour_axis(ax, t_end_s: float) -> None:
    """Time in hours with ticks every 12 h over runs of a day or more (6 h over half a day,
    the default below): the report hours 12, 24 and 72 fall on ticks."""
    hours = t_end_s / 3600.0
    if hours >= 24:
        ax.xaxis.set_major_locator(MultipleLocator(12.0))
    elif hours >= 12:
        ax.xaxis.set_major_locator(MultipleLocator(6.0))
    ax.set_xlim(0.0, hours * 1.01)  # the last report-hour dot whole
    ax.set_xlabel("time (h)")


def position_error_figure(series: dict, title: str) -> Figure:
    """`series`: name -> (t s, horizontal m, linear (t, horizontal) or None, report hours).
    One colour per scheme, the navigation solid, the linear model dashed (one legend entry
    for all: where the two agree the dashed line lies under the solid one), dots at the
    report hours."""
    fig, (ax,) = new_figure(1, height=6.0)
    top = max((float(np.max(h)) for _, h, _, _ in series.values() if len(h)), default=1.0)
    for i, (name, (t, h, lin, hours)) in enumerate(series.items()):
        c = COLOURS[i % len(COLOURS)]
        keep = t > 0
        ax.plot(t[keep] / 3600.0, h[keep], color=c, linewidth=1.1, label=name)
        if lin is not None:
            lt, lh = lin
            k = lt > 0
            ax.plot(lt[k] / 3600.0, lh[k], color=c, linewidth=0.9, linestyle="--",
                    label=f"_{name} (linear model)")
        at = [np.argmin(np.abs(t - x * 3600.0)) for x in hours]
        ax.plot(t[at] / 3600.0, h[at], "o", color=c, markersize=4, label="_hours")
    ax.set_yscale("log")
    ax.set_ylim(max(top * 1e-4, 1e-3), top * 10.0)  # a decade above the curves: the legend
    end = max((float(t[-1]) for t, _, _, _ in series.values() if len(t)), default=3600.0)
    hour_axis(ax, end)
    ax.set_ylabel("horizontal position error (m)")
    ax.grid(True, which="both", alpha=0.3)
    handles, _ = ax.get_legend_handles_labels()
    extra = [Line2D([], [], color="0.3", linewidth=0.9, linestyle="--",
                    label="linear model (same errors)")]
    if any(lin is not None for _, _, lin, _ in series.values()):
        handles += extra
    handles.append(Line2D([], [], color="0.3", marker="o", markersize=4, linestyle="",
                          label="report hours"))
    ax.legend(handles=handles, loc="upper left", fontsize="small", ncols=3, framealpha=0.9)
    fig.suptitle(title)
    return fig


def attitude_error_figure(series: dict, title: str) -> Figure:
    """`series`: name -> (t s, φ (N, 3) rad)."""
    allphi = np.concatenate([p for _, p in series.values()]) if series else np.zeros((1, 3))
    scale, unit = angle_scale(allphi)
    fig, axes = new_figure(3)
    for i, (name, (t, phi)) in enumerate(series.items()):
        for j in range(3):
            axes[j].plot(t / 3600.0, phi[:, j] * scale, color=COLOURS[i % len(COLOURS)],
                         linewidth=0.9, label=name)
    axes[0].legend(loc="upper left", fontsize="small", ncols=4)
    hour_axis(axes[-1], max((float(t[-1]) for t, _ in series.values() if len(t)), default=3600.0))
    return finish(fig, axes, "time (h)", title, [f"φ {e} ({unit})" for e in ENU], legend=None)


def mechanism_figure(cycles: dict, title: str) -> Figure:
    """`cycles`: name -> (t s, angle (N, 3) rad, C_diag (N, 3), reference)."""
    n = max(1, len(cycles))
    fig, axes = new_figure(n, 2, width=11.0, height=2.1 * n + 1.0, sharex=False)
    for i, (name, (t, angle, diag, ref)) in enumerate(cycles.items()):
        a, d = axes[2 * i], axes[2 * i + 1]
        for j in range(3):
            a.plot(t / 60.0, np.degrees(angle[:, j]), label=f"about sensor {AXES[j]}")
            d.plot(t / 60.0, diag[:, j] + 0.06 * (j - 1), label=f"$C_{{{AXES[j]}{AXES[j]}}}$")
        a.set_ylabel(f"{name}\nangle (deg)")
        d.set_ylabel(f"diag $C_s^{ref[0]}$ (offset ±0.06)")
        d.set_ylim(-1.3, 1.3)
        for ax in (a, d):
            ax.grid(True, alpha=0.3)
            ax.set_xlim(0, t[-1] / 60.0)
    axes[-2].set_xlabel("time in the cycle (min)")
    axes[-1].set_xlabel("time in the cycle (min)")
    # one legend per column above the panels: inside, it hides the dwell levels (±1, 180°)
    for ax in axes[:2]:
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), fontsize="small", ncols=3,
                  frameon=False, borderaxespad=0.0)
    fig.suptitle(title)
    return fig


def figures(f, name: str) -> dict:
    """The figures of a modulate results file: the linear model and the mechanism's cycle
    read back (:class:`~gcalign.modulate.linear.LinearSeries`,
    :class:`~gcalign.modulate.analysis.MechanismCycle`)."""
    from gcalign.io.stored import read_fields
    from gcalign.modulate.analysis import MechanismCycle
    from gcalign.modulate.linear import LinearSeries

    if "modulate" not in f:
        return {}
    root = f["modulate"]
    pos, att, cyc = {}, {}, {}
    hours = float(root.attrs.get("hours", 0.0))
    rep = [h for h in REPORT_HOURS if h <= hours + 1e-9]
    for s in _names(root):
        g = root[s]
        t = g["t"][()]
        e = g["error/pos"][()]
        lin = None
        if "linear" in g:
            ls = read_fields(g["linear"], LinearSeries)
            lin = (ls.t, ls.horizontal)
        pos[s] = (t, np.hypot(e[:, 0], e[:, 1]), lin, rep)
        att[s] = (t, g["error/phi"][()])
        if g.attrs.get("mechanism", True) and "mechanism" in g:
            m = read_fields(g["mechanism"], MechanismCycle)
            cyc[s] = (m.t, m.angle, m.C_diag, _s(g.attrs["reference"]))
    out = {
        "modulate_position_error": position_error_figure(
            pos, f"{name}: horizontal position error"),
        "modulate_attitude_error": attitude_error_figure(
            att, f"{name}: misalignment φ (ENU)"),
    }
    if cyc:
        out["modulate_mechanism"] = mechanism_figure(cyc, f"{name}: the mechanism over one "
                                                          "cycle")
    return out
