"""Calibration figures (seed 002 Figs. 1–3 and the filter's own checks).

* ``trajectory`` -- ground track and height of the flight, segments numbered (Fig. 1);
* ``sensor_biases`` -- ε (°/h) and ∇ (µg) estimates against time with ±3σ envelopes and
  the truth (Fig. 2; with ``--compare``: velocity, position and both on the designed
  flight, in the paper's styles: red dashed v+p, cyan v, purple dash-dot p);
* ``scale_factors`` -- δKg, δKa (ppm) likewise (Fig. 3);
* ``sigma`` -- σ/σ0 of the twelve sensor errors, log scale where a panel spans decades;
* ``navigation_errors`` -- φ, δv of the corrected INS (estimate − truth) with ±3σ;
* ``innovations`` -- standardized innovations with ±3, NEES with its χ²₂₁ band, NIS;
* ``attitude`` -- recorded data (no truth): the INS attitude with ±3σ of φ;
* ``solution_errors`` -- the solution at every navigation sample against the truth or the
  reference (position, velocity, attitude) with the filter's ±3σ, the smoothed solution at
  the filter epochs, and the outages of the aiding shaded.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import _s, finish, legend_right, new_figure, plain_numbers, suptitle
from gcalign.app.report import UNIT_TEXT
from gcalign.estimation.calibration import CalibrationResult, Errors, Spans
from gcalign.units import ANGLE_UNITS, angle_unit

STYLE: dict[str, dict[str, Any]] = {"both": dict(color="tab:red", linestyle="--"),
                                    "velocity": dict(color="tab:cyan", linestyle="-"),
                                    "position": dict(color="tab:purple", linestyle="-.")}
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class ShownRun:
    """A run of a calibrate file as its figures draw it: the filter's result read back by
    the generic reader (:class:`~gcalign.estimation.calibration.CalibrationResult`), and
    what the command keeps beside its fields: its label and measurement, and the errors
    of the solution at every navigation sample (``navigation``; ``t0``: the run's start in
    the file's time), of the smoothed solution and against a reference (each None where the
    file has none)."""

    result: CalibrationResult
    label: str
    measure: str
    navigation: Errors | None
    smoothed: Errors | None
    reference_error: Errors | None
    t0: float


def read_runs(f) -> tuple[list[ShownRun], dict]:
    """The runs of a calibrate file (arrays SI) and the group's attributes, with its
    ``segments`` (:class:`~gcalign.estimation.calibration.Spans`) and ``outages``."""
    from gcalign.io.stored import read_fields

    g = f["calibrate"]
    attrs = {k: (_s(v) if isinstance(v, (bytes, str)) else v) for k, v in g.attrs.items()}
    runs = []
    for key in sorted(g["runs"]):
        r = g["runs"][key]
        nav = r.get("navigation")
        on_rows, smoothed, against = (None if x is None else read_fields(x, Errors) for x in (
            None if nav is None else nav.get("error"), r.get("smoothed/error"),
            r.get("reference_error")))
        run = read_fields(r, CalibrationResult, innovation=None, nis=r["nis"][()],
                          settings=None)
        if run.updated is not None and int(run.updated.sum()) != len(run.nis):
            from gcalign.errors import ScenarioError

            raise ScenarioError(f"{f.filename}: dataset {r.name}/updated marks "
                                f"{int(run.updated.sum())} epochs with a fix, {r.name}/nis "
                                f"has {len(run.nis)}: one per fix")
        runs.append(ShownRun(run, _s(r.attrs.get("label", "")), _s(r.attrs["measure"]),
                             on_rows, smoothed, against, float(nav["t"][0] - nav["t_run"][0])
                             if nav is not None and len(nav["t"]) else 0.0))
    attrs["segments"] = read_fields(g["segments"], Spans)
    o = g.get("outages")
    attrs["outages"] = [] if o is None else list(zip(o["start"][()].tolist(),
                                                     o["end"][()].tolist(), strict=True))
    return runs, attrs


def shade_outages(ax, outages, minutes: bool) -> None:
    """Grey bands over the outages of the aiding (run time, s)."""
    k = 60.0 if minutes else 1.0
    for i, (a, b) in enumerate(outages):
        ax.axvspan(a / k, b / k, color="0.5", alpha=0.18, linewidth=0,
                   label="outage (no fix)" if i == 0 else "_outage")


def _time_axis(t: np.ndarray) -> tuple[np.ndarray, str]:
    return (t / 60.0, "time (min)") if t[-1] - t[0] > 1200 else (t, "time (s)")


def _segment_lines(ax, segments: Spans, minutes: bool) -> None:
    for a in segments.t0[1:]:
        ax.axvline(a / 60.0 if minutes else a, color="0.85", linewidth=0.6, zorder=0,
                   label="_segment")


def _ylim(est, sig, truth, t) -> float:
    """Half-height that shows the second half of the run's estimate ± 3σ and the truth."""
    half = t >= t[0] + 0.5 * (t[-1] - t[0])
    lim = float(np.max(np.abs(est[half]) + 3 * sig[half]))
    if truth is not None:
        lim = max(lim, float(np.max(np.abs(truth))) * 1.2)
    return 1.15 * lim if lim > 0 else 1.0


