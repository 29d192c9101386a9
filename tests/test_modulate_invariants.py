"""The invariant report (gcalign.modulate.invariants) against the spec's closed forms and the
parity argument (spec 004 §2, §3, §5 d), and against independent routes: closed forms per
turn, a dense trapezoid sum, and the attitude integrated from the erroneous gyro."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.modulate.invariants import invariant_report, running_integrals
from gcalign.modulate.schemes import BUILTIN_NAMES, Row, Turn, builtin_scheme, scheme_from_rows
from gcalign.modulate.terms import SEED004_LAT, ErrorTerms
from gcalign.nav.earth import SEED004
from gcalign.nav.rotation import misalignment, quat_mult, quat_to_dcm, rotvec_to_quat
from gcalign.units import DPH

PARITY = np.diag([-1.0, 1.0, 1.0])
INDEXING = ["single-4", "dual-16", "dual-16-improved", "seed-12", "four-position-12",
            "four-position-24"]


@pytest.mark.parametrize("dwell, turn", [
    (300.0, Turn(4.0, 4.0, 4.0)),   # the patent's timing
    (200.0, Turn(2.0, 8.0, 2.0)),
    (60.0, Turn(6.0, 0.0, 6.0)),    # triangular profile
    (17.3, Turn(0.5, 11.0, 0.5)),
    (0.0, Turn(3.0, 1.0, 3.0)),     # always turning
])
def test_seed12_integral_is_four_Ts_plus_Tz_times_parity(dwell, turn):
    """∫_cycle C_s^b dt = 4(Ts + Tz)·diag(−1, 1, 1) for any Ts, Tz and symmetric profile
    (spec §2, §5 d), to 1e-12 relative."""
    s = builtin_scheme("seed-12", dwell=dwell, turn=turn)
    tz = turn.t_accel + turn.t_const + turn.t_decel
    r = invariant_report(s)
    expected = 4.0 * (dwell + tz) * PARITY
    np.testing.assert_allclose(r.integral_C, expected, rtol=0, atol=1e-12 * 4 * (dwell + tz))
    np.testing.assert_allclose(r.mean_C, PARITY / 3.0, atol=1e-13)


def test_seed12_by_rate_and_acceleration_rows():
    """The same with turns given by rate and acceleration (30 °/s, 10 °/s²)."""
    rows = [Row(r.axis, r.angle, 250.0, rate=math.radians(30), accel=math.radians(10))
            for r in builtin_scheme("seed-12").rows]
    s = scheme_from_rows(rows)
    tz = s.schedule.steps[0].profile.duration
    np.testing.assert_allclose(invariant_report(s).integral_C, 4 * (250.0 + tz) * PARITY,
                               atol=1e-12 * s.period)


def test_identity_needs_a_common_profile_not_a_symmetric_one():
    """The spec asks for a symmetric profile (∫cos θ dt = 0 per turn). Not needed: with one
    profile for all twelve turns the cos θ terms cancel over each half cycle as well
    (Σ C_before (I − u uᵀ) = 0 over steps 1–6), so an asymmetric 2/4/6 s turn keeps the
    identity. Giving step 1 alone a different profile breaks it by far more than
    round-off."""
    s = builtin_scheme("seed-12", turn=Turn(2.0, 4.0, 6.0))
    np.testing.assert_allclose(invariant_report(s).integral_C, 4 * 312.0 * PARITY,
                               atol=1e-12 * s.period)
    rows = list(builtin_scheme("seed-12").rows)
    rows[0] = Row(rows[0].axis, rows[0].angle, rows[0].dwell, t_accel=2.0, t_const=4.0,
                  t_decel=6.0)
    dev = invariant_report(scheme_from_rows(rows)).integral_C - 4 * 312.0 * PARITY
    assert np.abs(dev).max() > 0.5  # s: the sine and cosine terms of step 1 (≈ 1.6 s)


def test_parity_argument_on_the_dwell_positions():
    """Each diagonal entry of the mean over the three positions is a sum of three ±1: odd."""
    pos = [np.eye(3), np.diag([-1.0, -1, 1]), np.diag([-1.0, 1, -1])]  # A, B, C
    total = sum(pos)
    assert np.all(np.abs(np.diag(total)) % 2 == 1)
    np.testing.assert_array_equal(total, PARITY)


@pytest.mark.parametrize("name", ["dual-16", "dual-16-improved", "four-position-12",
                                  "four-position-24"])
def test_cancelling_schemes_have_zero_mean(name):
    r = invariant_report(builtin_scheme(name))
    assert np.abs(r.integral_C).max() < 1e-12 * r.period
    e = ErrorTerms.seed004()
    assert np.abs(r.residual_gyro_bias).max() < 1e-12 * e.gyro_bias[0]


@pytest.mark.parametrize("name, mean", [("single-4", np.diag([0.0, 0, 1])),
                                        ("continuous", np.diag([0.0, 0, 1])),
                                        ("fixed", np.eye(3))])
def test_schemes_that_leave_an_axis(name, mean):
    np.testing.assert_allclose(invariant_report(builtin_scheme(name)).mean_C, mean, atol=1e-13)


def test_seed12_residual_biases_are_a_third():
    e = ErrorTerms(gyro_bias=np.array([1.0, 2.0, 3.0]) * 0.01 * DPH,
                   accel_bias=np.array([3.0, -1.0, 2.0]) * 1e-4)
    r = invariant_report(builtin_scheme("seed-12"), e)
    np.testing.assert_allclose(r.residual_gyro_bias, PARITY @ e.gyro_bias / 3, rtol=1e-12)
    np.testing.assert_allclose(r.residual_accel_bias, PARITY @ e.accel_bias / 3, rtol=1e-12)


def test_quadrature_against_a_dense_trapezoid_sum():
    """A user scheme with an oblique axis and a constant-rate turn: ∫C dt, the rate tensor
    and the running-integral peak agree with a 0.5 ms trapezoid sum (error ~1e-8)."""
    u = (0.6, 0.0, 0.8)
    rows = [Row(u, math.pi, 7.0, t_accel=2.0, t_const=1.0, t_decel=3.0),
            Row((0.0, 1.0, 0.0), 2 * math.pi, 3.0, rate=1.0),
            Row(u, -math.pi, 5.0, rate=0.8, accel=0.5)]
    s = scheme_from_rows(rows)
    r = invariant_report(s)
    # midpoint sums, cells of ≤ 1 ms inside each piece (the rate jumps at piece ends)
    t0 = np.append(s.schedule.tables()["t0"], s.period)
    edges = np.concatenate([np.linspace(a, b, max(2, int((b - a) / 1e-3)) + 1)[:-1]
                            for a, b in zip(t0[:-1], t0[1:], strict=True)] + [[s.period]])
    dt, mid = np.diff(edges), 0.5 * (edges[1:] + edges[:-1])
    Ct = s.schedule.dcm(mid)
    W = np.einsum("nai,nj->naij", Ct, s.schedule.rate(mid))
    np.testing.assert_allclose(r.integral_C, np.tensordot(dt, Ct, axes=(0, 0)), atol=1e-6)
    np.testing.assert_allclose(r.rate_tensor, np.tensordot(dt, W, axes=(0, 0)), atol=1e-6)
    run = np.cumsum(Ct * dt[:, None, None], 0)
    np.testing.assert_allclose(r.peak_integral_C, np.linalg.norm(run, axis=1).max(0), rtol=3e-5)


def _step_closed_forms(scheme, K, M):
    """Per step j about sensor axis u from C_before: scale-factor term Θ δk_u C_before u and
    misalignment term C_before ∫_0^Θ R_u(θ) dθ M u = 2 C_before (u × M u) for Θ = ±π
    (R_u(θ) = cos θ I + sin θ [u×] + (1 − cos θ) u uᵀ; M_uu = 0), and 0 for a full turn."""
    sf, mis, Cb = [np.zeros(3)], [np.zeros(3)], np.eye(3)
    for r in scheme.rows:
        u, th = np.asarray(r.axis), r.angle
        sf.append(sf[-1] + th * K[np.argmax(np.abs(u)), np.argmax(np.abs(u))] * (Cb @ u))
        integral = (math.sin(th) * np.eye(3) + (1 - math.cos(th)) * _skew(u)
                    + (th - math.sin(th)) * np.outer(u, u))
        mis.append(mis[-1] + Cb @ integral @ (M @ u))
        Cb = Cb @ quat_to_dcm(rotvec_to_quat(u * th))
    return np.array(sf), np.array(mis)


def _skew(u):
    return np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])


@pytest.mark.parametrize("name", INDEXING + ["continuous"])
def test_rate_terms_match_the_step_closed_forms(name):
    s = builtin_scheme(name)
    K = np.diag([1.0, 2.0, 3.0])
    M = np.array([[0, 1.0, -2.0], [0.5, 0, 1.5], [-1.0, 3.0, 0]])
    e = ErrorTerms(gyro_scale=np.diag(K), gyro_misalignment=M)
    r = invariant_report(s, e)
    sf, mis = _step_closed_forms(s, K, M)
    np.testing.assert_allclose(r.scale_factor_net, sf[-1], atol=1e-12)
    np.testing.assert_allclose(r.misalignment_net, mis[-1], atol=1e-12)
    np.testing.assert_allclose(r.scale_factor_peak, np.abs(sf).max(0), atol=1e-12)


@pytest.mark.parametrize("name", INDEXING + ["continuous"])
def test_asymmetric_scale_factor_closed_form_per_step(name):
    """δk_asym ⊙ |ω| per step about sensor axis u from C_before: |Θ| δk_u C_before u,
    whatever the sense. The ccw and cw halves of seed-12 therefore add: 4π·diag(−1, 1, 1)
    δk per cycle (0.0069 °/h of residual drift for 10 ppm); four-position-12 (all turns
    one way, its symmetric term cancels) and the dual schemes cancel it."""
    s = builtin_scheme(name)
    k = np.array([1.0, 2.0, 3.0])
    r = invariant_report(s, ErrorTerms(gyro_asym=k))
    net, Cb = np.zeros(3), np.eye(3)
    for row in s.rows:
        u, th = np.asarray(row.axis), row.angle
        net += abs(th) * k[np.argmax(np.abs(u))] * (Cb @ u)
        Cb = Cb @ quat_to_dcm(rotvec_to_quat(u * th))
    np.testing.assert_allclose(r.asym_net, net, atol=1e-12)
    expected = {"seed-12": 4 * math.pi * PARITY @ k, "four-position-12": np.zeros(3),
                "four-position-24": np.zeros(3), "dual-16": np.zeros(3),
                "dual-16-improved": np.zeros(3)}
    if name in expected:
        np.testing.assert_allclose(r.asym_net, expected[name], atol=1e-12)
    if name == "seed-12":
        drift = invariant_report(s, ErrorTerms(gyro_asym=np.full(3, 10e-6))).asym_net / s.period
        assert np.abs(drift) / DPH == pytest.approx(np.full(3, 0.0069), abs=5e-5)


@pytest.mark.parametrize("name, peaks", [
    ("seed-12", [2 * math.pi] * 3),                    # spec §2: 2π δk on each axis
    ("four-position-12", [math.pi, math.pi, 2 * math.pi]),
    ("four-position-24", [math.pi, math.pi, 2 * math.pi]),
    ("single-4", [0.0, 0.0, math.pi]),
])
def test_scale_factor_returns_to_zero_with_the_implied_peaks(name, peaks):
    """Per unit δk (different on each axis, so that axes cannot hide one another): the
    net term over a cycle is < 1e-9 rad and the in-cycle peaks are as the schedule implies
    (spec 004's scale-factor invariant)."""
    dk = np.array([1.0, 1.3, 0.7])
    r = invariant_report(builtin_scheme(name), ErrorTerms(gyro_scale=dk))
    assert np.abs(r.scale_factor_net).max() < 1e-9
    np.testing.assert_allclose(r.scale_factor_peak, np.array(peaks) * dk, atol=1e-12)


def test_scale_factor_for_10_ppm_reaches_13_arcsec_in_the_seed_scheme():
    r = invariant_report(builtin_scheme("seed-12"), ErrorTerms(gyro_scale=np.full(3, 10e-6)))
    np.testing.assert_allclose(r.scale_factor_peak / (math.pi / 180 / 3600), 12.96, atol=0.01)


def test_dual_schemes_cancel_scale_factor_too():
    for name in ("dual-16", "dual-16-improved"):
        r = invariant_report(builtin_scheme(name), ErrorTerms(gyro_scale=np.ones(3)))
        assert np.abs(r.scale_factor_net).max() < 1e-9, name


def test_continuous_rotation_accumulates_two_pi_per_turn():
    dk = np.array([0.0, 0.0, 1.0])
    r = invariant_report(builtin_scheme("continuous"), ErrorTerms(gyro_scale=dk))
    np.testing.assert_allclose(r.scale_factor_net, [0, 0, 2 * math.pi], atol=1e-12)


def test_seed12_misalignment_cancels_because_each_edge_is_run_both_ways():
    M = np.array([[0, 1.0, -2.0], [0.5, 0, 1.5], [-1.0, 3.0, 0]])
    r = invariant_report(builtin_scheme("seed-12"), ErrorTerms(gyro_misalignment=M))
    assert np.abs(r.misalignment_net).max() < 1e-9
    assert r.misalignment_peak.max() > 1.0  # but not within the cycle


def _computed_attitude(scheme, G):
    """The attitude integrated from a gyro that measures G ω (G = I + δK + M): a turn about
    the sensor axis u by θ is sensed as the rotation vector G u θ (the axis is fixed within
    the step, so this is exact), step after step. Returns the true and computed C at every
    step end."""
    q_true, q_comp = np.array([1.0, 0, 0, 0]), np.array([1.0, 0, 0, 0])
    out_t, out_c = [], []
    for r in scheme.rows:
        u = np.asarray(r.axis)
        q_true = quat_mult(q_true, rotvec_to_quat(u * r.angle))
        q_comp = quat_mult(q_comp, rotvec_to_quat(G @ u * r.angle))
        out_t.append(quat_to_dcm(q_true))
        out_c.append(quat_to_dcm(q_comp))
    return np.array(out_t), np.array(out_c)


@pytest.mark.parametrize("name", ["seed-12", "four-position-12", "dual-16"])
def test_open_loop_term_is_the_gyro_only_attitude_error(name):
    """Second route: integrate the erroneous gyro through the rows and compare the attitude
    error C̃ Cᵀ ≈ I − [φ×] with φ = −m at every step end (first order; δ ~ 1e-7)."""
    s = builtin_scheme(name)
    K = np.diag([1.0, -2.0, 1.5]) * 1e-7
    M = np.array([[0, 1.0, -0.5], [0.7, 0, 0.4], [-0.3, 0.9, 0]]) * 1e-7
    r = invariant_report(s, ErrorTerms(gyro_scale=np.diag(K), gyro_misalignment=M))
    C_true, C_comp = _computed_attitude(s, np.eye(3) + K + M)
    phi = misalignment(C_comp, C_true)
    # running terms at the step ends: the last grid point of each row's turn
    ends = np.cumsum([st.duration for st in s.schedule.steps])
    idx = [int(np.argmin(np.abs(r.t - e))) for e in ends]
    m = np.einsum("kaij,ij->ka", r.running_rate[idx], K + M)
    np.testing.assert_allclose(phi, -m, atol=2e-12)  # second order: |m|² ≈ 5e-13
    assert np.abs(m).max() > 5e-7


def test_schuler_warning_fires_for_dual16_at_the_seed_timing_only():
    """Spec §3: 16·312 s = 83.2 min against the Schuler period 84.46 min; Ts = 200 s gives
    56.5 min, outside ±20 %."""
    r = invariant_report(builtin_scheme("dual-16"))
    assert r.schuler_period / 60 == pytest.approx(84.46, abs=0.01)
    ws = SEED004.schuler_rate(SEED004_LAT)
    assert ws == pytest.approx(1.23992e-3, rel=1e-5)  # spec §5
    assert r.schuler_warning and "83.2 min" in r.warnings[0]
    assert r.harmonics[0].k == 1
    w1 = 2 * math.pi / r.period
    assert r.harmonics[0].attenuation == pytest.approx(ws**2 / abs(w1**2 - ws**2), rel=1e-12)
    assert invariant_report(builtin_scheme("dual-16-improved")).schuler_warning
    for name, kw in [("dual-16", {"dwell": 200.0}), ("dual-16-improved", {"dwell": 200.0}),
                     ("seed-12", {}), ("four-position-12", {}), ("fixed", {}),
                     ("single-4", {}), ("continuous", {})]:
        assert not invariant_report(builtin_scheme(name, **kw)).schuler_warning, (name, kw)


def test_schuler_warning_checks_harmonics_not_only_the_cycle():
    """A single-axis ±180° scheme whose cycle is twice the Schuler period modulates C at
    T/2 (positions A, B, A, B…): harmonic 2 sits on Schuler and must warn; harmonic 1
    (±20 % band excludes it) must not be the reason."""
    ts = 2 * math.pi / SEED004.schuler_rate(SEED004_LAT)
    # 4 steps of ts/2 each: C alternates A/B every ts/2 → period of C is ts
    dwell = 0.5 * ts - 12.0
    r = invariant_report(builtin_scheme("single-4", dwell=dwell))
    assert r.period == pytest.approx(2 * ts)
    assert [h.k for h in r.harmonics] == [2] and r.schuler_warning


def test_fourier_amplitude_of_a_square_wave():
    """Single-axis scheme with instant-like turns: C_xx is a ±1 square wave of period T/2
    (harmonic 2 of the cycle), amplitude 4/π — minus what the 0.2 s turns take."""
    from gcalign.modulate.invariants import modulation_harmonic
    s = builtin_scheme("single-4", dwell=1000.0, turn=Turn(0.1, 0.0, 0.1)).schedule
    c2 = modulation_harmonic(s, 2)
    assert 2 * abs(c2[0, 0]) == pytest.approx(4 / math.pi, rel=1e-3)
    assert abs(modulation_harmonic(s, 1)[0, 0]) < 1e-12


def test_running_integrals_start_at_zero_and_end_at_the_cycle_integral():
    s = builtin_scheme("four-position-12").schedule
    run = running_integrals(s)
    assert run.t[0] == 0 and run.t[-1] == pytest.approx(s.period)
    np.testing.assert_array_equal(run.C[0], 0)
    # cycle mean of the running integral by parts vs the mean of the sampled running values
    # (dwell pieces are linear between samples: trapezoid is exact there)
    trap = np.tensordot(np.diff(run.t), 0.5 * (run.C[1:] + run.C[:-1]), axes=(0, 0)) / s.period
    np.testing.assert_allclose(run.mean_C, trap, atol=1e-3)


@pytest.mark.parametrize("name", BUILTIN_NAMES)
def test_report_is_complete_for_every_builtin(name):
    r = invariant_report(builtin_scheme(name))
    assert r.scheme == name and r.period > 0
    for v in (r.peak_integral_C, r.gyro_bias_excursion, r.scale_factor_peak):
        assert v.shape == (3,) and np.all(np.isfinite(v))
