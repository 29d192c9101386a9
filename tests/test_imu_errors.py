"""The IMU error model does what gcalign.sim.imu says (`apply_errors`, `SensorErrors`, `ImuErrors`).

Model (per sensor triad, increments of one sample of length ts):
``measured = (I + diag(scale) + misalignment) @ ideal + bias ts + noise sqrt(ts) n_k``,
n_k ~ N(0, I), then optional quantisation of the running sum. Every check below is a
seeded statistic whose tolerance comes from the noise (kσ of the estimator), or an exact
property (multiples of the quantum, bit-identical seeds). Units through the scenario file
are checked against numbers computed by hand here, not against gcalign.units.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.errors import ScenarioError
from gcalign.io.scenario import parse_scenario
from gcalign.sim.imu import ImuData, ImuErrors, SensorErrors, apply_errors, ideal_imu
from gcalign.sim.motions import Swing

TS = 0.01
DEG = math.pi / 180.0
SITE = np.array([45.7796 * DEG, 126.6705 * DEG, 0.0])
ARCSEC = DEG / 3600.0

# A navigation-grade triad, SI (rad/s, rad/√s; m/s², m/s/√s).
GYRO = SensorErrors(
    bias=np.array([0.01, -0.02, 0.03]) * DEG / 3600.0,
    noise=np.array([0.001, 0.002, 0.0015]) * DEG / 60.0,
)
ACCEL = SensorErrors(
    bias=np.array([50.0, -80.0, 120.0]) * 9.78e-6,
    noise=np.array([10.0, 20.0, 15.0]) * 9.78e-6,
)


def constant_block(n: int, ts: float = TS) -> ImuData:
    """n samples of a static body's increments (the ideal data does not matter for bias,
    noise, quantisation and seeding; a constant block keeps them easy to read)."""
    dtheta = np.tile(np.array([1e-7, 5e-7, 5e-7]), (n, 1))
    dv = np.tile(np.array([0.001, 0.002, 0.0978]), (n, 1))
    return ImuData(t=ts * np.arange(1, n + 1), dtheta=dtheta, dv=dv, ts=ts)


_TUMBLE: dict = {}


def tumbling_block() -> ImuData:
    """Ideal increments of a large three-axis swing (pitch ±60°, roll ±80°, yaw ±180° at
    incommensurate periods): every gyro and accelerometer axis sees large positive and
    negative inputs, so the 3x3 error matrix is observable from all nine entries."""
    if "imu" not in _TUMBLE:
        motion = Swing((0.0, 0.0, 0.0),
            300.0,
            amplitude=(60 * DEG, 80 * DEG, 180 * DEG),
            period=(7.0, 11.0, 13.0),
            phase=(0.3, 1.1, 2.0),
        )
        _TUMBLE["imu"] = ideal_imu(motion, SITE, TS)[1]
    return _TUMBLE["imu"]


# ---------------------------------------------------------------- bias and noise


def test_bias_is_the_mean_error():
    n = 200_000
    ideal = constant_block(n)
    meas = apply_errors(ideal, ImuErrors(GYRO, ACCEL), np.random.default_rng(11))
    for err, m, i in ((GYRO, meas.dtheta, ideal.dtheta), (ACCEL, meas.dv, ideal.dv)):
        d = (m - i) / TS  # rate (rad/s) or specific force (m/s²) error per sample
        sigma_mean = err.noise / math.sqrt(TS) / math.sqrt(n)  # σ of the mean of d
        z = (d.mean(0) - err.bias) / sigma_mean
        assert np.all(np.abs(z) < 3.0), z


def test_noise_std_is_arw_vrw():
    """Per-sample std of an increment is density * sqrt(ts); with 200k samples the std
    estimate has a relative σ of 1/sqrt(2N) = 0.16 %, so 3 % is a loose bound. Two
    rates: the density, not the per-sample std, is the model's invariant."""
    n = 200_000
    for ts in (0.01, 0.002):
        ideal = constant_block(n, ts)
        meas = apply_errors(ideal, ImuErrors(GYRO, ACCEL), np.random.default_rng(12))
        for err, m, i in ((GYRO, meas.dtheta, ideal.dtheta), (ACCEL, meas.dv, ideal.dv)):
            std = (m - i).std(0, ddof=1)
            np.testing.assert_allclose(std / math.sqrt(ts), err.noise, rtol=0.03)
        # Noise is white: lag-1 correlation within 4/sqrt(N).
        d = meas.dtheta - ideal.dtheta
        d = d - d.mean(0)
        rho = (d[1:] * d[:-1]).sum(0) / (d * d).sum(0)
        assert np.all(np.abs(rho) < 4.0 / math.sqrt(n)), rho


