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
            out += self.asym * np.abs(ideal)
        if self.rng is not None:
            noise = self.rng.standard_normal(ideal.shape)
            noise *= self.sigma  # in place: one block-sized temporary fewer
            out += noise
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
    the 3N gyro normals of `rng` (see the module docstring). It is positioned at the first
    block. `private`: nothing else draws from `rng` afterwards, so if the gyro has drawn all
    3N by then (the whole run in one block), the accelerometer continues the gyro's
    generator instead of skipping 3N normals on a copy of it (same numbers; a caller's
    generator otherwise ends where the gyro left it).
    """

    def __init__(self, errors: ImuErrors, ts: float, rng: np.random.Generator, samples: int,
                 private: bool = False):
        g_rng = rng if errors.gyro.noisy else None
        self._samples, self._private = samples, private
        # the generator at the start of the run, for the accelerometer to skip from
        self._a_start = None if not errors.accel.noisy else (
            copy.deepcopy(rng) if g_rng is not None else rng)
        self._g_drawn = 0  # gyro normals drawn so far
        self.gyro = _Channel(errors.gyro, ts, g_rng)
        self.accel = _Channel(errors.accel, ts, None)

    def _accel_rng(self) -> np.random.Generator:
        """The accelerometer's generator, 3N normals after the start of the run."""
        assert self._a_start is not None
        if self._private and self.gyro.rng is not None and self._g_drawn == 3 * self._samples:
            return self.gyro.rng  # the gyro's draws were the skip; it draws no more
        a_rng, left = self._a_start, 3 * self._samples
        while left > 0:  # skip the gyro part of the stream
            k = min(left, _SKIP_BLOCK)
            a_rng.standard_normal(k)
            left -= k
        return a_rng

    def apply(self, dtheta: np.ndarray, dv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured (dtheta, dv) of the next block."""
        gyro = self.gyro.apply(dtheta)
        if self.gyro.rng is not None:
            self._g_drawn += dtheta.size
        if self._a_start is not None:
            self.accel.rng, self._a_start = self._accel_rng(), None
        return gyro, self.accel.apply(dv)
