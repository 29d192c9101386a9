"""Strapdown navigation and the ideal IMU it is fed with (gcalign.nav.strapdown,
gcalign.nav._kernels, gcalign.sim.imu.ideal_imu).

References come from physics, never from our own earlier output:

- free navigation on exact ideal increments must reproduce the analytic truth (static,
  seed 000 §5.2 swing, seed 000 §5.3 moving base) over 400 s;
- forward then reverse over the same block (DESIGN.md "Reverse navigation") must return
  the initial state;
- the numba kernel must equal a slow NumPy reference of the same update, written here
  line by line from the docstring of :func:`gcalign.nav._kernels.strapdown_step`;
- the generator's Δv must not depend on its Simpson sub-step count, and a static body's
  increments are known in closed form: Δθ = C_bn ω_ie^n ts, Δv = C_bn [0, 0, g] ts;
- the scalar earth helpers of the kernels equal the vectorised :mod:`gcalign.nav.earth`.
"""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.nav import _kernels as K
from gcalign.nav import earth
from gcalign.nav._kernels import earth_at, transport_rate
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm, misalignment, quat_to_dcm
from gcalign.nav.strapdown import NavState, navigate, reverse_data
from gcalign.sim.imu import ideal_imu
from gcalign.sim.motions import Moving, Segment, Static, Swing
from gcalign.units import DEG

TS = 0.01
SITE = np.array([45.7796 * DEG, 126.6705 * DEG, 0.0])  # seed 000 (Harbin)
EPS = np.finfo(float).eps


def seed_motion(kind: str, duration: float = 400.0):
    """The seed 000 motions: static, §5.2 swing, §5.3 moving base (initial yaw 30°)."""
    att0 = (0.0, 0.0, 30.0 * DEG)
    if kind == "static":
        return Static(att0, duration)
    if kind == "swing":
        return Swing(att0,
            duration,
            amplitude=(2 * DEG, 3 * DEG, 4 * DEG),
            period=(10.0, 10.0, 20.0),
            phase=(0.0, 0.0, 0.0),
        )
    if kind == "climb":  # to 25 m/s, pitch up to 30° at 3 °/s, climb at 12.5 m/s
        return Moving(att0, 60.0, (Segment(5.0, accel=5.0), Segment(10.0, rate=(3 * DEG, 0, 0)),
                                   Segment(45.0)))
    right, left = (0.0, 0.0, -1.0 * DEG), (0.0, 0.0, 1.0 * DEG)
    segments = (
        Segment(10.0),  # still
        Segment(10.0, accel=1.0),  # +1 m/s² to 10 m/s
        Segment(10.0, rate=right),  # right turn (yaw decreases)
        Segment(10.0, rate=left),
        Segment(280.0),  # cruise
        Segment(10.0, rate=right),
        Segment(10.0),  # cruise (held to the end)
    )
    return Moving(att0, duration, segments)


_CACHE: dict = {}


def scenario(kind: str):
    """(Truth, ImuData) of a seed motion over 400 s at 100 Hz (generated once per session)."""
    if kind not in _CACHE:
        _CACHE[kind] = ideal_imu(seed_motion(kind), SITE, TS)
    return _CACHE[kind]


def true_start(truth, k: int = 0) -> NavState:
    return NavState.from_euler(truth.att[k], truth.v_n[k], truth.pos[k])


def att_error_deg(q_nb, att_true):
    """|φ| (deg) of the misalignment between estimated q_nb (N, 4) and true Euler (N, 3)."""
    phi = misalignment(quat_to_dcm(q_nb), euler_to_dcm(att_true))
    return np.degrees(np.linalg.norm(phi, axis=-1))


def horizontal_error_m(pos, pos_true):
    """Horizontal distance (m) between two [lat, lon, h] tracks: ENU metres from the
    latitude and longitude differences with the radii R_M, R_N of the true latitude."""
    lat, h = pos_true[..., 0], pos_true[..., 2]
    r_m, r_n = earth.radii(lat)
    d_north = (pos[..., 0] - lat) * (r_m + h)
    d_east = (pos[..., 1] - pos_true[..., 1]) * (r_n + h) * np.cos(lat)
    return np.hypot(d_east, d_north)


