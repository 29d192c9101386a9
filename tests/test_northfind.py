"""Tests of gcalign.northfind (seed 001): multi-position north-finding with tilt compensation.

Reference values come from geometry and closed forms (earth rate, least-squares
covariances, the tilt-leakage formula), never from earlier output of the code.
"""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.nav import earth
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm, wrap_pi
from gcalign.northfind import (
    METHODS,
    NorthfindSetup,
    azimuth_from_harmonics,
    azimuth_std_level,
    fit_harmonics,
    naive_error,
    none_error,
    pitch_roll_from_tilt,
    position_angles,
    predict_azimuth_std,
    run_northfind,
    simulate_table,
    table_dcm,
    tilt_from_pitch_roll,
)
from gcalign.units import ARCMIN, ARCSEC, DEG, DPH, DPSH, UG, UGPSHZ

LAT40 = 40.0 * DEG
SWEEP = np.arange(0.0, 360.0, 5.0) * DEG  # 72 azimuths
TILTS = np.array([0.0, 1.0, 5.0, 10.0]) * DEG
DIRECTIONS = np.array([0.0, 45.0, 137.0, 270.0]) * DEG
WITH_LITERAL = METHODS + ("vector_literal",)


def _noise_free(
    azimuths, tilt, direction, ref="north", lat=LAT40, positions=24, methods=METHODS, **kw
):
    setup = NorthfindSetup(
        azimuths=azimuths,
        lat=lat,
        positions=positions,
        tilt=tilt,
        tilt_direction=direction,
        tilt_direction_ref=ref,
        **kw,
    )
    return setup, run_northfind(setup, np.random.default_rng(1), methods=methods)


# ----------------------------------------------------------------------------- geometry


def test_table_dcm_geometry_and_euler_route():
    psi, eps, zeta = np.meshgrid(SWEEP, TILTS, DIRECTIONS, indexing="ij")
    C = table_dcm(psi, eps, zeta)
    # orthonormal, right-handed
    eye = np.broadcast_to(np.eye(3), C.shape)
    np.testing.assert_allclose(np.swapaxes(C, -1, -2) @ C, eye, atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(C), 1.0, atol=1e-14)
    z_t, y_t = C[..., 2], C[..., 1]
    # normal tilted by ε toward the descent azimuth ζ
    np.testing.assert_allclose(z_t[..., 2], np.cos(eps), atol=1e-14)
    tilted = eps > 0
    np.testing.assert_allclose(
        wrap_pi(np.arctan2(z_t[..., 0], z_t[..., 1]) - zeta)[tilted], 0.0, atol=1e-12
    )
    # horizontal projection of the reference axis at azimuth ψ; azimuth = -yaw (PSINS)
    np.testing.assert_allclose(wrap_pi(np.arctan2(y_t[..., 0], y_t[..., 1]) - psi), 0, atol=1e-12)
    np.testing.assert_allclose(wrap_pi(-dcm_to_euler(C)[..., 2] - psi), 0.0, atol=1e-12)
    # second route: PSINS Euler angles from (ε, ζ - ψ)
    p, r = pitch_roll_from_tilt(eps, zeta - psi)
    C2 = euler_to_dcm(np.stack([p, r, -psi], -1))
    np.testing.assert_allclose(C2, C, atol=1e-14)
    e2, z2 = tilt_from_pitch_roll(p, r)
    np.testing.assert_allclose(e2, eps, atol=1e-14)
    np.testing.assert_allclose(wrap_pi(z2 - (zeta - psi))[tilted], 0.0, atol=1e-12)


def test_level_table_earth_rate_harmonics():
    # level: a = Ω cos L cos ψ, b = Ω cos L sin ψ (seed eq. 4), R = gyro bias
    bias = 3.0 * DPH
    setup, res = _noise_free(SWEEP, 0.0, 0.0, gyro_bias=bias)
    h = earth.OMEGA_IE * np.cos(LAT40)
    coef = res.gyro_coef[:, 0]
    np.testing.assert_allclose(coef[:, 0], bias, atol=1e-19)
    np.testing.assert_allclose(coef[:, 1], h * np.cos(SWEEP), atol=1e-18)
    np.testing.assert_allclose(coef[:, 2], h * np.sin(SWEEP), atol=1e-18)
    np.testing.assert_allclose(res.gyro_residual, 0.0, atol=1e-18)


