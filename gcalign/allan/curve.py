"""The overlapping Allan deviation of IMU increments, with its interval from the number of
clusters.

A triad's increments ``Δ_k`` (angle, rad, or velocity, m/s) over ``(t_k − T, t_k]`` are the
phase of the Allan deviation's vocabulary: their running sum ``x_k = Σ Δ`` is the angle
(velocity) and the rate averaged over a cluster of ``m`` samples (τ = mT) is
``(x_{k+m} − x_k)/τ``. The overlapping Allan variance (IEEE Std 952-1997 eq. C.2, NIST SP
1065 eq. 11) is::

    σ²(τ) = 1 / (2 τ² (N − 2m + 1)) · Σ_k (x_{k+2m} − 2 x_{k+m} + x_k)²

computed by allantools (``oadev``, phase data). Its 1σ interval is that of IEEE Std
952-1997 (C.3) for K = ⌊N/m⌋ independent clusters: ``σ(τ)·(1 ± 1/√(2(K − 1)))``, as PSINS's
``avar`` draws it; for overlapping estimates it is conservative (they have more degrees of
freedom than K − 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.errors import InputError

#: Fewest samples a curve is computed from: four clusters of two samples.
MIN_SAMPLES = 8


@dataclass(frozen=True)
class AllanCurve:
    """Allan deviation of each axis of a triad.

    tau : (M,) s, cluster times m·ts.
    adev : (M, k) Allan deviation of the rate (rad/s or m/s²).
    clusters : (M,) K = ⌊N/m⌋, the number of independent clusters at each τ.
    samples : N, increments used.
    ts : s, sample interval.
    """

    tau: np.ndarray
    adev: np.ndarray
    clusters: np.ndarray
    samples: int
    ts: float

    @property
    def error(self) -> np.ndarray:
        """(M,) relative 1σ error of σ(τ) from the number of clusters, 1/√(2(K − 1))."""
        return 1.0 / np.sqrt(2.0 * (self.clusters - 1.0))

    @property
    def lo(self) -> np.ndarray:
        """(M, k) lower end of the 1σ interval."""
        return self.adev * (1.0 - self.error)[:, None]

    @property
    def hi(self) -> np.ndarray:
        """(M, k) upper end of the 1σ interval."""
        return self.adev * (1.0 + self.error)[:, None]

    def between(self, lo: float, hi: float) -> AllanCurve:
        """The points with lo ≤ τ ≤ hi (InputError when fewer than two)."""
        keep = (self.tau >= lo * (1 - 1e-9)) & (self.tau <= hi * (1 + 1e-9))
        if keep.sum() < 2:
            raise InputError("tau", f"[{lo:g}, {hi:g}] s holds {int(keep.sum())} of the "
                             f"curve's cluster times ({self.tau[0]:g} … {self.tau[-1]:g} s); "
                             "it needs two")
        return AllanCurve(self.tau[keep], self.adev[keep], self.clusters[keep], self.samples,
                          self.ts)

    def at(self, tau: float) -> np.ndarray:
        """(k,) σ at `tau` (s), interpolated log-log between the computed points; NaN
        outside them."""
        lt = np.log(self.tau)
        out = np.full(self.adev.shape[1], np.nan)
        if not lt[0] - 1e-9 <= np.log(tau) <= lt[-1] + 1e-9:
            return out
        for j in range(self.adev.shape[1]):
            out[j] = np.exp(np.interp(np.log(tau), lt, np.log(self.adev[:, j])))
        return out


def cluster_sizes(samples: int, per_decade: int = 10, min_clusters: int = 4) -> np.ndarray:
    """Cluster sizes m (samples per cluster): about `per_decade` log-spaced per decade from 1
    to ⌊samples / min_clusters⌋, without repeats.

    >>> cluster_sizes(1000, 5, 10).tolist()
    [1, 2, 3, 4, 6, 10, 16, 25, 40, 63, 100]
    """
    m_max = samples // min_clusters
    if m_max < 1:
        raise InputError("samples", f"{samples} samples hold fewer than {min_clusters} "
                         "clusters of one sample")
    steps = int(np.floor(np.log10(m_max) * per_decade + 1e-9))
    m = np.round(10.0 ** (np.arange(steps + 1) / per_decade)).astype(np.int64)
    return np.unique(np.clip(m, 1, m_max))


def allan_deviation(increments: np.ndarray, ts: float, per_decade: int = 10,
                    min_clusters: int = 4) -> AllanCurve:
    """Overlapping Allan deviation of each column of `increments` (N, k) sampled every `ts`
    (s): of the rate ``Δ/ts`` (rad/s from angle increments, m/s² from velocity increments).

    τ runs over :func:`cluster_sizes` (`per_decade` points a decade, at least `min_clusters`
    clusters at the longest τ). The constant part of the rate (earth rate, gravity, a bias)
    is removed first: it cannot change σ(τ), and it would cost digits in the running sum.

    >>> rng = np.random.default_rng(1)
    >>> c = allan_deviation(rng.normal(0, 1e-3, (100000, 1)), 0.01, 5)
    >>> round(float(c.at(1.0)[0] * np.sqrt(1.0) / (1e-3 / np.sqrt(0.01))), 1)  # σ(1) = N
    1.0
    """
    import allantools

    x = np.asarray(increments, dtype=float)
    if x.ndim != 2 or x.shape[0] < MIN_SAMPLES:
        raise InputError("increments", f"must have shape (N, k) with N >= {MIN_SAMPLES}, got "
                         f"{x.shape}")
    if not np.isfinite(x).all():
        raise InputError("increments", "must be finite")
    n = x.shape[0]
    m = cluster_sizes(n, per_decade, min_clusters)
    adev = np.empty((len(m), x.shape[1]))
    for j in range(x.shape[1]):
        phase = np.concatenate([[0.0], np.cumsum(x[:, j] - x[:, j].mean())])
        taus, dev, _, _ = allantools.oadev(phase, rate=1.0 / ts, data_type="phase",
                                           taus=m * ts)
        if len(taus) != len(m):  # allantools drops a τ it cannot compute: none of ours
            raise InputError("increments", f"allantools computed {len(taus)} of {len(m)} "
                             "cluster times")
        adev[:, j] = dev
    return AllanCurve(tau=m * ts, adev=adev, clusters=n // m, samples=n, ts=ts)
