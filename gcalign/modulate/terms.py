"""The sensor errors a rotation scheme acts on (seed 004 §4, spec 004 §4): constant in the
sensor frame s, SI.

>>> e = ErrorTerms.seed004()
>>> round(float(e.gyro_bias[0] / DPH), 6), round(float(e.accel_bias[2]), 9)
(0.01, 0.000978049)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gcalign.units import DPH

SEED004_LAT = math.radians(45.7796)  # seed 004 §4: 45.7796°N, 126.6705°E
SEED004_G0 = 9.78049  # seed 004 §4: g0, m/s² (the accelerometer bias is 1e-4·g0)


def _vec(v, shape) -> np.ndarray:
    a = np.array(v, dtype=float)
    if a.shape != shape:
        a = np.broadcast_to(a, shape).copy()
    return a


@dataclass(frozen=True)
class ErrorTerms:
    """Constant sensor errors in the sensor frame and white noise (SI).

    gyro_bias : (3,) rad/s. accel_bias : (3,) m/s².
    gyro_scale : (3,) scale-factor errors δk (fraction).
    gyro_misalignment : (3, 3) small-angle non-orthogonality, zero diagonal; the gyro
        measures ``(I + diag(gyro_scale) + gyro_misalignment) ω + gyro_bias + noise``.
    arw : angle random walk, rad/√s (the same on every axis).
    vrw : velocity random walk, m/s/√s (the same on every axis).
    """

    gyro_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    arw: float = 0.0
    vrw: float = 0.0

    def __post_init__(self):
        for name, shape in (("gyro_bias", (3,)), ("accel_bias", (3,)), ("gyro_scale", (3,)),
                            ("gyro_misalignment", (3, 3))):
            object.__setattr__(self, name, _vec(getattr(self, name), shape))
        if np.any(np.diag(self.gyro_misalignment) != 0):
            raise ValueError("gyro_misalignment must have a zero diagonal (the diagonal is "
                             "gyro_scale)")
        if not (self.arw >= 0 and self.vrw >= 0):
            raise ValueError(f"arw and vrw must be ≥ 0, got {self.arw}, {self.vrw}")

    @property
    def gyro_matrix(self) -> np.ndarray:
        """``diag(gyro_scale) + gyro_misalignment``: the gyro error per unit rate, (3, 3)."""
        return np.diag(self.gyro_scale) + self.gyro_misalignment

    @classmethod
    def seed004(cls, *, gyro: bool = True, accel: bool = True, **kw) -> ErrorTerms:
        """The seed's simulation (seed 004 §4, all axes, positive): gyro drift 0.01 °/h and
        accelerometer bias 1e-4·g0 (g0 = 9.78049 m/s²); `kw` adds other terms."""
        return cls(gyro_bias=np.full(3, 0.01 * DPH if gyro else 0.0),
                   accel_bias=np.full(3, 1e-4 * SEED004_G0 if accel else 0.0), **kw)
