"""Gyrocompass loops (seed 000 eqs. 1-4, 11-13): kernel against a slow NumPy reference,
convergence and oscillation period against the designed poles, steady-state errors
against the closed forms of DESIGN.md, and the behaviour at a change of pass direction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign import units as u
from gcalign.align import kernel as K
from gcalign.align.cycles import loop_gains
from gcalign.align.gains import azimuth_gains
from gcalign.align.stages import Stage
from gcalign.app.align.run import run_alignment
from gcalign.app.data import scenario_data
from gcalign.io.scenario import parse_scenario
from gcalign.nav import earth
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm, misalignment, quat_to_dcm, rotvec_to_quat
from gcalign.sim.imu import ideal_imu
from gcalign.sim.motions import Swing

SITE = {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0.0}
LAT = np.radians(SITE["lat_deg"])


# The reference's rotations on single vectors, in plain floats (the vectorised helpers of
# gcalign.nav.rotation cost ~20 µs a call on one quaternion; the reference makes ten a step).


def _dcm(q):
    """DCM of the unit quaternion q = [w, x, y, z]."""
    w, x, y, z = q
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def _quat(r):
    """Quaternion of the rotation vector r (rad)."""
    th = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    ratio = 0.5 - th * th / 48.0 if th < 1e-4 else math.sin(0.5 * th) / th
    return np.array([math.cos(0.5 * th), r[0] * ratio, r[1] * ratio, r[2] * ratio])


def _mult(p, q):
    """Hamilton product p ⊗ q."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return np.array([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw])


def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _rot(r, v):
    """R(r) v by Rodrigues (exact)."""
    return _dcm(_quat(r)) @ v


def reference_block(state, dtheta, dv, vref, body, ts, sign, gains, mode):
    """Plain-NumPy transcription of the kernel's docstring equations, one step at a time."""
    ke1, ke2, ke3, kn1, kn2, kn3, ku1, ku2, ku3, ku4 = gains
    q, (ve, vn), (ie, inn), wcu = state[0:4].copy(), state[4:6], state[6:8], state[8]
    lat, lon, h = state[9:12]

    def ref_n(k, q):
        return _dcm(q) @ vref[k] if body else vref[k]

    r = ref_n(0, q)
    r_m, r_n = earth.radii(lat)
    wcn = wce = 0.0
    if mode != K.ATTITUDE:
        wcn = (ve - r[0]) * (1 + ke2) / (r_n + h) + ke3 * ie
        wce = (
            -(vn - r[1]) * (1 + kn2) / (r_m + h) - kn3 * inn
            if mode == K.LEVEL
            else -(vn - r[1]) * (1 + ku2) / (r_m + h)
        )
    out = [q.copy()]
    for k in range(len(dtheta)):
        r_m, r_n = earth.radii(lat)
        rmh, rnh = r_m + h, r_n + h
        w_ie = sign * earth.omega_ie_n(lat)
        w_en = earth.omega_en_n(lat, h, r)
        w_c = np.array([wce, wcn, wcu if mode == K.COMPASS else 0.0])
        w_in = w_ie + w_en + w_c
        f = _rot(-0.5 * w_in * ts, _dcm(q) @ _rot(0.5 * dtheta[k], dv[k]))
        q = _mult(_quat(-w_in * ts), _mult(q, _quat(dtheta[k])))
        q = q / np.linalg.norm(q)
        nxt = ref_n(k + 1, q)
        # position along the reference velocity: trapezoid, radii at mid-interval
        u = 0.5 * (r + nxt)
        h_mid = h + 0.5 * u[2] * ts
        lat_mid = lat + 0.5 * u[1] * ts / (r_m + h_mid)
        rm_mid, rn_mid = earth.radii(lat_mid)
        lat_new = lat + u[1] * ts / (rm_mid + h_mid)
        lon = lon + u[0] * ts / ((rn_mid + h_mid) * np.cos(lat_mid))
        h_new = h + u[2] * ts
        if mode != K.ATTITUDE:
            frame = 2 * w_ie + w_en + (w_c if body else 0.0)
            a = -_cross(frame, 0.5 * (r + nxt))
            k1n = kn1 if mode == K.LEVEL else ku1
            ve, vn = (
                ve + f[0] + a[0] * ts - ke1 * (ve - r[0]) * ts,
                vn + f[1] + a[1] * ts - k1n * (vn - r[1]) * ts,
            )
            dve, dvn = ve - nxt[0], vn - nxt[1]
            ie += dve * ts
            wcn = dve * (1 + ke2) / rnh + ke3 * ie
            if mode == K.LEVEL:
                inn += dvn * ts
                wce = -dvn * (1 + kn2) / rmh - kn3 * inn
            else:
                wcu = (wcu + ku3 * dvn * ts / w_ie[1]) / (1 + ku4 * ts)
                wce = -dvn * (1 + ku2) / rmh
        else:
            ve, vn = nxt[0], nxt[1]
        lat, h, r = lat_new, h_new, nxt
        out.append(q.copy())
    final = np.concatenate([q, [ve, vn, ie, inn, wcu, lat, lon, h]])
    return final, np.array(out)


