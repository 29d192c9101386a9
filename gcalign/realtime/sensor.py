"""The gyro channel at 5 kHz (spec 003 §4 [O] noise model): ideal increments of a turn about
one fixed axis, angle random walk, mechanical dither, quantised counts with carried remainder.

For a rotation about a fixed axis u the body rate is ``u θ̇`` and the exact gyro increment
over ``[t_{i−1}, t_i]`` is ``u (θ(t_i) − θ(t_{i−1}))`` (no coning, no earth rate in phase 1),
so the channel along u carries the whole motion. The sensed angle adds an angle random walk
(white rate noise, σ = arw·√Δt per increment) and the dither ``A_d sin(2π f_d t + φ_d)``.
A ring laser gyro counts fringes: the output is ``q · ⌊(sensed angle + phase)/q⌋``
differenced, the remainder carried from sample to sample (and chunk to chunk), so the
quantised angle never drifts more than one quantum from the sensed angle.

>>> import numpy as np
>>> q = 0.1
>>> y, rem = quantise(np.array([0.25, 0.25, 0.25, 0.25]), q, 0.0)
>>> np.round(y, 12).tolist(), round(rem, 12)
([0.2, 0.3, 0.2, 0.3], 0.0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.realtime.settings import SensorSettings
from gcalign.sim.schedule import Schedule

__all__ = ["GyroChannel", "axis_angle", "quantise"]


def axis_angle(schedule: Schedule, t: np.ndarray) -> np.ndarray:
    """Turn angle θ(t) (rad) of a one-step schedule about its axis, (N,)."""
    if len(schedule.steps) != 1:
        raise ValueError(f"a turntable case turns about one fixed axis: the schedule must "
                         f"have one step, got {len(schedule.steps)}")
    return schedule.angle_rate_accel(t)[0]


def quantise(dtheta: np.ndarray, quantum: float, remainder: float) -> tuple[np.ndarray, float]:
    """Quantised increments (N,) and the new remainder in [0, q) (rad).

    The counter holds ``remainder + Σ dθ``; each sample outputs the whole quanta reached,
    ``q (⌊c_i/q⌋ − ⌊c_{i−1}/q⌋)``. ``quantum = 0`` passes `dtheta` through.
    """
    d = np.asarray(dtheta, dtype=float)
    if quantum == 0:
        return d.copy(), 0.0
    c = remainder + np.cumsum(d)
    counts = np.floor(c / quantum)
    out = np.diff(counts, prepend=0.0) * quantum
    return out, float(c[-1] - counts[-1] * quantum) if len(d) else remainder


@dataclass
class GyroChannel:
    """Streaming state of the gyro channel: the counter remainder and the dither phase.

    Build it with :meth:`start` (draws the counter's initial phase, uniform in [0, q), and
    the dither phase from `rng`); :meth:`measure` then turns ideal increments of successive
    chunks into counts, drawing the noise from the same `rng`.
    """

    sensor: SensorSettings
    remainder: float
    dither_phase: float

    @classmethod
    def start(cls, sensor: SensorSettings, rng: np.random.Generator) -> GyroChannel:
        rem = rng.uniform(0.0, sensor.quantum) if sensor.quantum > 0 else 0.0
        phase = rng.uniform(0.0, 2.0 * np.pi)
        return cls(sensor, float(rem), float(phase))

    def dither_residual(self, response: complex, t: float) -> float:
        """The dither angle after a filter of complex `response` at the dither frequency,
        at time `t` (s), in steady state (rad): ``A_d Im(H e^{j(2π f_d t + φ_d)})``."""
        s = self.sensor
        return float(s.dither_amplitude * (response * np.exp(
            1j * (2.0 * np.pi * s.dither_hz * t + self.dither_phase))).imag)

    def measure(self, t: np.ndarray, ideal: np.ndarray, dt: float,
                rng: np.random.Generator) -> np.ndarray:
        """Counts (rad) for the ideal increments `ideal` (N,) ending at times `t` (N,) (s),
        sample interval `dt` (s)."""
        s = self.sensor
        d = np.array(ideal, dtype=float)
        if s.arw > 0:
            d += s.arw * np.sqrt(dt) * rng.standard_normal(len(d))
        if s.dither_amplitude > 0:
            w = 2.0 * np.pi * s.dither_hz
            d += s.dither_amplitude * (np.sin(w * t + self.dither_phase)
                                       - np.sin(w * (t - dt) + self.dither_phase))
        out, self.remainder = quantise(d, s.quantum, self.remainder)
        return out
