"""Coarse alignment: analytic double-vector and inertial-frame methods (seed 000 timeline [0, T1]).

Both methods take a block of body increments (PSINS layout: sample k holds Δθ_k, Δv_k over
``((k−1)·ts, k·ts]``) and return ``att = [pitch, roll, yaw]`` (rad) with
``C_nb = Rz(yaw) Rx(pitch) Ry(roll)``, navigation frame ENU, body x right / y forward / z up.

- :func:`analytic_coarse` -- static base. The block-averaged specific force (it points up
  at rest) and angular rate (earth rate) are matched to ``[0, 0, 1]`` and ω_ie^n by the
  double-vector (TRIAD) rule: gravity exactly, earth rate as closely as possible
  (``scipy.spatial.transform.Rotation.align_vectors`` with an infinite weight on gravity).
  Steady-state errors (ENU, ``C_nb,est ≈ (I − [φ×]) C_nb``): φ_E = −∇_N/g, φ_N = ∇_E/g,
  φ_U = −ε_E/(ω_ie cos L) + φ_N tan L, ∇ and ε the accelerometer and gyro biases in ENU.
- :func:`inertial_frame_coarse` -- swinging or disturbed base (Qin Yongyuan, Yan Gongmin).
  Angular motion of the base cancels because everything is resolved in inertial frames
  frozen at the block start: ``ib0`` (body at t0) and ``in0`` (navigation frame at t0).
  See its Notes for the equations.

>>> import numpy as np
>>> from gcalign.nav import earth, rotation
>>> lat, ts, n = np.radians(45.78), 0.01, 6000
>>> att = np.radians([1.0, -2.0, 30.0])
>>> C_bn = rotation.euler_to_dcm(att).T
>>> dtheta = np.tile(C_bn @ earth.omega_ie_n(lat) * ts, (n, 1))
>>> dv = np.tile(C_bn @ [0.0, 0.0, float(earth.gravity(lat))] * ts, (n, 1))
>>> err = rotation.attitude_error(analytic_coarse(dtheta, dv, ts, lat), att)
>>> bool(np.all(np.abs(err) < 1e-10))
True
>>> err = rotation.attitude_error(inertial_frame_coarse(dtheta, dv, ts, lat), att)
>>> bool(np.all(np.abs(err) < 1e-10))
True
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.nav import rotation
from gcalign.nav.earth import WGS84, EarthModel

Array = NDArray[np.float64]

COARSE_EPOCHS = ("end", "start")
"""Allowed values of ``at`` in :func:`inertial_frame_coarse`."""


def _check_inputs(dtheta: ArrayLike, dv: ArrayLike, ts: float, lat: float,
                  min_samples: int) -> tuple[Array, Array, float, float]:
    """Validate and convert the common inputs; errors name the field, value and range."""
    dtheta = np.asarray(dtheta, dtype=float)
    dv = np.asarray(dv, dtype=float)
    for name, arr in (("dtheta", dtheta), ("dv", dv)):
        if arr.ndim != 2 or arr.shape[1] != 3:
            raise ValueError(f"{name} must have shape (N, 3), got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite, got non-finite values")
    if dtheta.shape != dv.shape:
        raise ValueError(
            f"dtheta and dv must have the same shape (N, 3), got {dtheta.shape} and {dv.shape}"
        )
    if dtheta.shape[0] < min_samples:
        raise ValueError(
            f"dtheta/dv must hold at least {min_samples} samples, got {dtheta.shape[0]}"
        )
    try:
        ts_f = float(ts)
    except (TypeError, ValueError):
        ts_f = math.nan
    if not (math.isfinite(ts_f) and ts_f > 0.0):
        raise ValueError(f"ts (sample interval, s) must be a finite number > 0, got {ts!r}")
    try:
        lat_f = float(lat)
    except (TypeError, ValueError):
        lat_f = math.nan
    if not (math.isfinite(lat_f) and abs(lat_f) < 0.5 * math.pi):
        raise ValueError(
            f"lat (latitude, rad) must be a finite number with |lat| < π/2 "
            f"(heading is undefined at the poles), got {lat!r}"
        )
    return dtheta, dv, ts_f, lat_f


def _double_vector(a1: Array, a2: Array, b1: Array, b2: Array) -> Array:
    """C_ab from a primary pair (a1 = C_ab b1, kept exactly) and a secondary pair (a2, b2)."""
    a = np.stack([a1 / np.linalg.norm(a1), a2 / np.linalg.norm(a2)])
    b = np.stack([b1 / np.linalg.norm(b1), b2 / np.linalg.norm(b2)])
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.13 s to import

    rot, _ = Rotation.align_vectors(a, b, weights=[np.inf, 1.0])
    return rot.as_matrix()


def analytic_coarse(dtheta: ArrayLike, dv: ArrayLike, ts: float, lat: float,
                    earth: EarthModel = WGS84) -> Array:
    """Static-base analytic (double-vector) coarse alignment.

    Parameters
    ----------
    dtheta : (N, 3) float, rad. Gyro angle increments in the body frame.
    dv : (N, 3) float, m/s. Velocity increments in the body frame.
    ts : float, s. Sample interval.
    lat : float, rad. Latitude (|lat| < π/2).

    Returns
    -------
    att : (3,) float, rad. ``[pitch, roll, yaw]`` of the block (the base is assumed static).

    Raises
    ------
    ValueError
        On bad shapes, non-finite data, ``ts <= 0`` or ``|lat| >= π/2``.

    Notes
    -----
    With the block means ``f_b = ΣΔv/(N ts)`` and ``ω_b = ΣΔθ/(N ts)``, at rest
    ``C_nb f_b = [0, 0, g]`` (specific force points up) and ``C_nb ω_b = ω_ie^n =
    ω_ie [0, cos L, sin L]``. The TRIAD solution keeps the first pair exact and turns about
    it to put ``C_nb ω_b`` in the north-up plane. On a moving base the averaged angular rate
    is dominated by the motion and the heading is wrong (use
    :func:`inertial_frame_coarse`).
    """
    dtheta, dv, ts, lat = _check_inputs(dtheta, dv, ts, lat, min_samples=1)
    f_b = dv.sum(axis=0)  # the common factor 1/(N ts) does not change directions
    omega_b = dtheta.sum(axis=0)
    C_nb = _double_vector(np.array([0.0, 0.0, 1.0]), earth.omega_ie_n(lat), f_b, omega_b)
    return rotation.dcm_to_euler(C_nb)


def _gravity_velocity_in0(t: NDArray[np.floating], lat: float, g: float, w: float) -> Array:
    """Velocity ∫_0^t C_n^in0(τ) [0, 0, g] dτ (m/s) of a point at rest, in in0, shape (N, 3).

    ``C_n^in0(τ)`` is the rotation by ``ω_ie τ`` about the earth axis ``e = [0, cos L, sin L]``
    (ENU at t0). With ``u = [0, 0, 1] = (u·e) e + u_⊥`` and ``e × u_⊥ = [cos L, 0, 0]``::

        ∫ R(e, ωτ) u dτ = sin L · e t + sin(ωt)/ω · u_⊥ + (1 − cos ωt)/ω · [cos L, 0, 0]

    ``1 − cos ωt`` is evaluated as ``2 sin²(ωt/2)`` (ωt is ~1e-3: no cancellation).
    """
    sl, cl = math.sin(lat), math.cos(lat)
    e = np.array([0.0, cl, sl])
    u_perp = np.array([0.0, 0.0, 1.0]) - sl * e
    t = np.asarray(t, dtype=float)[:, None]
    v = (
        sl * e * t
        + np.sin(w * t) / w * u_perp
        + 2.0 * np.sin(0.5 * w * t) ** 2 / w * np.array([cl, 0.0, 0.0])
    )
    return g * v


def inertial_frame_coarse(dtheta: ArrayLike, dv: ArrayLike, ts: float, lat: float,
                          lon: float = 0.0, h: float = 0.0, at: str = "end",
                          earth: EarthModel = WGS84) -> Array:
    """Inertial-frame coarse alignment on a static, swinging or disturbed base.

    Parameters
    ----------
    dtheta : (N, 3) float, rad. Gyro angle increments in the body frame (N >= 2).
    dv : (N, 3) float, m/s. Velocity increments in the body frame.
    ts : float, s. Sample interval.
    lat : float, rad. Latitude (|lat| < π/2).
    lon : float, rad. Longitude. The frames are local, so it does not enter the result;
        accepted for a uniform site signature.
    h : float, m. Height; scales gravity only, which does not change the solved rotation.
    at : {"end", "start"}
        Epoch of the returned attitude: the end of the block (t = N ts, the attitude to
        start fine alignment or navigation from) or its start (t = 0).

    Returns
    -------
    att : (3,) float, rad. ``[pitch, roll, yaw]`` at the requested epoch.

    Raises
    ------
    ValueError
        On bad shapes, non-finite data, ``ts <= 0``, ``|lat| >= π/2`` or a bad ``at``.

    Notes
    -----
    Frames frozen in inertial space at t0 = 0: ``ib0`` = body frame at t0, ``in0`` =
    navigation frame at t0. For a point at rest on the earth (linear velocity zero; on a
    swing base the lever arm of the motion is ignored)::

        C_b^n(t) = C_in0^n(t) · C_ib0^in0 · C_b^ib0(t)

    1. ``C_b^ib0(t)``: quaternion integration of the gyro increments,
       ``q_k = q_{k−1} ⊗ q(Δθ_k)``, ``q_0 = 1`` (earth rate included, as measured).
    2. Specific force integrated in ib0 (rotation compensation, first order)::

           v^ib0(t_k) = Σ_{j≤k} C_b^ib0(t_{j−1}) (Δv_j + ½ Δθ_j × Δv_j)

    3. The same integral in in0 follows from physics: at rest ``f^n = [0, 0, g]`` and
       ``C_n^in0(t)`` is the earth rotation ``ω_ie t`` about ``[0, cos L, sin L]``, so
       ``v^in0(t)`` is analytic (see ``_gravity_velocity_in0``); its east component,
       ``g cos L (1 − cos ω_ie t)/ω_ie ≈ g cos L ω_ie t²/2``, carries the heading.
    4. ``v^in0(t_k) = C_ib0^in0 v^ib0(t_k)`` for all k: a Wahba problem over every epoch of
       the block, solved with ``Rotation.align_vectors`` (Kabsch/SVD). The vector lengths
       weight late epochs more, where the heading signal (∝ t²) is largest.
    5. ``C_b^n(0) = C_ib0^in0`` (start) and ``C_b^n(T) = C_n^in0(T)ᵀ C_ib0^in0 C_b^ib0(T)``
       (end).

    Angular motion of the base enters only through ``C_b^ib0``, which the gyros measure,
    so a swing does not bias the result; an accelerometer bias gives the usual level error
    ∇/g, a gyro bias a heading error of order ε/(ω_ie cos L).
    """
    dtheta, dv, ts, lat = _check_inputs(dtheta, dv, ts, lat, min_samples=2)
    if at not in COARSE_EPOCHS:
        raise ValueError(f"at must be one of {', '.join(map(repr, COARSE_EPOCHS))}, got {at!r}")
    n = len(dtheta)
    # 1. C_b^ib0 at t_1 … t_N (rows), and at t_0 … t_{N−1} for the velocity transformation
    q_ib0_b = rotation.cumulative_quat(rotation.rotvec_to_quat(dtheta))
    C_prev = np.concatenate([np.eye(3)[None], rotation.quat_to_dcm(q_ib0_b[:-1])])
    # 2. v^ib0(t_k) = Σ C_b^ib0(t_{j−1}) (Δv_j + ½ Δθ_j × Δv_j)  (rotation compensation)
    dv_comp = dv + 0.5 * np.cross(dtheta, dv)
    v_ib0 = np.cumsum(np.einsum("kij,kj->ki", C_prev, dv_comp), axis=0)
    # 3. v^in0(t_k) of a point at rest, analytic
    t = ts * np.arange(1, n + 1)
    v_in0 = _gravity_velocity_in0(t, lat, float(earth.gravity(lat, h)), earth.omega_ie)
    # 4. Wahba: v^in0 = C_ib0^in0 v^ib0 over all epochs
    from scipy.spatial.transform import Rotation

    rot, _ = Rotation.align_vectors(v_in0, v_ib0)
    C_in0_ib0 = rot.as_matrix()
    if at == "start":
        return rotation.dcm_to_euler(C_in0_ib0)  # n(0) = in0, b(0) = ib0
    # 5. C_b^n(T) = C_n^in0(T)^T C_ib0^in0 C_b^ib0(T)
    C_in0_n = rotation.quat_to_dcm(rotation.rotvec_to_quat(earth.omega_ie_n(lat) * t[-1]))
    C_nb = C_in0_n.T @ C_in0_ib0 @ rotation.quat_to_dcm(q_ib0_b[-1])
    return rotation.dcm_to_euler(C_nb)


def unexplained_velocity(dtheta: ArrayLike, dv: ArrayLike, ts: float, lat: float,
                         h: float = 0.0, earth: EarthModel = WGS84) -> float:
    """The largest velocity change (m/s) over a block that a base at rest on the earth
    cannot produce: how far the specific force integrated in ib0 (steps 1-2 of
    :func:`inertial_frame_coarse`) stays from gravity's own integral in in0 (step 3) after
    the best rotation and scale between them (step 4, with a scale so that an accelerometer
    scale error or a gravity model a few 1e-4 off is not counted).

    A still or swinging base leaves centimetres per second (lasergyro.imu: 0.02 m/s over
    300 s); a vehicle that speeds up, brakes or turns leaves its velocity changes, less
    what a tilt can absorb: a constant acceleration is indistinguishable from a tilt, and a
    constant velocity from rest, by any accelerometer. Gyro drift far beyond ω_ie
    (hundreds of °/h) also shows here: it mis-rotates gravity.
    """
    dtheta, dv, ts, lat = _check_inputs(dtheta, dv, ts, lat, min_samples=2)
    q_ib0_b = rotation.cumulative_quat(rotation.rotvec_to_quat(dtheta))
    C_prev = np.concatenate([np.eye(3)[None], rotation.quat_to_dcm(q_ib0_b[:-1])])
    v_ib0 = np.cumsum(np.einsum("kij,kj->ki", C_prev, dv + 0.5 * np.cross(dtheta, dv)), axis=0)
    t = ts * np.arange(1, len(dtheta) + 1)
    v_in0 = _gravity_velocity_in0(t, lat, float(earth.gravity(lat, h)), earth.omega_ie)
    from scipy.spatial.transform import Rotation

    rot, _ = Rotation.align_vectors(v_in0, v_ib0)
    fit = rot.apply(v_ib0)
    scale = float((v_in0 * fit).sum() / (fit * fit).sum())
    return float(np.linalg.norm(v_in0 - scale * fit, axis=1).max())
