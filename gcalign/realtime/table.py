"""Our Table 1 of seed 003 (§3.2): errors before and after prediction, per case.

For each case the reported component is the one the turn moves (heading for the seed's
z turns). Metrics skip ``settle_s``; windows of ±``corner_s`` around the ramp corners (steps
in α) are reported separately (spec 003 §4: the 3-point extrapolation has transients
there). "Before" is the latched attitude's error: its peak for rate and swing cases, its
slope during the acceleration phase for the acceleration cases (seed: "error grows
72″/s"); its peak is kept for every kind. Both metrics (truth, and the seed's INS-later
reference) are given for every predictor. At uniform rate the lag of the INS behind the
table (seed Fig. 4: 4.4 ms) is measured from the error before prediction, ``−e/ω``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from gcalign.nav.earth import WGS84, EarthModel
from gcalign.realtime.cases import TABLE1, Case
from gcalign.realtime.chain import METRICS, SITE, CaseResult, build_chain, run_case
from gcalign.realtime.filters import FilterChain
from gcalign.realtime.settings import Settings

__all__ = ["CaseSummary", "PredictorStats", "RealtimeResult", "run_realtime", "summarise",
           "table1"]


@dataclass(frozen=True)
class PredictorStats:
    """Errors of one predictor on one case (rad): max |e| and rms away from corners, max |e|
    within the corner windows (nan without corners), per metric (``truth``, ``seed``)."""

    max: dict[str, float]
    rms: dict[str, float]
    corner_max: dict[str, float]


@dataclass(frozen=True)
class CaseSummary:
    """One row of our Table 1.

    before : dict metric → float
        rad for rate and swing (peak |error| of ``none``), rad/s for accel (slope).
    before_max : dict metric → float
        Peak |error| of ``none`` (rad), every kind.
    before_theory : dict metric → float
        The closed form (:meth:`Case.before_theory`) with Tdelay = T_chain + Δt (truth) or
        T + Δt (seed): the largest Δt for the peaks (rate, swing), the mean Δt for the
        slope (accel); one value when the pulses sit at a fixed offset.
    stats : dict predictor → PredictorStats
    n_pulses : int
        Pulses evaluated (after the settle time).
    lag : float, s
        Uniform rate: mean lag of the latched attitude behind the truth, ``−mean(e)/ω`` (=
        T_chain + mean Δt); nan for other kinds.
    """

    name: str
    kind: str
    before: dict[str, float]
    before_max: dict[str, float]
    before_theory: dict[str, float]
    stats: dict[str, PredictorStats]
    n_pulses: int
    lag: float = math.nan


def _masks(res: CaseResult) -> tuple[np.ndarray, np.ndarray]:
    s = res.settings
    t = res.pulses.t
    window = t >= s.settle_s
    corner = np.zeros(len(t), dtype=bool)
    for c in res.case.corners():
        corner |= np.abs(t - c) <= s.corner_s
    return window & ~corner, window & corner


def _slope(res: CaseResult, metric: str, keep: np.ndarray) -> float:
    a, b = res.case.accel_window()
    t = res.pulses.t
    sel = keep & (t > a) & (t < b)
    e = res.error("none", metric)[sel, res.component]
    return abs(float(np.polyfit(t[sel], e, 1)[0]))


def summarise(res: CaseResult) -> CaseSummary:
    """Table-1 row of one case result."""
    keep, corner = _masks(res)
    c = res.component
    dt = res.pulses.dt_true[keep]
    dt_peak = float(np.mean(dt) if res.case.kind == "accel" else np.max(dt)) if keep.any() \
        else 0.0
    delays = {"truth": res.chain_delay + dt_peak, "seed": res.delay + dt_peak}
    before, before_max, theory = {}, {}, {}
    for m in METRICS:
        theory[m] = res.case.before_theory(delays[m])
        before_max[m] = float(np.max(np.abs(res.error("none", m)[keep, c])))
        before[m] = _slope(res, m, keep) if res.case.kind == "accel" else before_max[m]
    lag = math.nan
    if res.case.kind == "rate":
        lag = -float(np.mean(res.error("none", "truth")[keep, c])) / res.case.shape.rate
    stats = {}
    for p in res.predicted:
        mx, rms, cm = {}, {}, {}
        for m in METRICS:
            e = res.error(p, m)[:, c]
            mx[m] = float(np.max(np.abs(e[keep])))
            rms[m] = float(np.sqrt(np.mean(e[keep] ** 2)))
            cm[m] = float(np.max(np.abs(e[corner]))) if corner.any() else math.nan
        stats[p] = PredictorStats(max=mx, rms=rms, corner_max=cm)
    return CaseSummary(name=res.case.name, kind=res.case.kind, before=before,
                       before_max=before_max, before_theory=theory, stats=stats,
                       n_pulses=int(keep.sum()), lag=lag)


def table1(settings: Settings, rng: np.random.Generator, cases: Sequence[Case] = TABLE1, *,
           site: Sequence[float] | np.ndarray = SITE, earth: EarthModel = WGS84,
           progress: Callable[[int, int, str], None] | None = None) -> list[CaseResult]:
    """Run the seed's 12 cases (or `cases`) with `settings` at `site`; each case draws from
    its own child generator (``rng.spawn``), so a case's numbers do not depend on the
    others. `progress(done, total, what)`, if given, hears of each case finished."""
    children = rng.spawn(len(cases))
    out = []
    for i, (c, g) in enumerate(zip(cases, children, strict=True)):
        out.append(run_case(c, settings, g, site=site, earth=earth))
        if progress is not None:
            progress(i + 1, len(cases), "cases")
    return out


@dataclass(frozen=True)
class RealtimeResult:
    """A run of :func:`run_realtime` (SI, rad).

    settings : the settings the cases ran with. chain : the filter chain (taps, notch).
    chain_delay : s, the chain's low-frequency group delay (FIR ``N/(2 Fs)`` plus the
    notch's). delay : s, the T the predictors used (``settings.delay_s`` or `chain_delay`).
    cases : per case its pulse records (:class:`~gcalign.realtime.result.CaseResult`).
    rows : per case its row of our Table 1 (:class:`CaseSummary`).
    """

    settings: Settings
    chain: FilterChain
    chain_delay: float
    delay: float
    cases: tuple[CaseResult, ...]
    rows: tuple[CaseSummary, ...]


def run_realtime(settings: Settings, rng: np.random.Generator,
                 cases: Sequence[Case] = TABLE1, *,
                 site: Sequence[float] | np.ndarray = SITE, earth: EarthModel = WGS84,
                 progress: Callable[[int, int, str], None] | None = None) -> RealtimeResult:
    """Every case through the chain (:func:`table1`) and its row of the table
    (:func:`summarise`): the library route of ``gcalign realtime``. `site` is
    ``[lat, lon (rad), h (m)]``; `progress(done, total, what)` hears of each case."""
    chain = build_chain(settings)
    results = table1(settings, rng, cases, site=site, earth=earth, progress=progress)
    delay = chain.delay if settings.delay_s is None else float(settings.delay_s)
    return RealtimeResult(settings=settings, chain=chain, chain_delay=chain.delay, delay=delay,
                          cases=tuple(results), rows=tuple(summarise(r) for r in results))
