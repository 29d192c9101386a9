"""Sync pulses and the latch (gcalign.realtime.pulses): indices, Δt, drift, counter
resolution."""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.realtime.pulses import latch, make_pulses
from gcalign.realtime.settings import PulseSettings

F2 = 1000.0


def test_pulses_on_solution_instants():
    p = make_pulses(PulseSettings(rate_hz=250.0, offset_s=0.0), 2.0, F2,
                    np.random.default_rng(0))
    np.testing.assert_array_equal(p.k, np.arange(0, 2001, 4))
    assert np.all(p.dt == 0.0)
    np.testing.assert_allclose(p.t, p.k / F2)


def test_edges_on_instants_latch_that_instant():
    t = np.arange(12001) * 1e-3  # computed, so some are a hair below k·τ
    k, dt_true, dt = latch(t, F2)
    np.testing.assert_array_equal(k, np.arange(12001))
    assert np.max(dt_true) < 1e-12


def test_asynchronous_pulses():
    s = PulseSettings(mode="async", rate_hz=97.0, offset_s=None, drift_ppm=120.0,
                      resolution_s=1e-6)
    p = make_pulses(s, 12.0, F2, np.random.default_rng(7))
    tau = 1.0 / F2
    np.testing.assert_allclose(np.diff(p.t), (1 + 120e-6) / 97.0, rtol=1e-12)
    assert np.all((p.dt_true >= 0) & (p.dt_true < tau))
    np.testing.assert_allclose(p.k * tau + p.dt_true, p.t, atol=1e-15)
    assert np.max(np.abs(p.dt - p.dt_true)) <= 0.5e-6 + 1e-15
    # the phase is drawn: another generator, another train
    q = make_pulses(s, 12.0, F2, np.random.default_rng(8))
    assert q.t[0] != p.t[0]


def test_jitter_level():
    s = PulseSettings(mode="async", rate_hz=100.0, offset_s=0.5, jitter_s=5e-6)
    p = make_pulses(s, 100.0, F2, np.random.default_rng(1))
    ideal = 0.5 + np.arange(len(p.t)) / 100.0
    assert np.std(p.t - ideal) == pytest.approx(5e-6, rel=0.05)
