"""Rotation schemes as data: tables of rows → :class:`gcalign.sim.schedule.Schedule`.

A scheme is a table of rows, each one turn about a unit axis *of the sensor frame* (the
IMU's own axes, post-multiplied: ``C_s^r(t) = C_start · R_u(±θ(t))``, PSINS ``attrottt``;
counter-clockwise about the axis is +), with its angle profile, then a dwell. The table
repeats as a cycle. A scheme is referenced to the body (single- and dual-axis mechanisms:
the schedule is C_s^b) or to the navigation frame (seed 004's three-axis mechanism, which
isolates the carrier: the schedule is C_s^n relative to its start, spec 004 §2).

Built-in schemes (:func:`builtin_scheme`, names in :data:`BUILTIN_NAMES`; default timing
the seed's: 180° in 12 s = 4 s acceleration, 4 s constant rate, 4 s deceleration, then a
dwell Ts = 300 s):

``fixed``
    no rotation (one dwell of ``dwell`` seconds; 3600 s by default).
``single-4``
    +180/−180/−180/+180° about z (PSINS ``test_RSINS_1_axis``). Mean C = diag(0, 0, 1).
``dual-16``
    z+ x− z+ x− x− z+ x− z+, then the same with the signs reversed (PSINS
    ``test_RSINS_2_axis``, Yuan Baohua's 16-step scheme). PSINS's script then swaps x for
    y (``paras(:,2:3) = paras(:,[3,2])``); we keep the spec's x, which gives the same
    invariants with the x and y columns exchanged.
``dual-16-improved``
    the same with rows 9–16 reordered as 10, 9, 12, 11, 14, 13, 16, 15 (PSINS's
    "improved-16").
``seed-12``
    the patent's 12-step three-position scheme, literally (spec 004 §2 table):
    A→B (z), B→C (x), C→A (y), A→C (y), C→B (x), B→A (z) counter-clockwise, then the same
    six clockwise; A = I, B = Rz(π), C = Ry(π). Cycle 12·(Ts + Tz) = 3744 s. Its mean C is
    diag(−1, 1, 1)/3, not zero: it leaves one third of every constant bias.
``four-position-12``
    our 12-step scheme over four positions A, B, C, D = Rx(π), all turns +180° (spec 004
    §2 [P]): A→B (z), B→C (x), C→A (y), A→D (x), D→B (y), B→A (z), A→C (y), C→B (x),
    B→D (y), D→C (z), C→D (z), D→A (x). Mean C = 0 and net scale-factor term 0.
``four-position-24``
    ``four-position-12``, then the same twelve turns with the signs reversed (spec 004 §2:
    the forward/reverse version, 124.8 min, that avoids cable wind-up). The scale-factor
    term then also has a zero cycle mean (see :mod:`.invariants`).
``continuous``
    constant rate about one axis (z, 6 °/s by default), one turn per cycle.

User tables (:func:`rows_from_dicts`) are plain dicts in the YAML's units, with the unit
in the key: ``axis`` (``"x"``, ``"-y"``, … or three numbers with unit norm),
``angle_deg`` (signed), one profile — ``t_accel_s``, ``t_const_s``, ``t_decel_s`` |
``t_turn_s``, ``t_accel_s``, ``t_decel_s`` | ``rate_dps``, ``accel_dps2`` (trapezoid by
rate and acceleration) | ``rate_dps`` alone (constant rate, starts at speed) | none (a pure
dwell, ``angle_deg`` 0 or absent) — and ``dwell_s`` (≥ 0, default 0). They are converted
once, here, to :class:`Row` values in SI, and a bad row raises
:class:`gcalign.errors.ScenarioError` (a ``ValueError``) that names the row and field.

>>> s = builtin_scheme("seed-12")
>>> s.schedule.period, s.reference, len(s.rows)
(3744.0, 'navigation', 12)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import cast

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.nav.rotation import quat_to_rotvec
from gcalign.sim.schedule import AngleProfile, Schedule, Step
from gcalign.units import DEG

REFERENCES = ("body", "navigation")

# Axis names accepted in a user row, as unit vectors of the sensor frame.
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0),
        "-x": (-1.0, 0.0, 0.0), "-y": (0.0, -1.0, 0.0), "-z": (0.0, 0.0, -1.0)}


@dataclass(frozen=True)
class Turn:
    """Timing of a trapezoidal turn (s): constant acceleration, constant rate, deceleration."""

    t_accel: float = 4.0
    t_const: float = 4.0
    t_decel: float = 4.0


SEED_TURN = Turn()  # seed 004: 180° in 4 + 4 + 4 s (5.625 °/s², 22.5 °/s)
SEED_DWELL = 300.0  # seed 004: Ts = 5 min


@dataclass(frozen=True)
class Row:
    """One scheme row in SI: turn about `axis` (unit vector, sensor frame) by `angle` (rad,
    signed, ccw +) with one profile, then dwell `dwell` (s).

    Profile, by which fields are set: ``t_accel``, ``t_const``, ``t_decel`` (trapezoid by
    times; ``t_const`` 0 and ``t_decel = t_accel`` when not set); ``rate`` and ``accel``
    (trapezoid by rate, rad/s, and acceleration, rad/s²); ``rate`` alone (constant rate,
    starts at speed); none (``angle`` 0: a pure dwell).
    """

    axis: tuple[float, float, float]
    angle: float = 0.0
    dwell: float = 0.0
    t_accel: float | None = None
    t_const: float | None = None
    t_decel: float | None = None
    rate: float | None = None
    accel: float | None = None

    @property
    def turns(self) -> bool:
        """Whether the row has a turn profile (otherwise it is a pure dwell)."""
        return self.t_accel is not None or self.rate is not None

    def step(self) -> Step:
        """The :class:`Step` of this row (a pure dwell is one rest piece)."""
        if self.t_accel is not None:
            profile = AngleProfile.trapezoid(
                self.angle, t_accel=self.t_accel, t_const=self.t_const or 0.0,
                t_decel=self.t_accel if self.t_decel is None else self.t_decel)
        elif self.rate is not None and self.accel is not None:
            profile = AngleProfile.trapezoid_rate(self.angle, rate=self.rate, accel=self.accel)
        elif self.rate is not None:
            profile = AngleProfile.constant_rate(math.copysign(self.rate, self.angle),
                                                 abs(self.angle) / self.rate)
        else:
            return Step(self.axis, AngleProfile.rest(self.dwell))
        return Step(self.axis, profile, dwell=self.dwell)


@dataclass(frozen=True)
class Scheme:
    """A rotation scheme: its rows, the :class:`Schedule` they make (a cycle), and whether
    the schedule is C_s^b (``reference="body"``) or C_s^n relative to its start
    (``"navigation"``)."""

    name: str
    rows: tuple[Row, ...]
    schedule: Schedule
    reference: str
    description: str = ""

    @property
    def period(self) -> float:
        """Cycle period (s)."""
        return self.schedule.period


# ---------------------------------------------------------------------------- user rows

def _row_error(i: int, field: str, msg: str) -> ScenarioError:
    return ScenarioError(f"scheme row {i + 1}: {field}: {msg}")


def _axis(i: int, value: object) -> tuple[float, float, float]:
    if isinstance(value, str):
        key = value.strip().lower().lstrip("+")
        if key not in AXES:
            raise _row_error(i, "axis", f"got {value!r}; allowed: {', '.join(AXES)} or three "
                             "numbers with unit norm")
        return AXES[key]
    try:
        u = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _row_error(i, "axis", f"got {value!r}; expected a name or three numbers") from None
    n = float(np.linalg.norm(u)) if u.shape == (3,) else float("nan")
    if u.shape != (3,) or not abs(n - 1.0) <= 1e-6:
        raise _row_error(i, "axis", f"got {value!r} (norm {n:.6g}); the axis must be a unit "
                         "vector of 3 components")
    u = u / n
    return (float(u[0]), float(u[1]), float(u[2]))


_PROFILE_KEYS = {"t_accel_s", "t_const_s", "t_decel_s", "t_turn_s", "rate_dps", "accel_dps2"}
_ROW_KEYS = {"axis", "angle_deg", "dwell_s"} | _PROFILE_KEYS


def _positive(i: int, d: Mapping, key: str, *, allow_zero: bool = False) -> float:
    v = float(d[key])
    if not (v >= 0 if allow_zero else v > 0) or not math.isfinite(v):
        raise _row_error(i, key, f"must be {'≥' if allow_zero else '>'} 0, got {d[key]!r}")
    return v


def row_from_dict(i: int, d: Mapping) -> Row:
    """One user row (user units, see the module docstring) → :class:`Row` (SI).

    `i` is the row's index (0-based; messages count from 1)."""
    unknown = sorted(set(d) - _ROW_KEYS)
    if unknown:
        raise _row_error(i, unknown[0], f"unknown key; allowed: {', '.join(sorted(_ROW_KEYS))}")
    if "axis" not in d:
        raise _row_error(i, "axis", "missing")
    axis = _axis(i, d["axis"])
    angle = float(d.get("angle_deg", 0.0)) * DEG
    if not math.isfinite(angle):
        raise _row_error(i, "angle_deg", f"must be finite, got {d['angle_deg']!r}")
    dwell = _positive(i, d, "dwell_s", allow_zero=True) if "dwell_s" in d else 0.0
    keys = set(d) & _PROFILE_KEYS
    if not keys:
        if angle != 0.0:
            raise _row_error(i, "angle_deg", f"a turn of {d['angle_deg']} deg needs a profile: "
                             "t_accel_s/t_const_s/t_decel_s, t_turn_s/t_accel_s/t_decel_s, "
                             "rate_dps/accel_dps2 or rate_dps")
        if dwell <= 0:
            raise _row_error(i, "dwell_s", "a row without a turn must dwell > 0 s")
        return Row(axis, 0.0, dwell)
    if keys & {"t_accel_s", "t_decel_s", "t_turn_s", "t_const_s"}:
        extra = keys & {"rate_dps", "accel_dps2"}
        if extra:
            raise _row_error(i, sorted(extra)[0], "give either times or rate/acceleration")
        for k in ("t_accel_s", "t_decel_s"):
            if k not in d:
                raise _row_error(i, k, "missing (a turn by times needs t_accel_s and t_decel_s)")
        ta, td = _positive(i, d, "t_accel_s"), _positive(i, d, "t_decel_s")
        if "t_turn_s" in d:
            if "t_const_s" in d:
                raise _row_error(i, "t_const_s", "give t_const_s or t_turn_s, not both")
            tt = _positive(i, d, "t_turn_s")
            if tt < ta + td:
                raise _row_error(i, "t_turn_s", f"the turn ({tt:g} s) is shorter than its "
                                 f"acceleration plus deceleration ({ta:g} + {td:g} s)")
            tc = tt - ta - td
        else:
            tc = _positive(i, d, "t_const_s", allow_zero=True) if "t_const_s" in d else 0.0
        if angle == 0.0:
            raise _row_error(i, "angle_deg", "a turn profile needs a non-zero angle")
        return Row(axis, angle, dwell, t_accel=ta, t_const=tc, t_decel=td)
    rate = _positive(i, d, "rate_dps") * DEG
    if angle == 0.0:
        raise _row_error(i, "angle_deg", "a turn profile needs a non-zero angle")
    if "accel_dps2" in d:
        return Row(axis, angle, dwell, rate=rate, accel=_positive(i, d, "accel_dps2") * DEG)
    return Row(axis, angle, dwell, rate=rate)