def test_fit_harmonics_closed_form_and_general_angles():
    rng = np.random.default_rng(7)
    th = position_angles(24)
    y = rng.standard_normal((5, 24))
    coef, _ = fit_harmonics(y, th)
    closed = np.stack(
        [y.mean(-1), 2.0 / 24 * y @ np.cos(th), 2.0 / 24 * y @ np.sin(th)], -1
    )  # equally spaced: AᵀA = diag(n, n/2, n/2)
    np.testing.assert_allclose(coef, closed, rtol=0, atol=1e-14)
    # unequal angles: exact recovery of the three coefficients
    th2 = np.radians([0.0, 17.0, 95.0, 181.0, 260.0, 300.0])
    truth = np.array([0.3, -1.2, 2.5])
    y2 = truth[0] + truth[1] * np.cos(th2) + truth[2] * np.sin(th2)
    np.testing.assert_allclose(fit_harmonics(y2, th2)[0], truth, atol=1e-14)
    with pytest.raises(ValueError, match="rank-3"):
        fit_harmonics(np.zeros(3), np.zeros(3))


# ----------------------------------------------------------------------------- noise-free


@pytest.mark.parametrize("ref", ["north", "table"])
def test_noise_free_recovery_and_agreement(ref):
    worst = {m: 0.0 for m in ("coordinate", "vector")}
    worst_diff = 0.0
    for eps in TILTS:
        for zeta in DIRECTIONS:
            setup, res = _noise_free(SWEEP, eps, zeta, ref=ref)
            for m in worst:
                worst[m] = max(worst[m], np.abs(res.error(m)).max())
            diff = np.abs(wrap_pi(res.estimate("coordinate") - res.estimate("vector"))).max()
            worst_diff = max(worst_diff, diff)
            # tilt and its direction from the accelerometers
            np.testing.assert_allclose(res.tilt_est[:, 0], eps, atol=1e-12)
            if eps > 0:
                d = wrap_pi(res.tilt_direction_est[:, 0] - setup.tilt_direction_north)
                np.testing.assert_allclose(d, 0.0, atol=1e-10)
                att = dcm_to_euler(table_dcm(SWEEP, eps, setup.tilt_direction_north))
                np.testing.assert_allclose(res.pitch_est[:, 0], att[:, 0], atol=1e-12)
                np.testing.assert_allclose(res.roll_est[:, 0], att[:, 1], atol=1e-12)
    assert max(worst.values()) < 1e-4 * DEG  # requirement
    assert worst_diff < 1e-4 * DEG
    assert max(worst.values()) < 1e-12  # in fact: round-off
    assert worst_diff < 1e-12


def test_seed_eq10_literal_exact_only_for_axis_aligned_tilt():
    # Tilt along a table axis (u_x u_y = 0): eq. (10) as printed is exact ...
    for rel in np.radians([0.0, 90.0, 180.0, 270.0]):
        _, res = _noise_free(SWEEP, 10 * DEG, rel, ref="table", methods=WITH_LITERAL)
        assert np.abs(res.error("vector_literal")).max() < 1e-12
    # ... toward a diagonal it misses the skew of the projected x axis: O(ε²), like naive.
    _, res = _noise_free(SWEEP, 10 * DEG, 45 * DEG, ref="table", methods=WITH_LITERAL)
    lit = np.abs(res.error("vector_literal")).max()
    assert 0.5 * DEG < lit < 1.0 * DEG
    assert np.abs(res.error("vector")).max() < 1e-12


