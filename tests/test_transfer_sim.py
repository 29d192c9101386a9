"""Transfer alignment on a simulated wing-rock drive with the truth known (spec 006, test 1).

The cases of :mod:`gcalign.transfer.simulate`: 12 m/s, heading 30°, roll ±20° at 10 °/s;
μ, ε, ∇ drawn from the filter's P0 (1°, 500 °/h, 1000 µg), the slave's initial attitude
error from 0.1° independently of μ; master noise 1′ and 0.02 m/s at 10 Hz, the filter's R
set to it. What the linear model leaves out, and so what a consistency test must avoid:

* under attitude matching alone, the unmeasured vertical velocity carries g(1 − cos φ) of
  the unobservable forward-axis attitude error (about 1°): NEES 20.5 over 30 runs from the
  demo's start, every state in band (docs/decisions/019);
* starting from the master's attitude with a tight P0: φ0 = −C_nb μ exactly, a correlation
  P0 does not carry (NEES 17–21 over the first 5 s, 30 runs);
* a 1° initial φ0 with 500 °/h gyro biases: φ and μ stay confused (σ ≈ 1°) for seconds
  while ε acts through C_nb,est instead of C_nb, an error of |φ|·|ε| ≈ 4e-5 rad/s
  (NEES 21–26 over the first 5 s, back to 15–16 at 15 s).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lazy import lazy_attr

from gcalign.estimation.kalman import nees
from gcalign.transfer import transfer_align
from gcalign.transfer.simulate import estimation_error, transfer_case
from gcalign.units import ARCMIN, DEG, DPH

chi2 = lazy_attr("scipy.stats", "chi2")


def _run(seed: int, duration: float = 20.0, **kw):
    c = transfer_case(np.random.default_rng(seed), duration=duration)
    s = replace(c.settings, **{"attitude_feedback": True, **kw})
    return c, transfer_align(c.dtheta, c.dv, c.t, c.master, s, att0=c.att0)


def _monte_carlo(runs: int, duration: float):
    out = []
    for i in range(runs):
        c, r = _run(1000 + i, duration)
        out.append((nees(estimation_error(r, c), r.P), r.nis, r.t))
    return out


def _band(runs: int, n: int, p: float = 0.99):
    """The two-sided p band of the mean of `runs` χ²_n values."""
    a = (1 - p) / 2
    return chi2.ppf(a, runs * n) / runs, chi2.ppf(1 - a, runs * n) / runs


def _check_nees(mc, runs: int):
    nees_k = np.array([m[0] for m in mc])  # (runs, K)
    lo, hi = _band(runs, 15)
    # the last epoch, and the average over the epochs (correlated in time: its spread is
    # smaller than one epoch's, so the one-epoch band is the looser test)
    assert lo < nees_k[:, -1].mean() < hi, (nees_k[:, -1].mean(), (lo, hi))
    assert lo < nees_k.mean() < hi, (nees_k.mean(), (lo, hi))
    nis = np.concatenate([m[1] for m in mc])
    lo6, hi6 = _band(len(nis), 6)
    assert lo6 < nis.mean() < hi6, (nis.mean(), (lo6, hi6))


@pytest.mark.slow
def test_monte_carlo_nees_in_its_chi2_band():
    """30 seeded runs of 20 s: mean NEES of the 15 states inside the 99 % band of
    χ²(30·15)/30 ≈ [12.5, 17.7] (measured: 15.5 at 20 s, 16.1 on average); mean NIS in
    its χ²_6 band."""
    _check_nees(_monte_carlo(30, 20.0), 30)


@pytest.mark.slow
def test_monte_carlo_nees_in_its_chi2_band_60s():
    _check_nees(_monte_carlo(30, 60.0), 30)


def _mc_module():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "docs" / "transfer_monte_carlo.py"
    spec = importlib.util.spec_from_file_location("transfer_monte_carlo", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.slow
@pytest.mark.parametrize("start", ["wide", "tight"])
@pytest.mark.parametrize("matching", ["attitude+velocity", "velocity", "attitude"])
@pytest.mark.parametrize("feedback", [True, False])
def test_every_state_consistent_in_every_mode(matching, feedback, start):
    """30 seeded runs of 20 s per mode (docs/transfer_monte_carlo.py, the table of
    docs/results_transfer.md): the mean over the runs of each state's (e/σ)² at the end is
    a mean of 30 χ²₁ for a consistent filter. Band: two-sided, 1 % for the whole family of
    12 modes × 15 states (each 1 − 0.01/180: 0.37–2.23). Before the exact attitude
    measurement and the covariance reset (docs/decisions/019), attitude matching from the
    demo's start gave μ y 21.5 and φ E, N 21; without attitude feedback ∇ z 155.
    The NEES of the 15 states, a mean of 30 χ²₁₅, in its band of the same family level
    where the velocity is matched; under attitude matching alone the unmeasured vertical
    velocity carries g(1 − cos φ) of the unobservable forward-axis attitude error (≈ 1°,
    1.5 mm/s²), which the linear model leaves out: its NEES (20.5, with a 0.1° mounting
    15.2) is held to 25 only."""
    mc = _mc_module().monte_carlo(matching, feedback, start, runs=30, duration=20.0)
    cells = 12 * 15
    a = 0.01 / cells / 2
    lo, hi = chi2.ppf([a, 1 - a], 30) / 30
    z2 = mc["z2"].mean(axis=0)
    from gcalign.transfer.filter import NAMES_15

    bad = {n: round(float(v), 2) for n, v in zip(NAMES_15, z2, strict=True)
           if not lo < v < hi}
    assert not bad, (bad, (round(lo, 2), round(hi, 2)))
    a12 = 0.01 / 12 / 2
    lo15, hi15 = chi2.ppf([a12, 1 - a12], 30 * 15) / 30
    if matching == "attitude":
        assert mc["nees"].mean() < 25.0, mc["nees"].mean()
    else:
        assert lo15 < mc["nees"].mean() < hi15, (mc["nees"].mean(), (lo15, hi15))


def test_mu_and_gyro_bias_converge_to_the_injected_values():
    for seed in (1, 2, 3):
        c, r = _run(seed)
        e = estimation_error(r, c)[-1]
        sig = r.sigma[-1]
        assert np.all(np.abs(e[12:15]) < 3.5 * sig[12:15]), (e[12:15] / ARCMIN, sig[12:15])
        assert np.all(sig[12:15] < 2.5 * ARCMIN), sig[12:15] / ARCMIN
        assert np.all(np.abs(e[6:9]) < 3.5 * sig[6:9]) and np.all(sig[6:9] < 2.5 * DPH)
        # from a 1° prior and 500 °/h: the injected values are found, not the prior's zero
        assert np.all(np.abs(r.x[-1, 12:15] - c.mu) < 0.1 * np.abs(c.mu) + 3 * sig[12:15])


def _demo_start(matching: str):
    """The demo's start: the slave from the master's attitude, φ's P0 10° (a P0 of 0.1°
    would itself bound μ along the roll axis under attitude matching)."""
    c = transfer_case(np.random.default_rng(1), duration=20.0, phi0_sigma=10 * DEG)
    s = replace(c.settings, matching=matching, attitude_feedback=True)
    return transfer_align(c.dtheta, c.dv, c.t, c.master, s)


def test_velocity_matching_leaves_mu_at_its_p0():
    r = _demo_start("velocity")
    np.testing.assert_allclose(r.sigma[-1, 12:15], r.sigma0[12:15], rtol=1e-9)
    np.testing.assert_array_equal(r.x[:, 12:15], 0.0)


def test_attitude_matching_leaves_roll_axis_mu_poorly_observed():
    """The drive rolls about the body's forward axis at a constant heading: μ y and the
    attitude error about that axis cancel in the measurement, only the earth rate tells
    them apart, and the filter keeps σ(μ y) near its 60′ prior (measured 54.3′; 13′ with
    the mechanised attitude in H, which learnt what no data show: docs/decisions/019)."""
    r = _demo_start("attitude")
    sig = r.sigma[-1, 12:15] / ARCMIN
    assert sig[1] > 45.0, sig  # the roll axis (body y, forward)
    assert sig[0] < 1.0 and sig[2] < 1.0, sig


def test_same_seed_same_numbers():
    _, a = _run(7, 5.0)
    _, b = _run(7, 5.0)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.P, b.P)


LEVER = (0.5, 2.0, 0.3)  #: a slave 2 m ahead of the master (m, body axes)


def _lever_run(seed: int, **kw):
    c = transfer_case(np.random.default_rng(seed), duration=20.0, lever_arm_b=LEVER)
    s = replace(c.settings, **{"attitude_feedback": True, **kw})
    return c, transfer_align(c.dtheta, c.dv, c.t, c.master, s, att0=c.att0)


def test_lever_arm_is_compensated_and_matters():
    """A slave 2 m ahead of the master, one run: with the lever arm set, the innovations
    are those of the model, mean NIS of the 199 epochs inside the 99 % band of
    χ²(199·6)/199 ≈ [5.4, 6.7] (measured 6.3); with it ignored, the ω × l velocity
    (0.35 m/s at the ±10 °/s roll reversals) is outside the model: NIS ≈ 19 for 6 dof."""
    _, r = _lever_run(1000)
    lo, hi = _band(len(r.nis), 6)
    assert lo < r.nis.mean() < hi, (r.nis.mean(), (lo, hi))
    _, off = _lever_run(1000, lever_arm_b=(0.0, 0.0, 0.0))
    assert off.nis.mean() > 3 * 6, off.nis.mean()


@pytest.mark.slow
def test_lever_arm_nees_in_its_band_over_8_runs():
    """With the lever arm set, the final NEES of 8 runs inside the 99 % band of
    χ²(8·15)/8 (measured 14.2)."""
    nees_end = []
    for i in range(8):
        c, r = _lever_run(1000 + i)
        nees_end.append(nees(estimation_error(r, c)[-1], r.P[-1]))
    lo, hi = _band(8, 15)
    assert lo < np.mean(nees_end) < hi, (np.mean(nees_end), (lo, hi))


def test_master_interpolated_between_its_epochs():
    """The master at 10 Hz interpolated to the IMU samples between its epochs: the roll
    turns at a constant rate within a segment, where the rotation-vector interpolation is
    exact and the velocity (constant) too; the triangle's vertices are left out."""
    from gcalign.nav.rotation import euler_to_quat, misalignment_q
    from gcalign.transfer.filter import MasterSeries, _slerp_master
    from gcalign.transfer.simulate import _ideal

    truth, _ = _ideal(20.0, 0.01)
    k = np.arange(0, len(truth.t), 10)
    master = MasterSeries(truth.t[k], truth.att[k], truth.v_n[k], truth.pos[k])
    t = truth.t[5:-5]
    q, v, _pos = _slerp_master(master, t)
    away = np.abs(((t - 2.0) % 4.0) - 2.0) > 0.1  # vertices at 2, 6, 10, … s
    err = misalignment_q(q, euler_to_quat(truth.att[5:-5]))
    assert np.max(np.abs(err[away])) < 1e-9
    assert np.max(np.abs(v - truth.v_n[5:-5])) < 1e-9