AIDED = {"velocity": "velocity", "position": "position", "both": "velocity and position"}
UNIT_WORD = {"arcsec": "arcsec", "arcmin": "arcmin"}  # readable as a label, unlike ″ and ′


def _panel(ax, name: str, unit: str, lim: float) -> None:
    ax.set_ylim(-lim, lim)
    ax.set_title(name, fontsize="medium")
    ax.set_ylabel(UNIT_WORD.get(unit) or UNIT_TEXT.get(unit, unit))


def _display(attrs: dict) -> tuple[list[str], list[str], np.ndarray]:
    """The file's state names, their display units and the factors from SI to them."""
    return (attrs["states"].split(","), attrs["display_units"].split(","),
            np.asarray(attrs["display_scale"]))


def estimates_figure(runs: list[ShownRun], attrs, states: list[str], title: str) -> Figure:
    """Estimates of `states` (2 rows × 3 axes) against time with ±3σ and the truth."""
    names, units, scale = _display(attrs)
    fig, axes = new_figure(2, 3, width=12.0, height=6.0)
    for ax, name in zip(axes, states, strict=True):
        i = names.index(name)
        k = scale[i]
        lim = 0.0
        for r in runs:
            tx, xlabel = _time_axis(r.result.t)
            minutes = xlabel.endswith("(min)")
            est, sig = r.result.estimate[:, i] * k, r.result.sigma[:, i] * k
            style = STYLE[r.measure] if len(runs) > 1 else {"color": "tab:blue",
                                                              "linestyle": "-"}
            lab = r.measure if len(runs) > 1 else "estimate"
            ax.plot(tx, est, linewidth=1.1, label=lab, **style)
            if len(runs) == 1:
                ax.fill_between(tx, est - 3 * sig, est + 3 * sig, color=style["color"],
                                alpha=0.18, linewidth=0, label="±3σ")
            else:  # envelopes as thin lines in the run's colour and style
                for sign in (1, -1):
                    ax.plot(tx, est + sign * 3 * sig, linewidth=0.7, alpha=0.7,
                            label="_3s", **style)
            truth = None if r.result.truth is None else r.result.truth[:, i] * k
            lim = max(lim, _ylim(est, sig, truth, r.result.t))
        if runs[0].result.truth is not None:
            ax.axhline(runs[0].result.truth[0, i] * k, color="black", linewidth=0.9,
                       linestyle=(0, (4, 2)), label="truth")
        _segment_lines(ax, attrs["segments"], minutes)
        _panel(ax, name, units[i], lim)
    return finish(fig, axes, [xlabel] * 3, title, legend="below")


