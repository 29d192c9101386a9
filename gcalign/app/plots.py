"""PNG figures from results files (matplotlib, Agg canvas, no pyplot state).

One function per figure; each returns a :class:`matplotlib.figure.Figure` so that tests can
inspect ``fig.axes`` and ``ax.lines``. :func:`figures_for` picks the figures of a results
file by its ``kind``; :func:`plot_file` writes them as PNG.

* alignment (seed 000 figs. 7–12): the error of every pass against an *equivalent time*
  axis (the passes laid end to end, so a full-cycle run of 290 s of data × 5 passes spans
  1450 s), pass boundaries as vertical dotted lines, one subplot per angle (pitch, roll,
  yaw, degrees); and the attitude estimate against the truth on the same axis.
* north-finding (seed 001 figs. 3–5): the azimuth error against the true azimuth, one
  subplot per method (mean over repeats, ±1σ band when there are repeats, and the
  noise-free closed form where there is one); the difference coordinate − vector.
* batch: the distribution over seeds of each metric per variant (box plots), one figure per
  metric, one subplot per vector component.
* simulate / navigate: the true attitude; the navigation errors.

Series that are data carry a label; pass boundaries and other guides are labelled with a
leading underscore (matplotlib's "not in the legend"), so ``[l for l in ax.lines if not
l.get_label().startswith("_")]`` are the data series.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from gcalign.errors import ScenarioError

ANGLES = ("pitch", "roll", "yaw")
ENU = ("east", "north", "up")
PASS_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
               "tab:pink", "tab:olive", "tab:cyan")
METHOD_ORDER = ("coordinate", "vector", "naive", "none")
DPI = 120


def new_figure(rows: int, cols: int = 1, *, width: float = 9.0, height: float | None = None,
               sharex: bool = True) -> tuple[Figure, list]:
    """A Figure on the Agg canvas (no global pyplot state) and its axes, flattened."""
    fig = Figure(figsize=(width, height or 2.4 * rows + 1.0), dpi=DPI, layout="constrained")
    axes = fig.subplots(rows, cols, sharex=sharex, squeeze=False)
    return fig, list(axes.ravel())


# --------------------------------------------------------------------------------------
# Alignment (seed 000)
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PassSeries:
    """One pass read from ``/align/pass_NN``: times in processing order (s), attitude and
    error (rad, (n, 3)); direction, kind ("compass"/"attitude") and stage."""

    index: int
    direction: str
    kind: str
    stage: int
    t: np.ndarray
    att: np.ndarray
    error: np.ndarray | None


def equivalent_time(passes: list[PassSeries]) -> tuple[list[np.ndarray], list[float]]:
    """Each pass's time on the equivalent axis (passes end to end; the first pass keeps its
    data time) and the boundaries between passes (s)."""
    xs, bounds = [], []
    offset = float(passes[0].t[0]) if passes else 0.0
    for p in passes:
        x = offset + np.abs(p.t - p.t[0])
        xs.append(x)
        offset = float(x[-1])
        bounds.append(offset)
    return xs, bounds[:-1]


def _pass_label(p: PassSeries) -> str:
    kind = "" if p.kind == "compass" else f" {p.kind}"
    return f"pass {p.index + 1} {p.direction}{kind} (stage {p.stage + 1})"


def _mark_boundaries(ax, bounds) -> None:
    for b in bounds:
        ax.axvline(b, color="0.45", linestyle=":", linewidth=1.0, label="_pass boundary")


def _symlog_threshold(values: np.ndarray) -> float:
    """Linear range of the symlog axis: about the size of the converged error."""
    v = np.abs(values[np.isfinite(values)])
    if v.size == 0:
        return 1e-3
    tail = np.median(v[-max(1, v.size // 5):])
    return float(10.0 ** np.floor(np.log10(max(tail, 1e-6))))


def align_error_figure(passes: list[PassSeries], title: str = "alignment error") -> Figure:
    """Error (deg) of every pass against equivalent time, one subplot per angle."""
    xs_all, bounds = equivalent_time(passes)
    with_err = [(x, p, p.error) for x, p in zip(xs_all, passes, strict=True)
                if p.error is not None]
    if not with_err:
        raise ScenarioError("plot: the file has no alignment errors (no truth: recorded data)")
    fig, axes = new_figure(3)
    for j, (ax, name) in enumerate(zip(axes, ANGLES, strict=True)):
        for x, p, err in with_err:
            ax.plot(x, np.degrees(err[:, j]), color=PASS_COLORS[p.index % len(PASS_COLORS)],
                    linewidth=1.0, label=_pass_label(p))
        _mark_boundaries(ax, bounds)
        lin = _symlog_threshold(np.degrees(with_err[-1][2][:, j]))
        ax.set_yscale("symlog", linthresh=lin)
        ax.set_ylabel(f"{name} error (deg)\nsymlog, linear < {lin:g}")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].legend(loc="upper right", fontsize="small", ncols=min(3, len(with_err)))
    axes[-1].set_xlabel("equivalent time (s): passes laid end to end; dotted lines: "
                        "pass boundaries")
    fig.suptitle(title)
    return fig


def align_attitude_figure(passes: list[PassSeries], truth_t: np.ndarray | None = None,
                          truth_att: np.ndarray | None = None,
                          title: str = "attitude estimate") -> Figure:
    """Attitude estimate (deg) of every pass and, if known, the truth at the same data
    times, against equivalent time; one subplot per angle."""
    xs, bounds = equivalent_time(passes)
    fig, axes = new_figure(3)
    for j, (ax, name) in enumerate(zip(axes, ANGLES, strict=True)):
        for x, p in zip(xs, passes, strict=True):
            y = np.degrees(np.unwrap(p.att[:, j]) if j == 2 else p.att[:, j])
            ax.plot(x, y, color=PASS_COLORS[p.index % len(PASS_COLORS)], linewidth=1.0,
                    label=_pass_label(p))
        if truth_t is not None and truth_att is not None:
            ref = np.unwrap(truth_att[:, j]) if j == 2 else truth_att[:, j]
            tx = np.concatenate([np.append(x, np.nan) for x in xs])
            ty = np.concatenate([np.append(np.interp(p.t, truth_t, ref), np.nan)
                                 for p in passes])
            ax.plot(tx, np.degrees(ty), color="black", linestyle="--", linewidth=1.0,
                    label="truth")
        _mark_boundaries(ax, bounds)
        ax.set_ylabel(f"{name} (deg)")
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="best", fontsize="small", ncols=min(3, len(passes) + 1))
    axes[-1].set_xlabel("equivalent time (s): passes laid end to end; dotted lines: "
                        "pass boundaries")
    fig.suptitle(title)
    return fig


def read_passes(f) -> list[PassSeries]:
    g = f["align"]
    out = []
    for name in sorted(k for k in g if k.startswith("pass_")):
        p = g[name]
        out.append(PassSeries(
            index=int(name.split("_")[1]), direction=_s(p.attrs.get("direction", "forward")),
            kind=_s(p.attrs.get("kind", "compass")), stage=int(p.attrs.get("stage", 0)),
            t=p["t"][()], att=p["att"][()], error=p["error"][()] if "error" in p else None))
    return out


# --------------------------------------------------------------------------------------
# North-finding (seed 001)
# --------------------------------------------------------------------------------------


def _methods_in_order(names) -> list[str]:
    names = list(names)
    return [m for m in METHOD_ORDER if m in names] + [m for m in names if m not in METHOD_ORDER]


def northfind_error_figure(azimuth_true: np.ndarray, errors: dict[str, np.ndarray],
                           error_pred: dict[str, np.ndarray] | None = None,
                           title: str = "north-finding error") -> Figure:
    """Azimuth error (deg) against true azimuth (deg), one subplot per method.

    errors : method -> (M,) or (repeats, M) rad. error_pred : method -> (M,) rad (closed
    form, NaN where there is none).
    """
    methods = _methods_in_order(errors)
    az = np.degrees(np.asarray(azimuth_true, float))
    order = np.argsort(az)
    fig, axes = new_figure(len(methods), height=2.2 * len(methods) + 1.0)
    for ax, m in zip(axes, methods, strict=True):
        e = np.degrees(np.atleast_2d(errors[m]))[:, order]
        r = e.shape[0]
        mean = e.mean(0)
        ax.plot(az[order], mean, marker="." if az.size < 100 else None, linewidth=1.0,
                label="error" if r == 1 else f"mean of {r} repeats")
        if r > 1:
            sd = e.std(0, ddof=1)
            ax.fill_between(az[order], mean - sd, mean + sd, alpha=0.25, label="±1σ")
        pred = None if error_pred is None else error_pred.get(m)
        if pred is not None and np.any(np.isfinite(pred)):
            ax.plot(az[order], np.degrees(np.asarray(pred))[order], color="black",
                    linestyle="--", linewidth=0.8, label="closed form (noise-free)")
        ax.set_ylabel(f"{m}\nerror (deg)")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize="small")
    axes[-1].set_xlabel("true azimuth (deg, clockwise from north)")
    axes[-1].set_xlim(0, 360)
    axes[-1].set_xticks(np.arange(0, 361, 45))
    fig.suptitle(title)
    return fig


def northfind_difference_figure(azimuth_true: np.ndarray, a: np.ndarray, b: np.ndarray,
                                names: tuple[str, str] = ("coordinate", "vector"),
                                title: str = "difference of the two compensation methods"
                                ) -> Figure:
    """Seed 001 fig. 5: estimate difference of two methods (arc-seconds) against true
    azimuth; a, b are errors (M,) or (repeats, M) rad."""
    az = np.degrees(np.asarray(azimuth_true, float))
    order = np.argsort(az)
    d = (np.degrees(np.atleast_2d(a) - np.atleast_2d(b)) * 3600.0)[:, order]
    fig, axes = new_figure(1, height=3.6)
    ax = axes[0]
    ax.plot(az[order], d.mean(0), marker="." if az.size < 100 else None, linewidth=1.0,
            label=f"{names[0]} − {names[1]}" + (f" (mean of {d.shape[0]})" if len(d) > 1 else ""))
    ax.set_xlabel("true azimuth (deg, clockwise from north)")
    ax.set_ylabel("difference (arcsec)")
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize="small")
    fig.suptitle(title)
    return fig


def read_northfind(f) -> tuple[np.ndarray, dict, dict]:
    g = f["northfind"]
    names = _s(g.attrs.get("methods", "")).split(",") if "methods" in g.attrs else []
    import h5py

    names = [n for n in names if n in g] or [k for k in g if isinstance(g[k], h5py.Group)
                                             and "error" in g[k]]
    errors = {m: g[m]["error"][()] for m in names}
    pred = {m: g[m]["error_pred"][()] for m in names if "error_pred" in g[m]}
    return g["azimuth_true"][()], errors, pred


# --------------------------------------------------------------------------------------
# Batch
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# Simulate / navigate
# --------------------------------------------------------------------------------------


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


def navigate_error_figure(t: np.ndarray, att: np.ndarray, vel: np.ndarray, pos: np.ndarray,
                          title: str = "navigation error") -> Figure:
    """Attitude (deg), velocity (m/s) and position (m) errors against time."""
    fig, axes = new_figure(3)
    for j, name in enumerate(ANGLES):
        axes[0].plot(t, np.degrees(att[:, j]), label=name)
    for j, name in enumerate(ENU):
        axes[1].plot(t, vel[:, j], label=name)
        axes[2].plot(t, pos[:, j], label=name)
    for ax, lab in zip(axes, ("attitude error (deg)", "velocity error (m/s)",
                              "position error (m)"), strict=True):
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(title)
    return fig


# --------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------


def _s(x) -> str:
    return x.decode() if isinstance(x, bytes) else str(x)


def figures_for(path: Path) -> dict[str, Figure]:
    """The figures of a results file, by name (file stem of the PNG)."""
    from gcalign.io import results

    path = Path(path)
    with results.open_results(path) as f:
        kind = _s(f.attrs.get("kind", ""))
        summary = json.loads(_s(f.attrs.get("summary_json", "{}")))
        name = summary.get("scenario") or summary.get("sweep") or path.stem
        figs: dict[str, Figure] = {}
        if kind == "align" and "align" in f:
            passes = read_passes(f)
            mode = _s(f["align"].attrs.get("mode", ""))
            head = f"{name}: {mode}, {len(passes)} pass(es)"
            has_truth = "truth" in f
            figs["align_attitude"] = align_attitude_figure(
                passes, truth_t=f["truth/t"][()] if has_truth else None,
                truth_att=f["truth/att"][()] if has_truth else None,
                title=f"{head} — attitude estimate vs truth")
            if any(p.error is not None for p in passes):
                figs["align_error"] = align_error_figure(
                    passes, title=f"{head} — attitude error per pass")
        elif kind == "northfind" and "northfind" in f:
            az, errors, pred = read_northfind(f)
            head = f"{name}: {len(az)} azimuth(s)"
            figs["northfind_error"] = northfind_error_figure(
                az, errors, pred, title=f"{head} — azimuth error per method")
            if "coordinate" in errors and "vector" in errors:
                figs["northfind_difference"] = northfind_difference_figure(
                    az, errors["coordinate"], errors["vector"],
                    title=f"{head} — coordinate − vector (seed 001 fig. 5)")
        elif kind == "batch" and "batch" in f:
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
        elif kind == "navigate" and "navigate/error" in f:
            e = f["navigate/error"]
            figs["navigate_error"] = navigate_error_figure(
                f["navigate/t"][()], e["att"][()], e["v_n"][()], e["pos"][()],
                title=f"{name}: free-inertial navigation error")
        if not figs and "truth" in f:
            figs["truth"] = truth_figure(f["truth/t"][()], f["truth/att"][()],
                                         f["truth/v_n"][()], title=f"{name}: truth")
    if not figs:
        raise ScenarioError(f"{path}: nothing to plot in a {kind!r} results file "
                            "(figures exist for align, northfind, batch, navigate, simulate)")
    return figs


def default_plot_dir(path: Path) -> Path:
    """``runs/x.h5`` -> ``runs/x_plots/``."""
    path = Path(path)
    return path.with_name(path.stem + "_plots")


def plot_file(path: Path, out_dir: Path | None = None) -> list[Path]:
    """Write every figure of a results file as PNG; the paths written."""
    figs = figures_for(path)
    out_dir = Path(out_dir) if out_dir is not None else default_plot_dir(path)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for stem, fig in figs.items():
        p = out_dir / f"{stem}.png"
        fig.savefig(p, dpi=DPI)
        written.append(p)
    return written
