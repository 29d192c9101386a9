"""Aiding measured at its own epochs: GNSS fixes, velocities, and the outages between them.

A receiver's fix is a measurement at the time it was taken. The filter propagates the INS
to each fix and updates there; it never interpolates the aiding across time, so a gap in
the file is a stretch without measurements (an outage), not a straight line between the
fixes on either side of it.

:func:`find_outages` lists the stretches of a run longer than `max_gap` without a fix,
including the stretch before the first fix and after the last one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Fixes:
    """Measurements at their epochs (SI, times in the run's time base: that of
    :attr:`gcalign.calibrate.FlightData.t`).

    t : (M,) strictly increasing epochs, s.
    pos : (M, 3) ``[L, λ, h]`` (rad, rad, m), or None. sigma_pos : (M, 3) the fixes' σ
        east, north, up (m), or None (the filter's ``sigma_p`` then).
    v_n : (M, 3) ENU m/s, or None. sigma_v : (M, 3) σ east, north, up (m/s), or None.
    lever_arm_p_b, lever_arm_v_b : (3,) the point each measures (an antenna) from the IMU in
        body axes x right, y forward, z up, m.
    """

    t: np.ndarray
    pos: np.ndarray | None = None
    sigma_pos: np.ndarray | None = None
    v_n: np.ndarray | None = None
    sigma_v: np.ndarray | None = None
    lever_arm_p_b: np.ndarray = field(default_factory=lambda: np.zeros(3))
    lever_arm_v_b: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1 or (len(t) > 1 and not np.all(np.diff(t) > 0)):
            raise ValueError("fixes: t must be (M,) and strictly increasing")
        for name in ("pos", "sigma_pos", "v_n", "sigma_v"):
            a = getattr(self, name)
            if a is not None and np.shape(a) != (len(t), 3):
                raise ValueError(f"fixes: {name} must be ({len(t)}, 3), got {np.shape(a)}")
        for name in ("sigma_pos", "sigma_v"):
            a = getattr(self, name)
            if a is not None and not (np.isfinite(a).all() and (np.asarray(a) > 0).all()):
                raise ValueError(f"fixes: {name} must be finite and > 0")

    def __len__(self) -> int:
        return len(self.t)

    @property
    def median_interval(self) -> float:
        """The median spacing of the epochs (s); inf for fewer than two."""
        return float(np.median(np.diff(self.t))) if len(self.t) > 1 else np.inf


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


def inside(t: np.ndarray, outages: tuple[Outage, ...]) -> np.ndarray:
    """Boolean mask (N,): which times lie strictly inside an outage."""
    t = np.asarray(t, dtype=float)
    mask = np.zeros(t.shape, dtype=bool)
    for o in outages:
        mask |= (t > o.start) & (t < o.end)
    return mask