# ---------------------------------------------------------------- free navigation


@pytest.mark.parametrize("kind", ["static", "swing", "moving"])
def test_free_navigation_reproduces_truth(kind):
    truth, imu = scenario(kind)
    sol = navigate(imu.t, imu.dtheta, imu.dv, imu.ts, true_start(truth))
    np.testing.assert_allclose(sol.t, truth.t, atol=1e-9)
    att = att_error_deg(sol.q_nb, truth.att).max()
    vel = np.abs(sol.v_n - truth.v_n).max()
    hor = horizontal_error_m(sol.pos, truth.pos).max()
    assert att < 1e-5, f"{kind}: attitude error {att:.3g}°"
    assert vel < 1e-3, f"{kind}: velocity error {vel:.3g} m/s"
    assert hor < 0.05, f"{kind}: horizontal position error {hor:.3g} m"


def test_moving_truth_is_the_seed_trajectory():
    """Truth sanity, from the seed's numbers: 10 m/s forward, yaw 30° -> 20° at the end."""
    truth, _ = scenario("moving")
    np.testing.assert_allclose(np.degrees(truth.att[-1]), [0.0, 0.0, 20.0], atol=1e-9)
    # forward (body y) at yaw 20° CCW from north: v = 10 [-sin 20°, cos 20°, 0]
    np.testing.assert_allclose(
        truth.v_n[-1], 10.0 * np.array([-np.sin(20 * DEG), np.cos(20 * DEG), 0.0]), atol=1e-9
    )


# ---------------------------------------------------------------- forward then reverse


@pytest.mark.parametrize("kind", ["swing", "moving"])
def test_forward_then_reverse_returns_initial_state(kind):
    truth, imu = scenario(kind)
    n = int(round(300.0 / TS))
    t, dth, dv = imu.t[:n], imu.dtheta[:n], imu.dv[:n]
    start = true_start(truth)
    fwd = navigate(t, dth, dv, TS, start)
    back = navigate(t, dth, dv, TS, fwd.state(), reverse=True)
    np.testing.assert_allclose(back.t, fwd.t[::-1])
    end = back.state()
    att = att_error_deg(end.q_nb[None], truth.att[:1])[0]
    vel = np.abs(end.v_n - start.v_n).max()
    hor = horizontal_error_m(end.pos, start.pos)
    assert att < 1e-6, f"{kind}: attitude {att:.3g}°"
    assert vel < 1e-4, f"{kind}: velocity {vel:.3g} m/s"
    assert hor < 0.01, f"{kind}: horizontal position {hor:.3g} m"
    assert abs(end.pos[2] - start.pos[2]) < 0.01
    # The reverse pass retraces the forward one, in forward-time velocity.
    assert np.abs(back.v_n[::-1] - fwd.v_n).max() < 1e-4


# ---------------------------------------------------------------- kernel vs NumPy reference


def _rodrigues(r):
    """exp([r×]), (3, 3): I + (sin θ/θ) K + ((1 - cos θ)/θ²) K², 1 - cos θ = 2 sin²(θ/2)."""
    th = np.linalg.norm(r)
    K = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    if th == 0.0:
        return np.eye(3)
    a = np.sin(th) / th
    b = 2.0 * np.sin(0.5 * th) ** 2 / th**2
    return np.eye(3) + a * K + b * (K @ K)


def _rv2q(r):
    """Quaternion [w, x, y, z] of a rotation vector: [cos(θ/2), sin(θ/2) r/θ]."""
    th = np.linalg.norm(r)
    s = 0.5 if th == 0.0 else np.sin(0.5 * th) / th
    return np.concatenate([[np.cos(0.5 * th)], s * np.asarray(r)])


def _qmul(p, q):
    """Hamilton product p ⊗ q as the left-multiplication matrix [p⊗] @ q."""
    w, x, y, z = p
    L = np.array([[w, -x, -y, -z], [x, w, -z, y], [y, z, w, -x], [z, -y, x, w]])
    return L @ q