def sigma_figure(runs: list[ShownRun], attrs, title: str) -> Figure:
    """σ/σ0 of the twelve sensor errors against time (log scale), one panel per group."""
    names = attrs["states"].split(",")
    fig, axes = new_figure(2, 2, width=11.0, height=6.5)
    groups = (("gyro bias ε", "eb"), ("accelerometer bias ∇", "db"),
              ("gyro scale factor δKg", "dKg"), ("accelerometer scale factor δKa", "dKa"))
    colors = ("tab:blue", "tab:orange", "tab:green")
    for ax, (label, stem) in zip(axes, groups, strict=True):
        ratio = [r.result.sigma[:, names.index(stem + a)]
                 / r.result.sigma[0, names.index(stem + a)] for r in runs for a in AXES]
        # a group that learnt (almost) nothing, e.g. scale factors held at a 1 ppm prior:
        # σ/σ0 would read 1.000000 on every tick; draw what was learnt, 1 − σ/σ0
        held = min(float(np.min(x)) for x in ratio) > 0.99
        for r in runs:
            tx, xlabel = _time_axis(r.result.t)
            ls = STYLE[r.measure]["linestyle"] if len(runs) > 1 else "-"
            for c, axis in zip(colors, AXES, strict=True):
                i = names.index(stem + axis)
                y = r.result.sigma[:, i] / r.result.sigma[0, i]
                ax.semilogy(tx, np.maximum(1.0 - y, 1e-16) if held else y, color=c,
                            linestyle=ls, linewidth=1.0,
                            label=f"{axis}" + (f" {r.measure}" if len(runs) > 1 else ""))
        _segment_lines(ax, attrs["segments"], xlabel.endswith("(min)"))
        ax.set_title(label + (" — σ within 1 % of P0" if held else ""), fontsize="medium")
        ax.set_ylabel("1 − σ / σ0" if held else "σ / σ0")
        if not held:
            _plain_log_ticks(ax)
        ax.grid(True, which="minor", alpha=0.3)  # of the log scale (the major: finish)
    return finish(fig, axes, [xlabel] * 2, title)


def _plain_log_ticks(ax) -> None:
    """A log axis spanning less than a decade labels its minor ticks, and matplotlib's
    scientific labels then round them alike ("10 × 10⁻¹" on every tick; a scale factor held
    at its 1 ppm prior spans 0.9996–1): such a panel is drawn linear, with plain numbers."""
    lo, hi = ax.get_ylim()
    if lo > 0 and hi / lo < 10:
        ax.set_yscale("linear")
        plain_numbers(ax)


def navigation_figure(run: CalibrationResult, attrs, title: str) -> Figure:
    """φ and δv of the corrected INS solution (estimate − truth: what the closed loop
    leaves; feed-forward: the error of the estimate) with the filter's ±3σ."""
    names, units, scale = _display(attrs)
    assert run.truth is not None  # drawn only with truth
    fig, axes = new_figure(2, 3, width=12.0, height=6.0)
    tx, xlabel = _time_axis(run.t)
    for ax, name in zip(axes, names[:6], strict=True):
        i = names.index(name)
        k = scale[i]
        err = (run.estimate[:, i] - run.truth[:, i]) * k
        sig = run.sigma[:, i] * k
        ax.fill_between(tx, -3 * sig, 3 * sig, color="tab:blue", alpha=0.18, linewidth=0,
                        label="±3σ")
        ax.plot(tx, err, color="black", linewidth=0.8, label="error")
        _panel(ax, name, units[i], _ylim(err, sig, None, run.t))
    return finish(fig, axes, [xlabel] * 3, title, legend="below")


