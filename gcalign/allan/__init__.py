"""IMU noise from a recording: the overlapping Allan deviation of each gyro and
accelerometer axis (:func:`allan_deviation`, allantools underneath) with its interval from
the number of clusters, and the IEEE Std 952 terms fitted to it (:func:`fit_terms`):
quantization, white noise (ARW/VRW), bias instability (flat part / 0.664) and rate random
walk, each with its τ range and interval. :func:`analyse` does both for a triad pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.allan.curve import AllanCurve, allan_deviation, cluster_sizes
from gcalign.allan.fit import FLAT, TERMS, NoiseFit, TermFit, fit_terms

__all__ = ["FLAT", "TERMS", "AllanCurve", "AllanResult", "NoiseFit", "TermFit",
           "allan_deviation", "analyse", "cluster_sizes", "fit_terms"]


@dataclass(frozen=True)
class AllanResult:
    """Curves and fits of the gyros (rad/s) and the accelerometers (m/s²), and the mean
    rate and specific force of the window (rad/s, m/s²)."""

    gyro: AllanCurve
    accel: AllanCurve
    gyro_fit: NoiseFit
    accel_fit: NoiseFit
    mean_rate: np.ndarray
    mean_force: np.ndarray
    fit_tau: tuple[float, float] | None = None  #: the τ range the terms were fitted on


def analyse(dtheta: np.ndarray, dv: np.ndarray, ts: float, per_decade: int = 10,
            min_clusters: int = 4, fit_tau: tuple[float, float] | None = None
            ) -> AllanResult:
    """Allan deviation and noise terms of increments dtheta, dv (N, 3) sampled every `ts`;
    the terms fitted on the points with τ in `fit_tau` (s) only, if given (a base that sways
    shapes the short τ of a recording; the sensor shows beyond)."""
    g = allan_deviation(dtheta, ts, per_decade, min_clusters)
    a = allan_deviation(dv, ts, per_decade, min_clusters)
    gf, af = (g, a) if fit_tau is None else (g.between(*fit_tau), a.between(*fit_tau))
    return AllanResult(g, a, fit_terms(gf), fit_terms(af), np.mean(dtheta, axis=0) / ts,
                       np.mean(dv, axis=0) / ts, fit_tau)
