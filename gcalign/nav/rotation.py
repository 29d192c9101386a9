"""Rotation helpers: Euler angles, direction cosine matrices, quaternions, rotation vectors.

Conventions (PSINS): ``att = [pitch, roll, yaw]`` (rad), ``C_nb = Rz(yaw) @ Rx(pitch) @ Ry(roll)``
maps body vectors to ENU (``v_n = C_nb @ v_b``); yaw is counter-clockwise positive.
Quaternions are scalar first ``[w, x, y, z]`` with the Hamilton product; ``q_nb`` rotates
body to navigation frame like ``C_nb``. All functions are vectorised over leading axes.

>>> import numpy as np
>>> C = euler_to_dcm(np.radians([10.0, -20.0, 30.0]))
>>> np.degrees(dcm_to_euler(C)).round(12).tolist()
[10.0, -20.0, 30.0]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """Cross-product matrix [v×], shape (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    z = np.zeros_like(v[..., 0])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack(
        [np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2
    )


def euler_to_dcm(att: ArrayLike) -> NDArray[np.float64]:
    """C_nb from ``att = [pitch, roll, yaw]`` (rad), shape (..., 3) -> (..., 3, 3)."""
    att = np.asarray(att, dtype=float)
    sp, sr, sy = np.sin(att[..., 0]), np.sin(att[..., 1]), np.sin(att[..., 2])
    cp, cr, cy = np.cos(att[..., 0]), np.cos(att[..., 1]), np.cos(att[..., 2])
    rows = [
        [cy * cr - sy * sp * sr, -sy * cp, cy * sr + sy * sp * cr],
        [sy * cr + cy * sp * sr, cy * cp, sy * sr - cy * sp * cr],
        [-cp * sr, sp, cp * cr],
    ]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def dcm_to_euler(C: ArrayLike) -> NDArray[np.float64]:
    """``[pitch, roll, yaw]`` (rad) from C_nb, (..., 3, 3) -> (..., 3); pitch in [-90°, 90°]."""
    C = np.asarray(C, dtype=float)
    pitch = np.arcsin(np.clip(C[..., 2, 1], -1.0, 1.0))
    roll = np.arctan2(-C[..., 2, 0], C[..., 2, 2])
    yaw = np.arctan2(-C[..., 0, 1], C[..., 1, 1])
    return np.stack([pitch, roll, yaw], -1)


def quat_mult(p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """Hamilton product p ⊗ q, shape (..., 4)."""
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    pw, px, py, pz = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qw, qx, qy, qz = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        -1,
    )


def quat_conj(q: ArrayLike) -> NDArray[np.float64]:
    """Conjugate (inverse of a unit quaternion), shape (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_to_dcm(q: ArrayLike) -> NDArray[np.float64]:
    """DCM of a unit quaternion, shape (..., 4) -> (..., 3, 3)."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    rows = [
        [w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
    ]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def dcm_to_quat(C: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternion (w >= 0) of a DCM, shape (..., 3, 3) -> (..., 4); robust for all angles."""
    C = np.asarray(C, dtype=float)
    tr = C[..., 0, 0] + C[..., 1, 1] + C[..., 2, 2]
    # Squared magnitudes of each component; take the largest as pivot (Shepperd's method).
    cand = np.stack(
        [1 + tr, 1 + 2 * C[..., 0, 0] - tr, 1 + 2 * C[..., 1, 1] - tr, 1 + 2 * C[..., 2, 2] - tr],
        -1,
    )
    k = np.argmax(cand, axis=-1)
    s = 2.0 * np.sqrt(np.take_along_axis(cand, k[..., None], -1)[..., 0])
    d21, d02, d10 = (
        C[..., 2, 1] - C[..., 1, 2],
        C[..., 0, 2] - C[..., 2, 0],
        C[..., 1, 0] - C[..., 0, 1],
    )
    s21, s02, s10 = (
        C[..., 2, 1] + C[..., 1, 2],
        C[..., 0, 2] + C[..., 2, 0],
        C[..., 1, 0] + C[..., 0, 1],
    )
    options = np.stack(
        [
            np.stack([s / 4, d21 / s, d02 / s, d10 / s], -1),
            np.stack([d21 / s, s / 4, s10 / s, s02 / s], -1),
            np.stack([d02 / s, s10 / s, s / 4, s21 / s], -1),
            np.stack([d10 / s, s02 / s, s21 / s, s / 4], -1),
        ],
        -2,
    )
    q = np.take_along_axis(options, k[..., None, None], -2)[..., 0, :]
    return q * np.where(q[..., :1] < 0, -1.0, 1.0)


def euler_to_quat(att: ArrayLike) -> NDArray[np.float64]:
    """q_nb from ``[pitch, roll, yaw]`` (rad), shape (..., 3) -> (..., 4), scalar part ≥ 0:
    the product of the axis quaternions qz(yaw) ⊗ qx(pitch) ⊗ qy(roll) (the order of C_nb)."""
    att = np.asarray(att, dtype=float)
    cp, sp = np.cos(0.5 * att[..., 0]), np.sin(0.5 * att[..., 0])
    cr, sr = np.cos(0.5 * att[..., 1]), np.sin(0.5 * att[..., 1])
    cy, sy = np.cos(0.5 * att[..., 2]), np.sin(0.5 * att[..., 2])
    q = np.stack([cy * cp * cr - sy * sp * sr, cy * sp * cr - sy * cp * sr,
                  cy * cp * sr + sy * sp * cr, sy * cp * cr + cy * sp * sr], -1)
    return q * np.where(q[..., :1] < 0, -1.0, 1.0)


def quat_to_euler(q: ArrayLike) -> NDArray[np.float64]:
    """``[pitch, roll, yaw]`` (rad) from q_nb, shape (..., 4) -> (..., 3); the five elements
    of C_nb that :func:`dcm_to_euler` reads, straight from the quaternion."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    c21 = 2.0 * (y * z + w * x)
    c20 = 2.0 * (x * z - w * y)
    c22 = w * w - x * x - y * y + z * z
    c01 = 2.0 * (x * y - w * z)
    c11 = w * w - x * x + y * y - z * z
    return np.stack([np.arcsin(np.clip(c21, -1.0, 1.0)), np.arctan2(-c20, c22),
                     np.arctan2(-c01, c11)], -1)


def rotvec_to_quat(r: ArrayLike) -> NDArray[np.float64]:
    """Quaternion of the rotation vector `r` (rad), shape (..., 3) -> (..., 4)."""
    r = np.asarray(r, dtype=float)
    th = np.linalg.norm(r, axis=-1)
    half = 0.5 * th
    # sin(θ/2)/θ with its series below 1e-4 rad, where the ratio loses digits.
    small = th < 1e-4
    ratio = np.where(small, 0.5 - th * th / 48.0, np.sin(half) / np.where(small, 1.0, th))
    return np.concatenate([np.cos(half)[..., None], r * ratio[..., None]], -1)


def quat_to_rotvec(q: ArrayLike) -> NDArray[np.float64]:
    """Rotation vector (rad, angle in [0, π]) of a unit quaternion, shape (..., 4) -> (..., 3)."""
    q = np.asarray(q, dtype=float)
    q = q * np.where(q[..., :1] < 0, -1.0, 1.0)
    n = np.linalg.norm(q[..., 1:], axis=-1)
    th = 2.0 * np.arctan2(n, q[..., 0])
    small = n < 1e-12
    ratio = np.where(small, 2.0 / np.where(small, q[..., 0], 1.0), th / np.where(small, 1.0, n))
    return q[..., 1:] * ratio[..., None]


def cumulative_quat(dq: ArrayLike) -> NDArray[np.float64]:
    """Prefix products ``dq_1 ⊗ dq_2 ⊗ … ⊗ dq_k`` for k = 1..N, shape (N, 4).

    A Hillis-Steele scan: log2(N) vectorised passes instead of a Python loop per sample;
    each result is a product of at most log2(N) partial products (less round-off than
    the sequential product), renormalised after every pass.
    """
    q = np.array(dq, dtype=float)
    step = 1
    while step < len(q):
        q[step:] = quat_mult(q[:-step], q[step:])
        q[step:] /= np.linalg.norm(q[step:], axis=-1, keepdims=True)
        step *= 2
    return q


def wrap_pi(a: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles (rad) to [-π, π)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def attitude_error(att_est: ArrayLike, att_true: ArrayLike) -> NDArray[np.float64]:
    """Euler-angle error ``est - true`` (rad), roll and yaw wrapped to ±π, shape (..., 3)."""
    d = np.asarray(att_est, dtype=float) - np.asarray(att_true, dtype=float)
    return np.concatenate([d[..., :1], wrap_pi(d[..., 1:])], -1)


def misalignment(C_nb_est: ArrayLike, C_nb_true: ArrayLike) -> NDArray[np.float64]:
    """Misalignment φ (rad, ENU) from ``C_nb_est C_nb_true^T = exp(-[φ×]) ≈ I - [φ×]``."""
    D = np.asarray(C_nb_est) @ np.swapaxes(np.asarray(C_nb_true), -1, -2)
    return -quat_to_rotvec(dcm_to_quat(D))


def misalignment_q(q_nb_est: ArrayLike, q_nb_true: ArrayLike) -> NDArray[np.float64]:
    """:func:`misalignment` from quaternions: φ = −rotvec(q_est ⊗ q_true*)."""
    return -quat_to_rotvec(quat_mult(q_nb_est, quat_conj(q_nb_true)))
