"""Rotation schedules (gcalign.sim.schedule): profiles against their closed forms, the rate
against the derivative of the rotation, exact commanded angles, cycles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.nav.rotation import quat_conj, quat_mult, quat_to_rotvec
from gcalign.sim.schedule import AngleProfile, Schedule, Step

DEG = math.pi / 180.0
Z, X, Y = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)


def test_seed004_turn_numbers_and_exact_end():
    """180° in 4 + 4 + 4 s: 5.625 °/s², 22.5 °/s (spec 004 §2), ends at exactly π."""
    p = AngleProfile.trapezoid(math.pi, t_accel=4.0, t_const=4.0, t_decel=4.0)
    assert p.pieces[0].accel == pytest.approx(5.625 * DEG, rel=1e-15)
    assert p.pieces[1].rate == pytest.approx(22.5 * DEG, rel=1e-15)
    s = Schedule((Step(Z, p),))
    theta, w, a, _ = s.angle_rate_accel(np.array([0.0, 2.0, 6.0, 10.0, 12.0]))
    assert theta[-1] == pytest.approx(math.pi, abs=4e-16)
    np.testing.assert_allclose(w / DEG, [0.0, 11.25, 22.5, 11.25, 0.0], atol=1e-12)
    np.testing.assert_allclose(a / DEG, [5.625, 5.625, 0.0, -5.625, -5.625], atol=1e-12)
    # closed form of the first piece: θ = α t²/2
    assert s.angle_rate_accel(np.array([3.0]))[0][0] == pytest.approx(0.5 * 5.625 * DEG * 9)


@pytest.mark.parametrize("angle, rate, accel", [(math.pi, 0.4, 0.3), (0.1, 0.4, 0.3),
                                                (-2.0, 1.0, 20 * DEG)])
def test_trapezoid_by_rate_reaches_commanded_angle(angle, rate, accel):
    p = AngleProfile.trapezoid_rate(angle, rate=rate, accel=accel)
    s = Schedule((Step(Z, p),))
    theta, w, _, _ = s.angle_rate_accel(np.linspace(0.0, p.duration, 2001))
    assert theta[-1] == pytest.approx(angle, abs=1e-14)
    assert np.abs(w).max() <= rate * (1 + 1e-12) and w[-1] == pytest.approx(0.0, abs=1e-12)
    q_end = s.quat(np.array([p.duration + 5.0]))[0]  # past the end: final state holds
    np.testing.assert_allclose(quat_to_rotvec(q_end), [0.0, 0.0, angle], atol=1e-14)


def test_ramp_with_jerk_is_continuous_and_reaches_the_rate():
    p = AngleProfile.ramp(10 * DEG, 15 * DEG, 4.0, jerk=100 * DEG)
    t = np.linspace(0.0, 4.0, 40001)
    theta, w, a, _ = Schedule((Step(Z, p),)).angle_rate_accel(t)
    assert np.abs(np.diff(a)).max() < 100 * DEG * (t[1] - t[0]) * 1.0001  # jerk-limited
    assert w[-1] == pytest.approx(15 * DEG, rel=1e-12) and a[-1] == pytest.approx(0.0)
    # central differences: error ≤ max|jerk| h²/6 = 2.9e-9 rad/s here
    np.testing.assert_allclose(np.gradient(theta, t)[1:-1], w[1:-1], atol=4e-9)


def test_rate_is_the_derivative_of_the_rotation():
    """ω = u θ̇ in the rotating frame: rotvec(q(t)* q(t + h)) / h → ω (central)."""
    steps = (Step(Z, AngleProfile.trapezoid(math.pi, t_accel=4, t_const=4, t_decel=4), 3.0),
             Step(X, AngleProfile.swing(10 * DEG, 0.4, 5.0, phase=0.3)),
             Step(Y, AngleProfile.trapezoid_rate(-math.pi, rate=0.5, accel=0.4), 1.0))
    s = Schedule(steps, repeat=True, q0=(math.cos(0.2), 0.0, math.sin(0.2), 0.0))
    t = np.linspace(0.05, 3 * s.period, 997)
    h = 1e-5
    # away from the corners, where θ̈ jumps and a difference quotient straddles them
    corners = np.add.outer(np.arange(4) * s.period, s.tables()["t0"]).ravel()
    t = t[np.abs(t[:, None] - corners).min(1) > 4 * h]
    d = quat_to_rotvec(quat_mult(quat_conj(s.quat(t - h)), s.quat(t + h))) / (2 * h)
    np.testing.assert_allclose(d, s.rate(t), atol=2e-9)
    da = (s.rate(t + h) - s.rate(t - h)) / (2 * h)
    np.testing.assert_allclose(da, s.angular_accel(t), atol=2e-5)


def test_cycle_and_mean_of_the_seed_12_step_scheme():
    """The literal seed-004 scheme (spec §2 table) returns to its start; ∫C dt over a cycle
    is 4(Ts + Tz)·diag(−1, 1, 1) (the parity argument), here by quadrature."""
    axes = "zxyyxzzxyyxz"
    sense = [1] * 6 + [-1] * 6
    turn = {+1: AngleProfile.trapezoid(math.pi, t_accel=4, t_const=4, t_decel=4),
            -1: AngleProfile.trapezoid(-math.pi, t_accel=4, t_const=4, t_decel=4)}
    unit = {"x": X, "y": Y, "z": Z}
    s = Schedule(tuple(Step(unit[a], turn[d], dwell=300.0) for a, d in
                       zip(axes, sense, strict=True)), repeat=True)
    assert s.period == 3744.0
    np.testing.assert_allclose(np.abs(s.cycle_rotation), [1, 0, 0, 0], atol=1e-15)
    # Gauss-Legendre on every piece (the dwell pieces are constant).
    tb = s.tables()
    edges = np.append(tb["t0"], s.period)
    x, w = np.polynomial.legendre.leggauss(12)
    total = np.zeros((3, 3))
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        tt = 0.5 * (b - a) * x + 0.5 * (b + a)
        total += np.einsum("k,kij->ij", 0.5 * (b - a) * w, s.dcm(tt))
    np.testing.assert_allclose(total, 4 * 312.0 * np.diag([-1.0, 1.0, 1.0]), atol=1e-9)
    # The next cycle repeats the first.
    t = np.array([17.0, 400.5, 1000.0])
    np.testing.assert_allclose(s.quat(t + 2 * s.period), s.quat(t), atol=1e-14)


def test_bad_rows_are_refused():
    with pytest.raises(ValueError, match="unit vector"):
        Step((1.0, 1.0, 0.0), AngleProfile.rest(1.0))
    with pytest.raises(ValueError, match="dwell"):
        Step(Z, AngleProfile.rest(1.0), dwell=-1.0)
    with pytest.raises(ValueError, match="takes"):
        AngleProfile.ramp(1.0, 10.0, 2.0)