def test_noise_free_and_default_errors_are_exact():
    ideal = tumbling_block()
    same = apply_errors(ideal, ImuErrors(), np.random.default_rng(1))
    np.testing.assert_array_equal(same.dtheta, ideal.dtheta)
    np.testing.assert_array_equal(same.dv, ideal.dv)
    bias_only = apply_errors(
        ideal,
        ImuErrors(SensorErrors(bias=GYRO.bias), SensorErrors(bias=ACCEL.bias)),
        np.random.default_rng(1),
    )
    # Exact up to the rounding of ideal + bias ts (one ulp of the ideal increment).
    for m, i, b in (
        (bias_only.dtheta, ideal.dtheta, GYRO.bias),
        (bias_only.dv, ideal.dv, ACCEL.bias),
    ):
        ulp = np.spacing(np.abs(i).max())
        np.testing.assert_allclose(m - i, np.tile(b * TS, (len(i), 1)), rtol=0, atol=ulp)
    # Only the increments change; times and metadata are kept.
    assert bias_only.ts == ideal.ts and bias_only.t is ideal.t


# ---------------------------------------------------------------- scale and misalignment


def matrix_errors():
    """Scale factors (ppm) and small non-orthogonality (arc-seconds), SI fractions/rad."""
    gyro_mis = np.array([[0.0, 20.0, -15.0], [-10.0, 0.0, 25.0], [30.0, -5.0, 0.0]]) * ARCSEC
    accel_mis = np.array([[0.0, -40.0, 10.0], [35.0, 0.0, -20.0], [-15.0, 45.0, 0.0]]) * ARCSEC
    gyro = SensorErrors(
        bias=GYRO.bias,
        noise=GYRO.noise,
        scale=np.array([300.0, -150.0, 80.0]) * 1e-6,
        misalignment=gyro_mis,
    )
    accel = SensorErrors(
        bias=ACCEL.bias,
        noise=ACCEL.noise,
        scale=np.array([-200.0, 100.0, 250.0]) * 1e-6,
        misalignment=accel_mis,
    )
    return gyro, accel


def least_squares(ideal, measured, noise_std):
    """Fit ``measured_k = M ideal_k + c`` per output axis: returns M (3, 3), c (3,) and
    the standard errors of M's entries from σ² (XᵀX)⁻¹ with the known noise σ."""
    X = np.column_stack([ideal, np.ones(len(ideal))])
    coef, *_ = np.linalg.lstsq(X, measured, rcond=None)
    cov = np.linalg.inv(X.T @ X)
    se = np.sqrt(np.diag(cov))[:3, None] * noise_std[None, :]  # (input j, output i)
    return coef[:3].T, coef[3], se.T


