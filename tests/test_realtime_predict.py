"""Tracker, least squares and prediction of seed 003 §2.3 (gcalign.realtime.predict) against
closed forms, a slow second route, χ² consistency and the frequency domain (spec 003 §5
tests 5–8; must-show 3–4)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from lazy import lazy_attr

from gcalign.realtime.predict import (
    TrackerModel,
    horizon_weights,
    ls_fit,
    ls_weights,
    predict_kalman_ls,
    predict_taylor,
    run_predictor,
    steady_state,
    swing_residual,
    track,
    track_reference,
    unwrap,
)
from gcalign.units import ARCSEC, DEG

chi2 = lazy_attr("scipy.stats", "chi2")

TAU = 1e-3
R = (0.03 * ARCSEC) ** 2


def _exact_states(theta, omega, alpha, t):
    """(…, 3 lags, 3) states [θ, ω, α] at t − 2τ, t − τ, t."""
    lags = np.asarray(t)[..., None] + np.array([-2, -1, 0]) * TAU
    return np.stack([theta(lags), omega(lags), alpha(lags)], -1)


# ---------------------------------------------------------------------------- least squares

def test_ls_weights_are_the_spec_closed_form():
    """m = 4 → 10, −24, 15 (spec 003 §3); noise gain √(10² + 24² + 15²) ≈ 30."""
    assert ls_weights(4.0).tolist() == [10.0, -24.0, 15.0]
    assert np.linalg.norm(ls_weights(4.0)) == pytest.approx(30.0, abs=0.02)
    assert ls_weights(0.0).tolist() == [0.0, -0.0, 1.0]


@pytest.mark.parametrize("t_k", [0.0, 12.345, 1e5])
def test_ls_extrapolation_is_exact_on_any_quadratic(t_k):
    """The three-point fit in local time reproduces any quadratic, also at t = 1e5 s (to the
    resolution of the time stamps themselves: spacing(1e5 s) = 1.5e-11 s)."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        a, b, c = rng.normal(size=3) * [1.0, 2.0, 50.0]
        t1 = t_k - rng.uniform(0, 0.1)  # the motion's own origin, near the time stamps
        def q(t, a=a, b=b, c=c, t1=t1):
            return a + b * (t - t1) + c * (t - t1) ** 2
        y = q(t_k + np.array([-2, -1, 0]) * TAU)
        slope = abs(b) + 2 * abs(c) * 0.11
        for m in [0.0, 0.5, 4.0, 4.37, 5.0]:
            w = ls_weights(m)
            # the data's own rounding (values and time stamps), amplified by Σ|w|
            tol = np.abs(w).sum() * (4e-16 * np.abs(y).max() + np.spacing(t_k) * slope)
            assert w @ y == pytest.approx(q(t_k + m * TAU), abs=tol)


def test_the_printed_normal_equations_fail_in_absolute_time():
    """Seed eq. (12) with x = absolute time: at t = 1e5 s the result is noise — why gcalign
    fits in local time (the test above passes there)."""
    t_k, a, b, c = 1e5, 0.3, -1.2, 2.5
    x = t_k + np.array([-2, -1, 0]) * TAU
    y = a + b * (x - t_k) + c * (x - t_k) ** 2
    t = t_k + 4 * TAU
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        coef = ls_fit(x, y)
    err = abs(coef @ [1.0, t, t * t] - (a + b * (t - t_k) + c * (t - t_k) ** 2))
    assert not err < 1e-3
    # …while near t = 0 the same printed form is fine
    coef0 = ls_fit(x - t_k, y)
    assert coef0 @ [1.0, 4 * TAU, (4 * TAU) ** 2] == pytest.approx(
        a + b * 4 * TAU + c * (4 * TAU) ** 2, abs=1e-12)


def test_horizon_weights_closed_form_sums_equal_the_explicit_sum():
    """W_ω = τ Σ_{i<n} L(i) + r L(n), W_α = ½τ² Σ L(i) + ½r² L(n): closed-form sums against
    the loop of reconstructed eq. (13)."""
    for H in [0.0, 0.3e-3, 1e-3, 4e-3, 4.0406e-3, 4.99e-3, 18.7e-3]:
        n = int(np.floor(H / TAU + 1e-9))
        r = H - n * TAU
        Wo = sum(TAU * ls_weights(i) for i in range(n)) + r * ls_weights(n)
        Wa = sum(0.5 * TAU**2 * ls_weights(i) for i in range(n)) + 0.5 * r**2 * ls_weights(n)
        got_o, got_a = horizon_weights(np.array(H), TAU)
        np.testing.assert_allclose(got_o, Wo, rtol=1e-12, atol=1e-18)
        np.testing.assert_allclose(got_a, Wa, rtol=1e-12, atol=1e-20)


