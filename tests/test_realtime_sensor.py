"""The gyro triad (gcalign.realtime.sensor): counts with carried remainder, noise level,
dither, chunk independence."""

from __future__ import annotations

import numpy as np

from gcalign.realtime.sensor import GyroChannel, quantise
from gcalign.realtime.settings import SensorSettings
from gcalign.units import ARCSEC, DEG


def test_quantised_angle_stays_within_one_quantum_and_chunks_join():
    rng = np.random.default_rng(0)
    q = 0.1 * ARCSEC
    d = rng.normal(3.6 * ARCSEC, 2 * ARCSEC, (20000, 3))
    r0 = np.array([0.37, 0.0, 0.99]) * q
    out, rem = quantise(d, q, r0)
    err = np.cumsum(out, 0) - np.cumsum(d, 0)  # = r0 − remainder_i ∈ (r0 − q, r0]
    assert np.all((err > r0 - q - 1e-18) & (err <= r0 + 1e-18))
    # every output is a whole number of counts
    np.testing.assert_allclose(out / q, np.round(out / q), atol=1e-6)
    parts, r = [], r0
    for a, b in [(0, 1), (1, 777), (777, 20000)]:
        o, r = quantise(d[a:b], q, r)
        parts.append(o)
    np.testing.assert_array_equal(np.concatenate(parts), out)
    np.testing.assert_allclose(r, rem, atol=1e-14)  # cumsum round-off over 0.35 rad


def test_angle_random_walk_level():
    """Increment noise σ = arw·√Δt (white rate noise), independent between the gyros."""
    arw = 0.01 * DEG / 60  # 0.01 °/√h
    ch = GyroChannel.start(SensorSettings(quantum=0.0, arw=arw, dither_amplitude=0.0),
                           np.random.default_rng(1))
    dt = 2e-4
    t = np.arange(1, 100001) * dt
    noise = ch.measure(t, np.zeros((len(t), 3)), dt, np.random.default_rng(2))
    np.testing.assert_allclose(np.std(noise, 0), arw * np.sqrt(dt), rtol=0.01)
    assert np.max(np.abs(np.corrcoef(noise.T) - np.eye(3))) < 0.01


def test_dither_increments_sum_to_the_dither_angle():
    s = SensorSettings(quantum=0.0, arw=0.0, dither_amplitude=100 * ARCSEC)
    ch = GyroChannel.start(s, np.random.default_rng(3))
    dt = 2e-4
    t = np.arange(1, 2001) * dt
    d = ch.measure(t, np.zeros((len(t), 3)), dt, np.random.default_rng(0))
    w = 2 * np.pi * 400.0
    np.testing.assert_allclose(np.cumsum(d, 0), s.dither_amplitude * (
        np.sin(w * t[:, None] + ch.dither_phase) - np.sin(ch.dither_phase)), atol=1e-15)
    np.testing.assert_allclose(ch.dither_residual(1.0, 0.0),
                               s.dither_amplitude * np.sin(ch.dither_phase))
    assert len(set(np.round(ch.dither_phase, 9))) == 3  # one phase per gyro
