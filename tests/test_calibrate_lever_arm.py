"""An aiding antenna at a lever arm in the calibration filter (seed 002's filter;
:func:`gcalign.estimation.ins_error.lever_arm_terms`).

* The offsets against an independent route: the antenna's positions computed from the
  truth, its velocity by differencing them (not from the gyro rates the filter uses).
* The H columns against finite differences of the offsets (the signs of φ, ε, δKg).
* A simulated flight aided at the antenna: with the lever arm the filter does what it does
  aided at the IMU; ignored, its position settles at the antenna, C_b^n l away.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from calibrate_cases import short

from gcalign.calibrate import Settings, calibrate, proposed_truth
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.nav.rotation import euler_to_dcm, quat_to_dcm, rotvec_to_quat

LEVER = np.array([0.8, 4.0, 1.5])  #: antenna right, ahead and above the IMU, m
S = 25  #: navigation steps per filter step (25 Hz, 1 Hz)


def _antenna(data, lever=LEVER):
    """The antenna's positions and velocities at the navigation times from the truth:
    ``r_a = r + C_b^n l`` (as [L, λ, h]) and ``v_a = v + d(C_b^n l)/dt + ω_en^n × C_b^n l``
    (the earth-referenced rate of the offset: its rate in the turning n frame plus the
    frame's turn), the derivative by central differences of the attitude's samples."""
    tr, e = data.truth, data.earth
    Cl = euler_to_dcm(tr.att) @ lever
    r_m, r_n = e.radii(tr.pos[:, 0])
    h = tr.pos[:, 2]
    pos = tr.pos + np.column_stack([Cl[:, 1] / (r_m + h),
                                    Cl[:, 0] / ((r_n + h) * np.cos(tr.pos[:, 0])), Cl[:, 2]])
    v = tr.v_n + np.gradient(Cl, tr.t, axis=0) + np.cross(e.omega_en_n(tr.pos[:, 0], h,
                                                                       tr.v_n), Cl)
    return pos, v, Cl


@pytest.fixture(scope="module")
def flight():
    return short(proposed_truth(), noise=True, seed=3)


def test_offsets_against_the_antenna_motion(flight):
    """At every filter epoch of the 162 s flight (turns at 9 °/s, rolls at 5 °/s), the
    offsets of lever_arm_terms from the truth's attitude and rates equal the antenna's
    motion: position to round-off, velocity to 1e-5 m/s (the central differences' own
    error is ~4e-6). The form with ω_in^n in place of ω_ie^n would miss by ω_en^n × C l,
    more than 3e-5 m/s here: the tolerance tells them apart."""
    tr, e = flight.truth, flight.earth
    pos_a, v_a, Cl = _antenna(flight)
    k = np.arange(S, len(tr.t) - 1, S)  # the epochs, inside the differences
    C = euler_to_dcm(tr.att[k])
    w = 0.5 * (tr.omega_ib_b[k - 1] + tr.omega_ib_b[k])  # the rate at the sample
    r_m, r_n = e.radii(tr.pos[k, 0])
    worst_v = 0.0
    for i, j in enumerate(k):
        off, _ = ie.lever_arm_terms("both", C[i], w[i], e.omega_ie_n(tr.pos[j, 0]), LEVER,
                                    LEVER)
        worst_v = max(worst_v, np.abs(off[:2] - (v_a[j] - tr.v_n[j])[:2]).max())
        dp = [(pos_a[j, 0] - tr.pos[j, 0]) * (r_m[i] + tr.pos[j, 2]),
              (pos_a[j, 1] - tr.pos[j, 1]) * (r_n[i] + tr.pos[j, 2]) * np.cos(tr.pos[j, 0])]
        np.testing.assert_allclose(off[2:], dp, atol=1e-9)
    assert worst_v < 1e-5
    w_en = e.omega_en_n(tr.pos[k, 0], tr.pos[k, 2], tr.v_n[k])
    assert np.abs(np.cross(w_en, Cl[k])[:, :2]).max() > 3e-5


def test_columns_against_finite_differences():
    """H_l φ + H_l,ε x_ε + H_l,δKg x_δKg is the change of the offsets when the INS's
    attitude is ``exp(−[φ×]) C`` and its rate ``(1 + x_δKg) ω + x_ε`` (to 1e-4 relative,
    second-order terms at perturbations of 1e-6)."""
    rng = np.random.default_rng(4)
    C = quat_to_dcm(rotvec_to_quat(rng.normal(size=3)))
    w, w_ie = rng.normal(size=3) * 0.3, np.array([0.0, 5e-5, 5e-5])
    l_v, l_p = rng.normal(size=3) * 2, rng.normal(size=3) * 2
    off0, H = ie.lever_arm_terms("both", C, w, w_ie, l_v, l_p)
    for _ in range(5):
        x = np.zeros(21)
        x[ie.PHI], x[ie.EB], x[ie.DKG] = rng.normal(size=(3, 3)) * 1e-6
        C_est = quat_to_dcm(rotvec_to_quat(-x[ie.PHI])) @ C
        off, _ = ie.lever_arm_terms("both", C_est, (1 + x[ie.DKG]) * w + x[ie.EB], w_ie, l_v,
                                    l_p)
        np.testing.assert_allclose(off - off0, H @ x, rtol=1e-4, atol=1e-12)
    assert np.all(H[:, ie.DV] == 0) and np.all(H[2:, ie.EB] == 0)  # position: φ only


def test_filter_with_and_without_the_lever_arm(flight):
    """DGNSS velocity and position (σ 0.05 m/s, 0.1 m) measured at an antenna at
    (0.8, 4, 1.5) m. With the lever arm the filter does what it does aided at the IMU itself:
    every state within 3.5σ of the truth at every epoch, the final sensor estimates within
    0.1σ and the NEES within 4 of that run's (the same noise). Ignored, the filter takes the
    antenna for the IMU: on the ground (the first 30 s, C_b^n l constant, the antenna's
    velocity that of the IMU to 3e-4 m/s) the INS position settles at the antenna, C_b^n l
    from the truth within 3σ, and over the flight the sensor estimates leave their σ by an
    order of magnitude."""
    pos_a, v_a, Cl = _antenna(flight)
    at_antenna = replace(flight, ref_v_n=v_a, ref_pos=pos_a)
    s = Settings(measure="both", sigma_v=0.05, sigma_p=0.1)
    imu = calibrate(flight, s, np.random.default_rng(5))
    lever = calibrate(replace(at_antenna, lever_arm_v_b=LEVER, lever_arm_p_b=LEVER), s,
                      np.random.default_rng(5))
    ignored = calibrate(at_antenna, s, np.random.default_rng(5))

    assert np.abs(lever.error / lever.sigma).max() < 3.5
    d = (lever.estimate[-1, ie.IMU] - imu.estimate[-1, ie.IMU]) / imu.sigma[-1, ie.IMU]
    assert np.abs(d).max() < 0.1
    assert np.abs(lever.nees - imu.nees).max() < 4.0

    tr, e = flight.truth, flight.earth
    ep = int(np.searchsorted(ignored.t, 29.0))  # the last epoch on the ground
    j = ep * S
    r_m, r_n = e.radii(tr.pos[j, 0])
    k_ne = np.array([r_m + tr.pos[j, 2], (r_n + tr.pos[j, 2]) * np.cos(tr.pos[j, 0])])
    err_ne = (ignored.pos[ep, :2] - tr.pos[j, :2]) * k_ne
    sigma_ne = ignored.sigma[ep, ie.IDX["dL"]: ie.IDX["dlam"] + 1] * k_ne
    assert np.hypot(*Cl[j, :2]) > 4.0
    assert np.all(np.abs(err_ne - Cl[j, [1, 0]]) < 3 * sigma_ne), (err_ne, Cl[j])
    assert np.abs(ignored.error[-1, ie.IMU] / ignored.sigma[-1, ie.IMU]).max() > 10


@pytest.mark.parametrize("bad", [[0.0, 1.0], [0.0, np.nan, 1.0], [np.inf, 0.0, 0.0]])
def test_a_lever_arm_that_is_not_three_finite_numbers(flight, bad):
    with pytest.raises(ScenarioError) as exc:
        calibrate(replace(flight, lever_arm_p_b=np.array(bad)), Settings(measure="position"),
                  np.random.default_rng(0))
    msg = str(exc.value)
    assert msg.startswith("lever_arm_p_b: must be 3 finite numbers") and "\n" not in msg
