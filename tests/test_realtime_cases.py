"""Turntable cases (gcalign.realtime.cases): the shape read from the rows, ramp corners in
closed form, a general turntable case end to end against the pure delay of its own truth,
and the lag at uniform rate (seed Fig. 4)."""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.realtime import (
    SensorSettings,
    Settings,
    accel_case,
    rate_case,
    run_case,
    summarise,
    swing_case,
)
from gcalign.realtime.cases import Case, describe
from gcalign.sim.schedule import AngleProfile, Step
from gcalign.units import ARCSEC, DEG

QUIET = SensorSettings(quantum=0.0, arw=0.0, dither_amplitude=0.0)
Z, X = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)


def test_the_shape_is_read_from_the_rows():
    r = describe(rate_case("r", -5 * DEG, 3.0, axis=X).steps)
    assert (r.kind, r.axis, r.rate) == ("rate", X, -5 * DEG)
    a = describe(accel_case("a", 10 * DEG, 15 * DEG, 5.0, jerk=100 * DEG).steps)
    assert (a.kind, a.rate, a.accel, a.jerk) == ("accel", 15 * DEG, 10 * DEG, 100 * DEG)
    assert describe(accel_case("a", -10 * DEG, -15 * DEG, 5.0, rest_s=0).steps).accel == \
        -10 * DEG
    s = describe(swing_case("s", 10 * DEG, 0.4, 3.0, phase=0.3).steps)
    assert (s.kind, s.amplitude, s.frequency, s.phase) == ("swing", 10 * DEG, 0.4, 0.3)
    trap = Step(Z, AngleProfile.trapezoid_rate(90 * DEG, rate=20 * DEG, accel=10 * DEG))
    assert describe((trap,)).kind == "turntable" and describe((trap,)).axis == Z
    two = (Step(Z, AngleProfile.constant_rate(DEG, 1.0)), Step(X, AngleProfile.rest(1.0)))
    assert describe(two).kind == "turntable"  # something after the moving row
    tilted = (Step(Z, AngleProfile.constant_rate(DEG, 1.0)),
              Step(X, AngleProfile.constant_rate(DEG, 1.0)))
    assert describe(tilted).axis is None
    assert Case(name="t", steps=tilted).component == 2  # heading when the axes differ


def test_ramp_corners_and_window_in_closed_form():
    """Rest 1 s; jerk j up to α in α/j, α held, then down in α/j to the rate limit ω:
    ω = α·(t_c + α/j), so t_c = ω/α − α/j."""
    a, w, j = 10 * DEG, 15 * DEG, 100 * DEG
    c = accel_case("a", a, w, 6.0, jerk=j)
    tj, tc = a / j, w / a - a / j
    np.testing.assert_allclose(c.corners(), [1.0, 1 + tj, 1 + tj + tc, 1 + 2 * tj + tc],
                               rtol=1e-12)
    assert c.accel_window() == pytest.approx((1.0, 1 + 2 * tj + tc), rel=1e-12)
    assert rate_case("r", DEG, 3.0).corners() == ()


def test_a_trapezoid_turn_lags_by_the_pure_delay_of_its_own_truth():
    """A 90° trapezoid turn (20 °/s, 10 °/s²) then a dwell: noise-free, before prediction
    the latched heading is θ(t − T) − θ(t) plus at most ½ασ² (0.011″) away from the
    corners; after prediction kalman-ls is within 1″ outside the corner windows."""
    rows = (Step(Z, AngleProfile.rest(1.0)),
            Step(Z, AngleProfile.trapezoid_rate(90 * DEG, rate=20 * DEG, accel=10 * DEG),
                 dwell=2.0))
    case = Case(name="trapezoid", steps=rows)
    assert case.kind == "turntable" and len(case.corners()) == 4
    s = Settings(sensor=QUIET)
    res = run_case(case, s, np.random.default_rng(0))
    t = res.pulses.t
    away = t >= s.settle_s
    for c in case.corners():
        away &= np.abs(t - c) > s.corner_s
    T = res.chain_delay
    delay = case.schedule.angle_rate_accel(t - T)[0] - case.schedule.angle_rate_accel(t)[0]
    e = res.error("none")[:, 2]
    assert np.max(np.abs(e - delay)[away]) < 0.012 * ARCSEC
    assert np.max(np.abs(delay[away])) == pytest.approx(20 * DEG * T, rel=1e-6)
    assert np.max(np.abs(res.error("kalman-ls")[away, 2])) < 1 * ARCSEC
    assert np.isnan(case.before_theory(T)) and np.isnan(summarise(res).lag)


def test_lag_at_uniform_rate_is_the_chain_delay_plus_dt():
    """Seed Fig. 4: the INS lags the table by T_chain (+ Δt, here 0.3 ms after each
    solution instant), noise-free to 1e-9 ms."""
    from gcalign.realtime import PulseSettings

    case = rate_case("r", 20 * DEG, 3.0)
    for offset in (0.0, 3e-4):
        s = Settings(sensor=QUIET, pulses=PulseSettings(offset_s=offset))
        res = run_case(case, s, np.random.default_rng(0))
        assert summarise(res).lag == pytest.approx(res.chain_delay + offset, abs=1e-12)
