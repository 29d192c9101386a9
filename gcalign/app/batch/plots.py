"""Batch figures, one per metric (and per numeric grid key).

- A grid with a numeric key (``align.stages.0.t_z_s: [100, 120, …]``): the median over
  seeds of |metric| against that key, one line per combination of the other grid values,
  one column per case of the sweep (when other grid values draw the lines), one row per
  vector component (:func:`sweep_figure`).
- Otherwise: box plots of the distribution over seeds, one box per variant, one subplot per
  vector component (:func:`batch_figure`).
"""

from __future__ import annotations

import json

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.batch.aggregate import metric_label, metric_units
from gcalign.app.batch.sweep import CASE_KEY, FILE_KEY
from gcalign.app.batch.tables import short_keys, written
from gcalign.app.plots import _s, angle_scale, finish, new_figure, suptitle
from gcalign.io.scenario.base import is_number


def _pairs(overrides: dict, keys: list[str], sep: str) -> str:
    """``key=value`` of the given override keys, short key names, floats as ``%g``."""
    short = short_keys(keys)
    return sep.join(f"{short[k]}={written(overrides[k])}" for k in keys if k in overrides)


def _variant_label(overrides: dict, grid_keys: list[str]) -> str:
    if list(overrides) == [FILE_KEY]:  # a batch of scenario files: the file's name
        return str(overrides[FILE_KEY]).rsplit("/", 1)[-1].removesuffix(".yaml")
    return _pairs(overrides, [*grid_keys, *(k for k in overrides if k not in grid_keys)],
                  "\n") or "base"


TICK_CHARS_PER_INCH = 13.0  #: characters of a "small" tick label per inch of width
TITLE_CHARS_PER_INCH = 9.0  #: characters of the title per inch of width


def wrap_words(text: str, width: int) -> str:
    """`text` on lines of at most `width` characters, broken after ``_ - + = , /`` or a
    space (a file name has no spaces), each line of a multi-line text on its own."""
    import re

    out = []
    for line in text.split("\n"):
        pieces = re.findall(r"[^_\-+=,/ ]*[_\-+=,/ ]?", line)
        row = ""
        for piece in filter(None, pieces):
            if row and len(row) + len(piece.rstrip()) > width:
                out.append(row.rstrip())
                row = ""
            row += piece
        out.append(row.rstrip())
    return "\n".join(out)


def _values_and_components(values, components: list[str] | None):
    """Values as (R, k) and the names of the panels: the components, or one pooled panel
    for more than 3 of them."""
    values = np.asarray(values, float)
    if values.ndim == 1:
        values = values[:, None]
    k = values.shape[1]
    if k > 3:
        return values, ["all components pooled"], True
    return values, components or ([""] if k == 1 else [str(i) for i in range(k)]), False


def batch_figure(metric: str, values: np.ndarray, variant: np.ndarray, labels: list[str],
                 components: list[str] | None = None, units: str = "",
                 title: str | None = None) -> Figure:
    """Box plots of one metric over seeds, one box per variant, one subplot per component.

    values : (R,) or (R, k) for the R successful runs; variant : (R,) variant index of each;
    labels : one per variant (its overrides). More than 3 components (e.g. the errors at
    every azimuth of a north-finding sweep) are pooled into one subplot.
    """
    values, comps, pooled = _values_and_components(values, components)
    n_var = len(labels)
    width = max(6.0, 1.1 * n_var + 3.0)
    per_box = max(8, int((width - 1.5) / n_var * TICK_CHARS_PER_INCH))  # no overlap
    labels = [wrap_words(x, per_box) for x in labels]
    fig, axes = new_figure(len(comps), width=width, height=2.8 * len(comps) + 1.4)
    for j, (ax, comp) in enumerate(zip(axes, comps, strict=True)):
        data = []
        for vi in range(n_var):
            sel = values[variant == vi]
            x = sel.ravel() if pooled else sel[:, j]
            data.append(x[np.isfinite(x)])
        unit = units
        if units == "deg":  # angles in the unit their size needs, as in the tables
            scale, unit = angle_scale(np.radians(np.concatenate(data)))
            data = [np.radians(d) * scale for d in data]
        ax.boxplot(data, patch_artist=True, showfliers=True, whis=(5, 95),
                   boxprops={"facecolor": "tab:blue", "alpha": 0.35},
                   medianprops={"color": "black"})
        ax.set_xticks(range(1, n_var + 1), labels, fontsize="small")
        name = metric if not comp else f"{metric}\n{comp}"
        ax.set_ylabel(f"{name} ({unit})" if unit else name)
        ax.grid(True, axis="y", alpha=0.3)
    axes[-1].set_xlabel("variant (whiskers 5–95 %, box quartiles, line median)")
    suptitle(fig, wrap_words(title or f"{metric}: distribution over seeds per variant",
                             int(width * TITLE_CHARS_PER_INCH)))
    return fig


def numeric_axes(grid: dict) -> list[str]:
    """Grid keys whose values are all numbers, at least two of them distinct: the x axes of
    :func:`sweep_figure`."""
    return [k for k, vals in grid.items()
            if k != CASE_KEY and all(map(is_number, vals)) and len(set(vals)) >= 2]