# ---------------------------------------------------------------------------- predictor

@pytest.mark.parametrize("horizon", [4e-3, 4.0406e-3, 4.9e-3, 0.2e-3, 18e-3])
def test_predictors_fed_exact_states_on_quadratic_and_cubic_motion(horizon):
    """Spec 003 §5 test 7: zero error on quadratic θ; on cubic θ (jerk j) kalman-ls misses
    j (nτ³ + r³)/6 (= j·T·τ²/6 for Tdelay = nτ) and taylor j·Tdelay³/6."""
    t = np.linspace(0.05, 0.3, 7)
    th0, w0, a0, j = 0.4, 0.25, -0.17, 2.3
    quad = _exact_states(lambda s: th0 + w0 * s + 0.5 * a0 * s**2, lambda s: w0 + a0 * s,
                         lambda s: a0 + 0 * s, t)
    truth_q = th0 + w0 * (t + horizon) + 0.5 * a0 * (t + horizon) ** 2
    for name in ("kalman-ls", "taylor"):
        np.testing.assert_allclose(run_predictor(name, quad, horizon, TAU), truth_q, rtol=0,
                                   atol=5e-16)
    cubic = _exact_states(lambda s: j * s**3 / 6, lambda s: j * s**2 / 2, lambda s: j * s, t)
    truth_c = j * (t + horizon) ** 3 / 6
    n = np.floor(horizon / TAU + 1e-9)
    r = horizon - n * TAU
    np.testing.assert_allclose(truth_c - predict_kalman_ls(cubic, horizon, TAU),
                               j * (n * TAU**3 + r**3) / 6, rtol=1e-6, atol=1e-17)
    np.testing.assert_allclose(truth_c - predict_taylor(cubic, horizon, TAU),
                               j * horizon**3 / 6, rtol=1e-5)
    if r == 0:
        np.testing.assert_allclose(truth_c - predict_kalman_ls(cubic, horizon, TAU),
                                   j * horizon * TAU**2 / 6, rtol=1e-6)


def test_unknown_predictor_is_rejected():
    with pytest.raises(ValueError, match="predictor must be one of"):
        run_predictor("kalman", np.zeros((3, 3)), 4e-3, TAU)


def test_unwrap_continues_across_chunks():
    yaw = np.arange(0, 20.0, 0.05)  # rad, many turns
    wrapped = (yaw + np.pi) % (2 * np.pi) - np.pi
    att = np.stack([0 * yaw, 0 * yaw, wrapped], -1)
    whole = unwrap(att)
    parts = [unwrap(att[:100])]
    parts.append(unwrap(att[100:], parts[-1][-1]))
    np.testing.assert_allclose(np.concatenate(parts), whole, atol=1e-15)
    np.testing.assert_allclose(whole[:, 2], yaw, atol=1e-12)


# ---------------------------------------------------------------------------- tracker

def test_tracker_model_is_the_van_loan_closed_form():
    """Spec 003 §3: Φ and Q_k of the [θ, ω, α] jerk model."""
    qc, tau = 1.7, TAU
    m = TrackerModel.of(qc, R, tau)
    np.testing.assert_allclose(m.Phi, [[1, tau, tau**2 / 2], [0, 1, tau], [0, 0, 1]],
                               rtol=1e-14)
    Q = qc * np.array([[tau**5 / 20, tau**4 / 8, tau**3 / 6], [tau**4 / 8, tau**3 / 3, tau**2 / 2],
                       [tau**3 / 6, tau**2 / 2, tau]])
    np.testing.assert_allclose(m.Qd, Q, rtol=1e-9)