@pytest.mark.parametrize("mode", [K.ATTITUDE, K.LEVEL, K.COMPASS])
@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("body", [False, True])
def test_kernel_matches_numpy_reference(mode, sign, body):
    motion = Swing(tuple(np.radians([1, 2, 30])),
        15.0,
        amplitude=tuple(np.radians([2, 3, 4])),
        period=(10, 10, 20),
    )
    _, imu = ideal_imu(motion, np.array([LAT, 2.2, 10.0]), 0.01)
    rng = np.random.default_rng(3)
    n = len(imu)
    dtheta = imu.dtheta + 1e-7 * rng.standard_normal((n, 3))
    dv = imu.dv + 1e-5 * rng.standard_normal((n, 3))
    vref = (
        np.column_stack([np.zeros(n + 1), 5.0 + 0.01 * np.arange(n + 1) * 0.01, np.zeros(n + 1)])
        if body
        else rng.normal(0, 3, (n + 1, 3))
    )
    gains = loop_gains(Stage(20.0, 100.0, 0.707), LAT, 10.0, "double-oscillator")
    state = K.new_state(
        rotvec_to_quat(np.radians([1.0, -1.5, 25.0])), [0.3, -0.2, 0], [LAT, 2.2, 10]
    )
    state[6:9] = [1e-4, -2e-4, 3e-6]
    expected, q_ref = reference_block(state.copy(), dtheta, dv, vref, body, 0.01, sign, gains, mode)
    q_out = np.empty((n + 1, 4))
    K.gyrocompass_block(state, dtheta, dv, vref, body, 0.01, sign, WGS84.params(), gains, mode,
                        q_out)
    np.testing.assert_allclose(q_out, q_ref, rtol=0, atol=1e-12)
    scale = np.maximum(np.abs(expected), 1e-300)
    assert np.max(np.abs(state - expected) / scale) < 1e-9 or np.allclose(
        state, expected, rtol=1e-12, atol=1e-15
    )


def _static(extra: dict | None = None, **align) -> dict:
    sc = {
        "name": "static",
        "site": SITE,
        "motion": {"kind": "static", "attitude_deg": [0, 0, 30], "duration_s": 1000},
        "align": {
            "coarse": {"method": "given", "error_deg": [1, 1, 10]},
            "mode": "conventional",
            "t1_s": 0,
            "t2_s": 960,
            "t3_s": 960,
            "azimuth_poles": "double-oscillator",
            "level_s": 60,
            "stages": [{"t_xy_s": 20, "t_z_s": 100, "xi": 0.707}],
            **align,
        },
    }
    sc.update(extra or {})
    return sc


def _run(d: dict, seed: int = 1):
    sc = parse_scenario(d)
    data = scenario_data(sc, seed)
    return sc, data, run_alignment(sc, data)


@pytest.mark.parametrize("poles", ["double-oscillator", "oscillator-overdamped"])
def test_static_ideal_converges_with_designed_period(poles):
    t_z, level = 100.0, 60.0
    _, data, run = _run(_static(azimuth_poles=poles))
    err = run.pass_errors[0]  # (N+1, 3) from T1 = 0
    t = np.arange(len(err)) * data.imu.ts
    after = t >= level + 6 * t_z
    assert np.abs(np.degrees(err[after])).max() < 1e-3
    # Heading oscillation: zero crossings after the level phase, while the envelope is
    # above round-off, are half a damped period apart. The oscillatory pole pair of both
    # pole sets has the damped period T_z.
    yaw = err[:, 2]
    live = (t > level + 20) & (np.abs(yaw) > 1e-11)
    idx = np.flatnonzero(live[:-1] & live[1:] & (np.sign(yaw[:-1]) != np.sign(yaw[1:])))
    assert len(idx) >= 4, len(idx)
    half_periods = np.diff(t[idx])[1:]
    period = 2 * np.median(half_periods)
    assert abs(period - t_z) / t_z < 0.10, period


