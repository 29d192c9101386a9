"""Motions with truth at any time (gcalign.sim.motions): sampled truth against the motion
itself, the analytic motion between samples, an independent integration of the position,
flight targets, exact commanded angles (core issue, must-show 2)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from lazy import lazy_attr

from gcalign.app.data import gather, scenario_stream
from gcalign.io.scenario import parse_scenario
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm, quat_to_rotvec, rotvec_to_quat
from gcalign.sim.motions import FlightSegment, Moving, Segment, Swing, flight
from gcalign.sim.schedule import AngleProfile, Schedule, Step

solve_ivp = lazy_attr("scipy.integrate", "solve_ivp")

ROOT = Path(__file__).resolve().parents[1]
D = math.pi / 180.0
SITE = np.array([45.7796 * D, 126.6705 * D, 100.0])
FLIGHT = yaml.safe_load((ROOT / "configs/seed002_designed.yaml").read_text())


def _flight_scenario(rate_hz=100.0):
    data = dict(FLIGHT, imu={"rate_hz": rate_hz})
    return parse_scenario(data, "flight")


@pytest.mark.slow
@pytest.mark.parametrize("rate_hz", [100.0, 130.0])
def test_sampled_truth_equals_truth_at_those_times(rate_hz):
    """Streamed blocks (sampled at 100 Hz, and at 130 Hz where segment boundaries fall
    inside samples) carry exactly the motion's truth at the sample instants."""
    sc = _flight_scenario(rate_hz)
    data = gather(scenario_stream(sc, block=4096))
    motion = sc.motion.to_motion()
    t = data.truth.t
    seg = motion.segment_index(t, side="left")
    kin = motion.kinematics(t, data.site, WGS84, segment=seg)
    np.testing.assert_allclose(data.truth.att, kin.att, rtol=0, atol=1e-12)
    np.testing.assert_allclose(data.truth.v_n, kin.v_n, rtol=0, atol=1e-12 * 165)
    np.testing.assert_allclose(data.truth.pos[:, :2], kin.pos[:, :2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(data.truth.pos[:, 2], kin.pos[:, 2], rtol=1e-12, atol=1e-9)


def test_moving_truth_is_analytic_between_samples():
    """Between samples: Euler angles linear with the segment rates, speed linear with its
    acceleration, velocity along the body's forward axis."""
    m = Moving((0.0, 0.0, 0.5), 40.0, (Segment(10.0, 1.0), Segment(30.0, -0.2, (0.01, 0.0, -0.02))))
    t = np.array([3.3333, 10.0, 17.123456, 39.9])
    att, rate, speed, accel = m.euler(t)
    np.testing.assert_allclose(speed, [3.3333, 10.0, 10 - 0.2 * 7.123456, 10 - 0.2 * 29.9])
    np.testing.assert_allclose(att[2], [0.0, 0.0, 0.5 + 0.01 * 7.123456 * 0 + 0.0][0] + att[2])
    np.testing.assert_allclose(att[:, 2], [0.5, 0.5, 0.5 - 0.02 * 7.123456, 0.5 - 0.02 * 29.9])
    np.testing.assert_allclose(att[:, 0], [0.0, 0.0, 0.01 * 7.123456, 0.01 * 29.9])
    kin = m.kinematics(t, SITE)
    np.testing.assert_allclose(kin.v_n, speed[:, None] * euler_to_dcm(att)[:, :, 1], atol=1e-14)


def test_position_matches_an_independent_integration():
    """Latitude, longitude and height from scipy's adaptive integrator (rtol 1e-12) of the
    position equations along the flight's own velocity: agreement to 1 mm over 590 s."""
    motion = _flight_scenario().motion.to_motion()
    site = np.array([38.0 * D, 121.0 * D, 0.0])

    def rate(t, p):
        v, *_ = motion.velocity(np.array([t]))
        r_m, r_n = WGS84.radii(p[0])
        return [v[0, 1] / (r_m + p[2]), v[0, 0] / ((r_n + p[2]) * math.cos(p[0])), v[0, 2]]

    times = np.sort(np.random.default_rng(3).uniform(0, motion.duration, 25))
    starts = np.cumsum([0.0] + [s.duration for s in motion.segments])
    # integrate segment by segment (the rates jump at the boundaries)
    pos, p = [], site.copy()
    for a, b in zip(starts[:-1], starts[1:], strict=True):
        inside = times[(times >= a) & (times < b)]
        sol = solve_ivp(rate, (a, b), p, t_eval=np.append(inside, b), rtol=1e-12, atol=1e-14,
                        method="DOP853")
        pos += list(sol.y.T[:-1])
        p = sol.y[:, -1]
    pos = np.array(pos)
    got = motion.position(times, site)
    r = WGS84.a
    np.testing.assert_allclose((got[:, :2] - pos[:, :2]) * r, 0.0, atol=1e-3)
    np.testing.assert_allclose(got[:, 2], pos[:, 2], atol=1e-3)


def test_flight_targets_and_envelope():
    """The designed take-off (spec 002 §3): 90 m/s after the 13.846 s ground roll, the
    pitch-up ends at 60°, a turn pair restores the heading, 590 s, about 8 km up."""
    motion = _flight_scenario().motion.to_motion()
    assert motion.duration == pytest.approx(590.0, abs=1e-3)
    starts = np.cumsum([0.0] + [s.duration for s in motion.segments])
    _, _, speed, _ = motion.euler(np.array([starts[2]]))
    assert speed[0] == pytest.approx(90.0, rel=1e-12) and starts[2] - starts[1] == pytest.approx(
        90 / 6.5)
    att, _, _, _ = motion.euler(np.array([starts[3]]))
    assert att[0, 0] == pytest.approx(60 * D, rel=1e-12)
    names = [s.name for s in motion.segments]
    i = names.index("right turn 90")
    a0 = motion.euler(np.array([starts[i]]))[0][0, 2]
    a1 = motion.euler(np.array([starts[i + 4]]))[0][0, 2]
    assert a1 == pytest.approx(a0, abs=1e-12)
    h = motion.position(np.linspace(0, 590, 591), np.array([38 * D, 121 * D, 0.0]))[:, 2]
    assert 7900 < h.max() < 8100


def test_flight_targets_that_cannot_be_reached_are_refused():
    with pytest.raises(ValueError, match="needs 30 s at the given rate"):
        flight((0.0, 0.0, 0.0), [FlightSegment("pitch", duration=10.0, rate=2 * D, angle=60 * D)],
               speed0=90.0)
    with pytest.raises(ValueError, match="moves away"):
        flight((0.0, 0.0, 0.0), [FlightSegment("accelerate", accel=-1.0, speed=10.0)])
    # a target reached early is held for the rest of the segment
    m = flight((0.0, 0.0, 0.0), [FlightSegment("roll", duration=20.0, rate=5 * D, angle=-45 * D)])
    assert [s.duration for s in m.segments] == pytest.approx([9.0, 11.0])
    assert m.euler(np.array([15.0]))[0][0, 1] == pytest.approx(-45 * D)


def test_turntable_reaches_exactly_its_commanded_angle():
    """A trapezoid by rate and acceleration (20 °/s²) ends at exactly the commanded angle, and
    the truth's attitude there is C_nb0 · Rz(angle)."""
    prof = AngleProfile.trapezoid_rate(137.5 * D, rate=30 * D, accel=20 * D)
    sched = Schedule((Step((0.0, 0.0, 1.0), prof, dwell=2.0),))
    from gcalign.sim.motions import Turntable

    tt = Turntable((0.1, -0.2, 0.3), prof.duration + 2.0, sched)
    end = tt.kinematics(np.array([prof.duration, prof.duration + 1.0]), SITE)
    C_expect = euler_to_dcm(np.array([0.1, -0.2, 0.3])) @ euler_to_dcm(np.array([0, 0, 137.5 * D]))
    np.testing.assert_allclose(end.C_nb, np.broadcast_to(C_expect, (2, 3, 3)), atol=2e-15)
    np.testing.assert_allclose(end.omega_nb_b, 0.0, atol=1e-15)


def test_swing_rates_are_the_derivative_of_the_attitude():
    sw = Swing((0.0, 0.0, 0.5), 60.0, (2 * D, 3 * D, 4 * D), (10.0, 10.0, 20.0), (0.1, 0.2, 0.3))
    t = np.linspace(0.3, 50.0, 97)
    h = 1e-5
    kin = sw.kinematics(t, SITE)
    Cp, Cm = sw.kinematics(t + h, SITE).C_nb, sw.kinematics(t - h, SITE).C_nb
    from gcalign.nav.rotation import dcm_to_quat, quat_conj, quat_mult

    d = quat_to_rotvec(quat_mult(quat_conj(dcm_to_quat(Cm)), dcm_to_quat(Cp))) / (2 * h)
    np.testing.assert_allclose(d, kin.omega_nb_b, atol=1e-9)
    assert rotvec_to_quat(np.zeros(3))[0] == 1.0
