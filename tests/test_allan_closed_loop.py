"""Closed loop of the noise model: the simulator's bias instability is flat where it should
be (closed form, then a simulation), and `gcalign allan` recovers every term the simulator
was given, within its interval, over seeds.

The IMU of the loop is chosen so that each term shows over a decade or more of τ in an 8 h
static run at 10 Hz (crossings near 0.1, 30 and 1000 s): quantum 2.2 noise steps (a
quantiser much coarser than the noise per sample has an error that is not white, and its
slope −1 shows only after many samples), ARW 0.005 °/√h, bias instability 0.08 °/h, rate
random walk 0.17 (°/h)/√h; VRW 20 µg/√Hz, 5.5 µg, 12 µg/√h.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from gcalign.allan import analyse
from gcalign.app.allan.run import KEYS
from gcalign.app.data import scenario_data
from gcalign.io.scenario import parse_scenario
from gcalign.sim.errors import (
    FLAT,
    FLICKER_TOLERANCE,
    flicker_components,
    gm_allan_variance,
)

TRUE = {"gyro": {"quantum_arcsec": 0.21, "arw_dprh": 0.005, "bias_instability_dph": 0.08,
                 "bias_rw_dphrh": 0.17},
        "accel": {"quantum_ugs": 14.0, "vrw_ugrhz": 20.0, "bias_instability_ug": 5.5,
                  "bias_rw_ughrh": 12.0}}
SEEDS = range(4)


def _scenario(imu: dict, hours: float, seed: int, rate_hz: float = 10.0):
    return parse_scenario({
        "name": "loop", "site": {"lat_deg": 34.0, "lon_deg": 108.0},
        "output": {"rate_hz": "full"},
        "motion": {"kind": "static", "duration_s": hours * 3600.0},
        "imu": {"rate_hz": rate_hz, "seed": seed, **imu}}, "loop")


@pytest.mark.parametrize("lo,hi,ts", [(1.0, 10.0, 0.01), (1.0, 3600.0, 0.01),
                                      (10.0, 600.0, 0.1), (0.1, 1e5, 0.01), (1.0, 7200, 0.1),
                                      (3.0, 28800, 0.1)])
def test_flicker_sum_is_flat(lo, hi, ts):
    """The Gauss–Markov sum's Allan deviation (the sampled closed form per process) stays
    within FLICKER_TOLERANCE of 0.664·B over its whole range, and leaves it outside (it is a
    band-limited flicker, not a flat line everywhere)."""
    times, std = flicker_components(np.array([2.0, 2.0, 2.0]), lo, hi, ts)
    assert times.min() >= ts * (1 - 1e-9)
    tau = np.geomspace(lo, hi, 500)
    sigma = np.sqrt(sum(gm_allan_variance(tau, s, T, ts) for s, T in zip(std[0], times,
                                                                         strict=True)))
    assert np.abs(sigma / (FLAT * 2.0) - 1).max() <= FLICKER_TOLERANCE
    far = np.sqrt(sum(gm_allan_variance(np.array([hi * 1e3]), s, T, ts)
                      for s, T in zip(std[0], times, strict=True)))
    assert far[0] < 0.5 * FLAT * 2.0


def test_gm_allan_variance_closed_form_can_fail():
    """The sampled closed form against a direct simulation of one Gauss–Markov process (so
    that the flatness above is about the process the simulator runs), down to τ = ts where
    it differs from the continuous form by half."""
    from gcalign.allan import allan_deviation

    rng = np.random.default_rng(5)
    T, s, ts, n = 20.0, 1e-4, 0.1, 400_000
    a = np.exp(-ts / T)
    from scipy.signal import lfilter

    x = lfilter([1.0], [1.0, -a], rng.standard_normal(n) * s * np.sqrt(1 - a * a),
                zi=[a * s * rng.standard_normal()])[0]
    c = allan_deviation((x * ts)[:, None], ts)
    for tau in (0.1, 1.0, 10.0, 40.0, 100.0):
        want = np.sqrt(gm_allan_variance(np.array([tau]), s, T, ts))[0]
        k = int(np.argmin(np.abs(c.tau - tau)))
        assert c.adev[k, 0] == pytest.approx(want, rel=3 * c.error[k]), tau


@pytest.mark.slow
def test_simulated_bias_instability_is_flat():
    """A simulated gyro with bias instability alone (1 h at 10 Hz, range 1 s to 1 h): its
    Allan deviation lies at 0.664·B within the curve's own interval (and the tolerance) from
    1 s to the longest τ with 10 clusters, on every axis and seed."""
    B = 0.05
    for seed in range(3):
        sc = _scenario({"gyro": {"bias_instability_dph": B}}, 1.0, seed)
        d = scenario_data(sc)
        res = analyse(d.imu.dtheta, d.imu.dv, d.imu.ts, min_clusters=10)
        c = res.gyro
        keep = c.tau >= 1.0
        flat = FLAT * B * np.pi / 180 / 3600
        z = (c.adev[keep] / flat - 1) / (c.error[keep, None] + FLICKER_TOLERANCE)
        assert np.abs(z).max() < 3.0, (seed, np.abs(z).max())
        assert np.sqrt(np.mean(z**2)) < 1.5


@functools.lru_cache(maxsize=1)
def recovery_table(hours: float = 8.0, seeds: tuple[int, ...] = tuple(SEEDS)) -> list[dict]:
    """Per term and axis-run: the true value, the fitted one, its 1σ interval and τ range
    (in the scenario key's unit)."""
    imu = {"gyro": dict(TRUE["gyro"]), "accel": dict(TRUE["accel"])}
    rows = []
    for seed in seeds:
        d = scenario_data(_scenario(imu, hours, seed))
        res = analyse(d.imu.dtheta, d.imu.dv, d.imu.ts)
        for triad, fit in (("gyro", res.gyro_fit), ("accel", res.accel_fit)):
            for name, (key, f) in KEYS[triad].items():
                t = fit.terms[name]
                for j in range(3):
                    rows.append({"key": f"{triad}.{key}", "seed": seed, "axis": "xyz"[j],
                                 "true": TRUE[triad][key], "fit": t.value[j] * f,
                                 "lo": t.lo[j] * f, "hi": t.hi[j] * f,
                                 "tau_range_s": tuple(t.tau_range[j])})
    return rows


KEYS_ALL = [f"{t}.{k}" for t in TRUE for k in TRUE[t]]


@pytest.mark.slow
@pytest.mark.parametrize("key", KEYS_ALL)
def test_allan_recovers_every_term(key):
    """Simulate the IMU of the module docstring (4 seeds × 3 axes, computed once), fit: the
    term is resolved in at least half of the 12 axis-runs (the rate random walk shows over
    its last half-decade only, so not always), and of those resolved 90 % lie within 3σ of
    their interval and at least 40 % within 1σ (the quantum: its mean within 1 %, below)."""
    mine = [r for r in recovery_table() if r["key"] == key]
    resolved = [r for r in mine if np.isfinite(r["fit"])]
    assert len(mine) == 12 and len(resolved) >= len(mine) // 2, key
    half = [(r["hi"] - r["lo"]) / 2 for r in resolved]
    z = np.array([(r["fit"] - r["true"]) / h for r, h in zip(resolved, half, strict=True)])
    assert np.mean(np.abs(z) <= 3) >= 0.9, (key, z)
    if "quantum" in key:
        # the quantiser's error is correlated from sample to sample at 2.2 noise steps
        # (lag-1 about 1 %): σ(τ0) and Q come out about 0.5 % low, a bias the clusters'
        # interval (0.45 %) does not know
        fits = np.array([r["fit"] for r in resolved])
        assert abs(fits.mean() / resolved[0]["true"] - 1) < 0.01, key
    else:
        assert np.mean(np.abs(z) <= 1) >= 0.4, (key, z)
