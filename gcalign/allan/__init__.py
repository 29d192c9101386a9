"""IMU noise from a recording: the overlapping Allan deviation of each gyro and
accelerometer axis (:func:`allan_deviation`, allantools underneath) with its interval from
the number of clusters, and the IEEE Std 952 terms fitted to it (:func:`fit_terms`):
quantization, white noise (ARW/VRW), bias instability (flat part / 0.664) and rate random
walk, each with its τ range and interval. :func:`analyse` does both for a triad pair.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.allan.curve import AllanCurve, allan_deviation, cluster_sizes
from gcalign.allan.fit import FLAT, TERMS, NoiseFit, TermFit, fit_terms
from gcalign.schema import stored

__all__ = ["FLAT", "TERMS", "AllanCurve", "AllanRecord", "AllanResult", "NoiseFit", "TermFit",
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

    def stored(self) -> AllanRecord:
        """What the results file keeps (``/allan``)."""
        return AllanRecord(self.gyro.samples, self.gyro.ts, None if self.fit_tau is None else
                           np.asarray(self.fit_tau, float),
                           TriadRecord.of(self.gyro, self.gyro_fit, UNITS["gyro"]),
                           TriadRecord.of(self.accel, self.accel_fit, UNITS["accel"]))


AXES = "sensor axes x, y, z"  #: the frame of a triad's values
#: SI units of σ and of each term's coefficient, per triad
UNITS = {
    "gyro": {"sigma": "rad/s", "quantization": "rad", "white": "rad/sqrt(s)",
             "instability": "rad/s", "rate_rw": "rad/s/sqrt(s)"},
    "accel": {"sigma": "m/s^2", "quantization": "m/s", "white": "m/s/sqrt(s)",
              "instability": "m/s^2", "rate_rw": "m/s^2/sqrt(s)"},
}
MEANING = {
    "quantization": "Q: sigma = sqrt(3) Q / tau (quantum q = sqrt(12) Q)",
    "white": "N (ARW/VRW): sigma = N / sqrt(tau)",
    "instability": "B: flat sigma = 0.6643 B (sqrt(2 ln2 / pi))",
    "rate_rw": "K: sigma = K sqrt(tau / 3)",
}
INTERVAL = "1 sigma, 1/sqrt(2(K-1))"


@dataclass(frozen=True)
class TermRecord:
    """One fitted term as the results file keeps it (``terms/<name>``), in `units` (SI;
    not read back: the datasets' units attributes say it)."""

    slope: float = field(metadata=stored("1", attr=True))
    meaning: str = field(metadata=stored(None, attr=True))
    value: np.ndarray = field(metadata=stored("{units}", frame=AXES, what="NaN: not resolved",
                                              dims="3", finite=False))
    interval: np.ndarray = field(metadata=stored(
        "{units}", frame=AXES, what="1 sigma [lo, hi]", dims="3 2", finite=False))
    bound: np.ndarray = field(metadata=stored(
        "{units}", frame=AXES, what="not resolved: the largest coefficient the curve allows; "
        "NaN where resolved", dims="3", finite=False))
    tau_range: np.ndarray = field(metadata=stored("s", frame=AXES, dims="3 2", finite=False))
    units: str = ""


@dataclass(frozen=True)
class TriadRecord:
    """A triad's curve (τ, σ, its 1σ interval, the clusters), the fitted model and each
    term, as the results file keeps them (``gyro``, ``accel``); σ in `units` (SI, as
    :class:`TermRecord`'s)."""

    tau: np.ndarray = field(metadata=stored("s", dims="M", rule="increasing"))
    adev: np.ndarray = field(metadata=stored("{units}", frame=AXES, dims="M 3"))
    adev_lo: np.ndarray = field(metadata=stored("{units}", frame=AXES, what=INTERVAL,
                                                dims="M 3"))
    adev_hi: np.ndarray = field(metadata=stored("{units}", frame=AXES, what=INTERVAL,
                                                dims="M 3"))
    clusters: np.ndarray = field(metadata=stored("", what="K = floor(N/m)", dims="M",
                                                 whole=True))
    model: np.ndarray = field(metadata=stored(
        "{units}", frame=AXES, what="sqrt of the sum of the four fitted terms", dims="M 3"))
    terms: dict[str, TermRecord] = field(metadata=stored(""))
    units: str = ""

    @classmethod
    def of(cls, curve: AllanCurve, fit: NoiseFit, units: dict[str, str]) -> TriadRecord:
        return cls(curve.tau, curve.adev, curve.lo, curve.hi, curve.clusters.astype(np.int64),
                   fit.model(curve.tau), {
                       name: TermRecord(t.slope, MEANING[name], t.value,
                                        np.stack([t.lo, t.hi], axis=1), t.bound, t.tau_range,
                                        units[name]) for name, t in fit.terms.items()},
                   units["sigma"])


@dataclass(frozen=True)
class AllanRecord:
    """``/allan``: the window (samples, interval ts, the τ range of the fit) and each
    triad's :class:`TriadRecord`."""

    samples: int = field(metadata=stored("1", attr=True))
    ts: float = field(metadata=stored("s", attr=True))
    fit_tau_s: np.ndarray | None = field(metadata=stored("s", attr=True))
    gyro: TriadRecord = field(metadata=stored(""))
    accel: TriadRecord = field(metadata=stored(""))


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