@pytest.mark.parametrize("noisy", [False, True])
def test_scale_and_misalignment_recovered_by_least_squares(noisy):
    ideal = tumbling_block()
    gyro, accel = matrix_errors()
    if not noisy:
        gyro = SensorErrors(bias=gyro.bias, scale=gyro.scale, misalignment=gyro.misalignment)
        accel = SensorErrors(bias=accel.bias, scale=accel.scale, misalignment=accel.misalignment)
    meas = apply_errors(ideal, ImuErrors(gyro, accel), np.random.default_rng(13))
    for err, x, y in ((gyro, ideal.dtheta, meas.dtheta), (accel, ideal.dv, meas.dv)):
        M_true = np.eye(3) + np.diag(err.scale) + err.misalignment
        M, c, se = least_squares(x, y, np.asarray(err.noise) * math.sqrt(TS))
        if noisy:
            # kσ of each estimated entry (18 entries: 4.5σ), and the estimate is
            # informative: σ below a fifth of the smallest error being recovered.
            assert np.all(np.abs(M - M_true) < 4.5 * se), (M - M_true) / se
            smallest = np.abs(M_true - np.eye(3))[M_true != np.eye(3)].min()
            assert se.max() < 0.2 * smallest, (se.max(), smallest)
        else:
            np.testing.assert_allclose(M, M_true, rtol=0, atol=1e-11)
            np.testing.assert_allclose(c, err.bias * TS, rtol=1e-6, atol=0)


# ---------------------------------------------------------------- quantisation


@pytest.mark.parametrize("sensor", ["gyro", "accel"])
def test_quantisation(sensor):
    """Every increment is a whole number of quanta; the quantiser keeps its remainder, so
    the running sum stays within half a quantum of the unquantised running sum."""
    ideal = tumbling_block()
    q_gyro, q_accel = 0.5 * ARCSEC, 10e-6 * 9.78  # typical RLG pulse; 10 µg·s
    gyro, accel = matrix_errors()
    quant = ImuErrors(
        SensorErrors(
            GYRO.bias,
            GYRO.noise,
            gyro.scale,
            gyro.misalignment,
            q_gyro if sensor == "gyro" else 0.0,
        ),
        SensorErrors(
            ACCEL.bias,
            ACCEL.noise,
            accel.scale,
            accel.misalignment,
            q_accel if sensor == "accel" else 0.0,
        ),
    )
    plain = ImuErrors(
        SensorErrors(GYRO.bias, GYRO.noise, gyro.scale, gyro.misalignment),
        SensorErrors(ACCEL.bias, ACCEL.noise, accel.scale, accel.misalignment),
    )
    mq = apply_errors(ideal, quant, np.random.default_rng(14))
    mp = apply_errors(ideal, plain, np.random.default_rng(14))  # same draws: no rng in quantum
    out, ref, q = (mq.dtheta, mp.dtheta, q_gyro) if sensor == "gyro" else (mq.dv, mp.dv, q_accel)
    other = (mq.dv, mp.dv) if sensor == "gyro" else (mq.dtheta, mp.dtheta)
    np.testing.assert_array_equal(*other)  # the other sensor is untouched
    counts = out / q
    # Whole quanta up to the round-off of a difference of two running sums.
    assert np.abs(counts - np.round(counts)).max() < 1e-6
    assert np.any(np.abs(np.round(counts)) >= 1)  # not trivially all zero
    drift = np.cumsum(out, 0) - np.cumsum(ref, 0)
    assert np.abs(drift).max() <= 0.5 * q * (1 + 1e-9), np.abs(drift).max() / q
    # And the quantisation is not a no-op: single increments are off by up to a quantum.
    assert np.abs(out - ref).max() > 0.4 * q


# ---------------------------------------------------------------- seeding


@pytest.mark.parametrize("quantum", [0.0, 0.001 * ARCSEC])
def test_same_seed_same_bits_different_seed_different(quantum):
    ideal = tumbling_block()
    gyro, accel = matrix_errors()
    errs = ImuErrors(
        SensorErrors(gyro.bias, gyro.noise, gyro.scale, gyro.misalignment, quantum), accel
    )
    a = apply_errors(ideal, errs, np.random.default_rng(2024))
    b = apply_errors(ideal, errs, np.random.default_rng(2024))
    c = apply_errors(ideal, errs, np.random.default_rng(2025))
    assert a.dtheta.tobytes() == b.dtheta.tobytes() and a.dv.tobytes() == b.dv.tobytes()
    # Another seed: other noise on (almost) every sample, uncorrelated with the first.
    assert np.mean(a.dtheta != c.dtheta) > 0.9 and np.mean(a.dv != c.dv) > 0.99
    deterministic = ideal.dv @ accel.matrix().T + accel.bias * TS
    da, dc = (a.dv - deterministic).ravel(), (c.dv - deterministic).ravel()
    assert abs(da @ dc) / math.sqrt((da @ da) * (dc @ dc)) < 4.0 / math.sqrt(da.size)