def _q2dcm(q):
    """C(q) = (w² - |u|²) I + 2 u uᵀ + 2 w [u×]."""
    w, u = q[0], q[1:]
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return (w * w - u @ u) * np.eye(3) + 2.0 * np.outer(u, u) + 2.0 * w * K


def reference_step(q, v, p, dth, dvb, ts, earth_sign):
    """One update, re-derived from the docstring of ``strapdown_step`` (slow, plain NumPy).

    Docstring:  v_k = v_{k-1} + R(-ω_in T/2) C_nb(k-1) R(Δθ/2) Δv
                      + (g_n - (2ω_ie + ω_en) × v_mid) T,
                q_k = q(-ω_in T) ⊗ q_{k-1} ⊗ q(Δθ_k),  ω_in = ω_ie + ω_en(v_mid),
                position by the trapezoid rule, radii at the mid-interval latitude.
    Where the docstring leaves a choice open, the choice made here (stated on the line)
    is the only one available without iterating: the specific-force rotation needs
    ω_in before v_mid is known, so it takes ω_en(v_{k-1}); v_mid is predicted from the
    specific-force increment and gravity (Coriolis is second order there); gravity in
    the velocity update is taken at the height v_mid gives at mid-interval; the other
    earth quantities are those of the start of the step.
    """
    lat, lon, h = p
    r_m, r_n = earth.radii(lat)
    g_n = np.array([0.0, 0.0, -earth.gravity(lat, h)])
    w_ie = earth_sign * earth.omega_ie_n(lat)
    w_in0 = w_ie + earth.omega_en_n(lat, h, v)  # at v_{k-1} (v_mid not known yet)
    # Specific-force increment resolved at mid-interval (body half, then nav half rotation).
    dv_n = _rodrigues(-0.5 * w_in0 * ts) @ _q2dcm(q) @ _rodrigues(0.5 * dth) @ dvb
    v_mid = v + 0.5 * (dv_n + g_n * ts)  # predicted mid-interval velocity
    w_en = earth.omega_en_n(lat, h, v_mid)
    g_mid = np.array([0.0, 0.0, -earth.gravity(lat, h + 0.5 * v_mid[2] * ts)])  # at mid height
    v_new = v + dv_n + (g_mid - np.cross(2.0 * w_ie + w_en, v_mid)) * ts
    # q_k = q(-ω_in T) ⊗ q_{k-1} ⊗ q(Δθ_k), renormalised.
    q_new = _qmul(_rv2q(-(w_ie + w_en) * ts), _qmul(q, _rv2q(dth)))
    q_new = q_new / np.linalg.norm(q_new)
    # Position: mean velocity (trapezoid); height and latitude at mid-interval for the radii.
    u = 0.5 * (v + v_new)
    h_mid = h + 0.5 * u[2] * ts
    lat_mid = lat + 0.5 * u[1] * ts / (r_m + h_mid)
    r_m, r_n = earth.radii(lat_mid)
    p_new = np.array(
        [
            lat + u[1] * ts / (r_m + h_mid),
            lon + u[0] * ts / ((r_n + h_mid) * np.cos(lat_mid)),
            h + u[2] * ts,
        ]
    )
    return q_new, v_new, p_new


def reference_block(q0, v0, p0, dtheta, dv, ts, earth_sign):
    q, v, p = (np.array(x, dtype=float) for x in (q0, v0, p0))
    out_q, out_v, out_p = [q], [v], [p]
    for k in range(len(dtheta)):
        q, v, p = reference_step(q, v, p, dtheta[k], dv[k], ts, earth_sign)
        out_q.append(q)
        out_v.append(v)
        out_p.append(p)
    return np.array(out_q), np.array(out_v), np.array(out_p)


