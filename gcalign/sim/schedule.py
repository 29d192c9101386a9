"""Rotation schedules: a sequence of turns about frame axes with angle profiles, as a value
with the rotation, its rate and its angular acceleration at any time.

One schedule type serves every turning thing in gcalign: a turntable that turns the whole
INS (motion kind ``turntable``, seed 003), and a mechanism that turns the IMU inside the
body or relative to the navigation frame (the sensor frame of seed 004). A schedule is a
list of :class:`Step` rows; each turns about a unit ``axis`` *of the rotating frame itself*
(post-multiplied, PSINS ``attrottt``: ``C(t) = C0 · C_before · R_u(θ(t))``) with an
:class:`AngleProfile`, then dwells. Counter-clockwise about the axis is positive. With
``repeat`` the list is a cycle that runs forever.

Angle profiles are piecewise: polynomial pieces ``θ(τ) = θ0 + ω0 τ + α0 τ²/2 + j τ³/6``
(trapezoids, ramps with optional jerk limits, constant rate, rest) and sinusoidal pieces
``θ(τ) = θ0 + A (sin(2π f τ + φ) − sin φ)`` (swing). The angle is continuous; the rate is
continuous within a step (a trapezoid starts and ends at rest).

Rate and acceleration are those of the rotating frame relative to the reference frame,
resolved in the rotating frame: ``ω = u θ̇``, ``ω̇ = u θ̈`` (``C^T Ċ = [u×] θ̇`` for a turn
about its own fixed axis u).

>>> import numpy as np
>>> turn = AngleProfile.trapezoid(np.pi, t_accel=4.0, t_const=4.0, t_decel=4.0)
>>> round(float(np.degrees(turn.pieces[0].accel)), 6), turn.duration
(5.625, 12.0)
>>> s = Schedule((Step((0.0, 0.0, 1.0), turn, dwell=300.0),), repeat=True)
>>> s.period, np.round(s.dcm(np.array([312.0])), 12)[0].tolist()
(312.0, [[-1.0, -0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]])
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.nav.rotation import quat_mult, quat_to_dcm, quat_to_rotvec, rotvec_to_quat

Array = NDArray[np.float64]  #: a float64 array (shapes in the docstrings)

POLY, SINE = 0, 1  # piece kinds


@dataclass(frozen=True)
class Piece:
    """One piece of an angle profile (SI).

    POLY: ``θ(τ) = θ0 + rate τ + accel τ²/2 + jerk τ³/6`` for τ in [0, duration], with θ0
    the angle at the piece's start (filled in by :class:`AngleProfile`).
    SINE: ``θ(τ) = θ0 + amplitude (sin(2π frequency τ + phase) − sin phase)``.
    """

    duration: float
    kind: int = POLY
    rate: float = 0.0
    accel: float = 0.0
    jerk: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0

    def angle_rate_accel(self, tau: ArrayLike) -> tuple[Array, Array, Array]:
        """θ − θ0, θ̇, θ̈ at local times `tau` (s) within the piece."""
        tau = np.asarray(tau, dtype=float)
        if self.kind == SINE:
            w = 2.0 * math.pi * self.frequency
            arg = w * tau + self.phase
            a = self.amplitude
            return (a * (np.sin(arg) - math.sin(self.phase)), a * w * np.cos(arg),
                    -a * w * w * np.sin(arg))
        j, a0, w0 = self.jerk, self.accel, self.rate
        return (w0 * tau + 0.5 * a0 * tau**2 + j * tau**3 / 6.0, w0 + a0 * tau + 0.5 * j * tau**2,
                a0 + j * tau)

    def end(self) -> tuple[float, float]:
        """Angle change and rate at the end of the piece."""
        d, w, _ = self.angle_rate_accel(self.duration)
        return float(d), float(w)


@dataclass(frozen=True)
class AngleProfile:
    """A sequence of pieces whose angle (and, within polynomial runs, rate) is continuous.

    ``angle`` is the total angle of the profile (rad); a trapezoid's is exactly the
    commanded angle (the last piece absorbs the round-off of the others).
    """

    pieces: tuple[Piece, ...]
    angle: float

    @property
    def duration(self) -> float:
        return float(sum(p.duration for p in self.pieces))

    # ------------------------------------------------------------------ constructors

    @classmethod
    def of_pieces(cls, pieces: Iterable[Piece]) -> AngleProfile:
        pieces = tuple(pieces)
        total = 0.0
        for p in pieces:
            total += p.end()[0]
        return cls(pieces, total)

    @classmethod
    def rest(cls, duration: float) -> AngleProfile:
        return cls((Piece(duration),), 0.0)

    @classmethod
    def constant_rate(cls, rate: float, duration: float) -> AngleProfile:
        """θ = rate·τ (rad/s, s): continuous rotation (starts at speed)."""
        return cls((Piece(duration, rate=rate),), rate * duration)

    @classmethod
    def trapezoid(cls, angle: float, *, t_accel: float, t_const: float,
                  t_decel: float) -> AngleProfile:
        """A turn by `angle` (rad, signed) from rest to rest: constant acceleration for
        `t_accel`, constant rate for `t_const`, constant deceleration for `t_decel` (s).

        The peak rate is ``ω = angle / (t_accel/2 + t_const + t_decel/2)`` (seed 004: 180° in
        4 + 4 + 4 s gives 22.5 °/s and 5.625 °/s²).
        """
        if t_accel <= 0 or t_decel <= 0 or t_const < 0:
            raise ValueError(f"trapezoid: t_accel and t_decel must be > 0 and t_const ≥ 0, got "
                             f"{t_accel}, {t_const}, {t_decel}")
        w = angle / (0.5 * t_accel + t_const + 0.5 * t_decel)
        pieces = [Piece(t_accel, accel=w / t_accel)]
        if t_const > 0:
            pieces.append(Piece(t_const, rate=w))
        pieces.append(Piece(t_decel, rate=w, accel=-w / t_decel))
        return cls(tuple(pieces), angle)

    @classmethod
    def trapezoid_rate(cls, angle: float, *, rate: float, accel: float) -> AngleProfile:
        """A turn by `angle` from rest to rest at most `rate` (rad/s, > 0) with acceleration
        `accel` (rad/s², > 0); triangular when the angle is too small to reach the rate."""
        if rate <= 0 or accel <= 0:
            raise ValueError(f"trapezoid: rate and accel must be > 0, got {rate}, {accel}")
        a = abs(angle)
        t_a = rate / accel
        if accel * t_a * t_a >= a:  # never reaches the rate: triangle
            t_a = math.sqrt(a / accel)
            return cls.trapezoid(angle, t_accel=t_a, t_const=0.0, t_decel=t_a)
        return cls.trapezoid(angle, t_accel=t_a, t_const=(a - accel * t_a * t_a) / rate,
                             t_decel=t_a)

    @classmethod
    def ramp(cls, accel: float, rate_limit: float, duration: float,
             jerk: float | None = None) -> AngleProfile:
        """From rest, accelerate at `accel` (rad/s², signed) up to `rate_limit` (rad/s,
        same sign), then hold the rate; `duration` in all (s). With `jerk` (rad/s³, > 0)
        the acceleration rises and falls linearly instead of jumping (seed 003 ramps)."""
        if accel == 0 or np.sign(accel) != np.sign(rate_limit):
            raise ValueError(f"ramp: accel and rate_limit must be non-zero and of one sign, "
                             f"got {accel}, {rate_limit}")
        sign, a, w = np.sign(accel), abs(accel), abs(rate_limit)
        pieces: list[Piece] = []
        if jerk is None:
            t_a = w / a
            pieces.append(Piece(t_a, accel=sign * a))
        else:
            if jerk <= 0:
                raise ValueError(f"ramp: jerk must be > 0, got {jerk}")
            t_j = a / jerk
            if a * t_j > w:  # the rate limit comes before full acceleration
                t_j = math.sqrt(w / jerk)
                a = jerk * t_j
            t_c = (w - a * t_j) / a
            w1 = 0.5 * jerk * t_j**2
            pieces += [Piece(t_j, jerk=sign * jerk)]
            if t_c > 0:
                pieces.append(Piece(t_c, rate=sign * w1, accel=sign * a))
            pieces.append(Piece(t_j, rate=sign * (w - w1), accel=sign * a, jerk=-sign * jerk))
        used = sum(p.duration for p in pieces)
        if used > duration + 1e-12:
            raise ValueError(f"ramp: reaching {rate_limit} rad/s takes {used:g} s, more than "
                             f"the duration {duration:g} s")
        if duration - used > 0:
            pieces.append(Piece(duration - used, rate=sign * w))
        return cls.of_pieces(pieces)

    @classmethod
    def swing(cls, amplitude: float, frequency: float, duration: float,
              phase: float = 0.0) -> AngleProfile:
        """``θ = A (sin(2π f τ + φ) − sin φ)`` (rad, Hz, s, rad): a harmonic swing."""
        if frequency <= 0:
            raise ValueError(f"swing: frequency must be > 0, got {frequency}")
        return cls.of_pieces([Piece(duration, SINE, amplitude=amplitude, frequency=frequency,
                                    phase=phase)])


def _unit(axis: ArrayLike) -> Array:
    u = np.asarray(axis, dtype=float)
    n = float(np.linalg.norm(u))
    if u.shape != (3,) or not abs(n - 1.0) < 1e-9:
        raise ValueError(f"axis must be a unit vector of 3 components, got {axis!r} "
                         f"(norm {n:.6g})")
    return u / n


@dataclass(frozen=True)
class Step:
    """One schedule row: turn about `axis` (unit vector of the rotating frame) with
    `profile`, then rest for `dwell` seconds."""

    axis: tuple[float, float, float]
    profile: AngleProfile
    dwell: float = 0.0

    def __post_init__(self) -> None:
        _unit(self.axis)
        if self.dwell < 0:
            raise ValueError(f"dwell must be ≥ 0, got {self.dwell}")

    @property
    def duration(self) -> float:
        return self.profile.duration + self.dwell


@dataclass(frozen=True)
class Schedule:
    """Steps in order, once or (``repeat``) as a cycle, from the start orientation `q0`
    (scalar-first quaternion of C0; identity by default).

    The tables below are built once for evaluation (vectorised here, and by the numba
    kernels of the ideal IMU): a piece table (start time in the cycle, kind, polynomial or
    sine coefficients, step), and per step its axis, the rotation before it, and the
    angle at the start of each piece.
    """

    steps: tuple[Step, ...]
    repeat: bool = False
    q0: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    _tables: dict[str, Any] = field(init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        if not self.steps:
            raise ValueError("a schedule needs at least one step")
        if self.period <= 0:
            raise ValueError("a schedule must last more than 0 s")

    @property
    def period(self) -> float:
        """Length of the step list (s): the cycle period when it repeats."""
        return float(sum(s.duration for s in self.steps))

    # ------------------------------------------------------------------ tables

    def tables(self) -> dict[str, Any]:
        """Arrays describing the schedule (cached): see the class docstring."""
        if self._tables:
            return self._tables
        t0, kind, coef, step_of, theta0 = [], [], [], [], []
        axes, before = [], []
        q = np.array([1.0, 0.0, 0.0, 0.0])
        t = 0.0
        for i, st in enumerate(self.steps):
            u = _unit(st.axis)
            axes.append(u)
            before.append(q.copy())
            th = 0.0
            pieces = list(st.profile.pieces)
            if st.dwell > 0:
                pieces.append(Piece(st.dwell))
            for p in pieces:
                t0.append(t)
                kind.append(p.kind)
                if p.kind == SINE:
                    coef.append([p.amplitude, 2.0 * math.pi * p.frequency, p.phase, 0.0])
                else:
                    coef.append([p.rate, p.accel, p.jerk, 0.0])
                step_of.append(i)
                theta0.append(th)
                th += p.end()[0]
                t += p.duration
            # The commanded angle is exact; the rotation after the step uses it.
            theta_end = st.profile.angle
            q = quat_mult(q, rotvec_to_quat(u * theta_end))
        cycle = q
        self._tables.update(
            t0=np.array(t0), kind=np.array(kind, dtype=np.int64), coef=np.array(coef),
            step=np.array(step_of, dtype=np.int64), theta0=np.array(theta0),
            axis=np.array(axes), before=np.array(before), cycle=cycle,
            cycle_rotvec=quat_to_rotvec(cycle), q0=np.asarray(self.q0, dtype=float),
            period=self.period, repeat=self.repeat,
        )
        return self._tables

    def kernel_tables(self) -> tuple[Any, ...]:
        """The tables as the tuple the numba kernels take (:mod:`gcalign.sim._kernels`)."""
        tb = self.tables()
        return (tb["t0"], tb["kind"], np.ascontiguousarray(tb["coef"]), tb["step"],
                tb["theta0"], np.ascontiguousarray(tb["axis"]),
                np.ascontiguousarray(tb["before"]), np.asarray(tb["cycle_rotvec"], float),
                tb["q0"], float(tb["period"]), bool(tb["repeat"]))

    @property
    def cycle_rotation(self) -> Array:
        """Quaternion of the rotation over one pass through the steps (identity for a
        schedule that returns the frame to its start)."""
        return self.tables()["cycle"]

    # ------------------------------------------------------------------ evaluation

    def _locate(self, t: ArrayLike) -> tuple[dict[str, Any], Array, Array, NDArray[np.int64],
                                              NDArray[np.bool_]]:
        """Tables, cycle count k, local time in the piece, piece index, and whether t is past
        the end of a schedule that does not repeat (its final state then holds)."""
        tb = self.tables()
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if self.repeat:
            k = np.floor(t / tb["period"])
            tau = t - k * tb["period"]
            past = np.zeros(t.shape, dtype=bool)
        else:
            k = np.zeros_like(t)
            tau = np.clip(t, 0.0, tb["period"])
            past = t > tb["period"]
        j = np.clip(np.searchsorted(tb["t0"], tau, side="right") - 1, 0, len(tb["t0"]) - 1)
        return tb, k, tau - tb["t0"][j], j, past

    def angle_rate_accel(self, t: ArrayLike) -> tuple[Array, Array, Array, NDArray[np.int64]]:
        """Step angle θ (rad, from the step's start), θ̇, θ̈ (rad/s, rad/s²) and the step
        index at times t (s), shapes (N,)."""
        tb, _, tau, j, past = self._locate(t)
        c = tb["coef"][j]
        sine = tb["kind"][j] == SINE
        th_p = c[:, 0] * tau + 0.5 * c[:, 1] * tau**2 + c[:, 2] * tau**3 / 6.0
        w_p = c[:, 0] + c[:, 1] * tau + 0.5 * c[:, 2] * tau**2
        a_p = c[:, 1] + c[:, 2] * tau
        arg = c[:, 1] * tau + c[:, 2]
        th_s = c[:, 0] * (np.sin(arg) - np.sin(c[:, 2]))
        w_s = c[:, 0] * c[:, 1] * np.cos(arg)
        a_s = -c[:, 0] * c[:, 1] ** 2 * np.sin(arg)
        theta = tb["theta0"][j] + np.where(sine, th_s, th_p)
        w = np.where(past, 0.0, np.where(sine, w_s, w_p))
        a = np.where(past, 0.0, np.where(sine, a_s, a_p))
        return theta, w, a, tb["step"][j]

    def quat(self, t: ArrayLike) -> Array:
        """Quaternion of C(t) (rotating frame → reference frame), shape (N, 4)."""
        tb, k, _, _, _ = self._locate(t)
        theta, _, _, s = self.angle_rate_accel(t)
        q = quat_mult(tb["before"][s], rotvec_to_quat(tb["axis"][s] * theta[:, None]))
        if self.repeat:
            q = quat_mult(rotvec_to_quat(k[:, None] * tb["cycle_rotvec"]), q)
        return quat_mult(np.broadcast_to(tb["q0"], q.shape), q)

    def dcm(self, t: ArrayLike) -> Array:
        """C(t), shape (N, 3, 3)."""
        return quat_to_dcm(self.quat(t))

    def rate(self, t: ArrayLike) -> Array:
        """Angular rate of the rotating frame (rad/s), resolved in it, shape (N, 3)."""
        _, w, _, s = self.angle_rate_accel(t)
        return self.tables()["axis"][s] * w[:, None]

    def angular_accel(self, t: ArrayLike) -> Array:
        """Angular acceleration (rad/s²), resolved in the rotating frame, shape (N, 3)."""
        _, _, a, s = self.angle_rate_accel(t)
        return self.tables()["axis"][s] * a[:, None]
