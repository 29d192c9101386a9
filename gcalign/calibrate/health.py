"""Does a calibration run's filter agree with its data? Checks on a
:class:`~gcalign.calibrate.filter.CalibrationResult` that need no truth, so that they hold
for recorded data too, each failure one line for the run's warnings.

* The mean NIS over the K update epochs, m measurement components each: for a filter whose
  model fits the data the NIS are independent χ²_m, so their mean is χ²_{K·m} / K, whose
  two-sided 95 % band is the check. Below it the innovations are smaller than the filter
  expects (its R or Q too large, its σ too pessimistic); above it larger (R or Q too
  small, or a motion the model does not follow).
* A state whose σ grows past :data:`SIGMA_GROWTH` times its initial σ: no measurement
  holds it (height under horizontal velocity aiding), so its estimate says nothing.
"""

from __future__ import annotations

import numpy as np

from gcalign.calibrate.filter import CalibrationResult
from gcalign.estimation import ins_error as ie

NIS_LEVEL = 0.95  #: two-sided level of the mean-NIS band
SIGMA_GROWTH = 10.0  #: a σ beyond this multiple of its start warns


def mean_nis_band(epochs: int, dof: int, level: float = NIS_LEVEL) -> tuple[float, float]:
    """The two-sided `level` band of the mean of `epochs` independent χ²_`dof` values."""
    from scipy.stats import chi2

    n = epochs * dof
    return (float(chi2.ppf((1 - level) / 2, n)) / epochs,
            float(chi2.ppf((1 + level) / 2, n)) / epochs)


def nis_warnings(r: CalibrationResult, label: str = "") -> list[str]:
    """One line if the mean NIS lies outside its band (:func:`mean_nis_band`)."""
    k, m = r.standardized.shape
    if k == 0 or m == 0:
        return []
    lo, hi = mean_nis_band(k, m)
    mean = float(np.mean(r.nis))
    if lo <= mean <= hi:
        return []
    side, why = (("below", "the innovations are smaller than the filter expects: its "
                  "measurement or process noise is too large for these data and its σ too "
                  "pessimistic") if mean < lo else
                 ("above", "the innovations are larger than the filter expects: its "
                  "measurement or process noise is too small, or the data do not follow "
                  "its model, and its σ are too optimistic"))
    return [f"{label}mean NIS {mean:.3g} over {k} epochs is {side} its 95 % band "
            f"{lo:.3g}–{hi:.3g} (a mean of {k} χ² of {m} dof; the innovations "
            f"{np.sqrt(mean / m):.2g}× the size expected): {why}"]


def sigma_growth_warnings(r: CalibrationResult, label: str = "") -> list[str]:
    """One line per state whose σ grows past :data:`SIGMA_GROWTH` times its initial σ."""
    s0, peak = r.sigma[0], r.sigma.max(axis=0)
    out = []
    for i in np.flatnonzero((s0 > 0) & (peak > SIGMA_GROWTH * s0)):
        unit = ie.STATE_UNITS[i]
        out.append(f"{label}{r.names[i]}: σ grew from {s0[i]:.3g} to {peak[i]:.3g} {unit} "
                   f"({peak[i] / s0[i]:.0f}×): no measurement holds it, its estimate says "
                   "nothing")
    return out


def health_warnings(r: CalibrationResult, label: str = "") -> list[str]:
    """The checks of this module on one run; `label` heads each line."""
    return nis_warnings(r, label) + sigma_growth_warnings(r, label)
