"""The attitude-only kernel (gcalign.nav.strapdown.integrate_attitude): exact composition at
one sub-sample, the PSINS cone factors against the coning drift they are made to remove,
the navigation-frame rate, decimated output."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.nav.rotation import quat_conj, quat_mult, quat_to_rotvec, rotvec_to_quat
from gcalign.nav.strapdown import integrate_attitude

TAU, OMEGA, ALPHA = 2e-4, 2 * math.pi * 10, math.radians(1.0)  # 5 kHz, 10 Hz, 1° cone
N = 12000  # 2.4 s: a multiple of 1 … 5 sub-samples


def coning(t: np.ndarray) -> np.ndarray:
    """q(t) of classical coning: the body's z axis sweeps a cone of half-angle α about the
    reference z at ω, q(t) = rotvec(α [cos ωt, sin ωt, 0]) (known exactly at any time)."""
    r = ALPHA * np.stack([np.cos(OMEGA * t), np.sin(OMEGA * t), np.zeros_like(t)], -1)
    return rotvec_to_quat(r)


def angle_error(q_est, q_true) -> float:
    return float(np.linalg.norm(quat_to_rotvec(quat_mult(quat_conj(q_true), q_est))))


def gyro_increments() -> tuple[np.ndarray, np.ndarray]:
    """What a gyro measures, ∫ω dt over each 5 kHz sample (the body rate from the exact
    attitude by central differences, Simpson on 16 points a sample), and the true attitude
    at the sample times."""
    m, h = 16, 1e-7
    t = np.arange(N * m + 1) * (TAU / m)
    w = quat_to_rotvec(quat_mult(quat_conj(coning(t - h)), coning(t + h))) / (2 * h)
    W = np.ones(m + 1)
    W[1:-1:2], W[2:-1:2] = 4.0, 2.0
    W *= (TAU / m) / 3.0
    dth = np.einsum("j,kjc->kc", W, np.stack([w[i * m:(i + 1) * m + 1] for i in range(N)]))
    return dth, coning(t[::m])


@pytest.fixture(scope="module")
def gyro():
    return gyro_increments()


def test_one_sample_composes_exact_rotation_vectors():
    """gcalign's ideal increments are the exact rotation vectors between samples: composed
    one by one they give the truth to round-off (through any coning)."""
    q = coning(np.arange(N + 1) * TAU)
    dth = quat_to_rotvec(quat_mult(quat_conj(q[:-1]), q[1:]))
    assert angle_error(integrate_attitude(q[0], dth, TAU)[-1], q[-1]) < 1e-12


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_cone_factors_remove_the_coning_drift_of_gyro_increments(gyro, n):
    """Integrated-rate increments (a real gyro's) taken one at a time drift about the cone
    axis (the classical coning error); summed n at a time as well; the PSINS cone factors
    over n sub-samples bring the 2.4 s error down by ≥ 1e4 against the plain sum."""
    dth, q = gyro
    err = angle_error(integrate_attitude(q[0], dth, TAU, subsamples=n)[-1], q[-1])
    plain = q[0].copy()
    for k in range(0, len(dth), n):
        plain = quat_mult(plain, rotvec_to_quat(dth[k:k + n].sum(0)))
    err_plain = angle_error(plain, q[-1])
    assert err_plain > 1e-6  # the drift the factors are for (rad)
    assert err < err_plain * 1e-4, (err, err_plain)


def test_one_gyro_increment_at_a_time_shows_the_coning_drift(gyro):
    """The same gyro increments one per update drift at about ½ ω α² (ωτ)²/6 rad/s (the
    classical single-sample coning error), 6e-7 rad over 2.4 s: why sub-samples exist."""
    dth, q = gyro
    err = angle_error(integrate_attitude(q[0], dth, TAU)[-1], q[-1])
    rate = 0.5 * OMEGA * ALPHA**2 * (OMEGA * TAU) ** 2 / 6.0
    assert err == pytest.approx(rate * N * TAU, rel=0.05)


def test_navigation_frame_rate_and_stride():
    """A body at rest relative to a frame turning at w: the gyros sense w (in the body), the
    kernel removes it through the frame rotation; every stride-th update is returned."""
    w = np.array([1e-4, -2e-4, 7.3e-5])
    tau, n = 0.01, 3000
    q0 = rotvec_to_quat(np.array([0.2, -0.1, 1.0]))
    from gcalign.nav.rotation import quat_to_dcm


    w_b = quat_to_dcm(quat_conj(q0)) @ w
    dth = np.tile(w_b * tau, (n, 1))
    out = integrate_attitude(q0, dth, tau, w_in_n=w, subsamples=1, stride=100)
    assert out.shape == (31, 4)
    np.testing.assert_allclose(np.abs(out @ q0), 1.0, atol=1e-14)  # stays at q0


def test_bad_subsamples():
    with pytest.raises(ValueError, match="multiple"):
        integrate_attitude(np.array([1.0, 0, 0, 0]), np.zeros((7, 3)), 0.01, subsamples=2)
    with pytest.raises(ValueError, match="1 to 5"):
        integrate_attitude(np.array([1.0, 0, 0, 0]), np.zeros((6, 3)), 0.01, subsamples=6)