def test_gyro_noise_drawn_before_accel():
    """apply_errors draws gyro noise first: the gyro output does not depend on the
    accelerometer's settings, and the accel output equals a second draw of the stream."""
    ideal = constant_block(1000)
    a = apply_errors(ideal, ImuErrors(GYRO, ACCEL), np.random.default_rng(5))
    b = apply_errors(ideal, ImuErrors(GYRO, SensorErrors()), np.random.default_rng(5))
    np.testing.assert_array_equal(a.dtheta, b.dtheta)
    rng = np.random.default_rng(5)
    rng.standard_normal((1000, 3))
    expected = ideal.dv + ACCEL.bias * TS + rng.standard_normal((1000, 3)) * ACCEL.noise * 0.1
    np.testing.assert_allclose(a.dv, expected, rtol=0, atol=1e-16)


@pytest.mark.parametrize("gyro_noisy", [True, False])
def test_error_stream_same_bits_whole_run_blocks_or_private(gyro_noisy):
    """One block or many, a private generator or the caller's: the same measured bits; a
    caller's generator ends where the gyro's draws left it (3N normals on)."""
    from gcalign.sim.errors import ErrorStream

    ideal = constant_block(2500)
    errs = ImuErrors(GYRO if gyro_noisy else SensorErrors(bias=GYRO.bias), ACCEL)
    n = len(ideal)

    def run(private: bool, block: int, rng: np.random.Generator):
        s = ErrorStream(errs, TS, rng, n, private=private)
        parts = [s.apply(ideal.dtheta[k:k + block], ideal.dv[k:k + block])
                 for k in range(0, n, block)]
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

    ref = run(False, n, np.random.default_rng(9))
    for private, block in ((True, n), (True, 700), (False, 700)):
        got = run(private, block, np.random.default_rng(9))
        assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])
    caller, fresh = np.random.default_rng(9), np.random.default_rng(9)
    run(False, n, caller)
    if gyro_noisy:
        fresh.standard_normal(3 * n)
    else:  # the accelerometer skipped the gyro's 3N and drew its own 3N
        fresh.standard_normal(6 * n)
    assert caller.standard_normal() == fresh.standard_normal()


# ---------------------------------------------------------------- units through the config


def scenario_dict(imu: dict) -> dict:
    return {
        "name": "units",
        "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0},
        "imu": {"rate_hz": 100, "seed": 3, **imu},
        "motion": {"kind": "static", "attitude_deg": [0, 0, 30], "duration_s": 10},
    }


