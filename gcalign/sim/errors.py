"""The IMU error model, applied to ideal increments block by block (in the sensor frame).

Per axis: constant bias, white noise (ARW/VRW), scale factor (optionally different for
positive and negative input: asymmetric), non-orthogonality/misalignment, quantisation.
The measured increment is ``(I + diag(k) + M) Δ_ideal + b T + n`` with ``k = scale`` or,
with an asymmetric part, ``scale + asym·sign(Δ_ideal)``; a quantiser keeps its remainder.

Random numbers: one seeded ``numpy.random.Generator`` per run. The gyro noise of all N
samples comes first in its stream, then the accelerometer noise (the layout of the
whole-run draw ``g = rng.normal((N, 3)); a = rng.normal((N, 3))``), so a run gives the
same numbers whatever its block size, and the same as before streaming existed.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np

_SKIP_BLOCK = 1 << 18  # normals discarded at a time when the accelerometer stream skips


@dataclass(frozen=True)
class SensorErrors:
    """Errors of one sensor triad (SI).

    bias : (3,) rad/s (gyro) or m/s² (accel).
    noise : (3,) white-noise density: ARW in rad/√s or VRW in m/s/√s; per-sample std of an
        increment is ``noise * sqrt(ts)``.
    scale : (3,) scale-factor errors (fraction).
    asym : (3,) asymmetric scale-factor errors (fraction): added for positive input,
        subtracted for negative input.
    misalignment : (3, 3) small-angle non-orthogonality; zero diagonal.
    quantum : increment quantisation step (rad or m/s); 0 disables it.
    """

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    noise: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    quantum: float = 0.0
    asym: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def matrix(self) -> np.ndarray:
        """``I + diag(scale) + misalignment``, shape (3, 3)."""
        return np.eye(3) + np.diag(self.scale) + self.misalignment

    @property
    def noisy(self) -> bool:
        return bool(np.any(np.asarray(self.noise) != 0))


@dataclass(frozen=True)
class ImuErrors:
    gyro: SensorErrors = field(default_factory=SensorErrors)
    accel: SensorErrors = field(default_factory=SensorErrors)


class _Channel:
    """One triad's error state across blocks: its noise stream and quantiser remainder."""

    def __init__(self, err: SensorErrors, ts: float, rng: np.random.Generator | None):
        self.err, self.ts, self.rng = err, ts, rng
        self.M = err.matrix().T
        self.unit = bool(np.all(self.M == np.eye(3)))  # no scale factor or misalignment
        self.bias_ts = np.asarray(err.bias, dtype=float) * ts
        self.asym = np.asarray(err.asym, dtype=float) if np.any(np.asarray(err.asym) != 0) \
            else None
        self.sigma = np.asarray(err.noise, dtype=float) * np.sqrt(ts)
        self.running = np.zeros(3)  # unquantised running sum
        self.total = np.zeros(3)  # quantised running sum already output

    def apply(self, ideal: np.ndarray) -> np.ndarray:
        err = self.err
        out = ideal + self.bias_ts if self.unit else ideal @ self.M + self.bias_ts
        if self.asym is not None:
            out = out + self.asym * np.abs(ideal)
        if self.rng is not None:
            out = out + self.rng.standard_normal(ideal.shape) * self.sigma
        if err.quantum > 0:
            # Quantise the running sum, then difference it (the remainder is kept).
            run = np.cumsum(np.concatenate([self.running[None], out]), axis=0)[1:]
            q = np.round(run / err.quantum) * err.quantum
            out = np.diff(np.concatenate([self.total[None], q]), axis=0)
            self.running, self.total = run[-1].copy(), q[-1].copy()
        return out


class ErrorStream:
    """Applies :class:`ImuErrors` to consecutive blocks of ideal increments.

    `samples` is the run's total length N: the accelerometer noise stream starts after
    the 3N gyro normals of `rng` (see the module docstring).
    """

    def __init__(self, errors: ImuErrors, ts: float, rng: np.random.Generator, samples: int):
        g_rng = a_rng = None
        if errors.gyro.noisy:
            g_rng = rng
        if errors.accel.noisy:
            a_rng = copy.deepcopy(rng) if g_rng is not None else rng
            left = 3 * samples
            while left > 0:  # skip the gyro part of the stream
                k = min(left, _SKIP_BLOCK)
                a_rng.standard_normal(k)
                left -= k
        self.gyro = _Channel(errors.gyro, ts, g_rng)
        self.accel = _Channel(errors.accel, ts, a_rng)

    def apply(self, dtheta: np.ndarray, dv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured (dtheta, dv) of the next block."""
        return self.gyro.apply(dtheta), self.accel.apply(dv)
