"""Real-time attitude figures from a results file (seed 003 Figs. 4–10), NumPy only.

* ``realtime_caseNN`` (seed Figs. 5–10): per case, the error of the turned Euler angle
  against time before prediction, after prediction per predictor on the run's reference,
  and (when that is the seed's INS-later reference) after prediction against the truth;
* ``realtime_filter``: the chain's magnitude (FIR, notch, both) and group delay, with T;
* ``realtime_lag`` (seed Fig. 4): at uniform rate the INS heading against the table's over
  a few tens of milliseconds, and the lag per pulse (T + Δt) of every uniform-rate case.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import ANGLES, _s, finish, new_figure, plain_numbers
from gcalign.io.stored import read_fields
from gcalign.nav.rotation import wrap_pi
from gcalign.realtime.filters import ChainResponse
from gcalign.realtime.result import CaseResult
from gcalign.units import ARCSEC

REFERENCE = {"seed": "against the INS's output T later (the seed's reference)",
             "truth": "against the truth"}


def _limits(ax, values: list[np.ndarray]) -> None:
    """y-limits that hold the scored values (the start-up transient may run off)."""
    v = np.concatenate([np.ravel(x) for x in values]) if values else np.zeros(1)
    v = v[np.isfinite(v)]
    if v.size:
        lo, hi = float(v.min()), float(v.max())
        pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1e-3) * 0.1
        ax.set_ylim(lo - pad, hi + pad)


def case_figure(t: np.ndarray, scored: np.ndarray, before: np.ndarray,
                after: dict[str, np.ndarray], truth_after: dict[str, np.ndarray] | None, *,
                component: str, reference: str, title: str) -> Figure:
    """Errors (″) against time (s): before prediction, after per predictor on `reference`,
    and after per predictor against the truth when `truth_after` is given. The start that
    the metrics skip (where `scored` is false) is shaded; the y-limits hold the rest."""
    rows = 2 + (truth_after is not None)
    fig, axes = new_figure(rows, height=2.3 * rows + 1.0)
    ref = REFERENCE.get(reference, reference)
    panels = [({"latched (no prediction)": before}, f"before prediction, {ref}"),
              (after, f"after prediction, {ref}")]
    if truth_after is not None:
        panels.append((truth_after, "after prediction, against the truth"))
    for i, (ax, (series, what)) in enumerate(zip(axes, panels, strict=True)):
        for name, e in series.items():
            ax.plot(t, e / ARCSEC, linewidth=0.6, label=name)
        _limits(ax, [e[scored] / ARCSEC for e in series.values()])
        plain_numbers(ax)  # −288.01″, not 0.01 and "−2.88e2" at the top of the axis
        ax.set_title(what, fontsize="small", loc="left")
        ax.set_ylabel(f"{component} error (″)")
        if (~scored).any():
            ax.axvspan(t[0], t[~scored][-1], color="0.85",  # said once, in the first legend
                       label="_settling" if i else "settling: not in the metrics")
    return finish(fig, axes, "pulse time (s)", title)


def filter_figure(freq: np.ndarray, magnitude: dict[str, np.ndarray], group_delay: np.ndarray,
                  delay: float, chain_delay: float, title: str) -> Figure:
    """Magnitude (dB) of the chain and its stages, and the chain's group delay (ms) up to
    1 kHz, with the T used and the chain's low-frequency delay."""
    fig, axes = new_figure(2, sharex=False, height=6.0)
    for name, m in magnitude.items():
        axes[0].plot(freq, 20 * np.log10(np.maximum(m, 1e-12)), linewidth=0.9, label=name)
    axes[0].set_ylim(-120, 5)
    axes[0].set_xlim(0, freq[-1])
    axes[0].set_ylabel("magnitude (dB)")
    sel = freq <= 1000.0
    axes[1].plot(freq[sel], group_delay[sel] * 1e3, linewidth=0.9, label="chain group delay")
    axes[1].axhline(delay * 1e3, color="black", linestyle="--", linewidth=0.8,
                    label=f"T used {delay * 1e3:.4f} ms")
    axes[1].axhline(chain_delay * 1e3, color="tab:red", linestyle=":", linewidth=0.8,
                    label=f"chain at 0 Hz {chain_delay * 1e3:.4f} ms")
    lo, hi = chain_delay * 1e3 - 0.2, chain_delay * 1e3 + 0.4
    axes[1].set_ylim(lo, hi)
    axes[1].set_xlim(0, 1000)
    axes[1].set_ylabel("group delay (ms)")
    return finish(fig, axes, ["frequency (Hz)"] * 2, title)