def innovations_figure(run: CalibrationResult, title: str, outages=()) -> Figure:
    """Standardized innovations (each ~ N(0, 1)) with ±3, NEES with the χ²₂₁ 95 % band, NIS."""
    from scipy.stats import chi2

    has_nees = run.nees is not None
    fig, axes = new_figure(3 if has_nees else 2, height=7.5 if has_nees else 5.5)
    t = run.t
    tx, xlabel = _time_axis(t)
    z = run.standardized
    tu = _time_axis(np.concatenate([t[:1], run.update_t]))[0][1:]  # the epochs with a fix
    for j, name in enumerate(run.measure_names):
        axes[0].plot(tu, z[:, j], ".", markersize=2, label=name)
    for y in (-3, 3):
        axes[0].axhline(y, color="black", linewidth=0.7, linestyle="--", label="_3")
    axes[0].set_ylabel("standardized\ninnovation")
    m = z.shape[1]
    lo, hi = chi2.ppf([0.025, 0.975], m)
    axes[1].semilogy(tu, np.maximum(run.nis, 1e-6), ".", markersize=2, label="NIS")
    for ax in axes:
        shade_outages(ax, outages, xlabel.endswith("(min)"))
    axes[1].axhspan(lo, hi, color="tab:green", alpha=0.15, label=f"χ²({m}) 95 %")
    axes[1].set_ylabel("NIS")
    if run.nees is not None:
        lo, hi = chi2.ppf([0.025, 0.975], 21)
        axes[2].plot(tx, run.nees, linewidth=0.9, label="NEES")
        axes[2].axhspan(lo, hi, color="tab:green", alpha=0.15,
                        label="χ²(21) 95 % (truth drawn from P0)")
        axes[2].set_ylabel("NEES")
    return finish(fig, axes, xlabel, title)


def attitude_figure(run: CalibrationResult, title: str) -> Figure:
    """Recorded data: the corrected INS attitude (deg) with ±3σ of the misalignment."""
    fig, axes = new_figure(3, height=7.0)
    tx, xlabel = _time_axis(run.t)
    sig = run.sigma[:, :3]
    # ±3σ of φ as an attitude band: φE, φN for pitch and roll (small angles), φU for yaw
    for ax, j, name, s in zip(axes, range(3), ("pitch", "roll", "yaw"),
                              (sig[:, 0], sig[:, 1], sig[:, 2]), strict=True):
        a = np.degrees(run.att[:, j])
        ax.plot(tx, a, color="tab:blue", linewidth=1.0, label=name)
        ax.fill_between(tx, a - 3 * np.degrees(s), a + 3 * np.degrees(s), color="tab:blue",
                        alpha=0.15, label="±3σ")
        # the whole curve and, where it is narrow enough to read, its band: the ±3σ of the
        # first epochs (P0: tens of degrees in yaw) would flatten the curve
        half = run.t >= run.t[0] + 0.5 * (run.t[-1] - run.t[0])
        band = float(np.max(3 * np.degrees(s[half])))
        lo, hi = float(np.min(a)) - band, float(np.max(a)) + band
        pad = 0.05 * (hi - lo) if hi > lo else 0.5
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_ylabel(f"{name} (deg)")
    return finish(fig, axes, xlabel, title)


def reference_figure(e: Errors, title: str) -> Figure:
    """Attitude (in the unit its size needs), velocity and position of the INS solution
    minus the reference, per component, against time."""
    fig, axes = new_figure(3, 1, width=10.0, height=8.0)
    tx, xlabel = _time_axis(e.t)
    unit = angle_unit(float(np.max(np.abs(e.att))))
    rows = ((e.att / ANGLE_UNITS[unit][0], ("pitch", "roll", "yaw")),
            (e.v_n, ("E", "N", "U")), (e.pos, ("E", "N", "U")))
    for ax, (values, names) in zip(axes, rows, strict=True):
        for j, n in enumerate(names):
            ax.plot(tx, values[:, j], linewidth=0.9, label=n)
    return finish(fig, axes, xlabel, title, [f"attitude ({unit})", "velocity (m/s)",
                                              "position (m)"])