def rows_from_dicts(rows: Sequence[Mapping]) -> tuple[Row, ...]:
    """A user table (list of dicts in user units) → rows in SI, each row checked."""
    if not rows:
        raise ScenarioError("scheme rows: the table is empty; give at least one row")
    out = []
    for i, d in enumerate(rows):
        if not isinstance(d, Mapping):
            raise _row_error(i, "row", f"expected a mapping of fields, got {d!r}")
        out.append(row_from_dict(i, d))
    return tuple(out)


def _checked_step(i: int, r: Row) -> Step:
    """The step of row `i`, with errors that name the row and field (rows built in SI by
    another layer come here unchecked)."""
    _axis(i, r.axis)
    if not r.dwell >= 0:
        raise _row_error(i, "dwell_s", f"must be ≥ 0, got {r.dwell!r}")
    for name in ("t_accel", "t_decel", "rate", "accel"):
        v = getattr(r, name)
        if v is not None and not v > 0:
            raise _row_error(i, f"{name}", f"must be > 0, got {v!r}")
    if r.t_const is not None and not r.t_const >= 0:
        raise _row_error(i, "t_const", f"must be ≥ 0, got {r.t_const!r}")
    if not r.turns and r.angle != 0.0:
        raise _row_error(i, "angle", f"a turn of {r.angle!r} rad needs a profile (t_accel… "
                         "or rate)")
    if r.turns and r.angle == 0.0:
        raise _row_error(i, "angle", "a turn profile needs a non-zero angle")
    try:
        step = r.step()
    except ValueError as e:
        raise _row_error(i, "profile", str(e)) from None
    if not step.duration > 0:
        raise _row_error(i, "dwell_s", "a row must last more than 0 s")
    return step


