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
from numpy.typing import ArrayLike, NDArray

from gcalign.align import kernel as K
from gcalign.align.cycles import Block, run_block
from gcalign.choices import COMPENSATIONS
from gcalign.nav.earth import WGS84, C_en, EarthModel
from gcalign.nav.rotation import dcm_to_quat, quat_to_dcm
from gcalign.nav.strapdown import integrate_attitude

METHODS = COMPENSATIONS
Array = NDArray[np.float64]


def _C_in(pos: Array, tau: ArrayLike, earth: EarthModel) -> Array:
    """C_n^i at elapsed times tau (s) since T2 and positions [lat, lon, h]: Rz(ω τ) C_n^e."""
    a = earth.omega_ie * np.asarray(tau, float)
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    R = np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)
    return R @ C_en(pos[..., 0], pos[..., 1])


def _track(pos0: Array, t: Array, v_n: Array, earth: EarthModel) -> Array:
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


def one_off(state_t2: Array, after: Block, earth: EarthModel = WGS84) -> Array:
    """q_nb at the end of `after` by seed eqs. 14-18 (see module docstring)."""
    # eq. 18: pure gyro quaternion integration from the body inertial frame frozen at T2
    q_ib0_b = integrate_attitude(np.array([1.0, 0.0, 0.0, 0.0]), after.dtheta, after.ts)
    pos_t2 = state_t2[K.POS]
    C_i_ib0 = _C_in(pos_t2, 0.0, earth) @ quat_to_dcm(state_t2[K.ATT])  # eq. 14 at T2
    tau = after.t - after.t[0]
    C_ib0_b = quat_to_dcm(q_ib0_b)
    n = len(after.dtheta)
    pos = np.broadcast_to(pos_t2, (n + 1, 3))
    # The position at T3 needs the velocity, which (odometer) needs the attitude: two rounds.
    for _ in range(2):
        C_nb = np.swapaxes(_C_in(pos, tau, earth), -1, -2) @ C_i_ib0 @ C_ib0_b  # eqs. 14-17
        v_n = np.einsum("kij,kj->ki", C_nb, after.vref) if after.vref_body else after.vref
        pos = _track(pos_t2, after.t, v_n, earth)
    return dcm_to_quat(C_nb[-1])


def continued(state_t2: np.ndarray, after: Block, earth: EarthModel = WGS84) -> np.ndarray:
    """q_nb at the end of `after` by a plain strapdown attitude update from T2."""
    state = state_t2.copy()
    q_out = np.empty((len(after.dtheta) + 1, 4))
    run_block(state, after, 0, len(after.dtheta), False, np.zeros(K.GAINS_SIZE), K.ATTITUDE,
              q_out, earth)
    return q_out[-1]


def compensate(method: str, state_t2: np.ndarray, after: Block,
               earth: EarthModel = WGS84) -> np.ndarray:
    """q_nb at T3 from the kernel state at T2 and the data stored after T2."""
    if method == "none" or len(after.dtheta) == 0:
        return state_t2[K.ATT].copy()
    if method == "one-off":
        return one_off(state_t2, after, earth)
    if method == "continued":
        return continued(state_t2, after, earth)
    raise ValueError(f"compensation: got {method!r}, allowed: {', '.join(METHODS)}")