def solution_figure(run: ShownRun, attrs, title: str) -> Figure:
    """The solution at every navigation sample minus the truth or the reference: position
    and velocity east, north, up and the attitude, with the filter's ±3σ at its epochs (φ
    for the attitude), the smoothed solution at the epochs where there is one, and the
    outages shaded."""
    e = run.navigation
    assert e is not None  # drawn only where the file holds it
    scale = np.asarray(attrs["display_scale"])
    tx, xlabel = _time_axis(e.t - run.t0)
    minutes = xlabel.endswith("(min)")
    te = _time_axis(run.result.t)[0] if not minutes else run.result.t / 60.0
    unit = angle_unit(float(np.max(np.abs(e.att))))
    k_att = 1.0 / ANGLE_UNITS[unit][0]
    fig, axes = new_figure(3, 3, width=13.0, height=8.5, sharex=True)
    sig_pos = run.result.sigma[:, [7, 6, 8]] * scale[[7, 6, 8]]  # east, north, up in metres
    sig_v = run.result.sigma[:, 3:6]
    sig_att = run.result.sigma[:, 0:3] * k_att
    rows = (("position", e.pos, sig_pos, ("east", "north", "up"), "m"),
            ("velocity", e.v_n, sig_v, ("east", "north", "up"), "m/s"),
            ("attitude", e.att * k_att, sig_att, ("pitch", "roll", "yaw"),
             UNIT_WORD.get(unit, unit)))
    sm = run.smoothed
    smoothed = None if sm is None else (sm.t / 60.0 if minutes else sm.t,
                                        (sm.pos, sm.v_n, sm.att * k_att))
    for r, (what, err, sig, labels, u) in enumerate(rows):
        for c in range(3):
            ax = axes[3 * r + c]
            ax.plot(tx, err[:, c], color="black", linewidth=0.6, label="forward filter")
            ax.fill_between(te, -3 * sig[:, c], 3 * sig[:, c], step="post", color="tab:blue",
                            alpha=0.15, linewidth=0, label="±3σ (filter)")
            if smoothed is not None:
                ts, sm_rows = smoothed
                ax.plot(ts, sm_rows[r][:, c], color="tab:red", linewidth=1.0,
                        label="smoothed (filter epochs)")
            shade_outages(ax, attrs["outages"], minutes)
            half = np.abs(err[:, c])
            lim = 1.2 * float(max(np.percentile(half, 99.5), 3 * np.median(sig[:, c])))
            ax.set_ylim(-lim, lim)
            ax.set_title(f"{what} {labels[c]}", fontsize="medium")
            if c == 0:
                ax.set_ylabel(u)
    return finish(fig, axes, [xlabel] * 3, title, legend="below")


def enu_track(pos: np.ndarray) -> np.ndarray:
    """East, north, up (m) from the first point: angles times the radii at the start
    latitude and each point's own height (the horizontal distance flown at altitude, as
    the flight's envelope measures it; WGS-84)."""
    from gcalign.nav.earth import WGS84

    r_m, r_n = WGS84.radii(pos[0, 0])
    h = pos[:, 2]
    return np.stack([(pos[:, 1] - pos[0, 1]) * (r_n + h) * np.cos(pos[0, 0]),
                     (pos[:, 0] - pos[0, 0]) * (r_m + h), h - pos[0, 2]], -1)


def trajectory_figure(t, pos, segment, names, title: str) -> Figure:
    """Seed 002 Fig. 1: ground track (km) and height (km) against time, segments numbered
    (the numbers refer to the list on the right)."""
    enu = enu_track(pos) / 1000.0
    fig = Figure(figsize=(13.0, 5.2), dpi=120, layout="constrained")
    ax_track, ax_h = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.0, 1.3]})
    seg = np.asarray(segment)
    colors = [f"C{i % 10}" for i in range(len(names))]
    for i in range(len(names)):
        m = seg == i
        idx = np.flatnonzero(m)
        if idx.size == 0:
            continue
        lo, hi = idx[0], min(idx[-1] + 2, len(t))
        ax_track.plot(enu[lo:hi, 0], enu[lo:hi, 1], color=colors[i], linewidth=1.5)
        ax_h.plot(t[lo:hi], enu[lo:hi, 2], color=colors[i], linewidth=1.5)
        ax_track.annotate(str(i + 1), enu[lo, :2], fontsize=7, color=colors[i],
                          xytext=(3, 3), textcoords="offset points")
        ax_h.annotate(str(i + 1), (t[lo], enu[lo, 2]), fontsize=7, color=colors[i],
                      xytext=(2, 4), textcoords="offset points")
    ax_track.plot(*enu[0, :2], "k^", label="start")
    ax_track.set_aspect("equal", adjustable="datalim")
    ax_track.set_xlabel("east (km)")
    ax_track.set_ylabel("north (km)")
    legend_right(ax_track)
    ax_h.set_xlabel("time (s)")
    ax_h.set_ylabel("height above the start (km)")
    for ax in (ax_track, ax_h):
        ax.grid(True, alpha=0.3)
    far = float(np.hypot(enu[:, 0], enu[:, 1]).max())
    ax_h.set_title(f"highest {enu[:, 2].max():.3f} km above the start, farthest {far:.2f} km "
                   "from it",
                   fontsize="medium")
    listing = "\n".join(f"{i + 1:2d} {n}" for i, n in enumerate(names))
    ax_h.text(1.02, 1.0, listing, transform=ax_h.transAxes, va="top", ha="left",
              fontsize=7, family="monospace")
    suptitle(fig, title)
    return fig


