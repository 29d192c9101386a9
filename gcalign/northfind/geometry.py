"""Geometry of the tilted north-finding table (seed 001 §2.1).

The table frame ``C_nt`` from azimuth, tilt and tilt direction (:func:`table_dcm`), the
equally spaced table angles (:func:`position_angles`), the conversions between the tilt
and the PSINS pitch and roll of the table (:func:`pitch_roll_from_tilt`,
:func:`tilt_from_pitch_roll`), and what the gyro and the accelerometers read at table
angle θ without errors (``_ideal_readings``, seed eqs. 4–5). The frames and the truth
parameters ψ, ε, ζ are defined in :mod:`gcalign.northfind`.
"""

from __future__ import annotations

import numpy as np

from gcalign.nav import earth

__all__ = ["pitch_roll_from_tilt", "position_angles", "table_dcm", "tilt_from_pitch_roll"]

#: A scalar or an array of any shape (broadcast together), in the unit the parameter names.
Values = float | np.ndarray
_TWO_PI = 2.0 * np.pi


def _wrap_2pi(a: Values) -> np.ndarray:
    """Wrap angles (rad) to [0, 2π)."""
    return np.mod(a, _TWO_PI)


def position_angles(n: int) -> np.ndarray:
    """Equally spaced table angles ``θ_i = (i-1)·2π/n`` (rad), shape (n,).

    >>> np.degrees(position_angles(4)).tolist()
    [0.0, 90.0, 180.0, 270.0]
    """
    return np.arange(n) * (_TWO_PI / n)


def table_dcm(azimuth: Values, tilt: Values, tilt_direction: Values) -> np.ndarray:
    """Attitude ``C_nt`` of the table frame (columns x_t, y_t, z_t in ENU).

    Parameters
    ----------
    azimuth : (...) float, rad
        Azimuth ψ of the horizontal projection of the reference axis y_t (clockwise from
        true north).
    tilt : (...) float, rad
        Angle ε between the table normal z_t and Up, ``0 <= ε < π/2``.
    tilt_direction : (...) float, rad
        True azimuth ζ toward which the table surface descends.

    Returns
    -------
    C_nt : (..., 3, 3) float
        ``v_n = C_nt @ v_t``; equals ``euler_to_dcm([p, r, -ψ])`` with
        ``p, r = pitch_roll_from_tilt(ε, ζ - ψ)``.

    Notes
    -----
    ``z_t = cos ε U + sin ε d`` with ``d = [sin ζ, cos ζ, 0]`` (the normal leans toward the
    low side); ``y_t`` is the unit vector in the table plane whose horizontal projection is
    ``h = [sin ψ, cos ψ, 0]``: ``y_t ∝ h - tan ε cos(ψ - ζ) U`` (from ``y_t·z_t = 0``);
    ``x_t = y_t × z_t``.
    """
    psi, eps, zeta = np.broadcast_arrays(
        np.asarray(azimuth, float), np.asarray(tilt, float), np.asarray(tilt_direction, float)
    )
    zero = np.zeros_like(psi)
    up = np.stack([zero, zero, zero + 1.0], -1)
    d = np.stack([np.sin(zeta), np.cos(zeta), zero], -1)
    h = np.stack([np.sin(psi), np.cos(psi), zero], -1)
    z_t = np.cos(eps)[..., None] * up + np.sin(eps)[..., None] * d
    y_t = h - (np.tan(eps) * np.cos(psi - zeta))[..., None] * up
    y_t = y_t / np.linalg.norm(y_t, axis=-1, keepdims=True)
    x_t = np.cross(y_t, z_t)
    return np.stack([x_t, y_t, z_t], -1)


def pitch_roll_from_tilt(
    tilt: Values, tilt_direction_rel: Values
) -> tuple[np.ndarray, np.ndarray]:
    """PSINS pitch and roll of a table tilted by ε toward ζ_rel (relative to its axis).

    Parameters
    ----------
    tilt : (...) float, rad
        Tilt ε, ``0 <= ε < π/2``.
    tilt_direction_rel : (...) float, rad
        Direction of descent, clockwise from the reference axis in the horizontal plane.

    Returns
    -------
    pitch, roll : (...) float, rad
        ``C_nt = Rz(-ψ) Rx(pitch) Ry(roll)``. From ``U`` in table axes
        ``[u_x, u_y, u_z] = [-cos p sin r, sin p, cos p cos r]``,
        ``u_x = sin ε sin β / k``, ``u_y = -tan ε cos β / k``, ``β = -ζ_rel``,
        ``k = √(1 + tan²ε cos²β)``.

    >>> p, r = pitch_roll_from_tilt(np.radians(10.0), 0.0)   # descends along y_t
    >>> np.degrees([p, r]).round(12).tolist()
    [-10.0, 0.0]
    """
    eps = np.asarray(tilt, float)
    beta = -np.asarray(tilt_direction_rel, float)
    t = np.tan(eps)
    k = np.sqrt(1.0 + (t * np.cos(beta)) ** 2)
    ux = np.sin(eps) * np.sin(beta) / k
    uy = -t * np.cos(beta) / k
    uz = np.cos(eps)
    return np.arcsin(np.clip(uy, -1.0, 1.0)), np.arctan2(-ux, uz)


