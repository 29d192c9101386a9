"""Observability of transfer alignment on the simulated wing-rock drive by the library's
piece-wise constant systems + SVD (:mod:`gcalign.estimation.observability`, seed 002 §3),
with the continuous model of :mod:`gcalign.transfer.model`: the same structure the filter's
covariance shows (spec 006, "What the data support"). Then the table of
:func:`gcalign.transfer.observability.transfer_observability` on the filter's own run,
against the rank argument of attitude matching on a roll about body y: the combination
(φ along the forward axis d, μ along J_l(μ)⁻¹ e_y, the tangent of turning the slave about
d) is an exact null vector of the filter's H (decision 019) without the earth rate."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gcalign.estimation.observability import degree, piece_matrix, separation, tom
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm, quat_to_dcm, rotvec_to_quat
from gcalign.transfer import transfer_align
from gcalign.transfer.filter import P0_SIGMA_DEFAULT
from gcalign.transfer.model import error_matrix, measurement_matrix
from gcalign.transfer.observability import transfer_observability
from gcalign.transfer.simulate import transfer_case

MU = (12, 13, 14)


@pytest.fixture(scope="module")
def pieces():
    """F, duration and C_nb of 1 s pieces of a 20 s case (the slave frame: body ∘ μ)."""
    c = transfer_case(np.random.default_rng(5), duration=20.0)
    ts, per = 0.01, 100
    C_mu = quat_to_dcm(rotvec_to_quat(c.mu))
    Fs, Cs = [], []
    for j in range(len(c.t) // per):
        k = slice(j * per, (j + 1) * per)
        C_all = euler_to_dcm(c.truth.att[1:][k]) @ C_mu
        f_n = np.einsum("kij,kj->i", C_all, c.dv[k]) / (per * ts)  # mean over the piece
        mid = j * per + per // 2
        C = euler_to_dcm(c.truth.att[mid]) @ C_mu
        lat, h, v = c.truth.pos[mid, 0], c.truth.pos[mid, 2], c.truth.v_n[mid]
        w_in = WGS84.omega_ie_n(lat) + WGS84.omega_en_n(lat, h, v)
        Fs.append(error_matrix(C, f_n, w_in))
        Cs.append(C)
    return np.array(Fs), np.ones(len(Fs)), Cs, c.settings.p0_sigma


def _tom(pieces, matching):
    Fs, d, Cs, _ = pieces
    O = [piece_matrix(F, measurement_matrix(C, matching)) for F, C in zip(Fs, Cs, strict=True)]
    return tom(O, Fs, d)


def test_velocity_matching_cannot_see_mu(pieces):
    Q = _tom(pieces, "velocity")
    assert np.max(np.abs(Q[:, 12:15])) == 0.0  # μ enters neither H nor F: its σ stays at P0
    assert degree(Q, measured=[3, 4, 5]).rank <= 12


def test_attitude_matching_sees_roll_axis_mu_only_weakly(pieces):
    """How far μ_y's column is from the φ columns' span, against μ_x and μ_z: with the
    vehicle rolling about body y only, μ_y acts like a constant attitude error along the
    forward axis, told apart only through the earth rate (and, with velocity matching,
    through the tilt the velocity sees). Measured (relative residual of the μ x, y, z
    columns): attitude (3.6e-3, 1.5e-5, 1.1e-3), attitude+velocity (0.19, 0.95, 0.19)."""
    p0 = np.asarray(pieces[3])
    sep = {}
    for matching in ("attitude", "attitude+velocity"):
        Q = _tom(pieces, matching) * p0  # columns in units of their initial σ
        # residual of each μ column after projecting out the span of the other 14 columns
        res = []
        for k in MU:
            others = np.delete(Q, k, axis=1)
            coef, *_ = np.linalg.lstsq(others, Q[:, k], rcond=None)
            res.append(np.linalg.norm(Q[:, k] - others @ coef) / np.linalg.norm(Q[:, k]))
        sep[matching] = np.array(res)
    a, av = sep["attitude"], sep["attitude+velocity"]
    assert a[1] < 0.05 * min(a[0], a[2]), a        # roll axis: nearly a combination of others
    assert av[1] > 10 * a[1], (a, av)                # velocity matching separates it
    assert separation(_tom(pieces, "attitude"), 13, 1) > 0  # not exactly zero: earth rate


# ------------------------------------------------------------------ the filter's own F and H

@pytest.fixture(scope="module")
def attitude_run():
    """The command's route on the case (from the master's attitude, the demo's P0 of φ,
    attitude feedback), attitude matching; and the slave's true attitude at its epochs."""
    c = transfer_case(np.random.default_rng(3), duration=20.0)
    p0 = (*(P0_SIGMA_DEFAULT[0],) * 3, *c.settings.p0_sigma[3:])
    s = replace(c.settings, p0_sigma=p0, attitude_feedback=True, matching="attitude")
    r = transfer_align(c.dtheta, c.dv, c.t, c.master, s)
    k = np.rint(r.t / 0.01).astype(int)
    C_mu = quat_to_dcm(rotvec_to_quat(c.mu))
    return c, r, euler_to_dcm(c.truth.att[k]) @ C_mu, C_mu


