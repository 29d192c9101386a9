"""Motions of the base as types, each giving its truth at any time (not only at samples).

Kinds (DESIGN.md "Truth and IMU simulation"; seed 000 §5.2-5.3, seed 002 §3, seed 003 §4):

* :class:`Static` -- fixed attitude and position.
* :class:`Swing` -- ``att(t) = att0 + A sin(2π t/T + φ)`` per Euler angle, fixed position.
* :class:`Moving` -- segments of constant forward acceleration (along body y) and constant
  Euler-angle rates; the velocity is along the body's forward axis (so pitch is the flight
  path angle and height changes with it). :func:`flight` builds one from aircraft segments
  with targets (accelerate to a speed, pitch/roll/yaw at a rate to an angle, turns).
* :class:`Turntable` -- a :class:`~gcalign.sim.schedule.Schedule` turning the body about its
  own axes (``C_nb(t) = C_nb0 · S(t)``), fixed position (seed 003; indexing tables).

Every motion answers :meth:`kinematics` at arbitrary times: attitude, C_nb, angular rate of
the body relative to the navigation frame resolved in the body (ω_nb^b), ENU velocity and
its time derivative, and the position. Positions of a moving base are integrated on the
motion's own grid (nodes at most :data:`NODE_S` apart, split at segment boundaries,
Gauss–Legendre between nodes), so the truth at a time does not depend on how anybody
samples it. The earth model enters only through the radii.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm, quat_to_dcm
from gcalign.schema import ATT_FRAME, stored
from gcalign.sim.schedule import Schedule

Array = NDArray[np.float64]  #: a float64 array (shapes in the docstrings)

NODE_S = 0.25  #: largest spacing of the position nodes of a moving base (s)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(6)  # exact to degree 11 between nodes
_GL4 = np.polynomial.legendre.leggauss(4)


@dataclass(frozen=True)
class Kinematics:
    """Truth at times t (N,), SI: att (N, 3) [pitch, roll, yaw]; C_nb (N, 3, 3);
    omega_nb_b (N, 3) rad/s; v_n, a_n (N, 3) ENU m/s, m/s²; pos (N, 3) [lat, lon, h];
    segment (N,) index of the motion segment (0 where a motion has none)."""

    t: np.ndarray
    att: np.ndarray
    C_nb: np.ndarray
    omega_nb_b: np.ndarray
    v_n: np.ndarray
    a_n: np.ndarray
    pos: np.ndarray
    segment: np.ndarray


@dataclass(frozen=True)
class Truth:
    """Sampled truth (SI): times (N+1,), attitude (N+1, 3), ENU velocity (N+1, 3),
    position ``[lat, lon, h]`` (N+1, 3) in rad, rad, m; segment index (N+1,) or None."""

    t: np.ndarray = field(metadata=stored("s", dims="N", rule="increasing"))
    att: np.ndarray = field(metadata=stored("rad", frame=ATT_FRAME, dims="N 3"))
    v_n: np.ndarray = field(metadata=stored("m/s", frame="ENU", dims="N 3", optional=True))
    pos: np.ndarray = field(metadata=stored(
        "rad, rad, m", frame="[latitude, longitude, height], WGS-84", dims="N 3", optional=True))
    segment: np.ndarray | None = field(default=None, metadata=stored(
        "1", description="index into segment_names", dims="N", whole=True, optional=True,
        rule="index<G"))


def _fixed(t: ArrayLike, att0: ArrayLike, site: ArrayLike, C: Array | None = None,
           omega: Array | None = None) -> Kinematics:
    t = np.atleast_1d(np.asarray(t, dtype=float))
    n = t.shape[0]
    att0 = np.asarray(att0, dtype=float)
    C_nb = np.broadcast_to(euler_to_dcm(att0), (n, 3, 3)) if C is None else C
    att = np.broadcast_to(att0, (n, 3)) if C is None else dcm_to_euler(C)
    zeros = np.zeros((n, 3))
    return Kinematics(t, att, C_nb, zeros if omega is None else omega, zeros, zeros,
                      np.broadcast_to(np.asarray(site, float), (n, 3)), np.zeros(n, np.int64))


def _euler_rate_to_body(att: Array, att_dot: Array) -> Array:
    """ω_nb^b from Euler angles and their rates, C_nb = Rz(y) Rx(p) Ry(r):
    ω = Ry(r)ᵀ [ṗ, 0, 0] + Ry(r)ᵀ Rx(p)ᵀ [0, 0, ẏ] + [0, ṙ, 0]."""
    p, r = att[:, 0], att[:, 1]
    pd, rd, yd = att_dot[:, 0], att_dot[:, 1], att_dot[:, 2]
    cp, sp, cr, sr = np.cos(p), np.sin(p), np.cos(r), np.sin(r)
    return np.stack([pd * cr - yd * cp * sr, rd + yd * sp, pd * sr + yd * cp * cr], -1)


@dataclass(frozen=True)
class Static:
    """Fixed attitude ``att0`` (rad) at the site, for `duration` s."""

    att0: tuple[float, float, float]
    duration: float
    kind: str = field(default="static", init=False)

    def kinematics(self, t: ArrayLike, site: ArrayLike,
                   earth: EarthModel = WGS84) -> Kinematics:
        return _fixed(t, self.att0, site)


@dataclass(frozen=True)
class Swing:
    """``att(t) = att0 + amplitude sin(2π t / period + phase)`` per Euler angle (rad, s)."""

    att0: tuple[float, float, float]
    duration: float
    amplitude: tuple[float, float, float] = (0.0, 0.0, 0.0)
    period: tuple[float, float, float] = (1.0, 1.0, 1.0)
    phase: tuple[float, float, float] = (0.0, 0.0, 0.0)
    kind: str = field(default="swing", init=False)

    def euler(self, t: ArrayLike) -> tuple[Array, Array]:
        """Euler angles and their rates at times t."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        w = 2.0 * np.pi / np.asarray(self.period, dtype=float)
        arg = t[:, None] * w + np.asarray(self.phase, dtype=float)
        amp = np.asarray(self.amplitude, dtype=float)
        return np.asarray(self.att0, float) + amp * np.sin(arg), amp * w * np.cos(arg)

    def kinematics(self, t: ArrayLike, site: ArrayLike,
                   earth: EarthModel = WGS84) -> Kinematics:
        att, att_dot = self.euler(t)
        k = _fixed(t, self.att0, site, C=euler_to_dcm(att))
        return Kinematics(k.t, att, k.C_nb, _euler_rate_to_body(att, att_dot), k.v_n, k.a_n,
                          k.pos, k.segment)