def scheme_from_rows(rows: Sequence[Row] | Sequence[Mapping], *, name: str = "user",
                     reference: str = "body", description: str = "",
                     q0: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
                     tol: float = 1e-9) -> Scheme:
    """A :class:`Scheme` from rows (:class:`Row` in SI, or user dicts).

    The table must return the IMU to its start at the end of the cycle (the cycle's
    rotation within `tol` rad of the identity), otherwise the cycle would not repeat:
    a :class:`ScenarioError` then says where the last row leaves it.
    """
    if reference not in REFERENCES:
        raise ScenarioError(f"scheme reference: got {reference!r}; allowed: "
                            f"{', '.join(REFERENCES)}")
    if not rows:
        raise ScenarioError("scheme rows: the table is empty; give at least one row")
    if isinstance(rows[0], Mapping):
        si = rows_from_dicts(cast(Sequence[Mapping], rows))
    else:
        si = tuple(cast(Sequence[Row], rows))
    steps = [_checked_step(i, r) for i, r in enumerate(si)]
    schedule = Schedule(tuple(steps), repeat=True, q0=q0)
    check_cycle_closes(schedule, "scheme rows", tol)
    return Scheme(name, si, schedule, reference, description)


def check_cycle_closes(schedule: Schedule, field: str, tol: float = 1e-9) -> None:
    """ScenarioError naming `field` unless the schedule's cycle rotation is within `tol` rad
    of the identity (a table that does not return the IMU to its start would not repeat its
    positions); the message says where the last row leaves it."""
    rv = quat_to_rotvec(schedule.cycle_rotation)
    ang = float(np.linalg.norm(rv))
    if ang > tol:
        raise ScenarioError(
            f"{field}: the table does not return the IMU to its start: after the last row it "
            f"is turned by {ang / DEG:.6g} deg about {(np.round(rv / ang, 6) + 0.0).tolist()}; "
            "add rows that bring it back")


