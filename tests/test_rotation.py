"""Rotation helpers (gcalign.nav.rotation) against scipy.spatial.transform.Rotation, an
independent implementation, on seeded random inputs and the hard corners: rotation vectors
near zero (where sin(θ/2)/θ loses digits) and near π (where the quaternion's scalar part
vanishes and its sign is a choice), and Euler angles near gimbal lock (pitch → ±90°).

Our convention in scipy's terms: ``C_nb = Rz(yaw) Rx(pitch) Ry(roll)`` is the intrinsic
sequence ``"ZXY"`` with angles ``[yaw, pitch, roll]``; our quaternions are scalar first,
scipy's ``as_quat()`` scalar last (both Hamilton). Every entry compared is of order one, so
the tolerances are absolute and a few ulp of 1.

Euler angles from a DCM or a quaternion are ill-conditioned near pitch ±90°: pitch is an
arcsin of C21 (slope 1/cos pitch) and roll and yaw are atan2 of entries proportional to
cos pitch, so each angle carries about ε/cos(pitch) (ε = 2.2e-16). Those tests hold the
angles to :data:`K_COND` ε/cos(pitch), which is 1e-15 only away from the lock. (scipy's
``as_euler`` keeps its middle angle to 6e-16 up to the lock; ours, arcsin like the numba
kernel's, loses up to 3e-8 rad in pitch within 1e-8 rad of ±90°, and roll and yaw their
ε/cos(pitch): the rebuilt DCM is 5e-5 off at 1e-12 rad from the lock.)
"""

from __future__ import annotations

import numpy as np
import pytest
from lazy import lazy_attr

from gcalign.nav import rotation as rot

Rotation = lazy_attr("scipy.spatial.transform", "Rotation")

TOL = 1e-15  #: entries of DCMs and unit quaternions (4.5 ulp of 1)
EPS = np.finfo(float).eps
ANGLE_TOL = 4 * np.spacing(np.pi)  #: angles up to π: 4 ulp of π, 1.8e-15 rad
K_COND = 6.0  #: Euler angles to K_COND ε / cos(pitch) (measured: up to 4.2)
N = 2000
RNG_SEED = 20261201


def _rng() -> np.random.Generator:
    return np.random.default_rng(RNG_SEED)


def _euler(rng: np.random.Generator, n: int = N) -> np.ndarray:
    """Random ``[pitch, roll, yaw]``: pitch in (−90°, 90°), roll and yaw in [−180°, 180°)."""
    return np.column_stack([rng.uniform(-0.5, 0.5, n) * np.pi * 0.999,
                            rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)])


def _gimbal(rng: np.random.Generator, n: int = N) -> np.ndarray:
    """Pitch within 1e-12 … 1e-3 rad of ±90°, roll and yaw anywhere."""
    att = _euler(rng, n)
    att[:, 0] = rng.choice([-1.0, 1.0], n) * (0.5 * np.pi - 10.0 ** rng.uniform(-12, -3, n))
    return att


def _directions(rng: np.random.Generator, n: int) -> np.ndarray:
    u = rng.normal(size=(n, 3))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def _rotvecs(rng: np.random.Generator) -> np.ndarray:
    """Angles from 1e-12 rad to π − 1e-12 rad: uniform, near zero (both sides of the series
    switch at 1e-4 rad) and near π."""
    n = N // 4
    angles = np.concatenate([
        rng.uniform(0.0, np.pi, n),
        10.0 ** rng.uniform(-12, -2, n),
        1e-4 * (1.0 + rng.uniform(-1e-3, 1e-3, n)),
        np.pi - 10.0 ** rng.uniform(-12, -2, n),
    ])
    return _directions(rng, len(angles)) * angles[:, None]


def _quats(rng: np.random.Generator, n: int = N) -> np.ndarray:
    """Random unit quaternions (scalar first), either sign of the scalar part."""
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _scipy_euler(att: np.ndarray) -> Rotation:
    return Rotation.from_euler("ZXY", att[:, [2, 0, 1]])


def _wxyz(r: Rotation) -> np.ndarray:
    """scipy's quaternion, scalar first."""
    return r.as_quat(scalar_first=True)


def _same_sign(q: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """`ref` with the sign (q and −q are one rotation) that lies closest to q."""
    return ref * np.where(np.sum(q * ref, axis=-1, keepdims=True) < 0, -1.0, 1.0)


def _err(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))))


