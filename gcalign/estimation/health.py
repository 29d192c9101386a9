"""Does a Kalman filter agree with its data? Checks on a run's NIS and σ that need no truth,
so that they hold for recorded data too, each failure one line for the run's warnings
(in-flight calibration, :mod:`gcalign.calibrate.health`; transfer alignment).

* The mean NIS over the K update epochs, m measurement components each: for a filter whose
  model fits the data the NIS are independent χ²_m, so their mean is χ²_{K·m} / K, whose
  two-sided 95 % band is the check. Below it the innovations are smaller than the filter
  expects (its R or Q too large, its σ too pessimistic); above it larger (R or Q too
  small, or a motion the model does not follow).
* A state whose σ grows past :data:`SIGMA_GROWTH` times its initial σ: no measurement
  holds it (height under horizontal velocity aiding), so its estimate says nothing.

>>> nis_warnings(np.full(100, 6.0), 6)
[]
>>> nis_warnings(np.full(100, 0.06), 6)[0][:44]
'mean NIS 0.06 over 100 epochs is below its 9'
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

NIS_LEVEL = 0.95  #: two-sided level of the mean-NIS band
SIGMA_GROWTH = 10.0  #: a σ beyond this multiple of its start warns


def mean_nis_band(epochs: int, dof: int, level: float = NIS_LEVEL) -> tuple[float, float]:
    """The two-sided `level` band of the mean of `epochs` independent χ²_`dof` values."""
    from scipy.stats import chi2

    n = epochs * dof
    return (float(chi2.ppf((1 - level) / 2, n)) / epochs,
            float(chi2.ppf((1 + level) / 2, n)) / epochs)


def nis_warnings(nis: np.ndarray, dof: int, label: str = "") -> list[str]:
    """One line if the mean of the NIS (K,), `dof` components each, lies outside its band
    (:func:`mean_nis_band`); `label` heads the line."""
    k = len(nis)
    if k == 0 or dof == 0:
        return []
    lo, hi = mean_nis_band(k, dof)
    mean = float(np.mean(nis))
    if lo <= mean <= hi:
        return []
    side, why = (("below", "the innovations are smaller than the filter expects: its "
                  "measurement or process noise is too large for these data and its σ too "
                  "pessimistic") if mean < lo else
                 ("above", "the innovations are larger than the filter expects: its "
                  "measurement or process noise is too small, or the data do not follow "
                  "its model, and its σ are too optimistic"))
    return [f"{label}mean NIS {mean:.3g} over {k} epochs is {side} its 95 % band "
            f"{lo:.3g}–{hi:.3g} (a mean of {k} χ² of {dof} dof; the innovations "
            f"{np.sqrt(mean / dof):.2g}× the size expected): {why}"]


def sigma_growth_warnings(sigma0: np.ndarray, sigma: np.ndarray, names: Sequence[str],
                          units: Sequence[str], label: str = "") -> list[str]:
    """One line per state whose σ (K, n) grows past :data:`SIGMA_GROWTH` times its start
    `sigma0` (n,); `names`, `units` (n,) name the state and the unit of its σ."""
    s0, peak = np.asarray(sigma0, dtype=float), np.max(sigma, axis=0)
    out = []
    for i in map(int, np.flatnonzero((s0 > 0) & (peak > SIGMA_GROWTH * s0))):
        out.append(f"{label}{names[i]}: σ grew from {s0[i]:.3g} to {peak[i]:.3g} {units[i]} "
                   f"({peak[i] / s0[i]:.0f}×): no measurement holds it, its estimate says "
                   "nothing")
    return out