def test_none_error_matches_closed_form():
    worst = 0.0
    for ref in ("north", "table"):
        for eps in TILTS:
            for zeta in DIRECTIONS:
                setup, res = _noise_free(SWEEP, eps, zeta, ref=ref)
                pred = none_error(SWEEP, eps, setup.tilt_direction_north, LAT40)
                worst = max(worst, np.abs(res.error("none")[:, 0] - pred).max())
                np.testing.assert_array_equal(res.error_pred[METHODS.index("none")], pred)
    assert worst < 1e-12  # closed form vs simulated geometry (errors up to 0.16 rad)
    # other latitudes, southern hemisphere included
    for lat in np.radians([-60.0, -10.0, 0.0, 25.0, 75.0]):
        setup, res = _noise_free(SWEEP, 7 * DEG, 100 * DEG, lat=lat)
        pred = none_error(SWEEP, 7 * DEG, 100 * DEG, lat)
        np.testing.assert_allclose(res.error("none")[:, 0], pred, atol=1e-12)


def test_none_error_size_at_40_deg():
    # Small tilt: tan L · ε, i.e. tan 40° · 60′ = 50.35′ per degree (seed §1: "50′").
    eps = 0.1 * DEG
    zeta = np.arange(0.0, 360.0, 1.0) * DEG
    for psi in (0.0, 123 * DEG):
        _, res = _noise_free(np.full(zeta.size, psi), eps, zeta)
        per_degree = np.abs(res.error("none")).max() / eps * DEG
        assert per_degree / ARCMIN == pytest.approx(np.tan(LAT40) * 60.0, rel=2e-3)
        assert 49.5 * ARCMIN < per_degree < 51.0 * ARCMIN
    # 10° tilt fixed to the instrument along a table axis, swept over azimuth (seed
    # Fig. 4, "8.4°"): first order gives asin(tan L sin ε) = 8.38°, exact 8.55°.
    maxima = []
    for rel in np.radians([0.0, 90.0, 180.0, 270.0]):
        _, res = _noise_free(SWEEP, 10 * DEG, rel, ref="table")
        maxima.append(np.abs(res.error("none")).max())
    assert all(8.4 * DEG <= m <= 8.6 * DEG for m in maxima)
    assert np.degrees(np.arcsin(np.tan(LAT40) * np.sin(10 * DEG))) == pytest.approx(8.378, 1e-3)
    # over all tilt directions the maximum is larger (diagonal tilt adds the naive error)
    psi, zeta = np.meshgrid(SWEEP, np.arange(0.0, 360.0, 1.0) * DEG)
    worst = np.abs(none_error(psi, 10 * DEG, zeta, LAT40)).max()
    assert 8.9 * DEG < worst < 9.1 * DEG


def test_naive_error_closed_form_and_size():
    for ref in ("north", "table"):
        for zeta in DIRECTIONS:
            setup, res = _noise_free(SWEEP, 10 * DEG, zeta, ref=ref)
            pred = naive_error(SWEEP, 10 * DEG, setup.tilt_direction_north)
            np.testing.assert_allclose(res.error("naive")[:, 0], pred, atol=1e-12)
    # tilt along a table axis: max error asin(tan²(ε/2)) ≈ ε²/4 — 4.4 % of a 10° tilt
    # (seed: "about 5 %")
    for eps_deg in (1.0, 5.0, 10.0):
        eps = eps_deg * DEG
        _, res = _noise_free(SWEEP, eps, 90 * DEG, ref="table")
        worst = np.abs(res.error("naive")).max()
        assert worst == pytest.approx(np.arcsin(np.tan(eps / 2) ** 2), rel=1e-3)
    _, res = _noise_free(SWEEP, 10 * DEG, 0.0, ref="table")
    assert np.abs(res.error("naive")).max() / (10 * DEG) == pytest.approx(0.0439, abs=5e-4)


def test_biases_and_scale_noise_free():
    # constant biases are absorbed by R; a gyro scale error only mis-scales the known
    # vertical-rate correction: |δψ| <= k tan L sin ε / (1 - tan L sin ε) (small)
    setup, res = _noise_free(
        SWEEP, 5 * DEG, 200 * DEG, gyro_bias=10 * DPH, accel_bias=(300 * UG, -500 * UG)
    )
    for m in ("coordinate", "vector"):
        assert np.abs(res.error(m)).max() < 1e-12
    k = 100e-6
    setup, res = _noise_free(SWEEP, 5 * DEG, 200 * DEG, gyro_scale=k)
    x = np.tan(LAT40) * np.sin(5 * DEG)
    bound = k * x / (1 - x)
    assert 0.2 * bound < np.abs(res.error("coordinate")).max() < bound
    np.testing.assert_allclose(
        res.error("none")[:, 0], none_error(SWEEP, 5 * DEG, 200 * DEG, LAT40), atol=1e-12
    )


