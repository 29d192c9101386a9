"""The gyro triad at 5 kHz (spec 003 §4 [O] noise model): ideal increments from the core
(:func:`gcalign.sim.ideal.ideal_blocks`, earth rate included), angle random walk,
mechanical dither, quantised counts with carried remainder.

Each of the three ring laser gyros senses its ideal angle increment plus an angle random
walk (white rate noise, σ = arw·√Δt per increment) and its dither
``A_d sin(2π f_d t + φ_d)`` (one dither frequency, the notch's; an independent phase per
gyro). A ring laser gyro counts fringes: the output is ``q · ⌊(sensed angle + phase)/q⌋``
differenced, the remainder carried from sample to sample (and chunk to chunk), so the
quantised angle never drifts more than one quantum from the sensed angle.

>>> import numpy as np
>>> q = 0.1
>>> y, rem = quantise(np.array([[0.25], [0.25], [0.25], [0.25]]), q, np.zeros(1))
>>> np.round(y[:, 0], 12).tolist(), np.round(rem, 12).tolist()
([0.2, 0.3, 0.2, 0.3], [0.0])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.realtime.settings import SensorSettings

__all__ = ["GyroChannel", "quantise"]


def quantise(dtheta: np.ndarray, quantum: float,
             remainder: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quantised increments (N, m) and the new remainders (m,) in [0, q) (rad).

    Each counter holds ``remainder + Σ dθ``; each sample outputs the whole quanta reached,
    ``q (⌊c_i/q⌋ − ⌊c_{i−1}/q⌋)``. ``quantum = 0`` passes `dtheta` through.
    """
    d = np.asarray(dtheta, dtype=float)
    rem = np.asarray(remainder, dtype=float)
    if quantum == 0:
        return d.copy(), np.zeros_like(rem)
    if not len(d):
        return d.copy(), rem.copy()
    c = rem + np.cumsum(d, axis=0)
    counts = np.floor(c / quantum)
    out = np.diff(counts, axis=0, prepend=0.0) * quantum
    return out, c[-1] - counts[-1] * quantum


@dataclass
class GyroChannel:
    """Streaming state of the gyro triad: counter remainders and dither phases (3,).

    Build it with :meth:`start` (draws each counter's initial phase, uniform in [0, q), and
    each dither phase from `rng`); :meth:`measure` then turns ideal increments of successive
    chunks into counts, drawing the noise from the same `rng`.
    """

    sensor: SensorSettings
    remainder: np.ndarray
    dither_phase: np.ndarray

    @classmethod
    def start(cls, sensor: SensorSettings, rng: np.random.Generator) -> GyroChannel:
        rem = rng.uniform(0.0, sensor.quantum, 3) if sensor.quantum > 0 else np.zeros(3)
        phase = rng.uniform(0.0, 2.0 * np.pi, 3)
        return cls(sensor, rem, phase)

    def dither_residual(self, response: complex, t: float) -> np.ndarray:
        """The dither angles (3,) after a filter of complex `response` at the dither
        frequency, at time `t` (s), in steady state (rad): ``A_d Im(H e^{j(2π f_d t + φ_d)})``."""
        s = self.sensor
        return s.dither_amplitude * (response * np.exp(
            1j * (2.0 * np.pi * s.dither_hz * t + self.dither_phase))).imag

    def measure(self, t: np.ndarray, ideal: np.ndarray, dt: float,
                rng: np.random.Generator) -> np.ndarray:
        """Counts (N, 3) (rad) for the ideal increments `ideal` (N, 3) ending at times `t`
        (N,) (s), sample interval `dt` (s)."""
        s = self.sensor
        d = np.array(ideal, dtype=float)
        if s.arw > 0:
            d += s.arw * np.sqrt(dt) * rng.standard_normal(d.shape)
        if s.dither_amplitude > 0 and len(d):
            # the dither angle at the sample times and one sample before: its increments
            w = 2.0 * np.pi * s.dither_hz
            tt = np.concatenate([[t[0] - dt], np.asarray(t, dtype=float)])
            d += s.dither_amplitude * np.diff(np.sin(w * tt[:, None] + self.dither_phase),
                                              axis=0)
        out, self.remainder = quantise(d, s.quantum, self.remainder)
        return out
