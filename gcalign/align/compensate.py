"""Attitude compensation for the computing latency T2 → T3 (seed 000 §5.1, eqs. 14-18).

The passes give the attitude at T2; by the time they finish the vehicle has moved on to
T3. The IMU data stored after T2 carries the attitude forward:

- ``none``: report the T2 attitude at T3.
- ``one-off`` (eqs. 14-18): ``C_b^n(T3) = C_i^n(T3) C_ib0^i C_b^ib0(T3)`` with the body
  inertial frame i_b0 frozen at T2 (``C_ib0^i = C_n^i(T2) C_b^n(T2)``), ``C_b^ib0`` from pure
  gyro quaternion integration (eq. 18), and ``C_i^n`` from the earth rotation since T2 (eq. 17)
  and the position at T3 (eq. 16); the inertial frame is the ECEF frame at T2.
- ``continued``: a plain strapdown attitude update from T2 to T3.
"""

from __future__ import annotations

import numpy as np

from gcalign.align import kernel as K
from gcalign.align.cycles import Block
from gcalign.nav import earth
from gcalign.nav.rotation import dcm_to_quat, quat_to_dcm

METHODS = ("none", "one-off", "continued")


def _C_ni(pos, tau):
    """C_n^i at elapsed times tau (s) since T2 and positions [lat, lon, h]: Rz(ω τ) C_n^e."""
    a = earth.OMEGA_IE * np.asarray(tau, float)
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    R = np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)
    return R @ earth.C_en(pos[..., 0], pos[..., 1])


def _track(pos0, t, v_n):
    """Latitude/longitude/height along ENU velocity samples (trapezoid rule)."""
    dt = np.diff(t)[:, None]
    r_m, r_n = earth.radii(pos0[0])
    rate = np.stack(
        [v_n[:, 1] / (r_m + pos0[2]), v_n[:, 0] / ((r_n + pos0[2]) * np.cos(pos0[0])), v_n[:, 2]],
        -1,
    )
    return pos0 + np.concatenate(
        [np.zeros((1, 3)), np.cumsum(0.5 * (rate[1:] + rate[:-1]) * dt, 0)]
    )


def one_off(state_t2: np.ndarray, after: Block) -> np.ndarray:
    """q_nb at the end of `after` by seed eqs. 14-18 (see module docstring)."""
    n = len(after.dtheta)
    q_b_ib0 = np.empty((n + 1, 4))
    pure = K.new_state(np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3), state_t2[9:12])
    # Earth rate off and zero reference velocity: the kernel integrates the gyro alone (eq. 18).
    K.gyrocompass_block(
        pure,
        after.dtheta,
        after.dv,
        np.zeros((n + 1, 3)),
        False,
        after.ts,
        0.0,
        np.zeros(K.GAINS_SIZE),
        K.ATTITUDE,
        q_b_ib0,
    )
    pos_t2 = state_t2[9:12]
    C_ib0_i = _C_ni(pos_t2, 0.0) @ quat_to_dcm(state_t2[0:4])  # eq. 14 at T2
    tau = after.t - after.t[0]
    C_b_ib0 = quat_to_dcm(q_b_ib0)
    pos = np.broadcast_to(pos_t2, (n + 1, 3))
    # The position at T3 needs the velocity, which (odometer) needs the attitude: two rounds.
    for _ in range(2):
        C_nb = np.swapaxes(_C_ni(pos, tau), -1, -2) @ C_ib0_i @ C_b_ib0  # eqs. 14-17
        v_n = np.einsum("kij,kj->ki", C_nb, after.vref) if after.vref_body else after.vref
        pos = _track(pos_t2, after.t, v_n)
    return dcm_to_quat(C_nb[-1])


def continued(state_t2: np.ndarray, after: Block) -> np.ndarray:
    """q_nb at the end of `after` by a plain strapdown attitude update from T2."""
    n = len(after.dtheta)
    state = state_t2.copy()
    q_out = np.empty((n + 1, 4))
    K.gyrocompass_block(
        state,
        after.dtheta,
        after.dv,
        after.vref,
        after.vref_body,
        after.ts,
        1.0,
        np.zeros(K.GAINS_SIZE),
        K.ATTITUDE,
        q_out,
    )
    return q_out[-1]


def compensate(method: str, state_t2: np.ndarray, after: Block) -> np.ndarray:
    """q_nb at T3 from the kernel state at T2 and the data stored after T2."""
    if method == "none" or len(after.dtheta) == 0:
        return state_t2[0:4].copy()
    if method == "one-off":
        return one_off(state_t2, after)
    if method == "continued":
        return continued(state_t2, after)
    raise ValueError(f"compensation: got {method!r}, allowed: {', '.join(METHODS)}")
