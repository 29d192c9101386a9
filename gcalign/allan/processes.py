"""The fitted noise terms as a Kalman filter's process models: what the aided-navigation
filter takes per sensor state (:class:`gcalign.estimation.ins_error.SensorProcesses`: a
random constant, a first-order Gauss–Markov process of std σ and correlation time T, or a
random walk of density q) and the white noise densities of its Q.

The mapping, per bias axis:

* bias instability B resolved → one Gauss–Markov process whose Allan deviation peaks at the
  flat level FLAT·B in the middle (geometric) of the τ range where the flicker was fitted:
  a Gauss–Markov process of std σ peaks at :data:`GM_PEAK`·σ at τ = :data:`GM_PEAK_AT`·T
  (1.89 T, IEEE Std 952 C.1.6), so σ = FLAT·B / 0.617 = 1.076 B and T = τ_mid / 1.89. One
  process cannot be flat over decades: it matches the floor where it was seen and falls
  below it (as 1/√τ) at short τ and (as 1/√τ) at long τ — where white noise and the rate
  random walk take over.
* else a rate random walk K resolved → a random walk of density K.
* else a random constant (the filter's P0 says how large).

ARW and VRW go to the filter's white noise (one density per triad in the filter's Q: the
largest resolved axis). Scale factors stay random constants: the Allan deviation of a
static recording does not see them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gcalign.allan.fit import FLAT, NoiseFit


def _gm_peak() -> tuple[float, float]:
    """(max over x of σ_GM(xT)/σ, that x) of a Gauss–Markov process (closed form)."""
    x = np.geomspace(0.5, 5.0, 20001)
    v = 2.0 / x * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x))
    i = int(np.argmax(v))
    return math.sqrt(float(v[i])), float(x[i])


#: Peak of a Gauss–Markov process's Allan deviation over its std, and where (τ/T)
GM_PEAK, GM_PEAK_AT = _gm_peak()


@dataclass(frozen=True)
class FilterModel:
    """Per sensor state in the filter's order (ε x y z, ∇ x y z, δKg x y z, δKa x y z): the
    process kind (``constant``, ``gauss-markov``, ``random-walk``), the Gauss–Markov std and
    correlation time, the random-walk density (SI, NaN where unused); and the white noise
    densities arw (rad/√s) and vrw (m/s/√s), NaN where no axis resolved it."""

    kinds: tuple[str, ...]
    std: np.ndarray
    tau: np.ndarray
    density: np.ndarray
    arw: float
    vrw: float


def filter_model(gyro: NoiseFit, accel: NoiseFit) -> FilterModel:
    """The filter's process models from the fits of both triads (module docstring)."""
    kinds: list[str] = []
    std, tau, dens = (np.full(12, np.nan) for _ in range(3))
    for t, fit in enumerate((gyro, accel)):
        b, k = fit.terms["instability"], fit.terms["rate_rw"]
        for j in range(3):
            i = 3 * t + j
            if np.isfinite(b.value[j]):
                lo, hi = b.tau_range[j]
                kinds.append("gauss-markov")
                std[i] = FLAT * b.value[j] / GM_PEAK
                tau[i] = math.sqrt(lo * hi) / GM_PEAK_AT
            elif np.isfinite(k.value[j]):
                kinds.append("random-walk")
                dens[i] = k.value[j]
            else:
                kinds.append("constant")
    kinds += ["constant"] * 6  # δKg, δKa

    def white(fit: NoiseFit) -> float:
        v = fit.terms["white"].value
        return float(np.nanmax(v)) if np.isfinite(v).any() else math.nan

    return FilterModel(tuple(kinds), std, tau, dens, white(gyro), white(accel))
