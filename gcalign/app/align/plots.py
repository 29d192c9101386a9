"""Alignment figures (seed 000 figs. 7-12): the error of every pass against an *equivalent
time* axis (the passes laid end to end, so a full-cycle run of 290 s of data × 5 passes spans
1450 s), pass boundaries as dotted lines, one subplot per angle (degrees); and the attitude
estimate against the truth on the same axis."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import ANGLES, _s, new_figure
from gcalign.errors import ScenarioError

PASS_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
               "tab:pink", "tab:olive", "tab:cyan")



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


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of an align results file."""
    figs: dict[str, Figure] = {}
    if "align" not in f:
        return figs
    passes = read_passes(f)
    mode = _s(f["align"].attrs.get("mode", ""))
    head = f"{name}: {mode}, {len(passes)} pass(es)"
    has_truth = "truth" in f
    figs["align_attitude"] = align_attitude_figure(
        passes, truth_t=f["truth/t"][()] if has_truth else None,
        truth_att=f["truth/att"][()] if has_truth else None,
        title=f"{head} — attitude estimate vs truth")
    if any(p.error is not None for p in passes):
        figs["align_error"] = align_error_figure(passes, title=f"{head} — attitude error per pass")
    return figs
