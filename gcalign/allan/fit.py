r"""The IEEE Std 952-1997 noise terms fitted to an Allan deviation.

Each term has its slope on the log-log plot and its coefficient (Annex C)::

    σ²(τ) = 3Q²/τ²  +  N²/τ  +  (2 ln2/π) B²  +  K² τ/3
            slope −1   −½       0                +½

* quantization Q (rad, m/s): the increments' quantum q gives Q = q/√12;
* white rate noise N (rad/√s, m/s/√s): angle random walk ARW, velocity random walk VRW,
  read at τ = 1 s;
* bias instability B (rad/s, m/s²): the flat part of σ divided by √(2 ln2/π) = 0.6643
  (:data:`FLAT`), the flicker floor of a bias with PSD B²/(2πf);
* rate random walk K (rad/s/√s, m/s²/√s): a bias that walks, ḃ = w with density K, read at
  τ = 3 s.

How they are fitted. First all four together, by non-negative least squares on σ²(τ) with
the weights of the points' relative 1σ errors (:attr:`~gcalign.allan.curve.AllanCurve.error`),
iterated twice with the model's σ² in the weights (a low point must not weigh more than a
high one). A term's τ range is the longest run of points where it is the largest of the
four, at least half of σ² (:data:`MIN_SHARE`) and more than the 1σ of σ² there (2δ, so
that a fluctuation of a few long clusters is no term): where the log-log plot shows its
slope.
Its value is read on that range alone: each point gives c_i² = (σ_i² − rest_i)/f(τ_i), the
other terms of the whole-curve model taken off (so a term read on a bend, ARW beside the
flicker floor, is not biased by its neighbour, as a line of fixed slope through the points
is), and the value is their mean weighted by 1/h_i².

Its interval: the curve's 1σ from the number of clusters (IEEE Std 952 C.3),
δ_i = 1/√(2(K_i − 1)), plus what the rest taken off is uncertain by (the other terms' shares
s_l times their own relative half-widths h_l; a term in the model but resolved nowhere
counts as unknown to 100 %), over the term's share s_i of σ² at that point (σ² = c²f + rest
gives dc/c = (dσ/σ)/s): h_i = (δ_i + Σ s_l h_l)/s_i, computed twice so that each term
sees the others' widths. The points of a range share their data (overlapping
clusters), so they are not combined as independent: the half-width is the weighted mean of
the h_i, the largest the sd of a mean of correlated estimates can be. Monte Carlo over seeds
(``tests/test_allan_closed_loop.py``) holds the fitted values to these intervals.

A term that is nowhere resolved has no value but an upper bound: the smallest over τ of what
the curve's upper 1σ end allows it (``σ_hi(τ)² / f(τ)``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gcalign.allan.curve import AllanCurve

#: √(2 ln2 / π): σ of flicker noise of coefficient B is FLAT·B (IEEE Std 952 C.1.3)
FLAT = math.sqrt(2.0 * math.log(2.0) / math.pi)

#: A term is resolved where it is the largest and at least this share of σ²
MIN_SHARE = 0.5

#: The terms in order of slope: name, slope of σ(τ), basis f(τ) of σ² = c² f(τ).
TERMS: tuple[tuple[str, float, Callable[[np.ndarray], np.ndarray]], ...] = (
    ("quantization", -1.0, lambda t: 3.0 / t**2),
    ("white", -0.5, lambda t: 1.0 / t),
    ("instability", 0.0, lambda t: np.full_like(t, FLAT**2)),
    ("rate_rw", 0.5, lambda t: t / 3.0),
)


@dataclass(frozen=True)
class TermFit:
    """One term fitted on each axis (SI: Q rad or m/s, N rad/√s or m/s/√s, B rad/s or m/s²,
    K rad/s/√s or m/s²/√s).

    value : (k,) coefficient, NaN where not resolved.
    lo, hi : (k,) its 1σ interval (NaN where not resolved).
    bound : (k,) where not resolved, the largest coefficient the curve allows; NaN where
        resolved.
    tau_range : (k, 2) s, first and last τ of the run of points where the term is the
        largest (NaN where not resolved).
    tau_best : (k,) s, the point of that run where the interval is read (the smallest δ/s,
        see the module docstring).
    """

    name: str
    slope: float
    value: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    bound: np.ndarray
    tau_range: np.ndarray
    tau_best: np.ndarray

    @property
    def resolved(self) -> np.ndarray:
        return np.isfinite(self.value)

    def line(self, tau: np.ndarray, axis: int) -> np.ndarray:
        """σ of this term alone at `tau` on `axis` (its fitted line), NaN if not resolved."""
        f = dict((n, b) for n, _, b in TERMS)[self.name]
        return np.asarray(self.value[axis] * np.sqrt(f(np.asarray(tau, float))))


@dataclass(frozen=True)
class NoiseFit:
    """The four terms of one triad and the coefficients of the whole-curve model."""

    terms: dict[str, TermFit]
    coef: np.ndarray  #: (k, 4) NNLS coefficients c (σ² = Σ c_j² f_j), zero for a term not used
    #: (k,) how far the curve lies from the model, in its own 1σ: the RMS over τ of
    #: ln(σ/σ_model)/δ. About 1 when the four terms describe the noise; far above when
    #: something else shapes σ(τ) (a base that sways, a periodic disturbance, a trend).
    misfit: np.ndarray

    def model(self, tau: np.ndarray) -> np.ndarray:
        """(len(tau), k) σ of the fitted model (all four terms, resolved or not)."""
        tau = np.asarray(tau, float)
        basis = np.stack([b(tau) for _, _, b in TERMS], axis=1)
        return np.sqrt(basis @ (self.coef**2).T)


def _nnls(basis: np.ndarray, var: np.ndarray, w: np.ndarray) -> np.ndarray:
    """c ≥ 0 minimising Σ ((var − basis c)/w)², the columns scaled first."""
    from scipy.optimize import nnls

    scale = np.abs(basis).max(axis=0)
    x, _ = nnls(basis / scale / w[:, None], var / w)
    return x / scale


def fit_terms(curve: AllanCurve) -> NoiseFit:
    """The four terms on each axis of `curve` (see the module docstring)."""
    tau, rel = curve.tau, curve.error
    basis = np.stack([b(tau) for _, _, b in TERMS], axis=1)  # (M, 4)
    k = curve.adev.shape[1]
    nt = len(TERMS)
    coef = np.zeros((k, nt))
    out = {name: {"value": np.full(k, np.nan), "lo": np.full(k, np.nan),
                  "hi": np.full(k, np.nan), "bound": np.full(k, np.nan),
                  "tau_range": np.full((k, 2), np.nan), "tau_best": np.full(k, np.nan)}
           for name, _, _ in TERMS}
    for j in range(k):
        var = curve.adev[:, j] ** 2
        if not (var > 0).any():  # no noise at all (ideal increments): nothing to fit
            for name, _, _ in TERMS:
                out[name]["bound"][j] = 0.0
            continue
        floor = var[var > 0].min()  # a point of exactly zero must not take all the weight
        # σ² of a point has the relative 1σ error 2·rel; weights from the points first,
        # then twice from the model (a point that fell low must not weigh more)
        c2 = _nnls(basis, var, np.maximum(var, floor) * rel)
        for _ in range(2):
            model = basis @ c2
            c2 = _nnls(basis, var, np.maximum(np.where(model > 0, model, var), floor) * rel)
        coef[j] = np.sqrt(c2)
        share = basis * c2 / np.maximum(basis @ c2, np.finfo(float).tiny)[:, None]
        largest = np.argmax(share, axis=1)
        runs: dict[int, tuple[int, int]] = {}
        for t, (name, _, _) in enumerate(TERMS):
            # where it is the largest, half of σ² at least, and more than σ²'s own 1σ
            # (2δ): a fluctuation of a few clusters at long τ is no term
            shows = (largest == t) & (share[:, t] >= np.maximum(MIN_SHARE, 2.0 * rel))
            run = _longest_run(shows)
            if run is None or c2[t] <= 0:
                # what the curve allows: below its upper 1σ end at every τ
                out[name]["bound"][j] = float(np.min(curve.hi[:, j] ** 2
                                                     / basis[:, t])) ** 0.5
            else:
                runs[t] = run
        # twice: the rest taken off a point is known as well as the other terms are (a term
        # in the model but resolved nowhere is taken as unknown to 100 %)
        known = np.where(c2 > 0, 1.0, 0.0)
        known[list(runs)] = 0.0  # first pass: δ/s alone
        for _ in range(2):
            half_of = known.copy()
            for t, (a, b) in runs.items():
                sl = slice(a, b + 1)
                # each point read alone, the other terms of the whole-curve model taken
                # off: c_i² = (σ_i² − rest_i)/f(τ_i); its relative 1σ
                # h_i = (δ_i + Σ_other s_l h_l) / s_i
                rest = basis[sl] @ c2 - basis[sl, t] * c2[t]
                c_i = np.sqrt(np.clip(var[sl] - rest, 0.0, None) / basis[sl, t])
                others = (share[sl] ** 2) @ (known**2) - (share[sl, t] * known[t]) ** 2
                h = np.sqrt(rel[sl] ** 2 + others) / share[sl, t]
                wgt = 1.0 / h**2
                value = float(np.sum(wgt * c_i) / np.sum(wgt))
                # the sd of a mean of correlated estimates is at most the mean of their
                # sd (equal when fully correlated)
                half = float(np.sum(wgt * h) / np.sum(wgt))
                half_of[t] = half
                o = out[TERMS[t][0]]
                if not value > 0:  # the other terms explain the whole range: no term
                    o["bound"][j] = float(np.min(curve.hi[:, j] ** 2 / basis[:, t])) ** 0.5
                    o["value"][j] = o["lo"][j] = o["hi"][j] = o["tau_best"][j] = np.nan
                    o["tau_range"][j] = np.nan
                    half_of[t] = 1.0
                    continue
                o["value"][j], o["bound"][j] = value, np.nan
                o["lo"][j] = value * max(1.0 - half, 0.0)
                o["hi"][j] = value * (1.0 + half)
                o["tau_range"][j] = (tau[a], tau[b])
                o["tau_best"][j] = tau[a + int(np.argmin(h))]
            known = half_of
    terms = {name: TermFit(name=name, slope=slope, **out[name]) for name, slope, _ in TERMS}
    model = np.sqrt(np.maximum(basis @ (coef**2).T, np.finfo(float).tiny))
    with np.errstate(divide="ignore"):
        ratio = np.log(np.maximum(curve.adev, np.finfo(float).tiny) / model)
    misfit = np.where((curve.adev > 0).any(axis=0),
                      np.sqrt(np.mean((ratio / rel[:, None]) ** 2, axis=0)), 0.0)
    return NoiseFit(terms=terms, coef=coef, misfit=misfit)


def _longest_run(mask: np.ndarray) -> tuple[int, int] | None:
    """First and last index of the longest run of True in `mask`, or None."""
    best: tuple[int, int] | None = None
    start = None
    for i, v in enumerate([*mask.tolist(), False]):
        if v and start is None:
            start = i
        elif not v and start is not None:
            if best is None or i - 1 - start > best[1] - best[0]:
                best = (start, i - 1)
            start = None
    return best