# ---------------------------------------------------------------------------- built-ins

def _turn_rows(table: Sequence[tuple[str, float]], turn: Turn, dwell: float) -> list[Row]:
    """(axis name, angle in degrees) pairs → rows with one turn timing and dwell."""
    return [Row(AXES[a], ang * DEG, dwell, t_accel=turn.t_accel, t_const=turn.t_const,
                t_decel=turn.t_decel) for a, ang in table]


SINGLE_4 = [("z", 180.0), ("z", -180.0), ("z", -180.0), ("z", 180.0)]
_DUAL_8 = [("z", 180.0), ("x", -180.0), ("z", 180.0), ("x", -180.0),
           ("x", -180.0), ("z", 180.0), ("x", -180.0), ("z", 180.0)]
DUAL_16 = _DUAL_8 + [(a, -ang) for a, ang in _DUAL_8]
DUAL_16_IMPROVED = DUAL_16[:8] + [DUAL_16[k - 1] for k in (10, 9, 12, 11, 14, 13, 16, 15)]
SEED_12 = [(a, 180.0) for a in "zxyyxz"] + [(a, -180.0) for a in "zxyyxz"]
FOUR_POSITION_12 = [(a, 180.0) for a in "zxyxyzyxyzzx"]
FOUR_POSITION_24 = FOUR_POSITION_12 + [(a, -ang) for a, ang in FOUR_POSITION_12]