@dataclass(frozen=True)
class Turntable:
    """The body turned by `schedule` about its own axes from ``att0``: C_nb = C_nb0 · S(t)."""

    att0: tuple[float, float, float]
    duration: float
    schedule: Schedule
    kind: str = field(default="turntable", init=False)

    def kinematics(self, t: ArrayLike, site: ArrayLike,
                   earth: EarthModel = WGS84) -> Kinematics:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        C = euler_to_dcm(np.asarray(self.att0, float)) @ quat_to_dcm(self.schedule.quat(t))
        return _fixed(t, self.att0, site, C=C, omega=self.schedule.rate(t))


@dataclass(frozen=True)
class Segment:
    """One piece of a moving-base motion (SI): duration (s), forward acceleration along
    body y (m/s²), Euler-angle rates ``[pitch, roll, yaw]`` (rad/s), and a name."""

    duration: float
    accel: float = 0.0
    rate: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str = ""


@dataclass(frozen=True)
class Moving:
    """Segments of constant forward acceleration and Euler-angle rates from ``att0`` and
    forward speed ``speed0``; the last segment is held until `duration`.

    The velocity is ``v_n = s C_nb[:, 1]`` (along the body's forward axis), its derivative
    ``ṡ c + s ċ`` with c the second column of C_nb (chain rule on the Euler angles).
    """

    att0: tuple[float, float, float]
    duration: float
    segments: tuple[Segment, ...]
    speed0: float = 0.0
    kind: str = field(default="moving", init=False)
    _nodes: dict[tuple[Any, ...], tuple[Array, Array]] = field(
        init=False, repr=False, compare=False, default_factory=dict)

    def __post_init__(self) -> None:
        if not self.segments:
            raise ValueError("segments: a moving base needs at least one segment")

    # ------------------------------------------------------------------ segments

    def _tables(self) -> tuple[Array, Array, Array, Array, Array]:
        d = np.array([s.duration for s in self.segments], dtype=float)
        accel = np.array([s.accel for s in self.segments], dtype=float)
        rate = np.array([s.rate for s in self.segments], dtype=float).reshape(-1, 3)
        starts = np.concatenate([[0.0], np.cumsum(d)[:-1]])
        att_start = np.asarray(self.att0, dtype=float) + np.concatenate(
            [np.zeros((1, 3)), np.cumsum(rate[:-1] * d[:-1, None], axis=0)])
        speed_start = self.speed0 + np.concatenate([[0.0], np.cumsum(accel[:-1] * d[:-1])])
        return starts, accel, rate, att_start, speed_start

    def segment_index(self, t: ArrayLike,
                      side: Literal["left", "right"] = "right") -> NDArray[np.int64]:
        """Segment of each time; a time on a boundary belongs to the later segment
        (``side="right"``) or the earlier one (``"left"``); the last one is held."""
        starts = self._tables()[0]
        j = np.searchsorted(starts, np.atleast_1d(np.asarray(t, float)), side=side) - 1
        return np.clip(j, 0, len(starts) - 1)

    def euler(self, t: ArrayLike, segment: NDArray[np.int64] | None = None,
              ) -> tuple[Array, Array, Array, Array]:
        """Euler angles, their rates, forward speed and its rate at times t; `segment`
        (optional) picks the segment of each time (a sample's integral over a boundary
        takes the limits of its own side)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        starts, accel, rate, att_start, speed_start = self._tables()
        j = self.segment_index(t) if segment is None else segment
        dt = t - starts[j]
        return (att_start[j] + rate[j] * dt[:, None], rate[j], speed_start[j] + accel[j] * dt,
                accel[j])

    def velocity(self, t: ArrayLike, segment: NDArray[np.int64] | None = None,
                 ) -> tuple[Array, Array, Array, Array]:
        """ENU velocity and acceleration (m/s, m/s²), attitude and its rates at times t."""
        att, att_dot, s, s_dot = self.euler(t, segment)
        p, y = att[:, 0], att[:, 2]
        pd, yd = att_dot[:, 0], att_dot[:, 2]
        sp, cp, sy, cy = np.sin(p), np.cos(p), np.sin(y), np.cos(y)
        c = np.stack([-sy * cp, cy * cp, sp], -1)  # the forward axis: C_nb[:, 1]
        c_dot = np.stack([-cy * cp * yd + sy * sp * pd, -sy * cp * yd - cy * sp * pd, cp * pd],
                         -1)
        return s[:, None] * c, s_dot[:, None] * c + s[:, None] * c_dot, att, att_dot

    # ------------------------------------------------------------------ position

    def _node_grid(self) -> np.ndarray:
        starts = list(self._tables()[0]) + [self.duration]
        grid = []
        for a, b in zip(starts[:-1], starts[1:], strict=True):
            b = min(b, self.duration) if a < self.duration else a
            n = max(1, math.ceil((b - a) / NODE_S - 1e-9))
            grid.append(a + (b - a) * np.arange(n) / n)
        last = self.duration
        return np.unique(np.concatenate(grid + [np.array([last])]))

    def _rate_of_position(self, t: Array, seg: NDArray[np.int64], lat: Array, h: Array,
                          earth: EarthModel) -> Array:
        v, *_ = self.velocity(t, seg)
        r_m, r_n = earth.radii(lat)
        return np.stack([v[:, 1] / (r_m + h), v[:, 0] / ((r_n + h) * np.cos(lat)), v[:, 2]],
                        -1)

    def _gl(self, a: Array, b: Array, seg: NDArray[np.int64], pos_a: Array, pos_b: Array,
            earth: EarthModel, nodes: tuple[Array, Array] = (_GL_X, _GL_W)) -> Array:
        """∫_a^b of the position rate (Gauss–Legendre, 6 points per interval). Latitude and
        height at the Gauss points come from the cubic Hermite through the interval's ends
        and their rates: a straight line between the ends would bend cos L enough in a
        9 °/s turn at 165 m/s to move the longitude by ~1e-11 rad over a flight."""
        x, w = nodes
        half = 0.5 * (b - a)
        tt = (0.5 * (a + b))[:, None] + half[:, None] * x
        u = 0.5 * (1.0 + x)  # position in the interval, 0 … 1
        ra = self._rate_of_position(a, seg, pos_a[:, 0], pos_a[:, 2], earth)
        rb = self._rate_of_position(b, seg, pos_b[:, 0], pos_b[:, 2], earth)
        dt = (b - a)[:, None]
        h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
        h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2

        def hermite(c: int) -> Array:
            return (h00 * pos_a[:, None, c] + h10 * dt * ra[:, None, c]
                    + h01 * pos_b[:, None, c] + h11 * dt * rb[:, None, c])

        lat, h = hermite(0), hermite(2)
        k = tt.shape[1]
        rate = self._rate_of_position(tt.ravel(), np.repeat(seg, k), lat.ravel(), h.ravel(),
                                      earth).reshape(-1, k, 3)
        return np.einsum("k,nkc->nc", w, rate) * half[:, None]

    def nodes(self, site: ArrayLike, earth: EarthModel = WGS84) -> tuple[Array, Array]:
        """Node times and positions (cached per site and earth model)."""
        key = (tuple(np.asarray(site, float)), earth.name)
        hit = self._nodes.get(key)
        if hit is not None:
            return hit
        tn = self._node_grid()
        seg = self.segment_index(0.5 * (tn[:-1] + tn[1:]))
        site = np.asarray(site, float)
        pos = np.tile(site, (len(tn), 1))
        for _ in range(3):  # fixed point: each pass improves the radii along the track
            inc = self._gl(tn[:-1], tn[1:], seg, pos[:-1], pos[1:], earth)
            pos = site + np.concatenate([np.zeros((1, 3)), np.cumsum(inc, axis=0)])
        self._nodes.clear()
        self._nodes[key] = (tn, pos)
        return tn, pos

    def position(self, t: ArrayLike, site: ArrayLike, earth: EarthModel = WGS84) -> Array:
        """``[lat, lon, h]`` at times t: the node before t plus the integral from it."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tn, pn = self.nodes(site, earth)
        i = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, len(tn) - 2)
        seg = self.segment_index(0.5 * (tn[i] + tn[i + 1]))
        # the end of the partial interval, for the radii: linear between the nodes
        frac = ((t - tn[i]) / (tn[i + 1] - tn[i]))[:, None]
        p_end = pn[i] + frac * (pn[i + 1] - pn[i])
        # within a node interval (≤ 0.25 s) 4 points are exact to degree 7: the velocity's
        # Taylor terms past that are below 1e-9 m/s over 0.25 s for any of our motions; the
        # end's position for the Hermite is the line between nodes, refined once
        p_end = pn[i] + self._gl(tn[i], t, seg, pn[i], p_end, earth, _GL4)
        return pn[i] + self._gl(tn[i], t, seg, pn[i], p_end, earth, _GL4)

    def kinematics(self, t: ArrayLike, site: ArrayLike, earth: EarthModel = WGS84,
                   segment: NDArray[np.int64] | None = None) -> Kinematics:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        seg = self.segment_index(t) if segment is None else segment
        v, a, att, att_dot = self.velocity(t, seg)
        return Kinematics(t, att, euler_to_dcm(att), _euler_rate_to_body(att, att_dot), v, a,
                          self.position(t, site, earth), seg)

    def grid_kinematics(self, grid: np.ndarray, segment: NDArray[np.int64], site: ArrayLike,
                        earth: EarthModel = WGS84) -> Kinematics:
        """:meth:`kinematics` on a sample grid (n, m+1) of equal sub-intervals, rows sharing
        their ends (the ideal IMU's), with the positions integrated along the grid itself:
        from :meth:`position` at the grid's first time, Simpson's rule over each row's
        velocities for the row ends and the quadratic through the row for the inner points.
        Same positions as :meth:`position` to ~1e-14 rad, at a fraction of the cost."""
        n, m1 = grid.shape
        t = grid.ravel()
        v, a, att, att_dot = self.velocity(t, segment)
        V = v.reshape(n, m1, 3)
        h = (grid[0, -1] - grid[0, 0]) / (m1 - 1)
        p0 = self.position(grid[:1, 0], site, earth)[0]
        # cumulative weights of the integral from a row's start to each of its points:
        # composite Simpson on the points of the row (m even), exact for cubic velocity
        W = _cumulative_simpson(m1 - 1) * h
        lat = np.full(n * m1, p0[0])
        hgt = p0[2] + np.zeros(n * m1)
        # radii and cos L at the previous pass's latitude and height: the first pass holds
        # them at the block's start, the second is within ~1e-7 rad (cos L then moves the
        # longitude by ~4e-11 rad over a block), the third within round-off
        for _ in range(3):
            r_m, r_n = earth.radii(lat)
            rate = np.stack([v[:, 1] / (r_m + hgt), v[:, 0] / ((r_n + hgt) * np.cos(lat)),
                             v[:, 2]], -1).reshape(n, m1, 3)
            within = np.einsum("jk,nkc->njc", W, rate)  # from each row's start
            ends = np.concatenate([np.zeros((1, 3)), np.cumsum(within[:, -1], axis=0)[:-1]])
            pos = (p0 + ends[:, None, :] + within).reshape(-1, 3)
            lat, hgt = pos[:, 0], pos[:, 2]
        del V
        # A segment boundary inside a row kinks the velocity there, which Simpson's rule
        # does not see: those rows take the node route (split at the boundary), and the rows
        # after them move by the difference.
        P = pos.reshape(n, m1, 3)
        starts = self._tables()[0][1:]
        rows = np.searchsorted(grid[:, 0], starts, side="right") - 1
        for r, b in zip(rows, starts, strict=True):
            if 0 <= r < n and grid[r, 0] < b < grid[r, -1]:
                exact = self.position(grid[r], site, earth)
                P[r + 1:] += exact[-1] - P[r, -1]
                P[r] = exact
        pos = P.reshape(-1, 3)
        return Kinematics(t, att, euler_to_dcm(att), _euler_rate_to_body(att, att_dot), v, a,
                          pos, segment)


