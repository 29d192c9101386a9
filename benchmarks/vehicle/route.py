"""A land vehicle's route: speed against time, curvature against distance, terrain height
against distance, all with exact derivatives.

The path is drawn in a plane (x north, y east, metres) by its horizontal arc length s: the
heading ψ(s) = ψ0 + ∫κ ds (clockwise from north, as a NED yaw), the curvature κ(s) made of
constant pieces joined by quintic smoothsteps (κ, κ', κ'' continuous). The speed ṡ(t) is
constant or changes by a quintic smoothstep (acceleration and jerk continuous). The terrain
is a sum of sines z(s). Every quantity the trajectory needs (s, ṡ, s̈, jerk; ψ, κ, κ'; z,
z', z'') is a closed form between joins; the joins (times of speed changes, distances of
curvature changes) are listed so that integrals over time can be split at them.

:class:`Builder` writes a route as a driver would do it (stop, speed up, cruise, turn,
U-turn, figure-eight); :func:`standard` is the 30 min drive of the benchmark and
:func:`short` a 6 min drive of the same kinds of manoeuvres for tests.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def smoothstep(u):
    """Quintic smoothstep S(u) on [0, 1] and its integral and three derivatives:
    ``(P, S, S', S'', S''')`` with P(u) = ∫₀ᵘ S."""
    u = np.clip(u, 0.0, 1.0)
    u2, u3 = u * u, u * u * u
    return (2.5 * u2 * u2 - 3.0 * u3 * u2 + u3 * u3,
            10.0 * u3 - 15.0 * u2 * u2 + 6.0 * u3 * u2,
            30.0 * u2 - 60.0 * u3 + 30.0 * u2 * u2,
            60.0 * u - 180.0 * u2 + 120.0 * u3,
            60.0 - 360.0 * u + 360.0 * u2)


@dataclass
class Route:
    """Speed segments (in time) and curvature pieces (in distance).

    Speed segment j: from time ``t0[j]`` for ``T[j]`` s, starting at distance ``s0[j]``, the
    speed goes from ``v0[j]`` to ``v0[j] + dv[j]`` by a smoothstep (dv 0: constant).
    Curvature piece i: from distance ``c_s0[i]`` for ``c_len[i]`` m, κ goes from ``k0[i]`` to
    ``k0[i] + dk[i]``; the heading there starts at ``psi0[i]``.
    """

    t0: list = field(default_factory=list)
    T: list = field(default_factory=list)
    s0: list = field(default_factory=list)
    v0: list = field(default_factory=list)
    dv: list = field(default_factory=list)
    c_s0: list = field(default_factory=list)
    c_len: list = field(default_factory=list)
    k0: list = field(default_factory=list)
    dk: list = field(default_factory=list)
    psi0: list = field(default_factory=list)
    #: named moments of the drive: (label, start time s, end time s)
    marks: list = field(default_factory=list)

    @property
    def duration(self) -> float:
        return self.t0[-1] + self.T[-1] if self.t0 else 0.0

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(getattr(self, k), float) for k in
                ("t0", "T", "s0", "v0", "dv", "c_s0", "c_len", "k0", "dk", "psi0")}

    # ------------------------------------------------------------------ evaluation

    def speed(self, t):
        """``(s, ṡ, s̈, jerk)`` at times `t` (M,) s from the route's start."""
        a = self.arrays()
        t = np.asarray(t, float)
        j = np.clip(np.searchsorted(a["t0"], t, side="right") - 1, 0, len(a["t0"]) - 1)
        T, dv = a["T"][j], a["dv"][j]
        tau = np.clip(t - a["t0"][j], 0.0, T)
        P, S, S1, S2, _ = smoothstep(tau / T)
        s = a["s0"][j] + a["v0"][j] * tau + dv * T * P
        return s, a["v0"][j] + dv * S, dv / T * S1, dv / T**2 * S2

    def heading(self, s):
        """``(ψ, κ, κ')`` at distances `s` (M,) m."""
        a = self.arrays()
        s = np.asarray(s, float)
        i = np.clip(np.searchsorted(a["c_s0"], s, side="right") - 1, 0, len(a["c_s0"]) - 1)
        L, dk = a["c_len"][i], a["dk"][i]
        sig = np.clip(s - a["c_s0"][i], 0.0, L)
        P, S, S1, _, _ = smoothstep(sig / L)
        return a["psi0"][i] + a["k0"][i] * sig + dk * L * P, a["k0"][i] + dk * S, dk / L * S1

    def joins(self) -> tuple[np.ndarray, np.ndarray]:
        """Times (s) where the speed law changes, distances (m) where the curvature does."""
        return np.asarray(self.t0[1:], float), np.asarray(self.c_s0[1:], float)

    def time_at(self, s_query) -> np.ndarray:
        """The first time (s) at which the vehicle reaches each distance of `s_query`
        (it never reverses), by bisection on the closed-form s(t), to 1e-12 s."""
        s_query = np.atleast_1d(np.asarray(s_query, float))
        lo = np.zeros_like(s_query)
        hi = np.full_like(s_query, self.duration)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            below = self.speed(mid)[0] < s_query
            lo = np.where(below, mid, lo)
            hi = np.where(below, hi, mid)
        return hi