def kernel_block(q0, v0, p0, dtheta, dv, ts, earth_sign):
    """The block kernel on the state vector (free vertical channel, every step kept)."""
    state = np.zeros(K.NAV_STATE)
    state[K.Q], state[K.V], state[K.P] = q0, v0, p0
    out = np.empty((len(dtheta), K.NAV_STATE))
    K.strapdown_block(state, np.ascontiguousarray(dtheta), np.ascontiguousarray(dv), ts,
                      earth_sign, WGS84.params(), np.zeros(4), np.zeros(1), 1, out)
    rows = np.vstack([np.concatenate([q0, v0, p0, [0.0]]), out])
    return rows[:, K.Q], rows[:, K.V], rows[:, K.P]


def relative_errors(kernel, reference, p0, ts):
    """Largest differences over a block, kernel - reference, each relative to its scale.

    - q_nb: unit norm, so the absolute difference is the relative one.
    - v_n: relative to ``s_v = max(max |v|, g N T)``, the gravity velocity the block
      integrates (each step adds ``C_nb Δv`` and cancels ``g T``). Why not max |v|: a
      round-off difference δφ of the attitudes (≈ 1e-14 rad after thousands of steps,
      unavoidable between two implementations) tilts gravity and grows a velocity
      difference ``g δφ t`` whatever the velocity is (≈ 1e-13 m/s on the swing, where
      |v| ≈ 1e-5 m/s). A per-step formula difference of relative size ε accumulates to
      ``ε g N T``, so this scale still tests the formulas to ε = 1e-12 (and
      :func:`test_kernel_step_matches_reference_step` tests single steps).
    - position: ENU metres (latitude and longitude differences times the radii, height
      difference) relative to ``max(largest displacement, ½ g (N T)²)``, same reasoning.
    """
    (qk, vk, pk), (qr, vr, pr) = kernel, reference
    duration = ts * (len(pr) - 1)
    g = earth.gravity(p0[0], p0[2])
    e_q = np.abs(qk - qr).max()
    e_v = np.abs(vk - vr).max() / max(np.abs(vr).max(), g * duration)
    r_m, r_n = earth.radii(p0[0])
    to_m = np.array([r_m + p0[2], (r_n + p0[2]) * np.cos(p0[0]), 1.0])
    d_m = np.abs((pk - pr) * to_m).max()
    e_p = d_m / max(np.abs((pr - p0) * to_m).max(), 0.5 * g * duration**2)
    return e_q, e_v, e_p


def forward_block(kind, k0, k1):
    truth, imu = scenario(kind)
    s = true_start(truth, k0)
    return s, (s.q_nb, s.v_n, s.pos, imu.dtheta[k0:k1], imu.dv[k0:k1], TS, 1.0)


def reverse_block(kind, k0, k1):
    """A reverse pass over [k0, k1): starts at the true state at k1, data transformed as
    navigate does (time reversed, Δθ negated, velocity negated), earth_sign = -1."""
    truth, imu = scenario(kind)
    s = true_start(truth, k1)
    dth, dv = reverse_data(imu.dtheta[k0:k1], imu.dv[k0:k1])
    return s, (s.q_nb, -s.v_n, s.pos, dth, dv, TS, -1.0)


# Blocks of a few thousand steps: the moving base through its acceleration and both
# turns (5-45 s, speeds to 10 m/s), the swing (|Δθ| > 1e-4 rad: the kernel's exact
# rotation-vector branch), the static base (|Δθ| < 1e-4 rad: its series branch), and a
# climb (pitch-up to a vertical velocity of 12.5 m/s: gravity at the mid-step height).
KERNEL_BLOCKS = [("moving", 500, 4500), ("climb", 1000, 4000), ("swing", 0, 3000),
                 ("static", 0, 3000)]


