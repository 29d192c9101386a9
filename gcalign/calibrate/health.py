"""Does a calibration run's filter agree with its data? The checks of
:mod:`gcalign.estimation.health` (mean NIS against the band of a mean over its epochs, a σ
growing past :data:`~gcalign.estimation.health.SIGMA_GROWTH` times its start) on a
:class:`~gcalign.calibrate.filter.CalibrationResult`, each failure one line for the run's
warnings.
"""

from __future__ import annotations

import numpy as np

from gcalign.calibrate.filter import CalibrationResult
from gcalign.estimation import health
from gcalign.estimation import ins_error as ie
from gcalign.estimation.health import NIS_LEVEL, SIGMA_GROWTH, mean_nis_band

__all__ = ["NIS_LEVEL", "SIGMA_GROWTH", "health_warnings", "mean_nis_band", "nis_warnings",
           "sigma_growth_warnings"]


def nis_warnings(r: CalibrationResult, label: str = "") -> list[str]:
    """One line if the mean NIS lies outside its band (:func:`mean_nis_band`)."""
    return health.nis_warnings(r.nis, r.standardized.shape[1], label)


def sigma_growth_warnings(r: CalibrationResult, label: str = "") -> list[str]:
    """One line per state whose σ grows past :data:`SIGMA_GROWTH` times its first σ, at the
    epochs with a measurement (in an outage the σ of what the fixes hold grows by design,
    and falls at the next fix)."""
    sigma = r.sigma if r.updated is None else r.sigma[np.r_[True, r.updated[1:]]]
    return health.sigma_growth_warnings(r.sigma[0], sigma, r.names, ie.STATE_UNITS, label)


def health_warnings(r: CalibrationResult, label: str = "") -> list[str]:
    """The checks of this module on one run; `label` heads each line."""
    return nis_warnings(r, label) + sigma_growth_warnings(r, label)
