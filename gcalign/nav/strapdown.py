"""Strapdown navigation over blocks or streams of IMU increments, forward or in reverse.

Public face of the private kernels (:mod:`gcalign.nav._kernels`):

* :func:`navigate` -- one block, every state kept (alignment passes, tests);
* :class:`Navigator` -- a stream of blocks with the state carried from one to the next, so
  that a 72 h run never holds more than a block (what ``gcalign navigate`` uses);
* :func:`integrate_attitude` -- attitude only, with coning correction over sub-samples.

Reverse navigation (seed 000 §3, after Yan Gongmin; DESIGN.md "Reverse navigation") runs
the forward kernel on transformed data: time reversed, gyro increments negated, velocity
increments unchanged, earth rate negated, velocity negated. With ω_en linear in v the
transformed equations are exactly the forward ones, so one kernel serves both.

The vertical channel (:class:`Vertical`): ``free`` (pure inertial: unstable, time constant
√(R/2g) ≈ 570 s), ``hold`` (height held at a reference, v_U = 0: PSINS's choice for ground
and long static runs) or ``damped`` (third-order loop to a reference height with a triple
pole at −1/τ).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.choices import VERTICAL_MODES
from gcalign.nav import _kernels as K
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import euler_to_quat, quat_to_euler


@dataclass(frozen=True)
class NavState:
    """Navigation state (SI): q_nb (4,), ENU velocity v_n (3,), pos ``[lat, lon, h]`` (3,)."""

    q_nb: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray

    @classmethod
    def from_euler(cls, att: ArrayLike, v_n: ArrayLike, pos: ArrayLike) -> NavState:
        return cls(euler_to_quat(att), np.asarray(v_n, float), np.asarray(pos, float))

    @property
    def att(self) -> np.ndarray:
        return quat_to_euler(self.q_nb)

    def vector(self) -> np.ndarray:
        """The kernel's state vector (:data:`gcalign.nav._kernels.NAV_STATE` floats)."""
        s = np.zeros(K.NAV_STATE)
        s[K.Q], s[K.V], s[K.P] = self.q_nb, self.v_n, self.pos
        return s


@dataclass(frozen=True)
class Vertical:
    """Vertical-channel treatment: mode ``free | hold | damped``; `tau` (s) is the damped
    loop's time constant (triple pole at −1/τ). The reference height comes with the data
    (:meth:`Navigator.run`) or is the start height."""

    mode: str = "free"
    tau: float = 30.0

    def __post_init__(self) -> None:
        if self.mode not in VERTICAL_MODES:
            raise ValueError(f"vertical: got {self.mode!r}, allowed: {', '.join(VERTICAL_MODES)}")
        if not self.tau > 0:
            raise ValueError(f"vertical tau: must be > 0 s, got {self.tau}")

    def params(self, earth: EarthModel) -> NDArray[np.float64]:
        """``[mode, k1, k2, k3]`` for the kernels."""
        if self.mode == "damped":
            return K.vertical_gains(self.tau, earth.g3)
        return np.array([K.FREE if self.mode == "free" else K.HOLD, 0.0, 0.0, 0.0])


FREE = Vertical("free")


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


