"""North-finding figures (seed 001 figs. 3-5): the azimuth error against the true azimuth,
one subplot per method (mean over repeats, ±1σ band with repeats, the noise-free closed
form where there is one); the difference coordinate − vector."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import angle_scale, finish, new_figure

METHOD_ORDER = ("coordinate", "vector", "naive", "none")
AZIMUTH = "true azimuth (deg, clockwise from north)"


def _methods_in_order(names) -> list[str]:
    names = list(names)
    return [m for m in METHOD_ORDER if m in names] + [m for m in names if m not in METHOD_ORDER]


def northfind_error_figure(azimuth_true: np.ndarray, errors: dict[str, np.ndarray],
                           error_pred: dict[str, np.ndarray] | None = None,
                           title: str = "north-finding error") -> Figure:
    """Azimuth error (deg, arcmin or arcsec per panel) against true azimuth (deg), one
    subplot per method.

    errors : method -> (M,) or (repeats, M) rad. error_pred : method -> (M,) rad (closed
    form, NaN where there is none).
    """
    methods = _methods_in_order(errors)
    az = np.degrees(np.asarray(azimuth_true, float))
    order = np.argsort(az)
    fig, axes = new_figure(len(methods), width=10.0, height=2.2 * len(methods) + 1.0)
    for ax, m in zip(axes, methods, strict=True):
        rad = np.atleast_2d(errors[m])[:, order]
        pred = None if error_pred is None else error_pred.get(m)
        has_pred = pred is not None and bool(np.any(np.isfinite(pred)))
        scale, unit = angle_scale(np.concatenate(
            [rad.ravel(), np.asarray(pred, float).ravel() if has_pred else []]))
        e = rad * scale
        r = e.shape[0]
        mean = e.mean(0)
        ax.plot(az[order], mean, marker="." if az.size < 100 else None, linewidth=1.0,
                label="error" if r == 1 else f"mean of {r} repeats")
        if r > 1:
            sd = e.std(0, ddof=1)
            ax.fill_between(az[order], mean - sd, mean + sd, alpha=0.25, label="±1σ")
        if has_pred:
            ax.plot(az[order], np.asarray(pred)[order] * scale, color="black",
                    linestyle="--", linewidth=0.8, label="closed form (noise-free)")
        ax.set_ylabel(f"{m}\nerror ({unit})")
    axes[-1].set_xlim(0, 360)
    axes[-1].set_xticks(np.arange(0, 361, 45))
    return finish(fig, axes, AZIMUTH, title)


#: Below this the difference of two methods is round-off (arc-seconds).
ROUND_OFF_ARCSEC = 1e-6
#: The size of the difference in seed 001 fig. 5 (1e-4°), as a reference line (arcsec).
SEED_FIG5_ARCSEC = 0.36


def northfind_difference_figure(azimuth_true: np.ndarray, a: np.ndarray, b: np.ndarray,
                                names: tuple[str, str] = ("coordinate", "vector"),
                                title: str = "difference of the two compensation methods"
                                ) -> Figure:
    """Seed 001 fig. 5: estimate difference of two methods (arc-seconds) against true
    azimuth; a, b are errors (M,) or (repeats, M) rad. The axis spans at least the seed's
    ±1e-4° (dashed); a difference below 1e-6″ is round-off and is drawn as zero, its
    largest value in the label (a curve of 1e-10″ noise would read as a finding)."""
    az = np.degrees(np.asarray(azimuth_true, float))
    order = np.argsort(az)
    d = (np.degrees(np.atleast_2d(a) - np.atleast_2d(b)) * 3600.0)[:, order]
    mean = d.mean(0)
    peak = float(np.max(np.abs(d))) if d.size else 0.0
    fig, axes = new_figure(1, height=3.6)
    ax = axes[0]
    what = f"{names[0]} − {names[1]}" + (f" (mean of {d.shape[0]})" if len(d) > 1 else "")
    if peak < ROUND_OFF_ARCSEC:
        ax.plot(az[order], np.zeros_like(mean), linewidth=1.5,
                label=f"{what}: zero to round-off (largest |difference| {peak:.1e}″)")
    else:
        ax.plot(az[order], mean, marker="." if az.size < 100 else None, linewidth=1.0,
                label=what)
    for sign in (1.0, -1.0):
        ax.axhline(sign * SEED_FIG5_ARCSEC, color="0.5", linestyle="--", linewidth=0.8,
                   label="seed fig. 5 size: ±1e-4°" if sign > 0 else "_seed size")
    lim = max(1.25 * peak, 1.5 * SEED_FIG5_ARCSEC)
    ax.set_ylim(-lim, lim)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    return finish(fig, axes, AZIMUTH, title, ["difference (arcsec)"], legend="below", ncols=1)


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of a northfind results file, from its result read back
    (:class:`gcalign.northfind.NorthfindResult`)."""
    from gcalign.io.stored import read_fields
    from gcalign.northfind import NorthfindResult

    figs: dict[str, Figure] = {}
    if "northfind" not in f:
        return figs
    res = read_fields(f["northfind"], NorthfindResult, gyro_residual=None, accel_residual=None)
    errors = {m: res.error(m).T for m in res.methods}
    pred = ({} if res.error_pred is None else dict(zip(res.methods, res.error_pred, strict=True)))
    head = f"{name}: {len(res.azimuth_true)} azimuth(s)"
    figs["northfind_error"] = northfind_error_figure(
        res.azimuth_true, errors, pred, title=f"{head} — azimuth error per method")
    if "coordinate" in errors and "vector" in errors:
        figs["northfind_difference"] = northfind_difference_figure(
            res.azimuth_true, errors["coordinate"], errors["vector"],
            title=f"{head} — coordinate − vector (seed 001 fig. 5)")
    return figs
