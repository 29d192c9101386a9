"""The two routes to the ideal increments agree: the numba fixed-site kernel (static bases
and turntables, with or without a mechanism; what long runs use) against the vectorised
NumPy route that serves every motion, sample by sample, through dwells and turns, at
block boundaries, body- and navigation-referenced."""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.io.scenario import parse_scenario
from gcalign.sim.ideal import _fixed_site_blocks, _numpy_blocks
from gcalign.sim.motions import sample_count

SITE = {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 120.0}
TURN = {"profile": "trapezoid", "angle_deg": 180, "accel_s": 1, "const_s": 1, "decel_s": 1,
        "dwell_s": 2.5}
CASES = {
    "static": {"motion": {"kind": "static", "attitude_deg": [1, -2, 30], "duration_s": 40}},
    "mechanism-navigation-12": {
        "earth": "seed004",
        "motion": {"kind": "static", "attitude_deg": [0, 0, 20], "duration_s": 80},
        "mechanism": {"reference": "navigation", "steps": [
            dict(TURN, axis=a, angle_deg=180 if i < 6 else -180)
            for i, a in enumerate("zxyyxzzxyyxz")]}},
    "mechanism-body": {
        "motion": {"kind": "static", "attitude_deg": [3, -4, 75], "duration_s": 40},
        "mechanism": {"reference": "body", "steps": [
            dict(TURN, axis="z"), dict(TURN, axis="x", angle_deg=-90)]}},
    "turntable-and-mechanism": {
        "motion": {"kind": "turntable", "attitude_deg": [0, 0, 10], "duration_s": 30,
                   "steps": [
                       {"axis": "z", "profile": "trapezoid", "angle_deg": 90, "rate_dps": 40,
                        "accel_dps2": 20, "dwell_s": 2},
                       {"axis": [0.6, 0.8, 0], "profile": "swing", "amplitude_deg": 10,
                        "frequency_hz": 0.5, "duration_s": 4}]},
        "mechanism": {"reference": "body", "steps": [dict(TURN, axis="y")]}},
}


def routes(name: str, rate_hz: float = 50.0, block: int = 700):
    data = {"name": name, "site": SITE, "imu": {"rate_hz": rate_hz}, **CASES[name]}
    sc = parse_scenario(data, name)
    motion = sc.motion.to_motion()
    mech = None if sc.mechanism is None else sc.mechanism.to_mechanism(sc.motion.attitude_deg)
    site, ts, earth = sc.site.to_si(), 1.0 / rate_hz, sc.earth_model
    n = sample_count(motion.duration, ts)
    fast = list(_fixed_site_blocks(motion, site, ts, earth, mech, block, 2, n))
    slow = list(_numpy_blocks(motion, site, ts, earth, mech, 1 << 14, 2, n))

    def cat(blocks, name):
        parts = [getattr(b, name) for b in blocks]
        return None if parts[0] is None else np.concatenate(parts)

    return {k: (cat(fast, k), cat(slow, k)) for k in ("t", "dtheta", "dv", "q_nb", "q_bs",
                                                      "att")}


def same_sign(q, ref):
    return q * np.sign(np.sum(q * ref, axis=1))[:, None]


@pytest.mark.parametrize("name", list(CASES))
def test_numba_route_equals_numpy_route(name):
    r = routes(name)
    assert np.array_equal(r["t"][0], r["t"][1])
    # 1e-14 rad of a 0.03 rad increment: round-off of the two orders of operations
    assert np.abs(r["dtheta"][0] - r["dtheta"][1]).max() < 1e-14
    assert np.abs(r["dv"][0] - r["dv"][1]).max() < 1e-14  # of 0.196 m/s
    q, ref = r["q_nb"]
    assert np.abs(same_sign(q, ref) - ref).max() < 1e-13
    if r["q_bs"][0] is not None:
        q, ref = r["q_bs"]
        assert np.abs(same_sign(q, ref) - ref).max() < 1e-13
    else:
        assert r["q_bs"][1] is None


def test_the_comparison_sees_a_turn():
    """The cases turn the IMU: the increments are not one repeated value."""
    r = routes("mechanism-navigation-12")
    spread = np.ptp(r["dtheta"][1], axis=0)
    assert spread.max() > 0.05  # rad per sample while turning at up to 90 °/s at 50 Hz


def test_a_long_rest_adds_up_to_the_earth_rotation():
    """At rest the increments sum to C_bn ω_ie^n T (a rotation about one axis adds up
    exactly): over an hour at 100 Hz (360 000 samples, 0.26 rad) to 1e-12 relative. A
    repeated increment carrying its round-off (~1e-16 rad) would be off by ~1e-10."""
    from gcalign.nav.earth import WGS84
    from gcalign.nav.rotation import euler_to_dcm

    att = np.radians([1.0, -2.0, 30.0])
    lat = np.radians(SITE["lat_deg"])
    site = np.array([lat, np.radians(SITE["lon_deg"]), SITE["height_m"]])
    sc = parse_scenario({"name": "rest", "site": SITE, "imu": {"rate_hz": 100},
                         "motion": {"kind": "static", "attitude_deg": np.degrees(att).tolist(),
                                    "duration_s": 3600}}, "rest")
    total = sum(b.dtheta.sum(0) for b in _fixed_site_blocks(
        sc.motion.to_motion(), site, 0.01, WGS84, None, 1 << 16, 2, 360000))
    w_n = WGS84.omega_ie * np.array([0.0, np.cos(lat), np.sin(lat)])
    expected = euler_to_dcm(att).T @ w_n * 3600.0
    assert np.linalg.norm(total - expected) / np.linalg.norm(expected) < 1e-12