def reverse_data(dtheta: NDArray[np.float64],
                 dv: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The data transform of a reverse pass: time reversed, gyro negated, Δv unchanged."""
    return np.ascontiguousarray(-dtheta[::-1]), np.ascontiguousarray(dv[::-1])


class Navigator:
    """Streamed strapdown navigation: :meth:`run` integrates one block after another,
    carrying the state (and the vertical loop) across blocks; the result of any split of
    the data into blocks is the same, bit for bit.

    Parameters
    ----------
    start : NavState at the time before the first increment.
    ts : sample interval, s.
    earth : earth model. vertical : vertical-channel treatment.
    reverse : feed the data in reverse time order already transformed? No: pass the blocks
        in *forward* order of the reverse pass (latest first) and ``reverse=True``; each
        block is reversed and negated here.
    """

    def __init__(self, start: NavState, ts: float, earth: EarthModel = WGS84,
                 vertical: Vertical = FREE, reverse: bool = False):
        self.ts = float(ts)
        self.earth = earth
        self.vertical = vertical
        self.reverse = reverse
        self._E = earth.params()
        self._vert = vertical.params(earth)
        self._sign = -1.0 if reverse else 1.0
        s = start.vector()
        if reverse:
            s[K.V] *= -1.0
        self._s = s
        self._h0 = float(start.pos[2])

    @property
    def state(self) -> NavState:
        """The current state (velocity in the forward-time sense)."""
        s = self._s
        return NavState(s[K.Q].copy(), self._sign * s[K.V], s[K.P].copy())

    def run(self, dtheta: ArrayLike, dv: ArrayLike, h_ref: ArrayLike | None = None,
            stride: int = 1) -> NDArray[np.float64]:
        """Integrate a block of increments (N, 3); the states after every `stride` steps,
        (N // stride, NAV_STATE) with the named slices of :mod:`gcalign.nav._kernels`
        (velocity in the forward-time sense). `h_ref` (N,) or a number: the reference
        height of ``hold``/``damped`` at the start of each step (default: the start height).
        """
        dtheta = np.ascontiguousarray(dtheta, dtype=float)
        dv = np.ascontiguousarray(dv, dtype=float)
        if self.reverse:
            dtheta, dv = reverse_data(dtheta, dv)
        href = np.atleast_1d(np.asarray(self._h0 if h_ref is None else h_ref, dtype=float))
        if href.size > 1 and self.reverse:
            href = np.ascontiguousarray(href[::-1])
        out = np.empty((len(dtheta) // stride, K.NAV_STATE))
        K.strapdown_block(self._s, dtheta, dv, self.ts, self._sign, self._E, self._vert,
                          href, int(stride), out)
        if self.reverse:
            out[:, K.V] *= -1.0
        return out


def navigate(t: NDArray[np.float64], dtheta: ArrayLike, dv: ArrayLike, ts: float,
             start: NavState, reverse: bool = False, *, earth: EarthModel = WGS84,
             vertical: Vertical = FREE, h_ref: ArrayLike | None = None) -> NavSolution:
    """Strapdown navigation over increments (N, 3) ending at times `t` (N,).

    Forward: `start` is the state at ``t[0] - ts``. Reverse: `start` is the state at
    ``t[-1]`` and the pass ends at ``t[0] - ts``.
    """
    times = np.concatenate([[t[0] - ts], t])
    nav = Navigator(start, ts, earth, vertical, reverse)
    states = nav.run(dtheta, dv, h_ref)
    q = np.concatenate([[np.asarray(start.q_nb, float)], states[:, K.Q]])
    v = np.concatenate([[np.asarray(start.v_n, float)], states[:, K.V]])
    p = np.concatenate([[np.asarray(start.pos, float)], states[:, K.P]])
    if reverse:
        times = times[::-1]
    return NavSolution(t=times, q_nb=q, v_n=v, pos=p)


def integrate_attitude(q0: ArrayLike, dtheta: ArrayLike, ts: float,
                       w_in_n: ArrayLike | None = None, subsamples: int = 1,
                       stride: int = 1) -> NDArray[np.float64]:
    """Attitude-only strapdown: ``q ← q(−ω_in T) ⊗ q ⊗ q(φ)`` every `subsamples` increments
    (T = subsamples·ts), φ the coning-corrected rotation vector of the group (PSINS cone
    factors, exact to the order of a polynomial rate of degree subsamples − 1).

    The cone factors are for increments that integrate the rate (what a gyro measures):
    they remove the coning drift of such data (tested to 1e-4 of the plain sum). The exact
    rotation vectors of gcalign's ideal IMU compose exactly one at a time (subsamples = 1);
    grouped, the factors would add a coning term they do not contain.

    q0 (4,); dtheta (N, 3) rad with N a multiple of `subsamples` (at most 5); w_in_n (3,)
    rad/s, constant (default zero: the gyros alone). Returns the attitude at the start and
    after every `stride` updates, (1 + N // subsamples // stride, 4).
    """
    if not 1 <= subsamples <= 5:
        raise ValueError(f"subsamples: 1 to 5 sub-increments per update, got {subsamples}")
    dtheta = np.ascontiguousarray(dtheta, dtype=float)
    if len(dtheta) % subsamples:
        raise ValueError(f"dtheta: {len(dtheta)} increments is not a multiple of "
                         f"subsamples = {subsamples}")
    q = np.array(q0, dtype=float)
    out = np.empty((len(dtheta) // subsamples // stride + 1, 4))
    out[0] = q
    w = np.zeros(3) if w_in_n is None else np.asarray(w_in_n, dtype=float)
    K.attitude_block(q, dtheta, float(ts), w, int(subsamples), int(stride), out[1:])
    return out