class Builder:
    """A drive written as a sequence of manoeuvres; each adds speed segments and curvature
    pieces and advances the time, the distance, the speed and the heading."""

    #: longest constant-curvature piece, rad of heading (the planar quadrature's pieces)
    MAX_TURN_PIECE = 0.5

    def __init__(self, heading_deg: float = 0.0) -> None:
        self.r = Route()
        self.t = 0.0
        self.s = 0.0
        self.v = 0.0
        self.psi = np.radians(heading_deg)
        self._curv(1.0, 0.0, 0.0)  # the start: a straight

    def _seg(self, T: float, v_end: float) -> None:
        r = self.r
        r.t0.append(self.t)
        r.T.append(T)
        r.s0.append(self.s)
        r.v0.append(self.v)
        r.dv.append(v_end - self.v)
        self.s += T * (self.v + 0.5 * (v_end - self.v))  # ∫₀¹ S = 1/2
        self.t += T
        self.v = v_end

    def _curv(self, length: float, k0: float, dk: float) -> None:
        r = self.r
        r.c_s0.append(self._c_end() if r.c_s0 else 0.0)
        r.c_len.append(length)
        r.k0.append(k0)
        r.dk.append(dk)
        r.psi0.append(self.psi)
        self.psi += k0 * length + 0.5 * dk * length

    def _c_end(self) -> float:
        return self.r.c_s0[-1] + self.r.c_len[-1]

    def _straight_to(self, s_end: float) -> None:
        """Extend the path straight to `s_end` (it must be straight there already)."""
        gap = s_end - self._c_end()
        if gap > 1e-9:
            self._curv(gap, 0.0, 0.0)

    def stop(self, T: float) -> Builder:
        if self.v != 0.0:
            raise ValueError("stop: slow down to 0 first")
        self._seg(T, 0.0)
        return self

    def speed(self, v: float, T: float) -> Builder:
        """Change speed to `v` (m/s) in `T` s on a straight."""
        self._seg(T, v)
        self._straight_to(self.s)
        return self

    def cruise(self, T: float) -> Builder:
        self._seg(T, self.v)
        self._straight_to(self.s)
        return self

    def turn(self, angle_deg: float, radius: float, ramp: float | None = None,
             label: str | None = None) -> Builder:
        """Turn by `angle_deg` (positive right) on a circle of `radius` m at the present
        speed, entered and left along a smoothstep of curvature over `ramp` m."""
        if self.v <= 0:
            raise ValueError("turn: the vehicle must move")
        self._straight_to(self.s)
        angle = np.radians(abs(angle_deg))
        ramp = min(0.3 * angle * radius, 12.0) if ramp is None else ramp
        k = np.sign(angle_deg) / radius
        hold = angle * radius - ramp
        if hold <= 0:
            raise ValueError("turn: the ramps take the whole turn; shorten them")
        t_start = self.t
        self._curv(ramp, 0.0, k)
        pieces = int(np.ceil(abs(k) * hold / self.MAX_TURN_PIECE))
        for _ in range(pieces):
            self._curv(hold / pieces, k, 0.0)
        self._curv(ramp, k, -k)
        self._seg((hold + 2 * ramp) / self.v, self.v)
        if label:
            self.r.marks.append((label, t_start, self.t))
        return self

    def figure_eight(self, radius: float, label: str = "figure-eight") -> Builder:
        t_start = self.t
        self.turn(360.0, radius)
        self.turn(-360.0, radius)
        self.r.marks.append((label, t_start, self.t))
        return self

    def route(self) -> Route:
        self._straight_to(self.s + 1000.0)  # a straight beyond the end of the drive
        return self.r


def standard() -> Route:
    """The benchmark's 30 min drive (1800 s): a stop at the start, town turns, speed
    changes between 5 and 20 m/s, two stops at lights, a figure-eight (radius 25 m), gentle
    curves at speed and two U-turns (radius 8 m), the two GNSS outages' places."""
    b = Builder(heading_deg=30.0)
    _town(b)
    return _fill(b, 1800.0)


