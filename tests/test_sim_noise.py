"""The noise kernels draw NumPy's normals: the same numbers as ``rng.standard_normal``, the
same results to the bit, the generator left at the same place."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gcalign.sim import _noise
from gcalign.sim.errors import ErrorStream, ImuErrors, SensorErrors

#: NumPy's ziggurat for normals takes its tail branch beyond this (distributions.c)
ZIGGURAT_R = 3.6541528853610088


def numpy_sum(ideal, bias, rng, sigma):
    out = ideal + bias
    noise = rng.standard_normal(ideal.shape)
    noise *= sigma
    out += noise
    return out


@pytest.mark.parametrize("seed", [0, 1, 7, 2**40 + 3])
def test_noisy_sum_is_numpys_expression(seed):
    n = 200_000  # 600 000 normals: the ziggurat's wedge and tail branches are taken
    ideal = np.random.default_rng(99).uniform(-1e-3, 1e-3, (n, 3))
    bias, sigma = np.array([1e-7, -2e-7, 3e-9]), np.array([1e-5, 2e-4, 3e-6])
    a, b = np.random.default_rng(seed), np.random.default_rng(seed)
    want = numpy_sum(ideal, bias, a, sigma)
    got = _noise.noisy_sum(ideal, bias, b, sigma)
    assert np.array_equal(got, want)
    draws = (want - ideal - bias) / sigma
    assert np.sum(np.abs(draws) > ZIGGURAT_R) > 20  # the tail branch was exercised
    assert np.array_equal(a.standard_normal(5), b.standard_normal(5))  # same place after


def test_add_noise_normals_and_skip_follow_the_stream():
    out = np.arange(30.0).reshape(10, 3)
    sigma = np.array([0.5, 2.0, -1.0])
    a, b = np.random.default_rng(3), np.random.default_rng(3)
    want = out + a.standard_normal((10, 3)) * sigma
    _noise.add_noise(out, b, sigma)
    assert np.array_equal(out, want)
    assert np.array_equal(_noise.normals(b, 1001), a.standard_normal(1001))
    a.standard_normal(12_345)
    _noise.skip_normals(b, 12_345)
    assert np.array_equal(a.standard_normal(4), b.standard_normal(4))


@pytest.mark.parametrize("kind", ["plain", "scaled", "asym-quantised", "processes"])
def test_error_stream_matches_the_numpy_formula(kind):
    """Every route of a triad's errors against the formula of the module docstring written
    with NumPy here: gyro noise first, the accelerometer's after the 3N gyro normals."""
    n, ts = 500, 0.01
    extra: dict = {"plain": {}, "scaled": {"scale": np.array([1e-4, -2e-4, 0.0])},
                   "asym-quantised": {"asym": np.array([1e-4, 0.0, 0.0]), "quantum": 1e-6},
                   "processes": {"bias_gm_std": np.array([1e-6] * 3),
                                 "bias_gm_tau": np.array([10.0] * 3)}}[kind]
    g = SensorErrors(bias=np.array([1e-6, 2e-6, -1e-6]), noise=np.array([1e-4] * 3),
                     **extra)
    acc = SensorErrors(bias=np.array([1e-3] * 3), noise=np.array([1e-2, 2e-2, 3e-2]))
    src = np.random.default_rng(5)
    dth, dv = src.normal(0, 1e-3, (n, 3)), src.normal(0, 0.1, (n, 3))
    got_g, got_a = ErrorStream(ImuErrors(g, acc), ts, np.random.default_rng(11), n,
                               private=True).apply(dth, dv)
    rng = np.random.default_rng(11)
    noise = rng.standard_normal((n, 3)) * (g.noise * np.sqrt(ts))
    if kind == "processes":  # the processes' terms first, as the stream without noise has them
        quiet = replace(g, noise=np.zeros(3))
        before = ErrorStream(ImuErrors(quiet, acc), ts, np.random.default_rng(11), n,
                             private=True).gyro.apply(dth)
        assert not np.array_equal(before, dth + g.bias * ts)  # the processes are there
        want_g = before + noise
    else:
        want_g = dth @ g.matrix().T + g.bias * ts
        if kind == "asym-quantised":
            want_g += g.asym * np.abs(dth)
        want_g += noise
        if kind == "asym-quantised":  # the running sum quantised, then differenced
            q = np.round(np.cumsum(want_g, axis=0) / g.quantum) * g.quantum
            want_g = np.diff(np.concatenate([np.zeros((1, 3)), q]), axis=0)
    assert np.array_equal(got_g, want_g)
    want_a = (dv + acc.bias * ts) + rng.standard_normal((n, 3)) * (acc.noise * np.sqrt(ts))
    assert np.array_equal(got_a, want_a)