@pytest.mark.slow
@pytest.mark.parametrize("direction", ["forward", "reverse"])
@pytest.mark.parametrize("kind, k0, k1", KERNEL_BLOCKS)
def test_kernel_matches_numpy_reference(kind, k0, k1, direction):
    s, args = (forward_block if direction == "forward" else reverse_block)(kind, k0, k1)
    kernel = kernel_block(*args)
    reference = reference_block(*args)
    e_q, e_v, e_p = relative_errors(kernel, reference, s.pos, TS)
    assert e_q < 1e-12 and e_v < 1e-12 and e_p < 1e-12, (e_q, e_v, e_p)
    np.testing.assert_allclose(kernel[2][:, :2], reference[2][:, :2], rtol=1e-12, atol=0)
    if direction == "reverse":
        # navigate(reverse=True) is this kernel call, with the velocity given forward in time.
        truth, imu = scenario(kind)
        sol = navigate(imu.t[k0:k1], imu.dtheta[k0:k1], imu.dv[k0:k1], TS, s, reverse=True)
        np.testing.assert_array_equal(sol.q_nb, kernel[0])
        np.testing.assert_array_equal(sol.v_n, -kernel[1])
        np.testing.assert_array_equal(sol.pos, kernel[2])


@pytest.mark.slow
@pytest.mark.parametrize("direction", ["forward", "reverse"])
@pytest.mark.parametrize("kind, k0, k1", KERNEL_BLOCKS[:3])
def test_kernel_step_matches_reference_step(kind, k0, k1, direction):
    """Single steps from the same state (every 10th state of the reference block): no
    accumulation, so the formulas agree to round-off of one step. Scales: |q| = 1; the
    velocity increment g T; the height increment g T²; latitude, longitude themselves."""
    _, (q0, v0, p0, dth, dv, ts, sign) = (
        forward_block if direction == "forward" else reverse_block
    )(kind, k0, k1)
    qr, vr, pr = reference_block(q0, v0, p0, dth, dv, ts, sign)
    g = earth.gravity(p0[0], p0[2])
    worst = np.zeros(4)
    for k in range(0, len(dth), 10):
        qk, vk, pk = kernel_block(qr[k], vr[k], pr[k], dth[k : k + 1], dv[k : k + 1], ts, sign)
        q1, v1, p1 = reference_step(qr[k], vr[k], pr[k], dth[k], dv[k], ts, sign)
        worst = np.maximum(
            worst,
            [
                np.abs(qk[1] - q1).max(),
                np.abs(vk[1] - v1).max() / (g * ts),
                np.abs(pk[1, :2] - p1[:2]).max() / np.abs(p1[:2]).min(),
                abs(pk[1, 2] - p1[2]) / (g * ts * ts),
            ],
        )
    assert np.all(worst < 1e-12), worst


# ---------------------------------------------------------------- ideal IMU generator


@pytest.mark.parametrize("kind", ["swing", "moving"])
def test_simpson_substeps_converged(kind):
    """Δv with 2 Simpson sub-steps equals Δv with 16 to 1e-7 m/s per sample (DESIGN.md);
    Δθ does not depend on the sub-steps at all (exact rotation vectors). The difference of a
    sample depends on the motion around it only: two periods of the swing's slowest axis
    (40 s) and the moving base's first 50 s (still, accelerating, both turns, cruise) hold
    every case of the 400 s runs (the same maxima, measured)."""
    motion = seed_motion(kind, {"swing": 40.0, "moving": 50.0}[kind])
    truth2, imu2 = ideal_imu(motion, SITE, TS, substeps=2)
    truth16, imu16 = ideal_imu(motion, SITE, TS, substeps=16)
    assert np.abs(imu2.dv - imu16.dv).max() < 1e-7
    assert np.abs(imu2.dtheta - imu16.dtheta).max() < 1e-14
    np.testing.assert_allclose(truth2.att, truth16.att, rtol=0, atol=1e-14)


def test_simpson_needs_even_substeps():
    with pytest.raises(ValueError, match="even"):
        ideal_imu(seed_motion("static", 1.0), SITE, TS, substeps=3)