def _null(c, r):
    """(φ = C_b(0) e_y, μ = J_l(μ)⁻¹ e_y), scaled by P0 σ and normalised."""
    from gcalign.transfer.model import left_jacobian_inv

    x = np.zeros(15)
    x[0:3] = euler_to_dcm(c.truth.att[0]) @ [0.0, 1.0, 0.0]
    x[12:15] = left_jacobian_inv(c.mu) @ [0.0, 1.0, 0.0]
    y = x / np.asarray(r.sigma0[:15])
    return y / np.linalg.norm(y)


def test_roll_axis_combination_is_exactly_unobservable_without_earth_rate(attitude_run):
    """Rank argument (attitude matching, roll about body y only): with the truth in the
    filter's H (the master's attitude C_b(t) without noise, μ̂ = μ: ``H(φ, φ) =
    J_l(C_b μ)⁻¹ = C_b J_l(μ)⁻¹ C_bᵀ``, ``H(φ, μ) = −C_b``) and ω_in = 0, x = (φ = d =
    C_b(t) e_y, μ = J_l(μ)⁻¹ e_y) gives H x = C_b J_l(μ)⁻¹ e_y − C_b J_l(μ)⁻¹ e_y = 0 and
    F x = 0 in the attitude rows, on every piece: an exact null vector. The weakest
    combination of the table is it (scaled by P0 σ) to round-off, with σ_min/σ_max at
    round-off; the earth rate lifts it to ~1e-6."""
    from gcalign.nav.rotation import euler_to_quat

    c, r, C_true, C_mu = attitude_run
    k = np.rint(r.t / 0.01).astype(int)
    x_true = r.x.copy()
    x_true[:, 12:15] = c.mu
    truth = replace(r, C_nb=C_true, q_master=euler_to_quat(c.truth.att[k]), x=x_true)
    flat = transfer_observability(replace(truth, omega_in_n=0 * r.omega_in_n))
    y = _null(c, r)
    assert flat.weakest_ratio < 1e-14
    np.testing.assert_allclose(flat.weakest, y, atol=1e-12)
    earth = transfer_observability(truth)
    assert 1e-8 < earth.weakest_ratio < 1e-4
    np.testing.assert_allclose(earth.weakest, y, atol=1e-3)


def test_the_filter_own_model_keeps_the_roll_axis_weakest(attitude_run):
    """The filter's own model (the master's noisy attitude, its μ̂, its mechanised C_nb in
    F) moves the weakest combination by less than 0.02 from the closed form, and it is
    mostly μ_y (> 0.99 of the unit vector); σ_min/σ_max 1.9e-4 against the truth's 1.5e-6."""
    c, r, _, C_mu = attitude_run
    own = transfer_observability(r)
    y = _null(c, r)
    assert np.abs(own.weakest - y).max() < 0.02 and own.weakest[13] > 0.99
    assert own.weakest_ratio < 1e-2
