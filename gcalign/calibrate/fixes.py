"""Aiding measured at its own epochs: GNSS fixes, velocities, and the outages between them.

A receiver's fix is a measurement at the time it was taken. The filter propagates the INS
to each fix and updates there; it never interpolates the aiding across time, so a gap in
the file is a stretch without measurements (an outage, :func:`gcalign.gaps.find_outages`),
not a straight line between the fixes on either side of it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.gaps import Outage, default_max_gap, find_outages, inside

__all__ = ["Fixes", "Outage", "default_max_gap", "find_outages", "inside"]


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