# ----------------------------------------------------------------------------- statistics


def test_level_std_matches_least_squares_prediction():
    arw = 0.01 * DPSH
    setup = NorthfindSetup(
        azimuths=np.arange(0.0, 360.0, 18.0) * DEG,
        lat=LAT40,
        positions=24,
        dwell_s=60.0,
        rate_hz=100.0,
        repeats=200,
        gyro_arw=arw,
    )
    res = run_northfind(setup, np.random.default_rng(2024))
    closed = (arw / np.sqrt(60.0)) * np.sqrt(2.0 / 24) / (earth.OMEGA_IE * np.cos(LAT40))
    assert azimuth_std_level(arw, 60.0, 100.0, 24, LAT40) == pytest.approx(closed, rel=1e-12)
    for m in METHODS:  # level: all four methods are the same estimator
        np.testing.assert_allclose(predict_azimuth_std(setup, m), closed, rtol=1e-6)
        err = res.error(m)
        assert np.std(err) / closed == pytest.approx(1.0, abs=0.10)
        assert abs(np.mean(err)) < 3 * closed / np.sqrt(err.size)


def test_tilted_std_with_accel_noise_and_index_error():
    setup = NorthfindSetup(
        azimuths=np.arange(0.0, 360.0, 18.0) * DEG,
        lat=LAT40,
        positions=24,
        dwell_s=60.0,
        rate_hz=100.0,
        tilt=8 * DEG,
        tilt_direction=60 * DEG,
        repeats=200,
        gyro_arw=0.01 * DPSH,
        accel_vrw=200 * UGPSHZ,
        index_error=20 * ARCSEC,
    )
    res = run_northfind(setup, np.random.default_rng(99))
    for i, m in enumerate(METHODS):
        z = (res.error(m) - res.error_pred[i][:, None]) / res.azimuth_std_pred[i][:, None]
        assert np.std(z) == pytest.approx(1.0, abs=0.10), m
        assert abs(np.mean(z)) < 3 / np.sqrt(z.size), m


def test_gyro_bias_does_not_bias_azimuth():
    arw = 0.02 * DPSH
    common = dict(
        azimuths=np.arange(0.0, 360.0, 30.0) * DEG,
        lat=LAT40,
        positions=12,
        dwell_s=30.0,
        tilt=3 * DEG,
        tilt_direction=150 * DEG,
        repeats=200,
        gyro_arw=arw,
    )
    big = NorthfindSetup(gyro_bias=20 * DPH, **common)  # bias larger than Ω cos L
    res = run_northfind(big, np.random.default_rng(5))
    sigma = predict_azimuth_std(big, "coordinate")[0]
    for m in ("coordinate", "vector"):
        err = res.error(m)
        assert abs(err.mean()) < 3 * sigma / np.sqrt(err.size)
    np.testing.assert_allclose(res.gyro_coef[..., 0].mean(), 20 * DPH, rtol=1e-3)
    # same seed, no bias: the bias moves only R, the azimuths are identical
    res0 = run_northfind(NorthfindSetup(**common), np.random.default_rng(5))
    np.testing.assert_allclose(wrap_pi(res.azimuth_est - res0.azimuth_est), 0.0, atol=1e-9 * DEG)


