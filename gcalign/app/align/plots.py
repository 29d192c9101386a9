"""Alignment figures (seed 000 figs. 7-12) on an *equivalent time* axis (the passes laid end
to end, so a full-cycle run of 290 s of data × 5 passes spans 1450 s), pass boundaries as
dotted lines.

* ``align_error``: the error of every pass, one row per angle, linear axes in the unit the
  values need: all passes on the left (the coarse transient whole), and on the right the
  same curves after the first pass (the second half of a single pass), where the settled
  error can be read;
* ``align_attitude``: the estimate of every pass and, when known, the truth.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from matplotlib.figure import Figure

from gcalign.align.result import PassRows
from gcalign.app.plots import ANGLES, _s, angle_scale, finish, new_figure
from gcalign.errors import ScenarioError

PASS_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
               "tab:pink", "tab:olive", "tab:cyan")
XLABEL = "equivalent time (s): passes laid end to end; dotted lines: pass boundaries"

def _xlabel(passes: list[PassRows], zoom: bool = False) -> str:
    """The time axis: equivalent time for passes laid end to end, the data time for one."""
    if len(passes) == 1:
        return "time (s)"
    return "equivalent time (s)" if zoom else XLABEL


def equivalent_time(passes: list[PassRows]) -> tuple[list[np.ndarray], list[float]]:
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


def _pass_label(p: PassRows) -> str:
    kind = "" if p.kind == "compass" else f" {p.kind} only"
    return f"pass {p.index + 1} {p.direction}{kind} (stage {p.stage})"


def _color(p: PassRows) -> str:
    return PASS_COLORS[p.index % len(PASS_COLORS)]


def _mark_boundaries(ax, bounds, lo: float = -np.inf, hi: float = np.inf) -> None:
    for b in bounds:
        if lo <= b <= hi:
            ax.axvline(b, color="0.45", linestyle=":", linewidth=1.0, label="_pass boundary")


def zoom_of(xs: list[np.ndarray], passes: list[PassRows]) -> tuple[float, str]:
    """Where the zoom starts on the equivalent axis, and what it shows: after the first
    pass, or the second half of a single pass."""
    if len(passes) > 1:
        return float(xs[1][0]), "after pass 1"
    x = xs[0]
    return float(x[len(x) // 2]), "second half of the pass"


def _zoomed(x: np.ndarray, p: PassRows, start: float, n_passes: int) -> np.ndarray:
    """The rows of a pass in the zoom: every pass after the first, or the second half of a
    single pass."""
    if n_passes > 1:
        return np.full(len(x), p.index > 0)
    return x >= start


def align_error_figure(passes: list[PassRows], title: str = "alignment error") -> Figure:
    """Error of every pass against equivalent time: one row per angle; left all passes,
    right the zoom (:func:`zoom_of`); linear axes, deg / arcmin / arcsec per panel."""
    xs_all, bounds = equivalent_time(passes)
    with_err = [(x, p, p.error) for x, p in zip(xs_all, passes, strict=True)
                if p.error is not None]
    if not with_err:
        raise ScenarioError("plot: the file has no alignment errors (no truth: recorded data)")
    start, what = zoom_of(xs_all, passes)
    fig, axes = new_figure(3, 2, width=12.0, height=8.4, sharex="col")
    for j, name in enumerate(ANGLES):
        full, zoom = axes[2 * j], axes[2 * j + 1]
        values = np.concatenate([e[:, j] for _, _, e in with_err])
        scale, unit = angle_scale(values)
        kept = [_zoomed(x, p, start, len(passes)) for x, p, _ in with_err]
        zscale, zunit = angle_scale(np.concatenate(
            [e[k, j] for (_, _, e), k in zip(with_err, kept, strict=True)]))
        for (x, p, err), keep in zip(with_err, kept, strict=True):
            full.plot(x, err[:, j] * scale, color=_color(p), linewidth=1.0,
                      label=_pass_label(p))
            if keep.any():
                zoom.plot(x[keep], err[keep, j] * zscale, color=_color(p), linewidth=1.0,
                          label=_pass_label(p))
        _mark_boundaries(full, bounds)
        _mark_boundaries(zoom, bounds, lo=start)
        full.set_ylabel(f"{name} error ({unit})")
        zoom.set_ylabel(f"{name} error ({zunit})")
        for ax in (full, zoom):
            ax.axhline(0.0, color="0.6", linewidth=0.6, label="_zero")
    axes[0].set_title("all passes", fontsize="medium")
    axes[1].set_title(f"{what} (zoom)", fontsize="medium")
    xlabels = [_xlabel(passes), _xlabel(passes, zoom=True)]
    return finish(fig, axes, xlabels, title, legend="below", ncols=min(3, len(with_err)))


def align_attitude_figure(passes: list[PassRows], truth_t: np.ndarray | None = None,
                          truth_att: np.ndarray | None = None,
                          title: str = "attitude estimate", label: str = "truth") -> Figure:
    """Attitude estimate (deg) of every pass and, if known, the truth (or the reference:
    `label`) at the same data times, against equivalent time; one subplot per angle."""
    xs, bounds = equivalent_time(passes)
    fig, axes = new_figure(3)
    for j, (ax, name) in enumerate(zip(axes, ANGLES, strict=True)):
        for x, p in zip(xs, passes, strict=True):
            y = np.degrees(np.unwrap(p.att[:, j]) if j == 2 else p.att[:, j])
            ax.plot(x, y, color=_color(p), linewidth=1.0, label=_pass_label(p))
        if truth_t is not None and truth_att is not None:
            ref = np.unwrap(truth_att[:, j]) if j == 2 else truth_att[:, j]
            tx = np.concatenate([np.append(x, np.nan) for x in xs])
            ty = np.concatenate([np.append(np.interp(p.t, truth_t, ref), np.nan)
                                 for p in passes])
            ax.plot(tx, np.degrees(ty), color="black", linestyle="--", linewidth=1.0,
                    label=label)
        _mark_boundaries(ax, bounds)
        ax.set_ylabel(f"{name} (deg)")
    return finish(fig, axes, _xlabel(passes), title, legend="below", ncols=min(4, len(passes) + 1))


def read_passes(f) -> list[PassRows]:
    """The passes of ``/align`` read back (:class:`~gcalign.align.result.PassRows`); files
    written before gcalign numbered them from 1 start at ``pass_00`` and stage 0, may lack
    direction and kind, and are renumbered."""
    from gcalign.io.stored import read_fields

    g = f["align"]
    names = sorted(k for k in g if k.startswith("pass_"))
    shift = 1 if "pass_00" in names else 0
    passes = [read_fields(g[n], PassRows, index=int(n[5:]) + shift - 1) for n in names]
    return [replace(p, direction=p.direction or "forward", kind=p.kind or "compass",
                    stage=(1 - shift if p.stage is None else p.stage) + shift)
            for p in passes]


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of an align results file."""
    figs: dict[str, Figure] = {}
    if "align" not in f:
        return figs
    if "transfer" in f["align"]:
        from gcalign.app.align.transfer import figures as transfer_figures
        return transfer_figures(f, name)
    passes = read_passes(f)
    mode = _s(f["align"].attrs.get("mode", ""))
    head = f"{name}: {mode}, {len(passes)} pass(es)"
    against = _s(f["align"].attrs.get("error_source", "truth"))
    has_truth = against in f and any(p.error is not None for p in passes)
    figs["align_attitude"] = align_attitude_figure(
        passes, truth_t=f[f"{against}/t"][()] if has_truth else None,
        truth_att=f[f"{against}/att"][()] if has_truth else None,
        title=f"{head} — attitude estimate" + (
            f" vs {against}" if has_truth else " (recorded data: no truth)"), label=against)
    if has_truth:
        figs["align_error"] = align_error_figure(
            passes, title=f"{head} — attitude error per pass" + (
                "" if against == "truth" else " (against the reference)"))
    return figs