def _cond_err(a: np.ndarray, b: np.ndarray, att: np.ndarray) -> float:
    """Largest error per sample in units of ε / cos(pitch), over the leading axis."""
    d = np.abs(np.asarray(a) - np.asarray(b)).reshape(len(att), -1).max(axis=1)
    return float(np.max(d * np.cos(att[:, 0]) / EPS))


# ----------------------------------------------------------------------------- Euler, DCM


@pytest.mark.parametrize("draw", [_euler, _gimbal])
def test_euler_to_dcm_is_scipys_ZXY(draw):
    att = draw(_rng())
    assert _err(rot.euler_to_dcm(att), _scipy_euler(att).as_matrix()) < TOL


def test_euler_to_dcm_by_hand():
    """The axis matrices written out: pitch about x, roll about y, yaw about z, C = Rz Rx Ry
    (a 90° yaw turns body forward, +y, to west, −x: yaw counter-clockwise positive)."""
    p, r, y = 0.3, -0.7, 1.1
    Rx = np.array([[1, 0, 0], [0, np.cos(p), -np.sin(p)], [0, np.sin(p), np.cos(p)]])
    Ry = np.array([[np.cos(r), 0, np.sin(r)], [0, 1, 0], [-np.sin(r), 0, np.cos(r)]])
    Rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    assert _err(rot.euler_to_dcm([p, r, y]), Rz @ Rx @ Ry) < TOL
    assert _err(rot.euler_to_dcm([0.0, 0.0, np.pi / 2]) @ [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]) \
        < TOL


def test_dcm_to_euler_matches_scipy_away_from_the_lock():
    att = _euler(_rng())
    att = att[np.abs(att[:, 0]) < np.radians(60.0)]
    C = _scipy_euler(att).as_matrix()
    assert _err(rot.dcm_to_euler(C), att) < ANGLE_TOL
    ypr = Rotation.from_matrix(C).as_euler("ZXY")
    assert _err(rot.dcm_to_euler(C), ypr[:, [1, 2, 0]]) < ANGLE_TOL


@pytest.mark.parametrize("draw", [_euler, _gimbal])
def test_dcm_and_quat_to_euler_to_their_conditioning(draw):
    """Up to 89.9° and within 1e-12 … 1e-3 rad of the lock: every angle, and the DCM the
    angles rebuild, within K_COND ε / cos(pitch) of scipy's rotation."""
    att = draw(_rng())
    R = _scipy_euler(att)
    for back in (rot.dcm_to_euler(R.as_matrix()), rot.quat_to_euler(_wxyz(R))):
        assert _cond_err(back, att, att) < K_COND
        assert _cond_err(rot.euler_to_dcm(back), R.as_matrix(), att) < K_COND


def test_dcm_to_euler_ranges():
    att = rot.dcm_to_euler(Rotation.random(N, rng=_rng()).as_matrix())
    assert np.all(np.abs(att[:, 0]) <= np.pi / 2)
    assert np.all(np.abs(att[:, 1:]) <= np.pi)


# ----------------------------------------------------------------------------- quaternions


def test_quat_to_dcm_is_scipys():
    q = _quats(_rng())
    assert _err(rot.quat_to_dcm(q), Rotation.from_quat(q, scalar_first=True).as_matrix()) \
        < 2 * TOL


