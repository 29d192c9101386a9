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
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model, NonNegVec3, PosVec3, Vec3, vector
from gcalign.io.scenario.schedule import RowModel, schedule_of
from gcalign.sim import motions as M


class _Base(Model):
    attitude_deg: Vec3 = vector(description="[pitch, roll, yaw]: initial (or mean, swing)")
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
    amplitude_deg: NonNegVec3 = vector((2.0, 3.0, 4.0))
    period_s: PosVec3 = vector((10.0, 10.0, 20.0))
    phase_deg: Vec3 = vector()


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
    accel_mps2: Annotated[float, B.ACCEL_MPS2] = 0.0
    rate_dps: Annotated[Vec3, B.RATE_DPS] = vector()
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
    accel_mps2: Annotated[float | None, B.ACCEL_MPS2] = None
    speed_mps: float | None = Field(None, ge=0)
    rate_dps: Annotated[float | None, B.RATE_DPS] = Field(None, gt=0)
    angle_deg: float | None = None
    name: str = ""

    def to_segment(self) -> M.FlightSegment:
        d = u.DEG
        return M.FlightSegment(
            self.kind, self.duration_s, self.accel_mps2, self.speed_mps,
            None if self.rate_dps is None else self.rate_dps * d,
            None if self.angle_deg is None else self.angle_deg * d, self.name)


def flight_extent(motion: M.Moving, step: float = 0.25) -> tuple[float, float]:
    """Highest climb above the start and largest horizontal distance from it (m) of a
    moving base: its ENU velocity integrated by Simpson's rule on pieces of at most `step`
    s inside each segment (smooth there), on the local level (the earth's curvature over
    15 km changes a distance by 1e-6 of itself)."""
    starts = np.concatenate([[0.0], np.cumsum([s.duration for s in motion.segments])])
    starts = np.minimum(starts, motion.duration)
    starts[-1] = motion.duration
    top = far = 0.0
    p = np.zeros(3)
    for j, (a, b) in enumerate(zip(starts[:-1], starts[1:], strict=True)):
        if b <= a:
            continue
        n = max(1, int(np.ceil((b - a) / step - 1e-9)))
        t = a + (b - a) * np.arange(2 * n + 1) / (2 * n)
        v = motion.velocity(t, np.full(t.size, min(j, len(motion.segments) - 1)))[0]
        h = (b - a) / (2 * n)
        inc = (v[0:-2:2] + 4 * v[1:-1:2] + v[2::2]) * h / 3.0  # Simpson per piece
        track = p + np.cumsum(inc, axis=0)
        top = max(top, float(track[:, 2].max()))
        far = max(far, float(np.hypot(track[:, 0], track[:, 1]).max()))
        p = track[-1]
    return top, far


class Envelope(Model):
    """Limits a flight must stay within (bad input otherwise)."""

    max_height_m: float | None = Field(None, gt=0, description="climb above the start")
    max_horizontal_m: float | None = Field(None, gt=0, description="distance from the start")


class FlightModel(_Base):
    kind: Literal["flight"]
    duration_s: float | None = Field(None, gt=0, le=1e6,  # type: ignore[assignment]
                                     description="default: the sum of the segments")
    speed_mps: float = Field(0.0, ge=0)
    segments: list[FlightSegmentModel] = Field(min_length=1)
    envelope: Envelope | None = None

    @model_validator(mode="after")
    def _resolve(self):
        motion = self._flight()
        if self.duration_s is not None and self.duration_s < motion.duration - 1e-9:
            raise ValueError(f"duration_s: {self.duration_s:g} s is shorter than the "
                             f"segments ({motion.duration:g} s); omit it to use their sum")
        env = self.envelope
        if env is not None and (env.max_height_m or env.max_horizontal_m):
            top, far = flight_extent(self.to_motion())
            if env.max_height_m is not None and top > env.max_height_m:
                raise ValueError(f"envelope.max_height_m: the flight climbs {top:.0f} m above "
                                 f"its start, above the envelope's {env.max_height_m:g} m")
            if env.max_horizontal_m is not None and far > env.max_horizontal_m:
                raise ValueError(f"envelope.max_horizontal_m: the flight goes {far:.0f} m from "
                                 f"its start, beyond the envelope's {env.max_horizontal_m:g} m")
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