def hour() -> Route:
    """The 30 min drive twice over (3600 s, four U-turns and so four outages): the
    benchmark's hour at 200 Hz."""
    b = Builder(heading_deg=30.0)
    _town(b)
    b.speed(0, 10)
    _town(b, lap=2)
    return _fill(b, 3600.0)


def _town(b: Builder, lap: int = 1) -> None:
    """The manoeuvres of the 30 min drive, from a stop; a second lap's marks numbered on
    (U-turns 3 and 4)."""
    u1, u2 = f"U-turn {2 * lap - 1}", f"U-turn {2 * lap}"
    tag = "" if lap == 1 else f" {lap}"
    b.stop(40).speed(10, 8).cruise(25).speed(5, 5).turn(90, 15).speed(12, 6).cruise(35)
    b.turn(-30, 300).speed(18, 10).cruise(50).turn(20, 400).cruise(30).speed(0, 12).stop(20)
    b.speed(8, 6).turn(-90, 25).cruise(25).speed(4, 6).turn(180, 8, label=u1)
    b.speed(12, 8).cruise(40).speed(7, 6).figure_eight(25, f"figure-eight{tag}")
    b.speed(14, 8).cruise(35)
    b.turn(90, 80).cruise(40).speed(20, 8).cruise(60).turn(-45, 500).cruise(40)
    b.speed(5, 12).turn(-90, 15).speed(10, 6).cruise(30).speed(4, 6)
    b.turn(-180, 8, label=u2).speed(15, 10).cruise(45).speed(0, 12).stop(25)
    b.speed(11, 8).turn(60, 120).cruise(40).speed(6, 6).turn(90, 18).speed(16, 8).cruise(50)
    b.turn(-90, 80).cruise(30).speed(9, 6).turn(-90, 35).speed(13, 6).cruise(40)
    b.turn(8, 150).turn(-8, 150).cruise(30).speed(20, 10).cruise(70).turn(30, 600)
    b.cruise(40).speed(0, 15).stop(30).speed(7, 7).turn(270, 20, label=f"roundabout{tag}")
    b.speed(15, 8).cruise(60).turn(-60, 150).cruise(40).speed(6, 8).turn(90, 18)
    b.speed(12, 6).cruise(45).turn(10, 120).turn(-10, 120).speed(17, 8).cruise(80)
    b.speed(0, 14).stop(25).speed(10, 8).turn(-90, 40).cruise(50).turn(45, 200)
    b.speed(14, 6).cruise(40)


def short() -> Route:
    """A 6 min drive (360 s) with the same kinds of manoeuvre: a stop, speed changes, a
    town turn, a U-turn (the outage's place) and a figure-eight."""
    b = Builder(heading_deg=-60.0)
    b.stop(20).speed(10, 8).cruise(20).speed(5, 5).turn(90, 15).speed(12, 6).cruise(25)
    b.speed(4, 8).turn(180, 8, label="U-turn 1").speed(12, 8).cruise(30).speed(7, 6)
    b.figure_eight(25).speed(12, 6)
    return _fill(b, 360.0)


def _fill(b: Builder, duration: float) -> Route:
    """Cruise to `duration`, then slow to a stop for the last 20 s."""
    left = duration - b.t - 30.0
    if left < 1.0:
        raise ValueError(f"the drive already takes {b.t:.1f} s of {duration:g}")
    b.cruise(left).speed(0, 10).stop(20)
    return b.route()


@dataclass(frozen=True)
class Terrain:
    """Height above the start z(s) = Σ aᵢ sin(2π s / λᵢ + φᵢ) − z(0), m."""

    amplitude: tuple = (3.0, 1.2, 0.4)
    wavelength: tuple = (900.0, 370.0, 160.0)
    phase: tuple = (0.3, 1.9, 4.0)

    def height(self, s):
        """``(z, z', z'', z''')`` at distances `s` (M,) m."""
        s = np.asarray(s, float)
        z = np.zeros_like(s)
        d = [np.zeros_like(s) for _ in range(3)]
        z0 = 0.0
        for a, lam, ph in zip(self.amplitude, self.wavelength, self.phase, strict=True):
            w = 2 * np.pi / lam
            arg = w * s + ph
            z += a * np.sin(arg)
            z0 += a * np.sin(ph)
            d[0] += a * w * np.cos(arg)
            d[1] -= a * w**2 * np.sin(arg)
            d[2] -= a * w**3 * np.cos(arg)
        return z - z0, d[0], d[1], d[2]