def test_index_error_effect():
    sig = 30 * ARCSEC
    setup = NorthfindSetup(
        azimuths=np.arange(0.0, 360.0, 10.0) * DEG,
        lat=LAT40,
        positions=24,
        repeats=120,
        index_error=sig,
    )
    # level, noise-free sensors: δψ = -(2/n) Σ δ_i sin²(ψ - θ_i), σ = σ_δ √(3/(2n))
    closed = sig * np.sqrt(3.0 / (2 * 24))
    np.testing.assert_allclose(predict_azimuth_std(setup), closed, rtol=1e-6)
    res = run_northfind(setup, np.random.default_rng(11))
    err = res.error("coordinate")
    assert np.std(err) / closed == pytest.approx(1.0, abs=0.10)
    assert abs(err.mean()) < 3 * closed / np.sqrt(err.size)
    data = simulate_table(setup, np.random.default_rng(3))
    assert data.theta_true.shape == (36, 120, 24)
    assert np.std(data.theta_true - data.theta) / sig == pytest.approx(1.0, abs=0.02)
    # smaller errors, proportionally smaller effect (linear regime)
    half = NorthfindSetup(
        azimuths=setup.azimuths, lat=LAT40, positions=24, repeats=120, index_error=sig / 2
    )
    res_half = run_northfind(half, np.random.default_rng(11))
    np.testing.assert_allclose(res_half.error("coordinate"), err / 2, rtol=1e-3, atol=1e-3 * closed)