def sweep_figure(metric: str, values: np.ndarray, variant: np.ndarray, overrides: list[dict],
                 x_key: str, components: list[str] | None = None, units: str = "",
                 title: str | None = None, name: str | None = None) -> Figure:
    """Median over seeds of |metric| against the numeric grid key `x_key`.

    values : (R,) or (R, k) for the R successful runs; variant : (R,) variant index of each;
    overrides : the overrides of every variant (by index). One line per combination of the
    other grid values; when the sweep has cases (``case`` in the overrides) and other grid
    values too, one column per case, else one line per case. One row per component (more
    than 3 are pooled); the band spans 25-75 % of |metric| over the seeds.
    A row shares one y scale, logarithmic when its medians span more than a factor 30 and
    are all > 0. Angles (`units` deg) are shown in the unit each row's values need
    (:func:`gcalign.app.plots.angle_scale`).
    """
    values, comps, pooled = _values_and_components(values, components)
    values = np.abs(values)
    row_units = [units] * len(comps)
    if units == "deg":  # angles in the unit each row's size needs, as in the tables
        for j in range(len(comps)):
            col = slice(None) if pooled else j
            scale, row_units[j] = angle_scale(np.radians(values[:, col]))
            values[:, col] = np.radians(values[:, col]) * scale
    keys = [key for key in dict.fromkeys(key for o in overrides for key in o) if key != x_key]
    other = [key for key in keys if key != CASE_KEY]
    # Cases get a column each when other grid values draw the lines; else they are the lines.
    by_column = CASE_KEY in keys and bool(other)
    cases = list(dict.fromkeys(o.get(CASE_KEY) for o in overrides)) if by_column else [None]
    if not by_column and CASE_KEY in keys:
        other = [CASE_KEY]
    def line_of(o: dict) -> str:
        return _pairs(o, other, ", ") or "median"

    lines = list(dict.fromkeys(line_of(o) for o in overrides))
    fig, axes = new_figure(len(comps), len(cases), width=4.3 * len(cases) + 1.5,
                           height=2.9 * len(comps) + 1.3)
    name = name or metric
    x_units = metric_units(x_key)
    for j, comp in enumerate(comps):
        row = axes[j * len(cases):(j + 1) * len(cases)]
        medians, spans = [], []
        for ax, case in zip(row, cases, strict=True):
            for li, line in enumerate(lines):
                pts = []
                for vi, o in enumerate(overrides):
                    if (by_column and o.get(CASE_KEY) != case) or line_of(o) != line:
                        continue
                    sel = values[variant == vi]
                    x = sel.ravel() if pooled else sel[:, j]
                    x = x[np.isfinite(x)]
                    if x.size:
                        pts.append((float(o[x_key]), *np.percentile(x, [50, 25, 75])))
                if not pts:
                    continue
                xs, med, lo, hi = np.array(sorted(pts)).T
                color = f"C{li % 10}"
                ax.plot(xs, med, marker="o", ms=3.5, color=color, label=line)
                ax.fill_between(xs, lo, hi, color=color, alpha=0.12, lw=0, label="_25-75 %")
                medians.extend(med)
                spans.extend([*lo, *hi])
        # One y scale per row, so that the cases compare at a glance.
        med_arr, span = np.asarray(medians), np.asarray(spans)
        log = bool(med_arr.size) and bool(np.all(med_arr > 0)) and (
            med_arr.max() > 30 * med_arr.min())
        for c, (ax, case) in enumerate(zip(row, cases, strict=True)):
            if log:
                ax.set_yscale("log")
                pos = span[span > 0]
                ax.set_ylim(min(pos.min(), med_arr.min()) / 1.5,
                            max(pos.max(), med_arr.max()) * 1.5)
            elif span.size:
                ax.set_ylim(0.0, 1.05 * max(span.max(), med_arr.max()))
            ax.grid(True, which="minor", alpha=0.3)  # of a log scale (the major: finish)
            if j == 0 and case is not None:
                ax.set_title(f"{CASE_KEY}: {case}", fontsize="medium")
            if c == 0:
                label = f"median |{name}{' ' + comp if comp else ''}|"
                ax.set_ylabel(f"{label} ({row_units[j]})" if row_units[j] else label)
    xlabel = f"{x_key} ({x_units})" if x_units else x_key
    return finish(fig, axes, [xlabel] * len(cases), title or f"median |{name}| over seeds "
                  f"against {x_key} (band: 25-75 % of the seeds)", legend="below")


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of a batch results file."""
    figs: dict[str, Figure] = {}
    if "batch" not in f:
        return figs
    summary = json.loads(_s(f.attrs["summary_json"]))
    runs = f["batch/runs"]
    ok = np.array([_s(x) for x in runs["status"][()]]) == "ok"  # the metrics of these runs
    metrics = {m: runs["metrics"][m][()][ok] for m in runs["metrics"]}
    variant = runs["variant"][()][ok]
    grid = summary.get("grid") or {}
    grid_keys = list(grid)
    overrides = [v["overrides"] for v in summary["variants"]]
    labels = [_variant_label(o, grid_keys) for o in overrides]
    x_keys = numeric_axes(grid)
    short = short_keys(x_keys)
    for m in summary["metrics"]:
        st = next((v["stats"].get(m) for v in summary["variants"]
                   if v["stats"].get(m, {}).get("components")), None) or {}
        units = next((v["stats"][m].get("units", "") for v in summary["variants"]
                      if m in v["stats"]), "")
        name = metric_label(summary["command"], m)
        stem = f"batch_{m.replace('.', '_')}"
        for x_key in x_keys:
            figs[f"{stem}_vs_{short[x_key].replace('.', '_')}"] = sweep_figure(
                m, metrics[m], variant, overrides, x_key, st.get("components"), units,
                title=f"{summary['sweep']}: median |{name}| over {summary['seeds']} seed(s) "
                      f"against {short[x_key]} (band: 25-75 % of the seeds)", name=name)
        if not x_keys:
            files = grid_keys == [FILE_KEY]
            what = f"{len(labels)} scenario files" if files else summary["sweep"]
            figs[stem] = batch_figure(
                m, metrics[m], variant, labels, st.get("components"), units,
                title=f"{what}: {name} over {summary['seeds']} seed(s) per "
                      f"{'file' if files else 'variant'}")
    return figs
