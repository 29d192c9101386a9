"""Turntable motions of seed 003 §3.2 / Table 1 as cases, and their closed forms (spec 003 §4).

A :class:`Case` is a turntable motion — rows of a :class:`~gcalign.sim.schedule.Schedule`
that turn the body about its own axes from ``att0`` (the core's
:class:`~gcalign.sim.motions.Turntable`) — with its pulse train and the seed's printed
values. Its *shape* is read from the rows: ``rate`` (one uniform-rate row), ``accel`` (from
rest, uniform acceleration up to a rate limit, optional finite jerk), ``swing``
(``A sin(2π f t + φ)``), or ``turntable`` (anything else: trapezoids, several rows). Before
t = 0 the table is at rest (the INS was aligned on it), so the filters and the tracker start
from rest and the metrics skip ``settle_s``; an ``accel`` case first rests ``rest_s`` so
that its first corner lies inside the evaluated window.

Closed forms of the error before prediction (``none``, truth metric, Tdelay = T + Δt):

* uniform rate: ``−ω Tdelay`` (72″ at 5 °/s, 4 ms);
* uniform acceleration: ``−(ω(t) Tdelay − ½ α Tdelay²)``, slope ``α Tdelay`` in magnitude;
* swing: ``A [sin(ω(t − Tdelay)) − sin(ωt)]``, peak ``2A sin(π f Tdelay)``.

>>> from gcalign.units import ARCSEC
>>> [c.name for c in TABLE1][:5]
['rate 5°/s', 'rate 10°/s', 'rate 15°/s', 'rate 20°/s', 'accel 5°/s²']
>>> [c.kind for c in TABLE1[3:9]]
['rate', 'accel', 'accel', 'accel', 'accel', 'swing']
>>> round(TABLE1[0].before_theory(4e-3) / ARCSEC, 6), round(TABLE1[11].before_theory(4e-3)
...                                                            / ARCSEC, 1)
(72.0, 904.8)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from gcalign.realtime.settings import PulseSettings, Settings, check_pulses
from gcalign.sim.motions import Turntable
from gcalign.sim.schedule import POLY, SINE, AngleProfile, Schedule, Step
from gcalign.units import DEG

__all__ = [
    "ASYNC_CASE",
    "CASE_KINDS",
    "TABLE1",
    "Case",
    "Shape",
    "accel_case",
    "async_case",
    "check_case",
    "describe",
    "rate_case",
    "swing_case",
    "table1_cases",
]

CASE_KINDS = ("rate", "accel", "swing", "turntable")
Z_AXIS = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Shape:
    """What a case's rows describe (SI): `kind` (:data:`CASE_KINDS`); the turn `axis` when
    every moving row turns about one axis (else None); ``rate`` (uniform rate, or the rate
    limit of a ramp), ``accel``, ``jerk`` (None: a step in α), ``amplitude``, ``frequency``,
    ``phase`` where they apply (0 elsewhere)."""

    kind: str
    axis: tuple[float, float, float] | None
    rate: float = 0.0
    accel: float = 0.0
    jerk: float | None = None
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0


def _is_rest(step: Step) -> bool:
    return all(p.kind == POLY and p.rate == 0 and p.accel == 0 and p.jerk == 0
               for p in step.profile.pieces)


def describe(steps: tuple[Step, ...]) -> Shape:
    """The shape of turntable rows: one moving row (rests before it allowed, nothing after
    it) that is a uniform rate, a ramp from rest to a held rate, or a swing; else
    ``turntable``."""
    moving = [i for i, s in enumerate(steps) if not _is_rest(s)]
    axes = {tuple(steps[i].axis) for i in moving}
    axis = next(iter(axes)) if len(axes) == 1 else None
    other = Shape("turntable", axis)  # type: ignore[arg-type]
    if len(moving) != 1 or moving[0] != len(steps) - 1 or steps[-1].dwell > 0:
        return other
    st = steps[-1]
    pieces = st.profile.pieces
    first, last = pieces[0], pieces[-1]
    if len(pieces) == 1 and first.kind == SINE:
        return Shape("swing", st.axis, amplitude=first.amplitude, frequency=first.frequency,
                     phase=first.phase)
    if any(p.kind != POLY for p in pieces):
        return other
    if len(pieces) == 1 and first.accel == 0 and first.jerk == 0:
        return Shape("rate", st.axis, rate=first.rate)
    sign = math.copysign(1.0, last.rate)
    ramp = (first.rate == 0 and last.rate != 0 and last.accel == 0 and last.jerk == 0
            and all(sign * p.accel >= 0 for p in pieces) and len(pieces) > 1)
    if not ramp:
        return other
    accel = max((p.accel for p in pieces), key=abs)
    jerk = max(abs(p.jerk) for p in pieces)
    return Shape("accel", st.axis, rate=last.rate, accel=accel, jerk=jerk or None)


@dataclass(frozen=True, kw_only=True)
class Case:
    """One turntable motion (SI).

    Parameters
    ----------
    name : str
    steps : tuple of Step
        The rows that turn the table (each about an axis of the body itself).
    att0 : (3,) float, rad
        ``[pitch, roll, yaw]`` of the body at rest before t = 0.
    duration_s : float or None, s
        Length of the case; None: the rows' total (a schedule holds its last state after).
    pulses : PulseSettings or None
        Pulse train of this case (None: the settings').
    seed_before, seed_after : str
        The seed's Table 1 entries (before; semi-physical after), as printed.
    """

    name: str
    steps: tuple[Step, ...]
    att0: tuple[float, float, float] = (0.0, 0.0, 0.0)
    duration_s: float | None = None
    pulses: PulseSettings | None = None
    seed_before: str = ""
    seed_after: str = ""

    def __post_init__(self) -> None:
        if not self.steps:
            raise ValueError(f"steps: case {self.name!r} needs at least one row")
        if self.duration_s is not None and not self.duration_s > 0:
            raise ValueError(f"duration_s: must be > 0 (case {self.name!r}), "
                             f"got {self.duration_s!r}")

    # ------------------------------------------------------------------ motion

    @cached_property
    def shape(self) -> Shape:
        return describe(self.steps)

    @property
    def kind(self) -> str:
        return self.shape.kind

    @property
    def duration(self) -> float:
        """Length of the case (s)."""
        return float(self.schedule.period if self.duration_s is None else self.duration_s)

    @cached_property
    def schedule(self) -> Schedule:
        return Schedule(self.steps)

    def motion(self) -> Turntable:
        """The core's motion: the body turned by the rows from ``att0``."""
        return Turntable(self.att0, self.duration, self.schedule)

    @property
    def component(self) -> int:
        """Euler component reported: the turn axis x → pitch, y → roll, z → yaw (exact for
        a level ``att0``); heading when the rows turn about several axes."""
        axis = self.shape.axis
        return 2 if axis is None else int(np.argmax(np.abs(axis)))

    def corners(self) -> tuple[float, ...]:
        """Times (s) inside the case where α steps or its slope changes (ramp corners,
        row boundaries); t = 0 (the start from rest) is not counted."""
        tb = self.schedule.tables()
        kind, coef, t0 = tb["kind"], tb["coef"], tb["t0"]
        out = []
        for i in range(1, len(t0)):
            change = kind[i] != kind[i - 1] or (kind[i] == POLY and (
                coef[i, 1] != coef[i - 1, 1] or coef[i, 2] != coef[i - 1, 2]))
            if change and 0.0 < t0[i] < self.duration:
                out.append(float(t0[i]))
        return tuple(out)

    def accel_window(self) -> tuple[float, float]:
        """Start and end (s) of the pieces with α or jerk ≠ 0 (the acceleration phase)."""
        tb = self.schedule.tables()
        ends = np.append(tb["t0"][1:], self.schedule.period)
        busy = (tb["kind"] == POLY) & ((tb["coef"][:, 1] != 0) | (tb["coef"][:, 2] != 0))
        if not busy.any():
            return 0.0, 0.0
        return float(tb["t0"][busy][0]), float(ends[busy][-1])

    # ------------------------------------------------------------------ closed forms

    def before_theory(self, delay: float) -> float:
        """Magnitude of the error before prediction for Tdelay = `delay` (s): rad for
        ``rate`` (ω T) and ``swing`` (2A sin(π f T)); rad/s for ``accel`` (the slope α T);
        nan for a general ``turntable``."""
        s = self.shape
        if s.kind == "rate":
            return abs(s.rate) * delay
        if s.kind == "accel":
            return abs(s.accel) * delay
        if s.kind == "swing":
            return 2.0 * abs(s.amplitude) * abs(math.sin(math.pi * s.frequency * delay))
        return math.nan


def rate_case(name: str, rate: float, duration: float, *,
              axis: tuple[float, float, float] = Z_AXIS, **kw: Any) -> Case:
    """Uniform rate `rate` (rad/s) about `axis` for `duration` (s), at speed from t = 0."""
    return Case(name=name, steps=(Step(axis, AngleProfile.constant_rate(rate, duration)),),
                **kw)


def accel_case(name: str, accel: float, rate_limit: float, duration: float, *,
               rest_s: float = 1.0, jerk: float | None = None,
               axis: tuple[float, float, float] = Z_AXIS, **kw: Any) -> Case:
    """Rest `rest_s`, then from rest uniform acceleration `accel` (rad/s², optional finite
    `jerk`, rad/s³) up to `rate_limit` (rad/s), held to the end; `duration` (s) in all."""
    if not 0 <= rest_s < duration:
        raise ValueError(f"rest_s: must be in [0, duration) (case {name!r}), got {rest_s!r}")
    steps = [Step(axis, AngleProfile.rest(rest_s))] if rest_s > 0 else []
    steps.append(Step(axis, AngleProfile.ramp(accel, rate_limit, duration - rest_s, jerk)))
    return Case(name=name, steps=tuple(steps), **kw)


def swing_case(name: str, amplitude: float, frequency: float, duration: float, *,
               phase: float = 0.0, axis: tuple[float, float, float] = Z_AXIS,
               **kw: Any) -> Case:
    """``θ = A (sin(2π f t + φ) − sin φ)`` (rad, Hz, rad) about `axis` for `duration` (s)."""
    return Case(name=name, steps=(Step(axis, AngleProfile.swing(amplitude, frequency, duration,
                                                                phase)),), **kw)


def check_case(case: Case, settings: Settings) -> None:
    """Checks of a case against the settings (spec 003 must-show 7); ValueError naming the
    row and key."""
    nyq = 0.5 * settings.solution_hz
    for i, st in enumerate(case.steps):
        for p in st.profile.pieces:
            if p.kind == SINE and not p.frequency < nyq:
                raise ValueError(f"steps.{i}.frequency_hz: a swing must be below the Nyquist "
                                 f"frequency of the {settings.solution_hz:g} Hz attitude "
                                 f"solution ({nyq:g} Hz), got {p.frequency:g} Hz")
    if not settings.settle_s < case.duration:
        raise ValueError(f"settle_s: must be shorter than the case ({case.duration:g} s), "
                         f"got {settings.settle_s:g} s")
    if case.pulses is not None:
        check_pulses(case.pulses, settings.solution_hz)
    pulses = case.pulses or settings.pulses
    scored = case.duration - settings.settle_s
    if scored * pulses.rate_hz < 2:  # each case's statistics need pulses to score
        raise ValueError(f"pulses.rate_hz: {pulses.rate_hz:g} Hz gives fewer than 2 pulses in "
                         f"the {scored:g} s scored (the case's {case.duration:g} s after "
                         f"settle_s); at least {2 / scored:.3g} Hz")


def check_filter(case: Case, settings: Settings) -> None:
    """The chain's FIR against a case: ValueError naming ``filter.nav_order`` (or
    ``align_order``) when the FIR spans more than the case, whose output would then be the
    filter's start-up transient only (an order of 1e6 on a 2 s case ran for minutes)."""
    f = settings.filter
    order, fs = (f.nav_order, f.fs_hz) if f.chain == "navigation" else (f.align_order, f.fs_hz)
    if not order / fs < case.duration:
        key = "nav_order" if f.chain == "navigation" else "align_order"
        raise ValueError(f"filter.{key}: an FIR of order {order} spans {order / fs:g} s at "
                         f"{fs:g} Hz, longer than case {case.name!r} ({case.duration:g} s): its "
                         f"output would be start-up transient only; at most "
                         f"{math.ceil(case.duration * fs) - 1}")


def table1_cases(duration_s: float = 12.0) -> tuple[Case, ...]:
    """Seed 003 Table 1 (§3.2), each case `duration_s` long: uniform rate 5/10/15/20 °/s;
    uniform acceleration from rest (after 1 s at rest) to 15 °/s at 5/10/15/20 °/s²;
    swing, 10° peak, 0.1/0.4/0.8/1 Hz; all about z (heading)."""
    d = duration_s
    rates = [rate_case(f"rate {v:g}°/s", v * DEG, d, seed_before=b, seed_after="< 0.3″")
             for v, b in ((5, "72″"), (10, "145″"), (15, "210″"), (20, "275″"))]
    accels = [accel_case(f"accel {a:g}°/s²", a * DEG, 15.0 * DEG, d, seed_before=b,
                         seed_after="< 0.4″")
              for a, b in ((5, "71″/s"), (10, "142″/s"), (15, "218″/s"), (20, "280″/s"))]
    swings = [swing_case(f"swing 10° {f:g} Hz", 10.0 * DEG, f, d, seed_before=b,
                         seed_after="< 1″")
              for f, b in ((0.1, "120″"), (0.4, "380″"), (0.8, "700″"), (1.0, "900″"))]
    return tuple(rates + accels + swings)


def async_case(duration_s: float = 12.0) -> Case:
    """A 13th case (not in the seed): 20 °/s with asynchronous 100 Hz pulses from a clock
    100 ppm off the INS's, 2 µs jitter, Δt counted at 1 µs — Δt then sweeps the solution
    interval [0, τ) once every 10 s (1 µs per pulse)."""
    return rate_case("rate 20°/s async", 20.0 * DEG, duration_s, pulses=PulseSettings(
        mode="async", rate_hz=100.0, offset_s=None, jitter_s=2e-6, drift_ppm=100.0,
        resolution_s=1e-6))


TABLE1: tuple[Case, ...] = table1_cases()
ASYNC_CASE: Case = async_case()