@pytest.mark.parametrize("att_deg", [[0.0, 0.0, 30.0], [5.0, -7.0, -120.0], [60.0, 170.0, 10.0]])
def test_static_increments_closed_form(att_deg):
    """At rest C_nb is constant, so ω_ib^b = C_bn ω_ie^n and f_b = C_bn [0, 0, g] are constant
    and the increments are exactly Δθ = C_bn ω_ie^n ts, Δv = C_bn [0, 0, g] ts.

    Δv agrees to 1e-12 relative. Δθ is the rotation vector of q_ib(k-1)* ⊗ q_ib(k) with
    q_ib of order 1 and |Δθ| = 7e-7 rad, so its floor is an absolute round-off of a few
    ulp of a unit quaternion (≈ 5e-16 rad, i.e. ≈ 7e-10 relative), not 1e-12 relative.
    What matters for navigation, the accumulated angle, telescopes: the sum of all
    40000 Δθ is exact to 1e-10 relative (about 3e-12 rad).
    """
    att = np.radians(att_deg)
    motion = Static(tuple(att), 400.0)
    truth, imu = ideal_imu(motion, SITE, TS)
    lat, _, h = SITE
    C_bn = euler_to_dcm(att).T
    dtheta = C_bn @ earth.omega_ie_n(lat) * TS
    dv = C_bn @ np.array([0.0, 0.0, earth.gravity(lat, h)]) * TS
    assert np.abs(imu.dv - dv).max() <= 1e-12 * np.linalg.norm(dv)
    assert np.abs(imu.dtheta - dtheta).max() <= 8 * EPS
    n = len(imu.dtheta)
    assert np.abs(imu.dtheta.sum(0) - n * dtheta).max() <= 1e-10 * n * np.linalg.norm(dtheta)
    np.testing.assert_array_equal(truth.pos, np.tile(SITE, (n + 1, 1)))
    np.testing.assert_array_equal(truth.v_n, 0.0)


# ---------------------------------------------------------------- earth helpers in step


@pytest.mark.parametrize("h", [0.0, 380.0, -500.0, 12_000.0])
def test_scalar_earth_helpers_match_vectorised(h):
    E = WGS84.params()
    lats = np.radians(np.linspace(-89.9, 89.9, 37))
    v_n = np.array([3.0, -7.0, 0.5])
    for lat in lats:
        r_m, r_n, g, sl, cl = earth_at(E, lat, h)
        ref_m, ref_n = earth.radii(lat)
        assert r_m == pytest.approx(ref_m, rel=1e-15, abs=0)
        assert r_n == pytest.approx(ref_n, rel=1e-15, abs=0)
        assert g == pytest.approx(earth.gravity(lat, h), rel=1e-15, abs=0)
        assert (sl, cl) == (np.sin(lat), np.cos(lat))
        rate = transport_rate(v_n[0], v_n[1], r_m, r_n, h, sl, cl)
        np.testing.assert_allclose(rate, earth.omega_en_n(lat, h, v_n), rtol=1e-14, atol=0)
        np.testing.assert_allclose(
            earth.OMEGA_IE * np.array([0.0, cl, sl]), earth.omega_ie_n(lat), rtol=1e-15, atol=0
        )


def test_earth_values_by_hand():
    """WGS-84 anchors: R_N(0) = a, R_M(0) = a (1 - e²), R_M(90°) = R_N(90°) = a / sqrt(1 - e²);
    normal gravity at the equator is GE, at the pole GE (1 + c1 + c2)."""
    E = WGS84.params()
    a, e2 = 6378137.0, (2 - 1 / 298.257223563) / 298.257223563
    r_m, r_n, g, _, _ = earth_at(E, 0.0, 0.0)
    assert r_n == pytest.approx(a, rel=1e-15)
    assert r_m == pytest.approx(a * (1 - e2), rel=1e-15)
    assert g == pytest.approx(9.7803267715, rel=1e-15)
    r_m, r_n, g, _, _ = earth_at(E, np.pi / 2, 0.0)
    assert r_m == pytest.approx(a / np.sqrt(1 - e2), rel=1e-14)
    assert r_n == pytest.approx(a / np.sqrt(1 - e2), rel=1e-14)
    assert g == pytest.approx(9.7803267715 * (1 + 5.27094e-3 + 2.32718e-5), rel=1e-15)
    assert earth_at(E, 0.0, 1000.0)[2] == pytest.approx(9.7803267715 - 3.086e-3, rel=1e-15)