def truth_trajectory(f, name: str) -> dict[str, Figure]:
    """The trajectory figure of any results file with /truth and a segment list."""
    if "truth" not in f or "segment" not in f["truth"]:
        return {}
    g = f["truth"]
    names = [_s(n) for n in g["segment_names"][()]] if "segment_names" in g else []
    seg = g["segment"][()]
    if not names:
        names = [f"segment {i + 1}" for i in range(int(seg.max()) + 1)]
    return {"trajectory": trajectory_figure(g["t"][()], g["pos"][()], seg, names,
                                            f"{name}: trajectory")}


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of a calibrate results file."""
    figs = truth_trajectory(f, name)
    if "calibrate" not in f:
        return figs
    runs, attrs = read_runs(f)
    shown = [r for r in runs if r.label in ("", "designed")]
    what = ("designed flight, velocity / position / both" if len(shown) > 1
            else f"{shown[0].measure} matching")
    figs["sensor_biases"] = estimates_figure(
        shown, attrs, ["ebx", "eby", "ebz", "dbx", "dby", "dbz"],
        f"{name}: gyro biases ε and accelerometer biases ∇, estimate ±3σ ({what})")
    figs["scale_factors"] = estimates_figure(
        shown, attrs, ["dKgx", "dKgy", "dKgz", "dKax", "dKay", "dKaz"],
        f"{name}: gyro and accelerometer scale factors, estimate ±3σ ({what})")
    figs["sigma"] = sigma_figure(shown, attrs, f"{name}: σ of the sensor errors relative to P0 "
                                               f"({what})")
    first = shown[0]
    aiding, aided = attrs.get("aiding", ""), AIDED.get(first.measure, first.measure)
    how = ("zero-velocity updates" if aiding == "zero-velocity" else
           f"{aided} from a file" if aiding == "file" else f"{aided} aiding")
    if first.result.truth is not None:
        figs["navigation_errors"] = navigation_figure(
            first.result, attrs, f"{name}: misalignment φ and velocity error of the corrected "
            f"INS (estimate − truth) with ±3σ ({first.measure})")
    else:
        figs["attitude"] = attitude_figure(first.result, f"{name}: INS attitude with ±3σ ({how})")
    if first.reference_error is not None:
        figs["reference_errors"] = reference_figure(
            first.reference_error, f"{name}: INS solution against the reference "
            f"(est − reference; {AIDED[first.measure]} aiding)")
    figs["innovations"] = innovations_figure(
        first.result, f"{name}: standardized innovations, NIS"
        + (" and NEES" if first.result.nees is not None else "") + f" ({how})", attrs["outages"])
    if first.navigation is not None and len(first.navigation.t):
        against = "truth" if first.result.truth is not None else "reference"
        figs["solution_errors"] = solution_figure(
            first, attrs, f"{name}: solution − {against} at every navigation sample "
            f"({AIDED[first.measure]} aiding)")
    return figs
