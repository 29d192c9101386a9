"""Error propagation of free-inertial navigation against closed forms (core issue, must-show
3 and 4): the seed-004 earth, Schuler and earth-rate loops with the height held, and the
vertical channel free (unstable), held and damped.

Static base at 45.7796°N (spec 004 §5), body = ENU, no rotation, ideal IMU plus one error.
The increments of a static base are exact at any rate, so these runs use 10 Hz.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.app.data import scenario_stream
from gcalign.app.navigate.run import Start, navigate_stream, run_navigation
from gcalign.io.scenario import parse_scenario
from gcalign.nav import _kernels as K
from gcalign.nav.earth import SEED004, WGS84
from gcalign.nav.strapdown import NavState, Vertical

LAT = math.radians(45.7796)
G0 = 9.78049
EPS = 0.01 * math.pi / 180 / 3600  # 0.01 °/h, rad/s


def test_seed004_earth_at_the_seed_site():
    """Spec 004 §5: R_M 6 368 531.5 m, R_N 6 389 423.2 m, g 9.806998 m/s², to the digits
    printed; ω_s 1.23992e-3 rad/s (84.46 min); the kernels' scalar earth equals the model."""
    r_m, r_n = SEED004.radii(LAT)
    assert round(float(r_m), 1) == 6368531.5 and round(float(r_n), 1) == 6389423.2
    assert round(float(SEED004.gravity(LAT)), 6) == 9.806998
    assert SEED004.schuler_rate(LAT) == pytest.approx(1.23992e-3, abs=5e-9)
    for model in (WGS84, SEED004):
        for lat, h in ((0.3, 0.0), (LAT, 500.0), (-1.2, 9000.0)):
            km, kn, g, sl, cl = K.earth_at(model.params(), lat, h)
            mm, mn = model.radii(lat)
            assert (km, kn) == pytest.approx((mm, mn), rel=1e-15)
            assert g == pytest.approx(model.gravity(lat, h), rel=1e-15)


def static(name, hours, vertical="hold", rate_hz=10, **imu):
    return parse_scenario({
        "name": name, "earth": "seed004",
        "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0.0},
        "imu": {"rate_hz": rate_hz, **imu},
        "motion": {"kind": "static", "duration_s": hours * 3600.0},
        "navigation": {"vertical": vertical}, "output": {"rate_hz": 1.0}}, name)


def series(sc):
    """The 1 Hz series of a run (t, position error ENU, velocity error ENU, φ)."""
    import h5py

    f = h5py.File("mem", "w", driver="core", backing_store=False)
    summary, _ = run_navigation(sc, sink=f.create_group("navigate"))
    g = f["navigate"]
    return (summary, g["t"][()], g["error/pos"][()], g["error/v_n"][()], g["error/phi"][()])


def test_east_gyro_drift_north_error_follows_the_closed_form():
    """−Rε[sin(Ωt)/Ω − sin(ω_s t)/ω_s]/(1 − Ω²/ω_s²) (Schuler and earth-rate loops, east
    drift) within 2 % at 1 h; φ_E peaks near (ε/ω_s) = 8.1″ (spec 004 §5 (b))."""
    _, t, pos, _, phi = series(static("east-drift", 1.0, gyro={"bias_dph": [0.01, 0, 0]}))
    W, ws = SEED004.omega_ie, SEED004.schuler_rate(LAT)
    R = SEED004.radii(LAT)[0]
    closed = -R * EPS * (np.sin(W * t) / W - np.sin(ws * t) / ws) / (1 - W**2 / ws**2)
    assert pos[-1, 1] == pytest.approx(closed[-1], rel=0.02)
    assert np.abs(phi[:, 0]).max() * 206264.8 == pytest.approx(EPS / ws * 206264.8, rel=0.05)


def test_east_accelerometer_bias_schuler_period_and_peak():
    """1e-4 g east: δx_E = (∇/ω_s²)(1 − cos ω_s t): period 84.4 min (±0.5 %) from the zero
    crossings of δv_E, peak 1272 m (±2 %) (spec 004 §5 (a))."""
    ug = 1e-4 * G0 / 9.7803267715 * 1e6  # 1e-4·g0 in the µg of gcalign's units (PSINS g0)
    _, t, pos, vel, _ = series(static("east-accel", 2.0, accel={"bias_ug": [ug, 0, 0]}))
    v = vel[:, 0]
    # δv_E = (∇/ω_s) sin ω_s t: the first upward zero crossing after t = 0 is one period
    up = np.flatnonzero((v[:-1] < 0) & (v[1:] >= 0))[0]
    period = t[up] - v[up] * (t[up + 1] - t[up]) / (v[up + 1] - v[up])
    assert period / 60 == pytest.approx(84.4, rel=0.005)
    assert pos[:, 0].max() == pytest.approx(1272.0, rel=0.02)


