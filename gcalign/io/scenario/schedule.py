"""Rotation rows in a scenario: the steps of a turntable motion or of a mechanism.

Each row turns about an axis of the rotating frame itself (``x``, ``y``, ``z``, ``-x`` …
or a unit vector) with one profile, then rests for ``dwell_s``::

    - {axis: z, profile: trapezoid, angle_deg: 180, accel_s: 4, const_s: 4, decel_s: 4,
       dwell_s: 300}
    - {axis: z, profile: trapezoid, angle_deg: -90, rate_dps: 30, accel_dps2: 20}
    - {axis: z, profile: rate, rate_dps: 5, duration_s: 12}
    - {axis: z, profile: ramp, accel_dps2: 10, rate_dps: 15, duration_s: 12, jerk_dps3: 200}
    - {axis: x, profile: swing, amplitude_deg: 10, frequency_hz: 0.4, duration_s: 12}
    - {profile: rest, duration_s: 5}
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from gcalign import units as u
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model
from gcalign.sim.schedule import AngleProfile, Schedule, Step

_NAMED_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
Axis = str | Annotated[list[float], Field(min_length=3, max_length=3)]


def axis_vector(axis) -> tuple[float, float, float]:
    """``x | y | z | -x | -y | -z`` or a unit 3-vector -> a unit vector; ValueError otherwise."""
    if isinstance(axis, str):
        sign, name = (-1.0, axis[1:]) if axis.startswith("-") else (1.0, axis.lstrip("+"))
        if name not in _NAMED_AXES:
            raise ValueError(f"axis: x, y, z (optionally signed) or a unit vector, got {axis!r}")
        a, b, c = _NAMED_AXES[name]
        return sign * a, sign * b, sign * c
    v = np.asarray(axis, dtype=float)
    n = float(np.linalg.norm(v))
    if abs(n - 1.0) > 1e-9:
        raise ValueError(f"axis: must be a unit vector (norm 1), got {list(axis)} "
                         f"(norm {n:.6g})")
    return float(v[0]), float(v[1]), float(v[2])


_PROFILE_KEYS = {  # (needed, optional) keys of each profile
    "trapezoid": ({"angle_deg"}, {"accel_s", "const_s", "decel_s", "rate_dps",
                                  "accel_dps2"}),
    "rate": ({"rate_dps", "duration_s"}, set()),
    "ramp": ({"accel_dps2", "rate_dps", "duration_s"}, {"jerk_dps3"}),
    "swing": ({"amplitude_deg", "frequency_hz", "duration_s"}, {"phase_deg"}),
    "rest": ({"duration_s"}, set()),
}


class RowModel(Model):
    axis: Axis = "z"
    profile: Literal["trapezoid", "rate", "ramp", "swing", "rest"]
    angle_deg: float | None = None
    accel_s: float | None = Field(None, gt=0)
    const_s: float | None = Field(None, ge=0)
    decel_s: float | None = Field(None, gt=0)
    rate_dps: Annotated[float | None, B.RATE_DPS] = None
    accel_dps2: Annotated[float | None, B.ANGULAR_ACCEL_DPS2] = None
    jerk_dps3: Annotated[float | None, B.ANGULAR_JERK_DPS3] = Field(None, gt=0)
    amplitude_deg: float | None = None
    frequency_hz: float | None = Field(None, gt=0)
    phase_deg: float = 0.0
    duration_s: float | None = Field(None, gt=0)
    dwell_s: float = Field(0.0, ge=0)

    @field_validator("axis")
    @classmethod
    def _axis(cls, v):
        axis_vector(v)
        return v

    @model_validator(mode="after")
    def _profile_keys(self):
        need, may = _PROFILE_KEYS[self.profile]
        given = {k for k in type(self).model_fields if k not in ("axis", "profile", "dwell_s",
                                                                  "phase_deg")
                 and getattr(self, k) is not None}
        missing = sorted(need - given)
        if missing:
            raise ValueError(f"{missing[0]}: missing; profile {self.profile!r} needs "
                             f"{', '.join(sorted(need))}")
        extra = sorted(given - need - may)
        if extra:
            raise ValueError(f"{extra[0]}: does not apply to profile {self.profile!r} "
                             f"(it takes {', '.join(sorted(need | may))})")
        if self.profile == "trapezoid":
            by_time = {"accel_s", "const_s", "decel_s"} & given
            by_rate = {"rate_dps", "accel_dps2"} & given
            if by_time and by_rate:
                raise ValueError("rate_dps: a trapezoid is given by times (accel_s, const_s, "
                                 "decel_s) or by rate_dps and accel_dps2, not both")
            if by_time and by_time != {"accel_s", "const_s", "decel_s"}:
                raise ValueError("accel_s: a trapezoid by times needs accel_s, const_s and "
                                 "decel_s")
            if by_rate and by_rate != {"rate_dps", "accel_dps2"}:
                raise ValueError("rate_dps: a trapezoid by rate needs rate_dps and accel_dps2")
            if not (by_time or by_rate):
                raise ValueError("accel_s: a trapezoid needs accel_s/const_s/decel_s or "
                                 "rate_dps/accel_dps2")
            if by_rate and not (self.rate_dps > 0 and self.accel_dps2 > 0):  # type: ignore
                raise ValueError(f"rate_dps: rate_dps and accel_dps2 must be > 0 (the sign "
                                 f"is the angle's), got {self.rate_dps}, {self.accel_dps2}")
        if self.profile == "ramp" and (self.accel_dps2 or 0) * (self.rate_dps or 0) <= 0:
            raise ValueError(f"rate_dps: a ramp's accel_dps2 and rate_dps must be non-zero and "
                             f"of one sign, got {self.accel_dps2}, {self.rate_dps}")
        self._implied_rate()
        return self

    def _implied_rate(self) -> None:
        """The peak rate of a trapezoid given by times and of a swing, held to the bound
        of a rate given itself."""
        if self.profile == "trapezoid" and self.accel_s is not None:
            key = "angle_deg"
            peak = abs(self.angle_deg or 0.0) / (0.5 * self.accel_s + (self.const_s or 0.0)
                                                 + 0.5 * (self.decel_s or 0.0))
        elif self.profile == "swing":
            key = "amplitude_deg"
            peak = 2.0 * math.pi * abs(self.amplitude_deg or 0.0) * (self.frequency_hz or 0.0)
        else:
            return
        if not B.RATE_DPS.holds(peak):
            raise ValueError(f"{key}: the turn's peak rate must be within {B.RATE_DPS.range()} "
                             f"({B.RATE_DPS.why}), got {peak:g} °/s")

    def to_step(self) -> Step:
        d = u.DEG
        if self.profile == "trapezoid":
            assert self.angle_deg is not None
            if self.accel_s is not None:
                prof = AngleProfile.trapezoid(self.angle_deg * d, t_accel=self.accel_s,
                                              t_const=self.const_s or 0.0,
                                              t_decel=self.decel_s or 0.0)
            else:
                assert self.rate_dps is not None and self.accel_dps2 is not None
                prof = AngleProfile.trapezoid_rate(self.angle_deg * d, rate=self.rate_dps * d,
                                                   accel=self.accel_dps2 * d)
        elif self.profile == "rate":
            prof = AngleProfile.constant_rate(self.rate_dps * d, self.duration_s)  # type: ignore
        elif self.profile == "ramp":
            prof = AngleProfile.ramp(self.accel_dps2 * d, self.rate_dps * d,  # type: ignore
                                     self.duration_s,  # type: ignore
                                     None if self.jerk_dps3 is None else self.jerk_dps3 * d)
        elif self.profile == "swing":
            prof = AngleProfile.swing(self.amplitude_deg * d, self.frequency_hz,  # type: ignore
                                      self.duration_s, self.phase_deg * d)  # type: ignore
        else:
            prof = AngleProfile.rest(self.duration_s)  # type: ignore
        return Step(axis_vector(self.axis), prof, self.dwell_s)


def steps_of(rows: list[RowModel]) -> tuple[Step, ...]:
    """The steps of validated rows; ValueError names a row that fails."""
    steps = []
    for i, r in enumerate(rows):
        try:
            steps.append(r.to_step())
        except ValueError as err:
            raise ValueError(f"steps.{i}: {err}") from None
    return tuple(steps)


def quat_of(att_deg=None) -> tuple[float, float, float, float]:
    """The quaternion of PSINS Euler angles ``[pitch, roll, yaw]`` in deg (None: the
    identity)."""
    from gcalign.nav.rotation import euler_to_quat

    if att_deg is None:
        return (1.0, 0.0, 0.0, 0.0)
    q = euler_to_quat(np.radians(att_deg))
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def schedule_of(rows: list[RowModel], repeat: bool, q0=(1.0, 0.0, 0.0, 0.0)) -> Schedule:
    """The :class:`Schedule` of validated rows starting at `q0`; ValueError names a row
    that fails."""
    return Schedule(steps_of(rows), repeat=repeat, q0=q0)
