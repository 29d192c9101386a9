"""Kalman steps (gcalign.estimation.kalman) against independent routes to the same numbers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from gcalign.estimation.kalman import nees, predict, update, van_loan


def test_van_loan_matches_the_closed_form_of_a_jerk_model():
    """θ, ω, α driven by white jerk of intensity q: Φ = [[1, τ, τ²/2], …] and
    Q_d = q [[τ⁵/20, τ⁴/8, τ³/6], [τ⁴/8, τ³/3, τ²/2], [τ³/6, τ²/2, τ]] (spec 003 §3)."""
    tau, q = 1e-3, 3.7
    F = np.array([[0, 1, 0], [0, 0, 1], [0, 0, 0]], float)
    Phi, Qd = van_loan(F, np.array([[0], [0], [1.0]]), np.array([[q]]), tau)
    np.testing.assert_allclose(Phi, [[1, tau, tau**2 / 2], [0, 1, tau], [0, 0, 1]], rtol=1e-14)
    ref = q * np.array([[tau**5 / 20, tau**4 / 8, tau**3 / 6], [tau**4 / 8, tau**3 / 3, tau**2 / 2],
                        [tau**3 / 6, tau**2 / 2, tau]])
    np.testing.assert_allclose(Qd, ref, rtol=1e-9)


def test_van_loan_equals_a_fine_riemann_sum():
    rng = np.random.default_rng(4)
    F = rng.normal(size=(4, 4)) * 0.3
    G = rng.normal(size=(4, 2))
    Qc = np.diag([0.5, 2.0])
    dt = 0.7
    Phi, Qd = van_loan(F, G, Qc, dt)
    from scipy.linalg import expm

    n = 400
    s = (np.arange(n) + 0.5) * dt / n  # midpoint rule, error O((dt/n)²)
    ref = sum(expm(F * si) @ G @ Qc @ G.T @ expm(F * si).T for si in s) * dt / n
    np.testing.assert_allclose(Phi, expm(F * dt), rtol=1e-12)
    np.testing.assert_allclose(Qd, ref, rtol=2e-5, atol=1e-9)


def test_joseph_update_equals_the_textbook_form_for_the_optimal_gain():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(5, 5))
    P = A @ A.T + np.eye(5)
    H = rng.normal(size=(2, 5))
    R = np.diag([0.3, 0.7])
    x = rng.normal(size=5)
    z = rng.normal(size=2)
    u = update(x, P, z, H, R)
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    np.testing.assert_allclose(u.K, K, rtol=1e-12)
    np.testing.assert_allclose(u.P, (np.eye(5) - K @ H) @ P, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(u.x, x + K @ (z - H @ x), rtol=1e-12)
    assert u.nis == pytest.approx((z - H @ x) @ np.linalg.solve(H @ P @ H.T + R, z - H @ x))


def test_filter_on_its_own_model_is_consistent():
    """A random walk plus drift observed in noise: NEES and NIS averages inside χ² bands."""
    rng = np.random.default_rng(7)
    F = np.array([[0.0, 1.0], [0.0, 0.0]])
    Phi, Qd = van_loan(F, np.array([[0.0], [1.0]]), np.array([[0.01]]), 1.0)
    H, R = np.array([[1.0, 0.0]]), np.array([[0.25]])
    P0 = np.diag([1.0, 0.1])
    runs, steps = 200, 50
    nees_sum = nis_sum = 0.0
    for _ in range(runs):
        truth = rng.multivariate_normal(np.zeros(2), P0)
        x, P = np.zeros(2), P0
        for _ in range(steps):
            truth = Phi @ truth + rng.multivariate_normal(np.zeros(2), Qd)
            x, P = predict(x, P, Phi, Qd)
            u = update(x, P, H @ truth + rng.normal(0, 0.5, 1), H, R)
            x, P = u.x, u.P
            nis_sum += u.nis
        nees_sum += nees(x - truth, P)
    lo, hi = chi2.ppf([0.025, 0.975], 2 * runs) / runs
    assert lo < nees_sum / runs < hi
    lo, hi = chi2.ppf([0.025, 0.975], runs * steps) / (runs * steps)
    assert lo < nis_sum / (runs * steps) < hi