@pytest.mark.slow
def test_numba_tracker_equals_the_slow_route():
    """Kernel against gcalign.estimation.kalman.predict/update to 1e-12; a deliberate change
    of one term (Q_d's α entry by 1e-6) is seen."""
    model = TrackerModel.of(1.0, R, TAU)
    rng = np.random.default_rng(11)
    t = np.arange(3000) * TAU
    w = 2 * np.pi * 0.8
    z = 10 * DEG * np.sin(w * t) + np.sqrt(R) * rng.standard_normal(len(t))
    x0 = np.array([z[0], 10 * DEG * w, 0.0])
    P0 = np.diag([R, (0.01 * DEG) ** 2, (0.1 * DEG) ** 2])

    def close(a, b, tol):
        return np.max(np.abs(a - b) / np.abs(b).max(axis=0)) < tol

    fast = track(z, model, x0, P0, store_covariance=True)
    slow = track_reference(z, model, x0, P0)
    assert close(fast.x, slow.x, 1e-12)
    assert close(fast.P, slow.P, 1e-12)
    assert close(fast.innovation, slow.innovation, 1e-12)
    assert close(fast.S, slow.S, 1e-12)
    # the reference route's Kalman steps are kernels held to their NumPy form to 1e-12 a
    # step (docs/decisions/016): after 3000 steps its last state is 1.2e-12 of itself off
    np.testing.assert_allclose(fast.x_last, slow.x_last, rtol=1e-11)
    # From a vague start (σ_ω, σ_α = 20°/s, 20°/s² against σ_θ = 0.03″) the first updates
    # cancel seven decades of P in both routes; they then agree to 1e-9, not 1e-12.
    vague = np.diag([R, (20 * DEG) ** 2, (20 * DEG) ** 2])
    assert close(track(z, model, x0, vague).x, track_reference(z, model, x0, vague).x, 1e-9)
    Qd = model.Qd.copy()
    Qd[2, 2] *= 1 + 1e-6
    changed = TrackerModel(tau=TAU, Phi=model.Phi, Qd=Qd, R=model.R, qc=model.qc)
    other = track(z, changed, x0, P0, store_covariance=True)
    assert not close(other.P, slow.P, 1e-8)


def test_tracker_converges_to_the_exact_state_of_a_quadratic():
    """Noise-free θ = θ0 + ω0 t + ½ α t²: the tracker reaches (θ, ω, α) to < 1e-9."""
    model = TrackerModel.of(1.0, R, TAU)
    t = np.arange(1, 3001) * TAU
    th0, w0, a0 = 0.3, 15 * DEG, 10 * DEG
    z = th0 + w0 * t + 0.5 * a0 * t**2
    out = track(z, model, np.array([th0, 0.0, 0.0]),
                np.diag([R, (20 * DEG) ** 2, (20 * DEG) ** 2]))
    err = out.x[-1] - [z[-1], w0 + a0 * t[-1], a0]
    assert np.all(np.abs(err) < 1e-9), err


def _model_data(model, P0, runs, steps, rng):
    """Truth from the tracker's own model (true Qc, R): X_{k+1} = Φ X_k + w, z = θ + v."""
    Lq = np.linalg.cholesky(model.Qd)
    X = rng.standard_normal((runs, 3)) @ np.linalg.cholesky(P0).T
    truth = np.empty((runs, steps, 3))
    for k in range(steps):
        X = X @ model.Phi.T + rng.standard_normal((runs, 3)) @ Lq.T
        truth[:, k] = X
    z = truth[..., 0] + np.sqrt(model.R) * rng.standard_normal((runs, steps))
    return truth, z


