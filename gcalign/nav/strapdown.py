"""Free strapdown navigation over a block of IMU data, forward or in reverse.

Reverse navigation (seed 000 §3, after Yan Gongmin; DESIGN.md "Reverse navigation") runs
the forward kernel on transformed data: time reversed, gyro increments negated, velocity
increments unchanged, earth rate negated, velocity negated. With ω_en linear in v the
transformed equations are exactly the forward ones, so one kernel serves both.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.nav._kernels import empty_states, strapdown_block
from gcalign.nav.rotation import euler_to_quat, quat_to_euler


@dataclass(frozen=True)
class NavState:
    """Navigation state (SI): q_nb (4,), ENU velocity v_n (3,), pos ``[lat, lon, h]`` (3,)."""

    q_nb: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray

    @classmethod
    def from_euler(cls, att, v_n, pos) -> NavState:
        return cls(euler_to_quat(att), np.asarray(v_n, float), np.asarray(pos, float))

    @property
    def att(self) -> np.ndarray:
        return quat_to_euler(self.q_nb)


@dataclass(frozen=True)
class NavSolution:
    """States along a pass, in processing order: t (N+1,), q_nb (N+1, 4), v_n, pos (N+1, 3).

    A reverse pass runs backwards in time, so its `t` decreases; its velocity is given
    in the ordinary (forward-time) sense.
    """

    t: np.ndarray
    q_nb: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray

    @property
    def att(self) -> np.ndarray:
        return quat_to_euler(self.q_nb)

    def state(self, k: int = -1) -> NavState:
        return NavState(self.q_nb[k].copy(), self.v_n[k].copy(), self.pos[k].copy())


def reverse_data(dtheta, dv):
    """The data transform of a reverse pass: time reversed, gyro negated, Δv unchanged."""
    return np.ascontiguousarray(-dtheta[::-1]), np.ascontiguousarray(dv[::-1])


def navigate(t, dtheta, dv, ts: float, start: NavState, reverse: bool = False) -> NavSolution:
    """Strapdown navigation over increments (N, 3) ending at times `t` (N,).

    Forward: `start` is the state at ``t[0] - ts``. Reverse: `start` is the state at
    ``t[-1]`` and the pass ends at ``t[0] - ts``.
    """
    dtheta = np.ascontiguousarray(dtheta, dtype=float)
    dv = np.ascontiguousarray(dv, dtype=float)
    times = np.concatenate([[t[0] - ts], t])
    sign = 1.0
    v0 = np.asarray(start.v_n, float)
    if reverse:
        dtheta, dv = reverse_data(dtheta, dv)
        times, sign, v0 = times[::-1], -1.0, -v0
    q, v, p = empty_states(len(dtheta))
    strapdown_block(
        np.asarray(start.q_nb, float),
        v0,
        np.asarray(start.pos, float),
        dtheta,
        dv,
        float(ts),
        sign,
        q,
        v,
        p,
    )
    return NavSolution(t=times, q_nb=q, v_n=sign * v, pos=p)