@pytest.mark.slow
@pytest.mark.parametrize("axis, slope", [(1, 542.4), (2, 557.4)])
def test_72h_east_error_grows_with_the_drift_along_the_earth_axis(axis, slope):
    """Only the drift component along the earth's axis grows without bound: 542.4 m/h of
    east error from a north drift, 557.4 m/h from an up drift (spec 004 §5 (c)), within
    5 %: the slope of a least-squares fit with the Schuler and earth-rate periodic terms."""
    bias = [0.0, 0.0, 0.0]
    bias[axis] = 0.01
    _, t, pos, _, _ = series(static(f"drift-{axis}", 72.0, gyro={"bias_dph": bias}))
    W, ws = SEED004.omega_ie, SEED004.schuler_rate(LAT)
    A = np.column_stack([np.ones_like(t), t, np.cos(W * t), np.sin(W * t), np.cos(ws * t),
                         np.sin(ws * t)])
    coef = np.linalg.lstsq(A, pos[:, 0], rcond=None)[0]
    assert abs(coef[1]) * 3600 == pytest.approx(slope, rel=0.05)


def _height_run(vertical: Vertical, seconds: float, dh0: float = 0.0, **imu):
    sc = static("vertical", seconds / 3600.0, vertical.mode, rate_hz=10, **imu)
    stream = scenario_stream(sc)
    att, v, pos = stream.truth_at(0)
    start = Start(0, NavState.from_euler(att, v, pos + [0.0, 0.0, dh0]), "test")
    import h5py

    f = h5py.File("mem", "w", driver="core", backing_store=False)
    navigate_stream(stream, start, vertical, 10, sink=f.create_group("n"))
    return f["n/t"][()], f["n/error/pos"][()][:, 2], f["n/error/v_n"][()][:, 2]


def test_free_vertical_channel_diverges_with_time_constant_sqrt_R_over_2g():
    """A 1 m height error grows as cosh(t/τ), τ = √(R/2g) ≈ 570 s (±2 %)."""
    t, dh, _ = _height_run(Vertical("free"), 1800.0, dh0=1.0)
    tau = t[-1] / np.arccosh(dh[-1])
    R = math.sqrt(np.prod(SEED004.radii(LAT)))
    expected = math.sqrt(R / (2 * SEED004.gravity(LAT)))
    assert 560 < expected < 580
    assert tau == pytest.approx(expected, rel=0.02)


def test_held_vertical_channel_keeps_height_and_zero_vertical_velocity():
    t, dh, dvu = _height_run(Vertical("hold"), 600.0, accel={"bias_ug": [0, 0, 500]})
    assert np.abs(dh).max() == 0.0 and np.abs(dvu).max() == 0.0


def test_damped_loop_has_the_designed_poles_and_learns_an_accelerometer_bias():
    """k1, k2, k3 give the characteristic polynomial (s + 1/τ)³ once the gravity feedback
    g3 is subtracted; in a run a 500 µg vertical bias leaves δh → 0 and the loop's
    acceleration state equal to the bias after 20 τ."""
    tau = 20.0
    _, k1, k2, k3 = K.vertical_gains(tau, SEED004.g3)
    np.testing.assert_allclose([1, k1, k2 - SEED004.g3, k3], np.poly([-1 / tau] * 3), rtol=1e-14)
    t, dh, dvu = _height_run(Vertical("damped", tau), 20 * tau, dh0=5.0,
                             accel={"bias_ug": [0, 0, 500]})
    assert abs(dh[-1]) < 1e-3 and abs(dvu[-1]) < 1e-4
    # the same start, free, is off by ~ ½·∇·t² plus the divergence: the loop matters
    _, dh_free, _ = _height_run(Vertical("free"), 20 * tau, dh0=5.0,
                                accel={"bias_ug": [0, 0, 500]})
    assert abs(dh_free[-1]) > 300
