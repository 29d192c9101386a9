"""The sensor errors a rotation scheme acts on (seed 004 §4, spec 004 §4): constant in the
sensor frame s, SI.

>>> e = ErrorTerms.seed004()
>>> round(float(e.gyro_bias[0] / DPH), 6), round(float(e.accel_bias[2]), 9)
(0.01, 0.000978049)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gcalign.sim.errors import SensorErrors
from gcalign.units import DPH

SEED004_LAT = math.radians(45.7796)  # seed 004 §4: 45.7796°N, 126.6705°E
SEED004_G0 = 9.78049  # seed 004 §4: g0, m/s² (the accelerometer bias is 1e-4·g0)


def _vec(v: object, shape: tuple[int, ...]) -> np.ndarray:
    a = np.array(v, dtype=float)
    if a.shape != shape:
        a = np.broadcast_to(a, shape).copy()
    return a


@dataclass(frozen=True)
class ErrorTerms:
    """Constant sensor errors in the sensor frame and white noise (SI), as
    :mod:`gcalign.sim.errors` applies them to the increments.

    gyro_bias : (3,) rad/s. accel_bias : (3,) m/s².
    gyro_scale : (3,) scale-factor errors δk (fraction).
    gyro_misalignment : (3, 3) small-angle non-orthogonality, zero diagonal; the gyro
        measures ``(I + diag(gyro_scale) + gyro_misalignment) ω + gyro_asym ⊙ |ω| +
        gyro_bias + noise``.
    gyro_asym : (3,) asymmetric scale factor (added for positive input, subtracted for
        negative: ``asym ⊙ |ω|``).
    accel_scale, accel_misalignment, accel_asym : the same for the accelerometers.
    lever : (3,) m, position of the accelerometers from the mechanism's rotation centre,
        sensor frame: they sense ``ω̇ × r + ω × (ω × r)`` from the mechanism's rate ω.
    arw : angle random walk, rad/√s (the same on every axis).
    vrw : velocity random walk, m/s/√s (the same on every axis).
    """

    gyro_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gyro_misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    arw: float = 0.0
    vrw: float = 0.0
    gyro_asym: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    accel_asym: np.ndarray = field(default_factory=lambda: np.zeros(3))
    lever: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        for name, shape in (("gyro_bias", (3,)), ("accel_bias", (3,)), ("gyro_scale", (3,)),
                            ("gyro_misalignment", (3, 3)), ("gyro_asym", (3,)),
                            ("accel_scale", (3,)), ("accel_misalignment", (3, 3)),
                            ("accel_asym", (3,)), ("lever", (3,))):
            object.__setattr__(self, name, _vec(getattr(self, name), shape))
        for name in ("gyro", "accel"):
            if np.any(np.diag(getattr(self, f"{name}_misalignment")) != 0):
                raise ValueError(f"{name}_misalignment must have a zero diagonal (the "
                                 f"diagonal is {name}_scale)")
        if not (self.arw >= 0 and self.vrw >= 0):
            raise ValueError(f"arw and vrw must be ≥ 0, got {self.arw}, {self.vrw}")

    @property
    def gyro_matrix(self) -> np.ndarray:
        """``diag(gyro_scale) + gyro_misalignment``: the gyro error per unit rate, (3, 3)."""
        return np.diag(self.gyro_scale) + self.gyro_misalignment

    @property
    def accel_matrix(self) -> np.ndarray:
        """``diag(accel_scale) + accel_misalignment``, (3, 3)."""
        return np.diag(self.accel_scale) + self.accel_misalignment

    @classmethod
    def of_sensors(cls, gyro: SensorErrors, accel: SensorErrors,
                   lever: Sequence[float] | np.ndarray = (0.0, 0.0, 0.0)) -> ErrorTerms:
        """The terms of the simulation's error model (:class:`gcalign.sim.errors.SensorErrors`,
        SI). Noise densities that differ between axes enter as their RMS (the model's noise
        is isotropic); quantisation is left out."""
        def rms(v: np.ndarray) -> float:
            return float(np.sqrt(np.mean(np.square(v))))

        return cls(gyro_bias=gyro.bias, accel_bias=accel.bias, gyro_scale=gyro.scale,
                   gyro_misalignment=gyro.misalignment, arw=rms(gyro.noise),
                   vrw=rms(accel.noise), gyro_asym=gyro.asym, accel_scale=accel.scale,
                   accel_misalignment=accel.misalignment, accel_asym=accel.asym,
                   lever=np.asarray(lever, dtype=float))

    @classmethod
    def seed004(cls, *, gyro: bool = True, accel: bool = True, **kw: Any) -> ErrorTerms:
        """The seed's simulation (seed 004 §4, all axes, positive): gyro drift 0.01 °/h and
        accelerometer bias 1e-4·g0 (g0 = 9.78049 m/s²); `kw` adds other terms."""
        return cls(gyro_bias=np.full(3, 0.01 * DPH if gyro else 0.0),
                   accel_bias=np.full(3, 1e-4 * SEED004_G0 if accel else 0.0), **kw)