def test_config_units_by_hand():
    mis = [[0, 10, -20], [5, 0, 0], [0, -30, 0]]
    sc = parse_scenario(
        scenario_dict(
            {
                "gyro": {
                    "bias_dph": [0.01, -0.02, 1.0],
                    "arw_dprh": 0.001,
                    "scale_ppm": [10, -20, 30],
                    "misalignment_arcsec": mis,
                    "quantum_arcsec": 0.5,
                },
                "accel": {
                    "bias_ug": [50, -100, 1000],
                    "vrw_ugrhz": [10, 20, 30],
                    "scale_ppm": [100, 0, -50],
                    "misalignment_arcsec": mis,
                    "quantum_ugs": 10,
                },
            }
        )
    )
    e = sc.imu.errors()
    assert isinstance(e, ImuErrors)
    g0 = 9.7803267715
    # 1 °/h = π/180/3600 rad/s; 1 °/√h = π/180/sqrt(3600) = π/180/60 rad/√s.
    np.testing.assert_allclose(
        e.gyro.bias, np.array([0.01, -0.02, 1.0]) * math.pi / 180 / 3600, rtol=1e-15
    )
    assert e.gyro.bias[2] == pytest.approx(4.84813681109536e-06, rel=1e-14)  # 1 °/h
    np.testing.assert_allclose(e.gyro.noise, [0.001 * math.pi / 180 / 60] * 3, rtol=1e-15)
    assert e.gyro.noise[0] == pytest.approx(2.908882086657216e-07, rel=1e-14)  # 0.001 °/√h
    np.testing.assert_allclose(e.gyro.scale, [10e-6, -20e-6, 30e-6], rtol=1e-15)
    arcsec = math.pi / 180 / 3600
    np.testing.assert_allclose(e.gyro.misalignment, np.array(mis) * arcsec, rtol=1e-15)
    assert e.gyro.quantum == pytest.approx(0.5 * arcsec, rel=1e-15)
    # 1 µg = 1e-6 g0 m/s²; 1 µg/√Hz = 1e-6 g0 m/s²/√Hz = 1e-6 g0 m/s/√s.
    np.testing.assert_allclose(e.accel.bias, np.array([50, -100, 1000]) * 1e-6 * g0, rtol=1e-15)
    assert e.accel.bias[2] == pytest.approx(9.7803267715e-3, rel=1e-15)  # 1000 µg = 1 mg
    np.testing.assert_allclose(e.accel.noise, np.array([10, 20, 30]) * 1e-6 * g0, rtol=1e-15)
    np.testing.assert_allclose(e.accel.scale, [100e-6, 0.0, -50e-6], rtol=1e-15)
    np.testing.assert_allclose(e.accel.misalignment, np.array(mis) * arcsec, rtol=1e-15)
    assert e.accel.quantum == pytest.approx(10 * 1e-6 * g0, rel=1e-15)  # µg·s -> m/s
    assert sc.imu.ts == 0.01


def test_config_defaults_are_an_ideal_imu():
    e = parse_scenario(scenario_dict({})).imu.errors()
    for s in (e.gyro, e.accel):
        for x in (s.bias, s.noise, s.scale, s.misalignment):
            assert not np.any(x)
        assert s.quantum == 0.0


@pytest.mark.parametrize(
    "imu, field",
    [
        ({"gyro": {"bias_dph": [0.01, 0.01]}}, "imu.gyro.bias_dph"),
        ({"gyro": {"arw_dprh": -0.001}}, "imu.gyro.arw_dprh"),
        (
            {"accel": {"misalignment_arcsec": [[1, 0, 0], [0, 0, 0], [0, 0, 0]]}},
            "imu.accel.misalignment_arcsec",
        ),
        ({"accel": {"bias_mg": [1, 1, 1]}}, "imu.accel.bias_mg"),
    ],
)
def test_config_rejects_bad_error_fields(imu, field):
    with pytest.raises(ScenarioError, match=field.replace(".", r"\.")):
        parse_scenario(scenario_dict(imu))


def test_config_errors_drive_the_model():
    """The converted errors, fed to apply_errors, give the configured bias in °/h and µg."""
    sc = parse_scenario(
        scenario_dict(
            {"gyro": {"bias_dph": [0.5, -0.5, 2.0]}, "accel": {"bias_ug": [100, 200, -300]}}
        )
    )
    ideal = constant_block(100)
    meas = apply_errors(ideal, sc.imu.errors(), np.random.default_rng(0))
    dph = (meas.dtheta - ideal.dtheta).mean(0) / TS / (math.pi / 180 / 3600)
    ug = (meas.dv - ideal.dv).mean(0) / TS / (9.7803267715e-6)
    np.testing.assert_allclose(dph, [0.5, -0.5, 2.0], rtol=1e-6)
    np.testing.assert_allclose(ug, [100, 200, -300], rtol=1e-6)
