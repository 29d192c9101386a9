"""Observability figures: the degree table as heat maps (log10 η, segments × states) per
segment and cumulative, the covariance degree σ(0)/σ(t) likewise, and the flight."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.calibrate.plots import truth_trajectory
from gcalign.app.plots import new_figure


def heat_map(values: np.ndarray, rows: list[str], cols: list[str], title: str, label: str,
             zero: str = "0", exponents: bool = True) -> Figure:
    """log10 of `values` (rows × cols) as colours, with the rounded exponent (or, with
    ``exponents=False``, the value to two digits) written in each cell; zeros
    (unobservable) grey and marked `zero`."""
    with np.errstate(divide="ignore"):
        logv = np.where(values > 0, np.log10(np.where(values > 0, values, 1.0)), np.nan)
    fig, (ax,) = new_figure(1, width=13.0, height=1.2 + 0.3 * len(rows))
    import matplotlib as mpl

    cmap = mpl.colormaps["viridis"].with_extremes(bad="0.85")
    finite = logv[np.isfinite(logv)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    im = ax.imshow(np.ma.masked_invalid(logv), cmap=cmap, aspect="auto", vmin=lo, vmax=hi,
                   interpolation="nearest")
    for i in range(len(rows)):
        for j in range(len(cols)):
            v = logv[i, j]
            if not np.isfinite(v):
                text = zero
            else:
                x = values[i, j]
                text = (f"{round(v):d}" if exponents else f"{x:.0f}" if x >= 100
                        else f"{x:.2g}")
            dark = np.isfinite(v) and (v - lo) < 0.55 * (hi - lo)
            ax.text(j, i, text, ha="center", va="center", fontsize=6,
                    color="white" if dark else "black")
    ax.set_xticks(range(len(cols)), cols, rotation=60, fontsize=8)
    ax.set_yticks(range(len(rows)), rows, fontsize=8)
    fig.colorbar(im, ax=ax, label=label, shrink=0.9)
    ax.set_title(title, fontsize="medium")
    return fig


def figures(f, name: str) -> dict[str, Figure]:
    """The flight's trajectory and heat maps of its table read back
    (:class:`gcalign.calibrate.observability.ObservabilityTable`)."""
    from gcalign.calibrate.observability import ObservabilityTable
    from gcalign.io.stored import read_fields

    figs = truth_trajectory(f, name)
    if "observability" not in f:
        return figs
    tab = read_fields(f["observability"], ObservabilityTable)
    states = list(tab.names)
    segs = [f"{i + 1} {n}" for i, n in enumerate(tab.segments)]
    how = f"{tab.measure} matching, scaling {tab.scaling}"
    figs["observability_segments"] = heat_map(
        tab.eta, segs, states, f"{name}: degree of observability η per segment ({how}; "
        "grey ·: 0)", "log10 η", "·")
    figs["observability_cumulative"] = heat_map(
        tab.eta_cum, [f"to {s}" for s in segs], states,
        f"{name}: cumulative degree η from the start ({how})", "log10 η", "·")
    if tab.cov_degree is not None:
        figs["covariance_degree"] = heat_map(
            tab.cov_degree, [f"after {s}" for s in segs], states,
            f"{name}: covariance degree σ(0)/σ(t) at the end of each segment (PSINS kfstat, "
            f"{tab.measure})", "log10 σ(0)/σ(t)", exponents=False)
    return figs