def _cumulative_simpson(m: int) -> Array:
    """Weights (m+1, m+1): row j integrates from point 0 to point j of m+1 equally spaced
    points (unit spacing): Simpson pairs, the odd points by the quadratic through their pair
    (∫_0^1 of the parabola through 0, 1, 2 is (5 f0 + 8 f1 − f2)/12)."""
    W = np.zeros((m + 1, m + 1))
    for j in range(1, m + 1):
        pairs = (j // 2) * 2
        for p in range(0, pairs, 2):
            W[j, p:p + 3] += np.array([1.0, 4.0, 1.0]) / 3.0
        if j % 2:
            W[j, j - 1:j + 2] += np.array([5.0, 8.0, -1.0]) / 12.0
    return W


MotionType = Static | Swing | Moving | Turntable


# ---------------------------------------------------------------------- flight


@dataclass(frozen=True)
class FlightSegment:
    """An aircraft manoeuvre with a target (SI, rad). Kinds and what they take:

    ``hold``: duration. ``accelerate``: accel (m/s², signed) to `speed` (m/s); duration
    optional (then it must allow reaching the speed; the rest is held). ``pitch`` /
    ``roll`` / ``yaw``: `rate` (rad/s, > 0) to the target `angle` (rad); duration optional.
    ``turn``: a level turn through `angle` (rad, + left, − right) at `rate` (rad/s, > 0).
    ``coordinated_turn``: the yaw rate of a coordinated turn at the current bank,
    ψ̇ = −g tan φ / V, for `duration` or through `angle`.
    """

    kind: str
    duration: float | None = None
    accel: float | None = None
    speed: float | None = None
    rate: float | None = None
    angle: float | None = None
    name: str = ""


FLIGHT_KINDS = ("hold", "accelerate", "pitch", "roll", "yaw", "turn", "coordinated_turn")
_AXIS = {"pitch": 0, "roll": 1, "yaw": 2}


def flight(att0: tuple[float, float, float], segments: Iterable[FlightSegment],
           speed0: float = 0.0, g: float = 9.80665) -> Moving:
    """A :class:`Moving` motion from aircraft segments with targets (seed 002 §3), each
    resolved from the state its predecessor leaves: the duration a target needs, or a
    ValueError naming the segment when the target cannot be reached in the given time.

    The total duration is the sum of the segment durations.
    """
    att = np.array(att0, dtype=float)
    speed = float(speed0)
    out: list[Segment] = []
    for i, fs in enumerate(segments):
        label = fs.name or f"{i}:{fs.kind}"
        where = f"segment {i} ({fs.kind})"
        if fs.kind not in FLIGHT_KINDS:
            raise ValueError(f"{where}: unknown kind; allowed: {', '.join(FLIGHT_KINDS)}")
        rate = np.zeros(3)
        accel = 0.0
        if fs.kind == "hold":
            need = None
        elif fs.kind == "accelerate":
            if fs.accel is None or fs.speed is None or fs.accel == 0:
                raise ValueError(f"{where}: needs a non-zero accel and a target speed")
            need = (fs.speed - speed) / fs.accel
            if need < 0:
                raise ValueError(f"{where}: accel {fs.accel:g} m/s² moves away from the "
                                 f"target speed {fs.speed:g} m/s (speed is {speed:g} m/s)")
            accel = fs.accel
        elif fs.kind in _AXIS:
            if fs.rate is None or fs.rate <= 0 or fs.angle is None:
                raise ValueError(f"{where}: needs a rate > 0 and a target angle")
            k = _AXIS[fs.kind]
            delta = fs.angle - att[k]
            need = abs(delta) / fs.rate
            rate[k] = math.copysign(fs.rate, delta)
        elif fs.kind == "turn":
            if fs.rate is None or fs.rate <= 0 or fs.angle is None:
                raise ValueError(f"{where}: needs a rate > 0 and an angle")
            need = abs(fs.angle) / fs.rate
            rate[2] = math.copysign(fs.rate, fs.angle)
        else:  # coordinated turn at the current bank and speed
            if speed <= 0:
                raise ValueError(f"{where}: needs forward speed, got {speed:g} m/s")
            rate[2] = -g * math.tan(att[1]) / speed
            if fs.angle is not None:
                if rate[2] == 0 or np.sign(rate[2]) != np.sign(fs.angle):
                    raise ValueError(f"{where}: the bank {math.degrees(att[1]):g}° turns the "
                                     f"other way (or not at all) for angle {fs.angle:g} rad")
                need = fs.angle / rate[2]
            else:
                need = None
        if need is None:
            if fs.duration is None:
                raise ValueError(f"{where}: needs a duration")
            duration = fs.duration
        elif fs.duration is None:
            duration = need
        else:
            if need > fs.duration * (1 + 1e-12):
                raise ValueError(f"{where}: the target needs {need:g} s at the given rate, "
                                 f"more than its duration {fs.duration:g} s")
            duration = fs.duration
        if duration <= 0:
            raise ValueError(f"{where}: duration must be > 0, got {duration:g} s")
        active = duration if need is None else need  # time spent changing the state
        out.append(Segment(active, accel, (float(rate[0]), float(rate[1]), float(rate[2])),
                           label))
        if active < duration:  # the target is reached early: hold it for the rest
            out.append(Segment(duration - active, 0.0, (0.0, 0.0, 0.0), label + " (held)"))
        att = att + rate * active
        speed += accel * active
        if speed < -1e-9:
            raise ValueError(f"{where}: forward speed would become negative ({speed:g} m/s)")
    total = float(sum(s.duration for s in out))
    return Moving((float(att0[0]), float(att0[1]), float(att0[2])), total, tuple(out), speed0)


# ---------------------------------------------------------------------- sampling


def sample_count(duration: float, ts: float) -> int:
    """Number of IMU samples in `duration` (rounded, so 400 s at 0.01 s gives 40000)."""
    return int(round(duration / ts))
