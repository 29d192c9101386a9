"""Turntable motions of seed 003 §3.2 / Table 1 as data, and their closed forms (spec 003 §4).

A :class:`Case` is one motion about one fixed axis (default: z, the heading the seed
reports): ``rate`` (uniform rate), ``accel`` (from rest, uniform acceleration up to a rate
limit, optional finite jerk), ``swing`` (``A sin(2π f t + φ)``). Before t = 0 the table is
at rest (the INS was aligned on it), so the filters and the tracker start from rest and
the metrics skip ``settle_s``; an ``accel`` case first rests ``rest_s`` so that its
first corner lies inside the evaluated window.

Closed forms of the error before prediction (``none``, truth metric, Tdelay = T + Δt):

* uniform rate: ``−ω Tdelay`` (72″ at 5 °/s, 4 ms);
* uniform acceleration: ``−(ω(t) Tdelay − ½ α Tdelay²)``, slope ``α Tdelay`` in magnitude;
* swing: ``A [sin(ω(t − Tdelay)) − sin(ωt)]``, peak ``2A sin(π f Tdelay)``.

>>> from gcalign.units import ARCSEC
>>> [c.name for c in TABLE1][:5]
['rate 5°/s', 'rate 10°/s', 'rate 15°/s', 'rate 20°/s', 'accel 5°/s²']
>>> round(TABLE1[0].before_theory(4e-3) / ARCSEC, 6), round(TABLE1[11].before_theory(4e-3)
...                                                            / ARCSEC, 1)
(72.0, 904.8)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gcalign.realtime.settings import PulseSettings, Settings, check_pulses
from gcalign.sim.schedule import AngleProfile, Piece, Schedule, Step
from gcalign.units import DEG

__all__ = ["ASYNC_CASE", "CASE_KINDS", "TABLE1", "Case", "check_case"]

CASE_KINDS = ("rate", "accel", "swing")


@dataclass(frozen=True, kw_only=True)
class Case:
    """One turntable motion (SI).

    Parameters
    ----------
    name : str
    kind : {"rate", "accel", "swing"}
    rate : float, rad/s
        ``rate``: the uniform rate; ``accel``: the rate limit (same sign as `accel`).
    accel : float, rad/s²
        ``accel``: the acceleration.
    jerk : float or None, rad/s³
        ``accel``: finite jerk (> 0) instead of a step in α.
    rest_s : float, s
        ``accel``: rest before the ramp.
    amplitude, frequency, phase : float (rad, Hz, rad)
        ``swing``: ``θ = A (sin(2π f t + φ) − sin φ)``.
    axis : (3,) float
        Unit turn axis (body frame of the table-mounted INS).
    pulses : PulseSettings or None
        Pulse train of this case (None: the settings').
    seed_before, seed_after : str
        The seed's Table 1 entries (before; semi-physical after), as printed.
    """

    name: str
    kind: str
    rate: float = 0.0
    accel: float = 0.0
    jerk: float | None = None
    rest_s: float = 1.0
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    pulses: PulseSettings | None = None
    seed_before: str = ""
    seed_after: str = ""

    def __post_init__(self) -> None:
        if self.kind not in CASE_KINDS:
            raise ValueError(f"case {self.name!r}: kind must be one of {CASE_KINDS}, "
                             f"got {self.kind!r}")
        if self.kind == "swing" and not (math.isfinite(self.frequency) and self.frequency > 0):
            raise ValueError(f"case {self.name!r}: swing frequency must be > 0 Hz, "
                             f"got {self.frequency!r}")
        if self.kind == "accel":
            if self.accel == 0 or (self.accel > 0) != (self.rate > 0):
                raise ValueError(f"case {self.name!r}: accel and its rate limit must be "
                                 f"non-zero and of one sign, got {self.accel!r}, {self.rate!r}")
            if self.rest_s < 0:
                raise ValueError(f"case {self.name!r}: rest_s must be ≥ 0, got {self.rest_s!r}")

    # ------------------------------------------------------------------ motion

    def profile(self, duration_s: float) -> AngleProfile:
        """The angle profile over `duration_s` (s)."""
        if self.kind == "rate":
            return AngleProfile.constant_rate(self.rate, duration_s)
        if self.kind == "swing":
            return AngleProfile.swing(self.amplitude, self.frequency, duration_s, self.phase)
        ramp = AngleProfile.ramp(self.accel, self.rate, duration_s - self.rest_s, self.jerk)
        pieces = ((Piece(self.rest_s),) if self.rest_s > 0 else ()) + ramp.pieces
        return AngleProfile.of_pieces(pieces)

    def schedule(self, duration_s: float) -> Schedule:
        """A one-step :class:`Schedule` about `axis` from the identity attitude."""
        return Schedule((Step(self.axis, self.profile(duration_s)),))

    def corners(self, duration_s: float) -> tuple[float, ...]:
        """Times (s) where α steps or its slope changes (ramp corners); empty otherwise."""
        if self.kind != "accel":
            return ()
        t, out = 0.0, []
        for p in self.profile(duration_s).pieces[:-1]:
            t += p.duration
            out.append(t)
        return tuple(out)

    def accel_window(self, duration_s: float) -> tuple[float, float]:
        """``accel``: start and end (s) of the acceleration phase."""
        c = self.corners(duration_s)
        return (c[0] if self.rest_s > 0 else 0.0), c[-1]

    # ------------------------------------------------------------------ closed forms

    def before_theory(self, delay: float) -> float:
        """Magnitude of the error before prediction for Tdelay = `delay` (s): rad for
        ``rate`` (ω T) and ``swing`` (2A sin(π f T)); rad/s for ``accel`` (the slope α T)."""
        if self.kind == "rate":
            return abs(self.rate) * delay
        if self.kind == "accel":
            return abs(self.accel) * delay
        return 2.0 * abs(self.amplitude) * abs(math.sin(math.pi * self.frequency * delay))


def check_case(case: Case, settings: Settings) -> None:
    """Checks of a case against the settings (spec 003 must-show 7)."""
    nyq = 0.5 * settings.solution_hz
    if case.kind == "swing" and case.frequency >= nyq:
        raise ValueError(f"case {case.name!r}: swing frequency must be below the Nyquist "
                         f"frequency of the {settings.solution_hz:g} Hz attitude solution "
                         f"({nyq:g} Hz), got {case.frequency:g} Hz")
    if case.kind == "accel":
        case.profile(settings.duration_s)  # raises if the rate limit is not reached in time
    if case.pulses is not None:
        check_pulses(case.pulses, settings.solution_hz)


def _rate(v: float, before: str) -> Case:
    return Case(name=f"rate {v:g}°/s", kind="rate", rate=v * DEG, seed_before=before,
                seed_after="< 0.3″")


def _accel(a: float, before: str) -> Case:
    return Case(name=f"accel {a:g}°/s²", kind="accel", accel=a * DEG, rate=15.0 * DEG,
                seed_before=before, seed_after="< 0.4″")


def _swing(f: float, before: str) -> Case:
    return Case(name=f"swing 10° {f:g} Hz", kind="swing", amplitude=10.0 * DEG, frequency=f,
                seed_before=before, seed_after="< 1″")


#: Seed 003 Table 1 (§3.2): uniform rate 5/10/15/20 °/s; uniform acceleration from rest to
#: 15 °/s at 5/10/15/20 °/s²; swing, 10° peak, 0.1/0.4/0.8/1 Hz; all about z (heading).
TABLE1: tuple[Case, ...] = (
    _rate(5.0, "72″"), _rate(10.0, "145″"), _rate(15.0, "210″"), _rate(20.0, "275″"),
    _accel(5.0, "71″/s"), _accel(10.0, "142″/s"), _accel(15.0, "218″/s"), _accel(20.0, "280″/s"),
    _swing(0.1, "120″"), _swing(0.4, "380″"), _swing(0.8, "700″"), _swing(1.0, "900″"),
)

#: A 13th case (not in the seed): 20 °/s with asynchronous 100 Hz pulses from a clock
#: 50 ppm off the INS's, 2 µs jitter, Δt counted at 1 µs — Δt then sweeps [0, τ).
ASYNC_CASE = Case(
    name="rate 20°/s async", kind="rate", rate=20.0 * DEG,
    pulses=PulseSettings(mode="async", rate_hz=100.0, offset_s=None, jitter_s=2e-6,
                         drift_ppm=50.0, resolution_s=1e-6),
)