_DESCRIPTIONS = {
    "fixed": "no rotation",
    "single-4": "single axis: +180/-180/-180/+180 deg about z (PSINS test_RSINS_1_axis)",
    "dual-16": "dual axis 16-step, z/x (PSINS test_RSINS_2_axis, Yuan)",
    "dual-16-improved": "dual axis improved 16-step (rows 9-16 swapped in pairs)",
    "seed-12": "seed 004 literal three-position 12-step (leaves diag(-1,1,1)/3 of each bias)",
    "four-position-12": "four positions A,B,C,D=Rx(pi), 12 turns of +180 deg (cancels)",
    "four-position-24": "four-position-12, then the same 12 turns reversed (no wind-up)",
    "continuous": "constant rate about one axis",
}
BUILTIN_NAMES = tuple(_DESCRIPTIONS)


def builtin_rows(name: str, *, dwell: float | None = None, turn: Turn = SEED_TURN,
                 rate: float = 6.0 * DEG, axis: str = "z") -> tuple[Row, ...]:
    """The rows of built-in scheme `name` (see the module docstring) with dwell `dwell`
    (s; default Ts = 300 s, and 3600 s for ``fixed``) and turn timing `turn`; ``continuous``
    turns at `rate` (rad/s) about `axis`."""
    if name not in _DESCRIPTIONS:
        raise ScenarioError(f"scheme: unknown scheme {name!r}; built-in: "
                            f"{', '.join(BUILTIN_NAMES)} (or a table of rows)")
    if dwell is not None and not dwell >= 0:
        raise ScenarioError(f"scheme dwell_s: must be ≥ 0, got {dwell!r}")
    if name == "fixed":
        if dwell == 0:
            raise ScenarioError("scheme dwell_s: the fixed scheme needs a dwell > 0 s")
        return (Row(AXES["z"], 0.0, 3600.0 if dwell is None else dwell),)
    if name == "continuous":
        if axis not in AXES:
            raise ScenarioError(f"scheme axis: got {axis!r}; allowed: {', '.join(AXES)}")
        if not rate > 0:
            raise ScenarioError(f"scheme rate_dps: must be > 0, got {rate / DEG!r}")
        return (Row(AXES[axis], 2.0 * math.pi, 0.0 if dwell is None else dwell, rate=rate),)
    table = {"single-4": SINGLE_4, "dual-16": DUAL_16, "dual-16-improved": DUAL_16_IMPROVED,
             "seed-12": SEED_12, "four-position-12": FOUR_POSITION_12,
             "four-position-24": FOUR_POSITION_24}[name]
    return tuple(_turn_rows(table, turn, SEED_DWELL if dwell is None else dwell))


@lru_cache(maxsize=64)  # a sweep's validation asks for the same few schemes hundreds of times
def builtin_scheme(name: str, *, dwell: float | None = None, turn: Turn = SEED_TURN,
                   rate: float = 6.0 * DEG, axis: str = "z") -> Scheme:
    """Built-in scheme `name` as a :class:`Scheme` (arguments as :func:`builtin_rows`).

    ``seed-12`` and ``four-position-12`` are navigation-referenced (the three-axis
    mechanism isolates the carrier, spec 004 §2), and so are the ``four-position`` schemes;
    the others are body-referenced.
    """
    rows = builtin_rows(name, dwell=dwell, turn=turn, rate=rate, axis=axis)
    return scheme_from_rows(rows, name=name, reference=builtin_reference(name),
                            description=_DESCRIPTIONS[name])


def builtin_reference(name: str) -> str:
    """The frame built-in scheme `name` turns in (see :func:`builtin_scheme`)."""
    return "navigation" if name.startswith(("seed-12", "four-position")) else "body"
