"""Time-varying sensor errors of the simulator: Gauss–Markov and random-walk biases and a
Gauss–Markov scale factor (gcalign.sim.errors), checked against their exact
discretisation and their stationary statistics, block by block."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.io.scenario import parse_scenario
from gcalign.sim.errors import ErrorStream, ImuErrors, SensorErrors
from gcalign.units import DPH, HOUR, PPM, UG

TS = 0.01


def _errors(n: int, errors: ImuErrors, seed: int = 3, block: int | None = None,
            ideal: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Measured − ideal increments (n, 3) of gyro and accel, in blocks of `block`."""
    dth = np.full((n, 3), ideal)
    dv = np.full((n, 3), ideal)
    s = ErrorStream(errors, TS, np.random.default_rng(seed), n)
    block = block or n
    g, a = [], []
    for k in range(0, n, block):
        gg, aa = s.apply(dth[k:k + block], dv[k:k + block])
        g.append(gg - dth[k:k + block])
        a.append(aa - dv[k:k + block])
    return np.concatenate(g), np.concatenate(a)


def test_gauss_markov_bias_is_the_exact_first_order_recursion_with_its_stationary_std():
    std, tau = 0.5 * DPH, 2.0
    err = ImuErrors(gyro=SensorErrors(bias_gm_std=np.full(3, std), bias_gm_tau=np.full(3, tau)))
    n = 200_000  # 1000 correlation times
    b = _errors(n, err)[0] / TS
    a = math.exp(-TS / tau)
    drive = b[1:] - a * b[:-1]  # = s w_k exactly
    s = std * math.sqrt(1 - a * a)
    assert np.allclose(drive.std(0), s, rtol=0.01)  # 2e5 normals: 0.16 % std of the std
    assert np.allclose(drive.mean(0), 0.0, atol=0.01 * s)
    # stationary from the first sample: the variance of x over 1000 τ is σ² within ~5 %
    assert np.allclose(b.std(0), std, rtol=0.10)
    lag = int(tau / TS)
    rho = np.mean(b[lag:] * b[:-lag], 0) / np.mean(b * b, 0)
    assert np.allclose(rho, math.exp(-1), atol=0.08)


def test_random_walk_bias_grows_as_q_root_t():
    q = 0.02 * DPH / math.sqrt(HOUR)
    err = ImuErrors(accel=SensorErrors(bias_rw=np.full(3, q)))
    b = _errors(100_000, err)[1] / TS
    steps = np.diff(np.vstack([np.zeros(3), b]), axis=0)
    assert np.allclose(steps.std(0), q * math.sqrt(TS), rtol=0.01)
    # across 200 seeds, the bias after 100 s has std q √100 s
    ends = np.array([_errors(10_000, err, seed=s)[1][-1] / TS for s in range(200)])
    assert np.allclose(ends.std(0), q * 10.0, rtol=0.2)


def test_gauss_markov_scale_factor_multiplies_the_input():
    std, tau = 300 * PPM, 5.0
    err = ImuErrors(gyro=SensorErrors(scale_gm_std=np.full(3, std), scale_gm_tau=np.full(3, tau)))
    g = _errors(50_000, err, ideal=1e-3)[0] / 1e-3  # the scale factor itself
    a = math.exp(-TS / tau)
    assert np.allclose((g[1:] - a * g[:-1]).std(0), std * math.sqrt(1 - a * a), rtol=0.02)
    zero = _errors(1000, err, ideal=0.0)[0]
    assert np.array_equal(zero, np.zeros_like(zero))  # no input, no scale-factor error


def test_blocks_give_the_same_numbers_and_a_process_changes_no_other_number():
    proc = dict(bias_gm_std=np.full(3, 0.1 * DPH), bias_gm_tau=np.full(3, 30.0),
                bias_rw=np.full(3, 0.01 * DPH / 60))
    plain = ImuErrors(gyro=SensorErrors(noise=np.full(3, 1e-4)),
                      accel=SensorErrors(noise=np.full(3, 1e-4)))
    varying = ImuErrors(gyro=SensorErrors(noise=np.full(3, 1e-4), **proc),
                        accel=SensorErrors(noise=np.full(3, 1e-4), **proc))
    whole = _errors(5000, varying)
    for block in (1, 7, 4096):
        parts = _errors(5000, varying, block=block)
        assert np.array_equal(whole[0], parts[0]) and np.array_equal(whole[1], parts[1])
    # the white noise is that of the run without processes: the difference is smooth
    base = _errors(5000, plain)
    diff = whole[0] - base[0]
    assert np.abs(np.diff(diff, axis=0)).max() < 1e-3 * np.abs(base[0]).max()


def test_scenario_keys_in_user_units():
    sc = parse_scenario({
        "name": "p", "site": {"lat_deg": 30, "lon_deg": 114},
        "motion": {"kind": "static", "duration_s": 1},
        "imu": {"gyro": {"bias_gm": {"std_dph": 0.5, "tau_s": 3600}, "bias_rw_dphrh": 0.1,
                         "scale_gm": {"std_ppm": [100, 200, 300], "tau_s": 1000}},
                "accel": {"bias_gm": {"std_ug": 50, "tau_s": [100, 200, 300]},
                          "bias_rw_ughrh": 20}}})
    g, a = sc.imu.errors().gyro, sc.imu.errors().accel
    assert np.allclose(g.bias_gm_std, 0.5 * DPH) and np.allclose(g.bias_gm_tau, 3600)
    assert np.allclose(g.bias_rw, 0.1 * DPH / 60)  # (°/h)/√h -> rad/s/√s
    assert np.allclose(g.scale_gm_std, [100e-6, 200e-6, 300e-6])
    assert np.allclose(a.bias_gm_std, 50 * UG) and np.allclose(a.bias_gm_tau, [100, 200, 300])
    assert np.allclose(a.bias_rw, 20 * UG / 60)
    assert g.varying and a.varying and not SensorErrors().varying


@pytest.mark.parametrize("key, value, word", [
    ("gyro.bias_gm", {"std_dph": 0.1, "tau_s": 0}, "tau_s"),
    ("gyro.bias_gm", {"std_dph": 0.1}, "tau_s"),
    ("accel.bias_rw_ughrh", -1, "bias_rw_ughrh"),
])
def test_bad_process_keys_name_the_field(key, value, word):
    from gcalign.errors import ScenarioError

    sensor, name = key.split(".")
    with pytest.raises(ScenarioError, match=word):
        parse_scenario({"name": "p", "site": {"lat_deg": 30, "lon_deg": 114},
                        "motion": {"kind": "static", "duration_s": 1},
                        "imu": {sensor: {name: value}}})