def tilt_from_pitch_roll(pitch: Values, roll: Values) -> tuple[np.ndarray, np.ndarray]:
    """Tilt ε and relative tilt direction ζ_rel from PSINS table pitch and roll.

    Parameters
    ----------
    pitch, roll : (...) float, rad

    Returns
    -------
    tilt : (...) float, rad
        ``acos(cos p cos r)``.
    tilt_direction_rel : (...) float, rad, [0, 2π)
        Direction of descent clockwise from the reference axis (horizontal plane),
        ``atan2(-u_x, -u_y u_z)``; set it with ``tilt_direction_ref="table"``.

    >>> e, z = tilt_from_pitch_roll(0.0, np.radians(3.0))   # right side down
    >>> np.degrees([e, z]).round(12).tolist()
    [3.0, 90.0]
    """
    p, r = np.asarray(pitch, float), np.asarray(roll, float)
    ux, uy, uz = -np.cos(p) * np.sin(r), np.sin(p), np.cos(p) * np.cos(r)
    tilt = np.arctan2(np.hypot(ux, uy), uz)
    return tilt, _wrap_2pi(np.arctan2(-ux, -uy * uz))


def _uz(ux: np.ndarray, uy: np.ndarray) -> np.ndarray:
    return np.sqrt(np.clip(1.0 - ux * ux - uy * uy, 0.0, 1.0))


def _ideal_readings(C_nt: np.ndarray, theta: np.ndarray, lat: float, g: float) -> np.ndarray:
    """Noise-free gyro and accelerometer readings.

    Parameters
    ----------
    C_nt : (M, 3, 3); theta : (M, R, n) rad; lat : rad; g : m/s².

    Returns
    -------
    (M, R, n, 3) float: [gyro rad/s, accel x m/s², accel y m/s²].

    Notes
    -----
    Seed eqs. 4–5. At table angle θ (counter-clockwise about ``z_t``, seed §2.1) the gyro
    axis is ``s(θ) = -sin θ x_t + cos θ y_t`` (``y_t`` turned by θ), the accelerometer axes
    are ``cos θ x_t + sin θ y_t`` (x) and ``s(θ)`` (y). Projecting ``ω_ie^n`` and ``g U``::

        ω(θ)   = a cos θ + b sin θ,        a = y_t·ω_ie,  b = -x_t·ω_ie
        f_x(θ) = g (u_x cos θ + u_y sin θ),
        f_y(θ) = g (u_y cos θ - u_x sin θ),  u_x = x_t·U, u_y = y_t·U, u_z = z_t·U = cos ε

    so every sensor follows ``y_i = R + a cos θ_i + b sin θ_i + w_i`` (seed eq. 4) with R its
    bias; (R, a, b) by least squares (seed eqs. 6–7), :func:`fit_harmonics`. Level table:
    ``a = Ω cos L cos ψ``, ``b = Ω cos L sin ψ``, so ``ψ = atan2(b, a)`` (seed eq. 8).
    """
    w_t = np.einsum("mij,i->mj", C_nt, earth.omega_ie_n(lat))  # ω^t = C_nt^T ω_ie^n
    u_t = C_nt[:, 2, :]  # U in table axes = third row of C_nt
    c, s = np.cos(theta), np.sin(theta)
    wx, wy = w_t[:, None, None, 0], w_t[:, None, None, 1]
    ux, uy = u_t[:, None, None, 0], u_t[:, None, None, 1]
    gyro = -wx * s + wy * c  # s(θ)·ω^t, s(θ) = [-sin θ, cos θ, 0]
    fx = g * (ux * c + uy * s)  # [cos θ, sin θ, 0]·g u^t
    fy = g * (-ux * s + uy * c)
    return np.stack([gyro, fx, fy], -1)