@pytest.mark.slow
def test_samples_path_agrees_with_averaged_path():
    common = dict(
        azimuths=np.radians([10.0, 100.0, 250.0, 300.0]),
        lat=LAT40,
        positions=6,
        dwell_s=0.5,
        rate_hz=200.0,  # N = 100 samples
        tilt=4 * DEG,
        tilt_direction=30 * DEG,
        repeats=250,
    )
    quiet = NorthfindSetup(**common)
    noisy = NorthfindSetup(gyro_arw=0.5 * DPSH, accel_vrw=100 * UGPSHZ, **common)
    truth = simulate_table(quiet, np.random.default_rng(0))
    # noise-free: the two paths give the same dwell means (round-off of N additions)
    t2 = simulate_table(quiet, np.random.default_rng(0), samples=True)
    np.testing.assert_allclose(t2.gyro, truth.gyro, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(t2.accel, truth.accel, rtol=1e-12)
    expect = np.array([noisy.gyro_arw, noisy.accel_vrw]) * np.sqrt(200.0 / 100)  # σ_s/√N
    for samples in (False, True):
        d = simulate_table(noisy, np.random.default_rng(42 + samples), samples=samples)
        ng = (d.gyro - truth.gyro).ravel()
        na = (d.accel - truth.accel).ravel()
        assert np.std(ng) / expect[0] == pytest.approx(1.0, abs=0.05)
        assert np.std(na) / expect[1] == pytest.approx(1.0, abs=0.05)
        assert abs(ng.mean()) < 4 * expect[0] / np.sqrt(ng.size)
        assert abs(na.mean()) < 4 * expect[1] / np.sqrt(na.size)
    # azimuth statistics of the two paths agree
    stds = [
        np.std(run_northfind(noisy, np.random.default_rng(s), samples=s).error("vector"))
        for s in (False, True)
    ]
    assert stds[1] / stds[0] == pytest.approx(1.0, abs=0.1)


def test_samples_kernel_is_literal_sample_average():
    # the kernel consumes the Generator exactly like rng.standard_normal((K, n, 3, N))
    setup = NorthfindSetup(
        azimuths=np.radians([20.0, 200.0]),
        lat=LAT40,
        positions=4,
        dwell_s=0.1,
        rate_hz=50.0,
        tilt=2 * DEG,
        repeats=3,
        gyro_bias=1 * DPH,
        gyro_arw=0.1 * DPSH,
        accel_bias=50 * UG,
        accel_vrw=100 * UGPSHZ,
        index_error=10 * ARCSEC,
    )
    d = simulate_table(setup, np.random.default_rng(8), samples=True)
    quiet = NorthfindSetup(
        azimuths=setup.azimuths,
        lat=LAT40,
        positions=4,
        dwell_s=0.1,
        rate_hz=50.0,
        tilt=2 * DEG,
        repeats=3,
        index_error=10 * ARCSEC,
    )
    ideal = simulate_table(quiet, np.random.default_rng(8))  # same indexing errors
    np.testing.assert_array_equal(ideal.theta_true, d.theta_true)
    rng = np.random.default_rng(8)
    rng.standard_normal((2, 3, 4))  # indexing errors
    w = rng.standard_normal((6, 4, 3, 5)).reshape(2, 3, 4, 3, 5)
    sig = np.array([setup.gyro_arw, setup.accel_vrw, setup.accel_vrw]) * np.sqrt(50.0)
    bias = np.array([1 * DPH, 50 * UG, 50 * UG])
    ref_means = (sig[:, None] * w).mean(-1) + bias
    np.testing.assert_allclose(d.gyro - ideal.gyro, ref_means[..., 0], rtol=1e-9, atol=1e-20)
    np.testing.assert_allclose(d.accel - ideal.accel, ref_means[..., 1:], rtol=1e-9, atol=1e-16)


def test_reproducible_with_rng_only():
    setup = NorthfindSetup(
        azimuths=SWEEP[:5], lat=LAT40, repeats=3, gyro_arw=0.01 * DPSH, index_error=ARCSEC
    )
    a = run_northfind(setup, np.random.default_rng(123))
    b = run_northfind(setup, np.random.default_rng(123))
    c = run_northfind(setup, np.random.default_rng(124))
    np.testing.assert_array_equal(a.azimuth_est, b.azimuth_est)
    assert np.all(a.azimuth_est != c.azimuth_est)
    assert a.azimuth_est.shape == (4, 5, 3)
    assert a.gyro_residual.shape == (5, 3, 24)
    assert a.accel_residual.shape == (5, 3, 24, 2)
    assert np.all((a.azimuth_est >= 0) & (a.azimuth_est < 2 * np.pi))


def test_azimuth_from_harmonics_level_quadrants_and_bad_method():
    h = earth.OMEGA_IE * np.cos(LAT40)
    psi = np.radians([0.0, 45.0, 135.0, 225.0, 315.0, 359.9])
    for m in METHODS:
        est = azimuth_from_harmonics(h * np.cos(psi), h * np.sin(psi), 0.0, 0.0, LAT40, m)
        np.testing.assert_allclose(wrap_pi(est - psi), 0.0, atol=1e-13)
    with pytest.raises(ValueError, match="method must be one of"):
        azimuth_from_harmonics(1.0, 0.0, 0.0, 0.0, LAT40, "magic")


# ----------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    ("kw", "pattern"),
    [
        (dict(positions=2), r"positions must be an integer >= 3.*got 2"),
        (dict(positions=3.5), r"positions must be an integer >= 3.*got 3\.5"),
        (dict(tilt=np.pi / 2), r"tilt must satisfy 0 <= tilt < pi/2.*\(90 deg\)"),
        (dict(tilt=100 * DEG), r"tilt must satisfy .*got 1\.745.*\(100 deg\)"),
        (dict(tilt=-0.01), r"tilt must satisfy .*got -0\.01"),
        (dict(lat=np.pi / 2), r"lat must satisfy \|lat\| < pi/2.*poles.*\(90 deg\)"),
        (dict(lat=-np.pi / 2), r"north is undefined at the poles.*\(-90 deg\)"),
        (dict(dwell_s=0.0), r"dwell_s must be > 0, got 0\.0"),
        (dict(dwell_s=-5.0), r"dwell_s must be > 0, got -5\.0"),
        (dict(rate_hz=0.0), r"rate_hz must be > 0, got 0\.0"),
        (dict(azimuths=[]), r"azimuths must hold at least one azimuth \(empty sweep\)"),
        (dict(repeats=0), r"repeats must be an integer >= 1, got 0"),
        (dict(gyro_arw=-1e-6), r"gyro_arw must be >= 0, got -1e-06"),
        (dict(tilt_direction_ref="east"), r"tilt_direction_ref must be 'north' or 'table'"),
        (dict(dwell_s=1e-3, rate_hz=100.0), r"at least one sample per position"),
    ],
)
def test_bad_setup_raises(kw, pattern):
    base = dict(azimuths=[0.0, 1.0], lat=LAT40)
    base.update(kw)
    with pytest.raises(ValueError, match=pattern):
        NorthfindSetup(**base)
