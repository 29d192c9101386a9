"""Sensor-error keys shared by the ``imu`` section (what the simulator draws) and the
filter's ``calibrate.q`` (what the filter models): per-axis values and first-order
Gauss–Markov processes, in the units their names carry."""

from __future__ import annotations

from typing import Annotated

import numpy as np
from pydantic import BeforeValidator, Field

from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model, NonNegVec3, PerAxis, is_number


def _broadcast_scalar(x):
    if is_number(x):
        if x < 0:
            raise ValueError(f"must be ≥ 0 (one number, or one per axis), got {x}")
        return [x, x, x]
    return x


# A noise density: one number for all three axes, or one per axis.
Noise = Annotated[NonNegVec3, BeforeValidator(_broadcast_scalar)]
Tau = Annotated[PerAxis, B.CORRELATION_TIME_S]


def per_axis(x) -> np.ndarray:
    """(3,) floats of a per-axis key."""
    return np.broadcast_to(np.asarray(x, dtype=float), (3,)).copy()


class GyroGaussMarkov(Model):
    """A first-order Gauss–Markov gyro bias: stationary std and correlation time."""

    std_dph: Annotated[Noise, B.GYRO_BIAS_DPH] = Field(description="stationary std, °/h")
    tau_s: Tau = Field(description="correlation time, s")


class AccelGaussMarkov(Model):
    """A first-order Gauss–Markov accelerometer bias: stationary std and correlation time."""

    std_ug: Annotated[Noise, B.ACCEL_BIAS_UG] = Field(description="stationary std, µg")
    tau_s: Tau = Field(description="correlation time, s")


class ScaleGaussMarkov(Model):
    """A first-order Gauss–Markov scale-factor error: stationary std and correlation time."""

    std_ppm: Annotated[Noise, B.SCALE_PPM] = Field(description="stationary std, ppm")
    tau_s: Tau = Field(description="correlation time, s")


def gauss_markov_si(gm: GyroGaussMarkov | AccelGaussMarkov | ScaleGaussMarkov | None,
                    unit: float) -> tuple[np.ndarray, np.ndarray]:
    """(std (3,) SI, τ (3,) s) of a Gauss–Markov key, or (zeros, inf) without one."""
    if gm is None:
        return np.zeros(3), np.full(3, np.inf)
    std = gm.std_dph if isinstance(gm, GyroGaussMarkov) else (
        gm.std_ug if isinstance(gm, AccelGaussMarkov) else gm.std_ppm)
    return per_axis(std) * unit, per_axis(gm.tau_s)
