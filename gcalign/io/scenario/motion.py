"""The `motion` section: one model per kind (a discriminated union on ``kind``).

``static``, ``swing`` and ``moving`` are the seed 000 bases; ``turntable`` turns the body
by rotation rows (:mod:`gcalign.io.scenario.schedule`; seed 003); ``flight`` is an aircraft
trajectory of manoeuvres with targets (seed 002 §3). Angles in degrees, rates in °/s.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from gcalign import units as u
from gcalign.io.scenario.base import Model, NonNegVec3, PosVec3, Vec3
from gcalign.io.scenario.schedule import RowModel, schedule_of
from gcalign.sim import motions as M

MOTION_KINDS = ("static", "swing", "moving", "turntable", "flight")


class _Base(Model):
    attitude_deg: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0],
                               description="[pitch, roll, yaw]: initial (or mean, swing)")
    duration_s: float = Field(gt=0, le=1e6)

    @field_validator("attitude_deg")
    @classmethod
    def _pitch_range(cls, v):
        if not -90 < v[0] < 90:
            raise ValueError(f"pitch must be within (-90, 90) deg, got {v[0]}")
        return v

    def duration(self) -> float:
        """Length of the motion (s)."""
        return float(self.duration_s)  # type: ignore[arg-type]

    def att0(self) -> tuple[float, float, float]:
        a = np.asarray(self.attitude_deg, float) * u.DEG
        return float(a[0]), float(a[1]), float(a[2])


class StaticModel(_Base):
    kind: Literal["static"]

    def to_motion(self) -> M.Static:
        return M.Static(self.att0(), self.duration_s)


class SwingParams(Model):
    amplitude_deg: NonNegVec3 = Field(default_factory=lambda: [2.0, 3.0, 4.0])
    period_s: PosVec3 = Field(default_factory=lambda: [10.0, 10.0, 20.0])
    phase_deg: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])


class SwingModel(_Base):
    kind: Literal["swing"]
    swing: SwingParams = Field(default_factory=SwingParams)

    def to_motion(self) -> M.Swing:
        sw = self.swing
        return M.Swing(self.att0(), self.duration_s,
                       amplitude=tuple(np.asarray(sw.amplitude_deg) * u.DEG),
                       period=(sw.period_s[0], sw.period_s[1], sw.period_s[2]),
                       phase=tuple(np.asarray(sw.phase_deg) * u.DEG))


class SegmentModel(Model):
    duration_s: float = Field(gt=0)
    accel_mps2: float = 0.0
    rate_dps: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    name: str = ""


class MovingModel(_Base):
    kind: Literal["moving"]
    speed_mps: float = Field(0.0, ge=0, description="forward speed at t = 0")
    segments: list[SegmentModel] = Field(min_length=1)

    def to_motion(self) -> M.Moving:
        return M.Moving(self.att0(), self.duration_s, tuple(
            M.Segment(s.duration_s, s.accel_mps2, tuple(np.asarray(s.rate_dps) * u.DEG), s.name)
            for s in self.segments), self.speed_mps)


class TurntableModel(_Base):
    kind: Literal["turntable"]
    steps: list[RowModel] = Field(min_length=1)
    repeat: bool = False

    @model_validator(mode="after")
    def _steps(self):
        self.schedule()  # every row builds (ValueError names it)
        return self

    def schedule(self):
        return schedule_of(self.steps, self.repeat)

    def to_motion(self) -> M.Turntable:
        return M.Turntable(self.att0(), self.duration_s, self.schedule())


class FlightSegmentModel(Model):
    kind: Literal["hold", "accelerate", "pitch", "roll", "yaw", "turn", "coordinated_turn"]
    duration_s: float | None = Field(None, gt=0)
    accel_mps2: float | None = None
    speed_mps: float | None = Field(None, ge=0)
    rate_dps: float | None = Field(None, gt=0)
    angle_deg: float | None = None
    name: str = ""

    def to_segment(self) -> M.FlightSegment:
        d = u.DEG
        return M.FlightSegment(
            self.kind, self.duration_s, self.accel_mps2, self.speed_mps,
            None if self.rate_dps is None else self.rate_dps * d,
            None if self.angle_deg is None else self.angle_deg * d, self.name)


class FlightModel(_Base):
    kind: Literal["flight"]
    duration_s: float | None = Field(None, gt=0, le=1e6,  # type: ignore[assignment]
                                     description="default: the sum of the segments")
    speed_mps: float = Field(0.0, ge=0)
    segments: list[FlightSegmentModel] = Field(min_length=1)

    @model_validator(mode="after")
    def _resolve(self):
        motion = self._flight()
        if self.duration_s is not None and self.duration_s < motion.duration - 1e-9:
            raise ValueError(f"duration_s: {self.duration_s:g} s is shorter than the "
                             f"segments ({motion.duration:g} s); omit it to use their sum")
        return self

    def _flight(self) -> M.Moving:
        try:
            return M.flight(self.att0(), [s.to_segment() for s in self.segments],
                            self.speed_mps)
        except ValueError as err:
            raise ValueError(f"segments: {err}") from None

    def duration(self) -> float:
        return self.to_motion().duration

    def to_motion(self) -> M.Moving:
        motion = self._flight()
        if self.duration_s is None or self.duration_s == motion.duration:
            return motion
        return M.Moving(motion.att0, self.duration_s, motion.segments, motion.speed0)


MotionModel = Annotated[StaticModel | SwingModel | MovingModel | TurntableModel | FlightModel,
                        Field(discriminator="kind")]