def lag_figure(window: tuple | None,
               lags: dict[str, tuple[np.ndarray, np.ndarray]], chain_delay: float,
               title: str) -> Figure:
    """Seed Fig. 4. Top: table and INS heading (deg) against time over a short window
    (t, table, INS, label). Bottom: lag per pulse (ms) of each uniform-rate case."""
    fig, axes = new_figure(2, sharex=False, height=6.0)
    if window is not None:
        t, table, ins, label = window
        axes[0].plot(t, np.degrees(table), marker=".", linewidth=0.8, label="table (truth)")
        axes[0].plot(t, np.degrees(ins), marker=".", linewidth=0.8, label="INS (latched)")
        axes[0].set_ylabel(f"{label}\nheading (deg)")
        axes[0].set_title(f"the INS lags the table by {lags[label][1].mean() * 1e3:.3f} ms "
                          f"(T + Δt)", fontsize="small", loc="left")
        axes[0].set_xlabel("pulse time (s)")
    for name, (t, lag) in lags.items():
        axes[1].plot(t, lag * 1e3, linewidth=0.8,
                     label=f"{name}: mean {np.mean(lag) * 1e3:.3f} ms")
    axes[1].axhline(chain_delay * 1e3, color="black", linestyle="--", linewidth=0.8,
                    label=f"_chain delay {chain_delay * 1e3:.4f} ms")
    axes[1].set_ylabel("INS lag behind the table (ms)")
    return finish(fig, axes, "pulse time (s)", title)


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of a realtime results file."""
    figs: dict[str, Figure] = {}
    if "realtime" not in f:
        return figs
    g = f["realtime"]
    reference = _s(g.attrs["reference"])
    settle = float(g.attrs.get("settle_s", 0.0))
    lags: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    window: tuple | None = None
    for key in sorted(g["cases"]):
        c = g["cases"][key]
        cname, kind, comp = _s(c.attrs["name"]), _s(c.attrs["kind"]), int(c.attrs["component"])
        # its per-pulse records; what the run knew besides (the case, the settings, the
        # site) is not kept in the file: the case's attributes stand for it
        res = read_fields(c, CaseResult, case=None, settings=None, site=None, earth=None,
                          chain_delay=None, delay=None, t_update=None)
        t, truth, latched = res.pulses.t, res.truth, res.latched
        keep = t >= settle
        predictors = [p for p in res.predicted if p != "none"]
        after = {p: res.error(p, reference)[:, comp] for p in predictors}
        truth_after = ({p: res.error(p)[:, comp] for p in predictors} if reference == "seed"
                       else None)
        figs[f"realtime_case{key}"] = case_figure(
            t, keep, res.error("none", reference)[:, comp], after, truth_after,
            component=ANGLES[comp], reference=reference,
            title=f"{name}: {cname} — error before and after prediction")
        rate = float(c.attrs.get("rate", 0.0))
        if kind == "rate" and rate != 0.0:
            lag = wrap_pi(truth - latched)[keep, comp] / rate
            lags[cname] = (t[keep], lag)
            sync = _s(c.attrs.get("pulses", "")) == "solution"
            if sync and (window is None or abs(rate) > window[4]):
                w = keep & (t >= t[keep][0] + 4.0) & (t < t[keep][0] + 4.03)
                window = (t[w], truth[w, comp], latched[w, comp], cname, abs(rate))
    if "filter" in g:
        fr = read_fields(g["filter"], ChainResponse)
        mags = {"FIR": fr.magnitude_fir}
        if fr.magnitude_notch is not None:
            mags["notch"] = fr.magnitude_notch
        mags["chain"] = fr.magnitude
        figs["realtime_filter"] = filter_figure(
            fr.freq, mags, fr.group_delay, float(g.attrs["delay"]),
            float(g.attrs["chain_delay"]),
            title=f"{name}: filter chain (order {int(fr.order)} FIR"
            + (" after a notch" if fr.notch_b is not None else "") + ")")
    if lags:
        figs["realtime_lag"] = lag_figure(
            None if window is None else window[:4], lags, float(g.attrs["chain_delay"]),
            title=f"{name}: INS heading against the table at uniform rate (seed Fig. 4)")
    return figs
