"""Kalman steps (gcalign.estimation.kalman) against independent routes to the same numbers."""

from __future__ import annotations

import numpy as np
import pytest
from lazy import lazy_attr

from gcalign.estimation.kalman import nees, predict, update, van_loan

chi2 = lazy_attr("scipy.stats", "chi2")


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


@pytest.mark.slow
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


def test_rts_equals_the_batch_posterior():
    """The smoothed means and covariances of all epochs equal the marginals of the joint
    Gaussian posterior of x_0…x_K given every measurement (the information form), 1e-9."""
    from gcalign.estimation.kalman import rts

    rng = np.random.default_rng(12)
    n, m, K = 3, 1, 6
    F = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -0.2]])
    Phi, Qd = van_loan(F, np.array([[0.0], [0.0], [1.0]]), np.array([[0.3]]), 0.5)
    H, R = np.array([[1.0, 0.0, 0.0]]), np.array([[0.2]])
    P0 = np.diag([1.0, 0.5, 0.2])
    z = rng.normal(size=(K, m))
    x, P = np.zeros(n), P0
    xs_post, Ps_post, xs_pri, Ps_pri = [x], [P], [], []
    for k in range(K):
        x, P = predict(x, P, Phi, Qd)
        xs_pri.append(x)
        Ps_pri.append(P)
        u = update(x, P, z[k], H, R)
        x, P = u.x, u.P
        xs_post.append(x)
        Ps_post.append(P)
    xs, Ps = rts(np.repeat(Phi[None], K, 0), np.array(Ps_pri), np.array(xs_pri),
                 np.array(Ps_post), np.array(xs_post))
    # information form of the joint density over X = [x_0; …; x_K]
    N = n * (K + 1)
    Lam = np.zeros((N, N))
    eta = np.zeros(N)
    Lam[:n, :n] += np.linalg.inv(P0)
    Qi, Ri = np.linalg.inv(Qd), np.linalg.inv(R)
    for k in range(K):
        a, b = slice(k * n, (k + 1) * n), slice((k + 1) * n, (k + 2) * n)
        Lam[a, a] += Phi.T @ Qi @ Phi
        Lam[b, b] += Qi + H.T @ Ri @ H
        Lam[a, b] -= Phi.T @ Qi
        Lam[b, a] -= Qi @ Phi
        eta[b] += H.T @ Ri @ z[k]
    cov = np.linalg.inv(Lam)
    mean = cov @ eta
    for k in range(K + 1):
        s = slice(k * n, (k + 1) * n)
        np.testing.assert_allclose(xs[k], mean[s], rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(Ps[k], cov[s, s], rtol=1e-9, atol=1e-12)
    assert not np.allclose(xs[0], xs_post[0])  # smoothing moved the start: the check can fail


def test_solve_spd_on_a_badly_scaled_covariance():
    """A covariance mixing 1e-14 and 1e6 variances: the scaled solve keeps its relative
    accuracy, and agrees with a plain solve on a well-scaled one."""
    from gcalign.estimation.kalman import solve_spd

    rng = np.random.default_rng(2)
    A = rng.normal(size=(6, 6))
    C = A @ A.T + 6 * np.eye(6)
    d = np.array([1e-7, 1e-5, 1.0, 1e3, 1e-6, 10.0])
    P = C * np.outer(d, d)
    e = rng.normal(size=6) * d
    ref = np.linalg.solve(C, e / d) / d  # exact: P⁻¹ = D⁻¹ C⁻¹ D⁻¹
    np.testing.assert_allclose(solve_spd(P, e), ref, rtol=1e-12)
    np.testing.assert_allclose(solve_spd(C, e), np.linalg.solve(C, e), rtol=1e-12)


def _predict_numpy(x, P, Phi, Qd):
    """The predict as plain NumPy expressions (the slow reference of the kernel)."""
    M = Phi @ P @ Phi.T + Qd
    return Phi @ x, 0.5 * (M + M.T)


def _update_numpy(x, P, z, H, R, joseph_r_term=True):
    """The Joseph-form update as plain NumPy expressions, I − KH formed (the slow reference
    of the kernel); `joseph_r_term` False drops K R Kᵀ (a one-term change for the test)."""
    y = z - H @ x
    S = H @ P @ H.T + R
    K = P @ H.T @ np.linalg.inv(S)
    I_KH = np.eye(len(x)) - K @ H
    Pn = I_KH @ P @ I_KH.T + (K @ R @ K.T if joseph_r_term else 0.0)
    w = np.linalg.solve(np.linalg.cholesky(0.5 * (S + S.T)), y)
    return x + K @ y, 0.5 * (Pn + Pn.T), y, S, K, w


@pytest.mark.parametrize(("n", "m"), [(21, 2), (21, 3), (21, 6), (4, 1)])
def test_predict_and_update_kernels_equal_the_numpy_form(n, m):
    """The numba predict and Joseph update (the O(n² m) evaluation of the product) against
    the NumPy expressions with I − KH formed: every output to 1e-12 of its largest entry
    (a covariance on its correlation scale), on a covariance whose standard deviations
    span six decades, as an INS error state's do."""
    rng = np.random.default_rng(n * 10 + m)
    d = np.logspace(-4, 2, n)
    A = rng.normal(size=(n, n))
    P = (A @ A.T + n * np.eye(n)) * np.outer(d, d)
    P = 0.5 * (P + P.T)
    Phi = np.eye(n) + 0.05 * rng.normal(size=(n, n))
    Qd = np.diag(rng.uniform(0.1, 1.0, n) * d**2)
    x, z = rng.normal(size=n) * d, rng.normal(size=m)
    H = rng.normal(size=(m, n))
    R = np.diag(rng.uniform(0.1, 1.0, m))

    def close(a, b):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max())

    def scaled(M):  # a covariance on its correlation scale: entries of order one
        s = np.sqrt(np.diag(M))
        return M / np.outer(s, s)

    xp, Pp = predict(x, P, Phi, Qd)
    xr, Pr = _predict_numpy(x, P, Phi, Qd)
    close(xp, xr)
    close(scaled(Pp), scaled(Pr))
    assert np.array_equal(Pp, Pp.T)
    u = update(xp, Pp, z, H, R)
    ref = _update_numpy(xp, Pp, z, H, R)
    for a, b in zip((u.x, u.innovation, u.S, u.standardized), ref[:1] + ref[2:4] + ref[5:],
                    strict=True):
        close(a, b)
    close(scaled(u.P), scaled(ref[1]))
    close(u.K / d[:, None], ref[4] / d[:, None])
    assert u.nis == pytest.approx(float(ref[-1] @ ref[-1]), rel=1e-12)
    assert np.array_equal(u.P, u.P.T)
    # the check can fail: the same reference without its K R Kᵀ term is far from it
    assert np.abs(scaled(_update_numpy(xp, Pp, z, H, R, False)[1]) - scaled(u.P)).max() > 1e-6


def test_update_refuses_an_innovation_covariance_that_is_not_positive_definite():
    P, H = np.eye(3), np.array([[1.0, 0.0, 0.0]])
    with pytest.raises(np.linalg.LinAlgError):
        update(np.zeros(3), P, np.zeros(1), H, np.array([[-2.0]]))