def test_dcm_to_quat_is_scipys_with_a_non_negative_scalar_part():
    rng = _rng()
    # uniform rotations and rotations within 1e-12 … 1e-2 rad of π (scalar part → 0),
    # where Shepperd's pivot must move off w
    R = Rotation.concatenate([Rotation.random(N, rng=rng),
                              Rotation.from_rotvec(_rotvecs(rng)[-N // 4:])])
    q = rot.dcm_to_quat(R.as_matrix())
    assert np.all(q[:, 0] >= 0)
    assert _err(q, _same_sign(q, _wxyz(R))) < 2 * TOL
    assert _err(np.linalg.norm(q, axis=1), 1.0) < 2 * TOL


@pytest.mark.parametrize("draw", [_euler, _gimbal])
def test_euler_to_quat_is_scipys(draw):
    att = draw(_rng())
    q = rot.euler_to_quat(att)
    assert np.all(q[:, 0] >= 0)
    assert _err(q, _same_sign(q, _wxyz(_scipy_euler(att)))) < TOL


def test_quat_to_euler_is_dcm_to_euler_of_its_dcm():
    q = _quats(_rng())
    att = rot.dcm_to_euler(rot.quat_to_dcm(q))
    assert _cond_err(rot.quat_to_euler(q), att, att) < K_COND
    att = _euler(_rng())
    att = att[np.abs(att[:, 0]) < np.radians(60.0)]
    assert _err(rot.quat_to_euler(_wxyz(_scipy_euler(att))), att) < ANGLE_TOL


def test_quat_mult_is_scipys_composition():
    """p ⊗ q is the rotation q followed by p: scipy's ``Rp * Rq``, matrix ``P @ Q``."""
    rng = _rng()
    p, q = _quats(rng), _quats(rng)
    pq = rot.quat_mult(p, q)
    ref = _wxyz(Rotation.from_quat(p, scalar_first=True) * Rotation.from_quat(q, scalar_first=True))
    assert _err(pq, _same_sign(pq, ref)) < 2 * TOL
    assert _err(rot.quat_to_dcm(pq), rot.quat_to_dcm(p) @ rot.quat_to_dcm(q)) < 4 * TOL
    # the Hamilton table: i j = k, j i = −k
    i, j, k = np.eye(4)[1], np.eye(4)[2], np.eye(4)[3]
    assert rot.quat_mult(i, j).tolist() == k.tolist()
    assert rot.quat_mult(j, i).tolist() == (-k).tolist()


def test_quat_conj_is_the_inverse():
    q = _quats(_rng())
    qc = rot.quat_conj(q)
    ref = _wxyz(Rotation.from_quat(q, scalar_first=True).inv())
    assert _err(qc, _same_sign(qc, ref)) < TOL
    assert _err(rot.quat_mult(q, qc), np.tile([1.0, 0.0, 0.0, 0.0], (N, 1))) < 2 * TOL


# ----------------------------------------------------------------------------- rotation vectors


def test_rotvec_to_quat_is_scipys_from_zero_to_pi():
    r = _rotvecs(_rng())
    q = rot.rotvec_to_quat(r)
    assert _err(q, _wxyz(Rotation.from_rotvec(r))) < TOL
    assert _err(np.linalg.norm(q, axis=1), 1.0) < 2 * TOL


def test_rotvec_to_quat_small_angle_keeps_relative_digits():
    """Below 1e-4 rad the vector part is r (1/2 − θ²/48): relative to scipy, not only
    absolute, since the vector part itself is tiny."""
    rng = _rng()
    r = _directions(rng, N) * 10.0 ** rng.uniform(-15, -4, N)[:, None]
    q = rot.rotvec_to_quat(r)
    ref = _wxyz(Rotation.from_rotvec(r))
    assert np.max(np.abs(q[:, 1:] - ref[:, 1:]) / np.abs(ref[:, 1:]).max(axis=1)[:, None]) \
        < 2 * TOL


def test_quat_to_rotvec_is_scipys_from_zero_to_pi():
    r = _rotvecs(_rng())
    q = _wxyz(Rotation.from_rotvec(r))
    assert _err(rot.quat_to_rotvec(q), Rotation.from_quat(q, scalar_first=True).as_rotvec()) \
        < ANGLE_TOL
    # either sign of the quaternion gives the same rotation vector (angle in [0, π])
    assert _err(rot.quat_to_rotvec(-q), rot.quat_to_rotvec(q)) == 0.0
    assert np.all(np.linalg.norm(rot.quat_to_rotvec(_quats(_rng())), axis=1) <= np.pi)


def test_quat_to_rotvec_small_angle_is_relative():
    rng = _rng()
    r = _directions(rng, N) * 10.0 ** rng.uniform(-15, -4, N)[:, None]
    back = rot.quat_to_rotvec(rot.rotvec_to_quat(r))
    assert np.max(np.linalg.norm(back - r, axis=1) / np.linalg.norm(r, axis=1)) < 2 * TOL


# ----------------------------------------------------------------------------- round trips


@pytest.mark.parametrize("draw", [_euler, _gimbal])
def test_round_trips_through_every_form(draw):
    """euler → dcm → quat → rotvec → quat → dcm → euler, the DCM compared at each step
    (angles themselves are ill-conditioned at the lock)."""
    att = draw(_rng())
    C = rot.euler_to_dcm(att)
    q = rot.dcm_to_quat(C)
    assert _err(q, rot.euler_to_quat(att)) < 2 * TOL
    r = rot.quat_to_rotvec(q)
    q2 = rot.rotvec_to_quat(r)
    assert _err(q2, _same_sign(q2, q)) < 4 * TOL
    assert _err(rot.quat_to_dcm(q2), C) < 4 * TOL
    assert _cond_err(rot.euler_to_dcm(rot.quat_to_euler(q2)), C, att) < K_COND
    assert _cond_err(rot.dcm_to_euler(C), att, att) < K_COND
    assert _cond_err(rot.quat_to_euler(rot.euler_to_quat(att)), att, att) < K_COND


def test_rotvec_round_trip_from_zero_to_pi():
    r = _rotvecs(_rng())
    assert _err(rot.quat_to_rotvec(rot.rotvec_to_quat(r)), r) < ANGLE_TOL
    C = Rotation.from_rotvec(r).as_matrix()
    assert _err(rot.quat_to_dcm(rot.dcm_to_quat(C)), C) < 4 * TOL


def test_every_function_broadcasts_over_leading_axes():
    rng = _rng()
    att = _euler(rng, 30).reshape(2, 5, 3, 3)
    C = rot.euler_to_dcm(att)
    assert C.shape == (2, 5, 3, 3, 3)
    assert np.array_equal(C.reshape(-1, 3, 3), rot.euler_to_dcm(att.reshape(-1, 3)))
    q = rot.dcm_to_quat(C)
    assert q.shape == (2, 5, 3, 4)
    assert np.array_equal(q.reshape(-1, 4), rot.dcm_to_quat(C.reshape(-1, 3, 3)))
    assert rot.quat_to_euler(q).shape == rot.quat_to_rotvec(q).shape == (2, 5, 3, 3)
    assert rot.misalignment(C, C).shape == (2, 5, 3, 3)


# ----------------------------------------------------------------------------- the rest


def test_skew_is_the_cross_product():
    rng = _rng()
    v, w = rng.normal(size=(N, 3)), rng.normal(size=(N, 3))
    assert _err(np.einsum("nij,nj->ni", rot.skew(v), w), np.cross(v, w)) < 4 * TOL
    assert _err(rot.skew(v), -np.swapaxes(rot.skew(v), -1, -2)) == 0.0


def test_misalignment_is_scipys_relative_rotation():
    """φ from C_est C_trueᵀ = exp(−[φ×]): minus the rotation vector of R_est R_true⁻¹,
    by DCMs and by quaternions alike, for small and large errors."""
    rng = _rng()
    true = Rotation.random(N, rng=rng)
    err = Rotation.from_rotvec(_rotvecs(rng))
    est = err.inv() * true
    phi = rot.misalignment(est.as_matrix(), true.as_matrix())
    assert _err(phi, -(est * true.inv()).as_rotvec()) < 2 * ANGLE_TOL
    phi_q = rot.misalignment_q(_wxyz(est), _wxyz(true))
    assert _err(phi_q, -(est * true.inv()).as_rotvec()) < 2 * ANGLE_TOL
    # small φ: C_est ≈ (I − [φ×]) C_true
    small = Rotation.from_rotvec(1e-6 * _directions(rng, N)) * true
    phi = rot.misalignment(small.as_matrix(), true.as_matrix())
    approx = (np.eye(3) - rot.skew(phi)) @ true.as_matrix()
    assert _err(approx, small.as_matrix()) < 1e-12  # second order: |φ|² / 2 = 5e-13


def test_wrap_pi_and_attitude_error():
    a = np.array([-3 * np.pi, -np.pi, -1.0, 0.0, 1.0, np.pi, 3 * np.pi, 7.5])
    w = rot.wrap_pi(a)
    assert np.all((w >= -np.pi) & (w < np.pi))
    assert _err(np.cos(w), np.cos(a)) < 4 * TOL and _err(np.sin(w), np.sin(a)) < 4 * TOL
    assert rot.wrap_pi(np.pi) == -np.pi
    # pitch is a plain difference, roll and yaw wrap: 179° − (−179°) is −2°, not 358°
    d = rot.attitude_error(np.radians([10.0, 179.0, 179.0]), np.radians([-80.0, -179.0, -179.0]))
    assert _err(np.degrees(d), [90.0, -2.0, -2.0]) < 1e-12