def test_static_bias_steady_state_matches_theory():
    gyro_b = np.array([0.02, -0.01, 0.05])  # °/h, body
    accel_b = np.array([50.0, 30.0, 80.0])  # µg, body
    att = np.radians([0.0, 0.0, 30.0])
    d = _static(
        {"imu": {"gyro": {"bias_dph": gyro_b.tolist()}, "accel": {"bias_ug": accel_b.tolist()}}},
        t2_s=1500,
        t3_s=1500,
    )
    d["motion"]["duration_s"] = 1500
    _, data, run = _run(d)
    phi = misalignment(euler_to_dcm(run.att_t2), euler_to_dcm(run.truth_t2))
    C = euler_to_dcm(att)
    eps, nab = C @ (gyro_b * u.DPH), C @ (accel_b * u.UG)
    g = float(earth.gravity(LAT))
    r_m, _ = earth.radii(LAT)
    omega = earth.OMEGA_IE * np.cos(LAT)
    az = azimuth_gains(100.0, 0.707, g, r_m, "double-oscillator")
    # Compass steady state: ω_cU = ε_U − Ω φ_E holds δv_N = Ω K_U4 ω_cU / K_U3 (DESIGN.md).
    phi_n = nab[0] / g
    phi_e0 = -nab[1] / g
    dvn = omega * az.k4 * (eps[2] - omega * phi_e0) / az.k3
    phi_e = phi_e0 + az.k1 * dvn / g
    phi_u = -eps[0] / omega + phi_n * np.tan(LAT) - (1 + az.k2) * dvn / (r_m * omega)
    expected = np.array([phi_e, phi_n, phi_u])
    np.testing.assert_allclose(phi, expected, rtol=0.05)
    # The main term alone: heading from the east gyro bias, ε_E/(ω_ie cos L).
    assert abs(phi[2] - (-eps[0] / omega)) < 0.1 * abs(eps[0] / omega)


def test_direction_change_does_not_kick_and_cycles_reach_forward_steady_state():
    # Level biases and east/north gyro biases (no up-gyro bias, whose compass shift
    # legitimately changes sign in a reverse pass: DESIGN.md).
    imu = {"gyro": {"bias_dph": [0.02, -0.015, 0.0]}, "accel": {"bias_ug": [60, -40, 0]}}
    d = _static({"imu": imu}, mode="full-cycle", t2_s=760, t3_s=760, compensation="none",
                stages=[{"t_xy_s": 20, "t_z_s": 100, "xi": 0.707, "passes": 3}])
    _, _, run = _run(d)
    fwd_end = run.passes[0].q_nb[-1]
    rev = run.passes[1].q_nb
    moved = [
        np.degrees(np.abs(misalignment(quat_to_dcm(q), quat_to_dcm(fwd_end))).max())
        for q in rev[:: len(rev) // 50]
    ]
    assert max(moved) < 1e-4, max(moved)
    # Same biases, one long forward run: the same steady state.
    long = _static({"imu": imu}, t2_s=1900, t3_s=1900)
    long["motion"]["duration_s"] = 2000
    _, _, ref = _run(long)
    diff = misalignment(euler_to_dcm(run.att_t2), euler_to_dcm(ref.att_t2))
    assert np.degrees(np.abs(diff)).max() < 1e-4


def test_up_gyro_bias_shift_changes_sign_in_reverse_as_designed():
    eps_u = 0.05 * u.DPH
    d = _static(
        {"imu": {"gyro": {"bias_dph": [0, 0, 0.05]}}},
        mode="full-cycle",
        stages=[{"t_xy_s": 20, "t_z_s": 100, "xi": 0.707, "passes": 3}],
        t2_s=760,
        t3_s=760,
        compensation="none",
    )
    _, data, run = _run(d)
    g = float(earth.gravity(LAT))
    r_m, _ = earth.radii(LAT)
    omega = earth.OMEGA_IE * np.cos(LAT)
    az = azimuth_gains(100.0, 0.707, g, r_m, "double-oscillator")
    shift = (1 + az.k2) * (eps_u * omega * az.k4 / az.k3) / (r_m * omega)  # rad
    fwd, rev = run.pass_errors[0][-1, 2], run.pass_errors[1][-1, 2]
    # Euler yaw error = -φ_U; the shift enters with opposite signs in the two directions.
    assert fwd == pytest.approx(shift, rel=0.05)
    assert rev == pytest.approx(-shift, rel=0.05)
