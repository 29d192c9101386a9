"""Gaps in a time series of epochs (aiding fixes, a reference solution): the stretches
longer than a largest gap without an epoch, where nothing is measured or compared; an
interpolation across one is not a measurement."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Outage:
    """A stretch of the run without a fix: start, end (s, the run's time base)."""

    start: float
    end: float

    @property
    def length(self) -> float:
        return self.end - self.start


def default_max_gap(t: np.ndarray) -> float:
    """Twice the median interval of the epochs `t`: one missed fix is not an outage, two
    are."""
    t = np.asarray(t, dtype=float)
    return 2.0 * float(np.median(np.diff(t))) if len(t) > 1 else np.inf


def find_outages(t_fix: np.ndarray, t_start: float, t_end: float,
                 max_gap: float) -> tuple[Outage, ...]:
    """The stretches of ``[t_start, t_end]`` longer than `max_gap` (s) without an epoch of
    `t_fix`: between two fixes, before the first one, after the last one (all of the run
    when no fix lies inside it).

    >>> find_outages(np.array([1.0, 2.0, 3.0, 10.0, 11.0]), 0.0, 20.0, 2.0)
    (Outage(start=3.0, end=10.0), Outage(start=11.0, end=20.0))
    """
    t = np.asarray(t_fix, dtype=float)
    t = t[(t >= t_start) & (t <= t_end)]
    edges = np.concatenate([[t_start], t, [t_end]])
    gaps = np.diff(edges)
    return tuple(Outage(float(edges[i]), float(edges[i + 1]))
                 for i in np.flatnonzero(gaps > max_gap))


def inside(t: np.ndarray, outages: tuple[Outage, ...], tol: float = 1e-6) -> np.ndarray:
    """Boolean mask (N,): which times lie inside an outage, more than `tol` (s) from its
    ends (an epoch that ends a gap, computed as ``t0 + k·ts``, is not in it)."""
    t = np.asarray(t, dtype=float)
    mask = np.zeros(t.shape, dtype=bool)
    for o in outages:
        mask |= (t > o.start + tol) & (t < o.end - tol)
    return mask
