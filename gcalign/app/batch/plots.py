"""Batch figures: the distribution over seeds of each metric per variant (box plots), one
figure per metric, one subplot per vector component."""

from __future__ import annotations

import json

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import _s, new_figure


def _variant_label(overrides: dict, grid_keys: list[str]) -> str:
    tails = [k.rsplit(".", 1)[-1] for k in grid_keys]
    short = {k: (t if tails.count(t) == 1 else k)
             for k, t in zip(grid_keys, tails, strict=True)}
    return "\n".join(f"{short.get(k, k)}={v:g}" if isinstance(v, float) else
                     f"{short.get(k, k)}={v}" for k, v in overrides.items()) or "base"


def batch_figure(metric: str, values: np.ndarray, variant: np.ndarray, labels: list[str],
                 components: list[str] | None = None, units: str = "",
                 title: str | None = None) -> Figure:
    """Box plots of one metric over seeds, one box per variant, one subplot per component.

    values : (R,) or (R, k) for the R successful runs; variant : (R,) variant index of each;
    labels : one per variant (its overrides). More than 3 components (e.g. the errors at
    every azimuth of a north-finding sweep) are pooled into one subplot.
    """
    values = np.asarray(values, float)
    if values.ndim == 1:
        values = values[:, None]
    k = values.shape[1]
    pooled = k > 3
    comps = ["all components pooled"] if pooled else (components or
                                                      ([""] if k == 1 else [str(i) for i in
                                                                           range(k)]))
    n_var = len(labels)
    fig, axes = new_figure(len(comps), width=max(6.0, 1.1 * n_var + 3.0),
                           height=2.8 * len(comps) + 1.4)
    for j, (ax, comp) in enumerate(zip(axes, comps, strict=True)):
        data = []
        for vi in range(n_var):
            sel = values[variant == vi]
            x = sel.ravel() if pooled else sel[:, j]
            data.append(x[np.isfinite(x)])
        ax.boxplot(data, patch_artist=True, showfliers=True, whis=(5, 95),
                   boxprops={"facecolor": "tab:blue", "alpha": 0.35},
                   medianprops={"color": "black"})
        ax.set_xticks(range(1, n_var + 1), labels, fontsize="small")
        name = metric if not comp else f"{metric}\n{comp}"
        ax.set_ylabel(f"{name} ({units})" if units else name)
        ax.grid(True, axis="y", alpha=0.3)
    axes[-1].set_xlabel("variant (whiskers 5–95 %, box quartiles, line median)")
    fig.suptitle(title or f"{metric}: distribution over seeds per variant")
    return fig


def read_batch(f) -> tuple[dict, dict[str, np.ndarray], np.ndarray, np.ndarray]:
    summary = json.loads(_s(f.attrs["summary_json"]))
    r = f["batch/runs"]
    status = np.array([_s(x) for x in r["status"][()]])
    ok = status == "ok"
    metrics = {m: r["metrics"][m][()][ok] for m in r["metrics"]}
    return summary, metrics, r["variant"][()][ok], ok


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of a batch results file."""
    figs: dict[str, Figure] = {}
    if "batch" not in f:
        return figs
    summary, metrics, variant, _ = read_batch(f)
    grid_keys = list(summary.get("grid") or {})
    labels = [_variant_label(v["overrides"], grid_keys) for v in summary["variants"]]
    for m in summary["metrics"]:
        st = next((v["stats"].get(m) for v in summary["variants"]
                   if v["stats"].get(m, {}).get("components")), None) or {}
        units = next((v["stats"][m].get("units", "") for v in summary["variants"]
                      if m in v["stats"]), "")
        figs[f"batch_{m.replace('.', '_')}"] = batch_figure(
            m, metrics[m], variant, labels, st.get("components"), units,
            title=f"{summary['sweep']}: {m} over {summary['seeds']} seed(s) per variant")
    return figs