@pytest.mark.slow
def test_nees_and_innovation_whiteness_on_data_from_the_model():
    """NEES (3 dof) and NIS averaged over runs inside their χ² bounds at several times;
    Ljung–Box on the standardized innovations of a long run inside χ²₂₀ (spec 003 §5
    test 6)."""
    rng = np.random.default_rng(2024)
    model = TrackerModel.of(1.0, R, TAU)
    P0 = np.diag([R, (1 * DEG) ** 2, (5 * DEG) ** 2])
    runs, steps = 300, 400
    truth, z = _model_data(model, P0, runs, steps, rng)
    nees = np.empty((runs, steps))
    nis = np.empty((runs, steps))
    for i in range(runs):
        tr = track(z[i], model, np.zeros(3), P0, store_covariance=True)
        e = tr.x - truth[i]
        nees[i] = np.einsum("ka,kab,kb->k", e, np.linalg.inv(tr.P), e)
        nis[i] = tr.innovation**2 / tr.S
    lo3, hi3 = chi2.ppf([0.0005, 0.9995], 3 * runs) / runs
    lo1, hi1 = chi2.ppf([0.0005, 0.9995], runs) / runs
    for k in (0, 5, 50, 399):
        assert lo3 < nees[:, k].mean() < hi3, (k, nees[:, k].mean())
        assert lo1 < nis[:, k].mean() < hi1, (k, nis[:, k].mean())
    # one long run: the standardized innovations are white
    truth, z = _model_data(model, P0, 1, 20000, rng)
    nu = track(z[0], model, np.zeros(3), P0).standardized[100:]
    nu = nu - nu.mean()
    N, L = len(nu), 20
    rho = np.array([nu[:-lag] @ nu[lag:] for lag in range(1, L + 1)]) / (nu @ nu)
    Q = N * (N + 2) * np.sum(rho**2 / (N - np.arange(1, L + 1)))
    assert Q < chi2.ppf(0.999, L), Q
    assert abs(np.mean(nu**2) - 1) < 4 * np.sqrt(2 / N)
    # the check can fail: a filter tuned with a 100× too small R is not consistent
    wrong = TrackerModel.of(1.0, R / 100, TAU)
    nis_wrong = track(z[0], wrong, np.zeros(3), P0).standardized[100:] ** 2
    assert nis_wrong.mean() > chi2.ppf(0.9995, N) / N


# ---------------------------------------------------------------------------- frequency domain

def _swing_run(model, f, T, dt, A=10 * DEG, seconds=20.0):
    """Time domain: observation A sin ω(kτ − T), tracker from the steady-state posterior,
    kalman-ls to the pulse at kτ + Δt; residual amplitude by least squares over whole
    periods after 1 s."""
    w = 2 * np.pi * f
    k = np.arange(int(seconds / TAU))
    z = A * np.sin(w * (k * TAU - T))
    tm = -TAU - T
    x0 = np.array([A * np.sin(w * tm), A * w * np.cos(w * tm), -A * w * w * np.sin(w * tm)])
    tr = track(z, model, x0, steady_state(model)[2])
    pred = predict_kalman_ls(np.stack([tr.x[:-2], tr.x[1:-1], tr.x[2:]], 1), T + dt, TAU)
    tk = k[2:] * TAU
    res = pred - A * np.sin(w * (tk + dt))
    periods = int(np.floor((tk[-1] - 1.0) * f))
    sel = (tk >= 1.0) & (tk < 1.0 + periods / f)
    M = np.stack([np.sin(w * tk[sel]), np.cos(w * tk[sel])], -1)
    return float(np.hypot(*np.linalg.lstsq(M, res[sel], rcond=None)[0]))


@pytest.mark.parametrize(("f", "T", "dt"), [(0.4, 4e-3, 0.0), (1.0, 4e-3, 0.0),
                                             (1.0, 4.0406e-3, 0.37e-3), (5.0, 4e-3, 0.9e-3)])
def test_swing_residual_frequency_domain_equals_time_domain(f, T, dt):
    """Spec 003 §5 test 8: with the steady-state gain (solve_discrete_are) the chain from z to
    the prediction is LTI; A·|G(e^{jωτ}) e^{−jω(T+Δt)} − 1| matches the run to 1e-6."""
    model = TrackerModel.of(1.0, R, TAU)
    got = _swing_run(model, f, T, dt)
    want = swing_residual(f, 10 * DEG, model, T, dt)[0]
    assert got == pytest.approx(want, rel=1e-6)
    # and is not the Taylor predictor's
    assert not swing_residual(f, 10 * DEG, model, T, dt, "taylor")[0] == pytest.approx(
        want, rel=1e-3)


def test_steady_state_gain_solves_the_riccati_equation():
    model = TrackerModel.of(1.0, R, TAU)
    Pm, K, Pp = steady_state(model)
    Phi, Q = model.Phi, model.Qd
    np.testing.assert_allclose(Phi @ Pp @ Phi.T + Q, Pm, rtol=1e-13)
    np.testing.assert_allclose(K, Pm[:, 0] / (Pm[0, 0] + R), rtol=1e-12)
    # the Kalman recursion from P0 converges to it
    out = track(np.zeros(2000), model, np.zeros(3), np.diag([R, 1e-2, 1e-1]),
                store_covariance=True)
    np.testing.assert_allclose(out.P[-1], Pp, rtol=1e-6)
