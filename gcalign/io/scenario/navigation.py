"""The `navigation`, `mechanism` and `output` sections of a scenario.

``navigation`` says how ``gcalign navigate`` runs (vertical channel, where it starts);
``mechanism`` turns the IMU inside the body (the sensor frame, seed 004); ``output`` says at
what rate long series are stored.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from gcalign.io.scenario.base import Model, Vec3
from gcalign.io.scenario.schedule import RowModel, schedule_of
from gcalign.sim.mechanism import Mechanism

#: Without ``output.rate_hz``, runs up to this long store every sample; longer ones 1 Hz.
FULL_RATE_UP_TO_S = 3600.0


class NavigationConfig(Model):
    vertical: Literal["auto", "free", "hold", "damped"] = Field(
        "auto", description="auto: hold when the true height is constant or the data are "
        "recorded, damped to the true height otherwise")
    vertical_tau_s: float | None = Field(
        None, gt=0, description="damped: time constant of the third-order height loop "
        "(triple pole at -1/tau), default 30 s")
    start_s: float = Field(0.0, ge=0, description="data time at which navigation starts")
    duration_s: float | None = Field(None, gt=0, description="default: to the end of the data")

    @model_validator(mode="after")
    def _tau_only_when_damped(self):
        if self.vertical_tau_s is not None and self.vertical not in ("damped", "auto"):
            raise ValueError(f"vertical_tau_s: applies to vertical 'damped' only, got vertical "
                             f"{self.vertical!r}")
        return self

    @property
    def tau_s(self) -> float:
        return 30.0 if self.vertical_tau_s is None else self.vertical_tau_s


class MechanismConfig(Model):
    reference: Literal["body", "navigation"] = Field(
        "body", description="body: C_s^b from the rows (single/dual axis); navigation: C_s^n "
        "(a three-axis mechanism that isolates the carrier)")
    start_deg: Vec3 | None = Field(
        None, description="[pitch, roll, yaw] of the sensor frame at t = 0 relative to the "
        "reference; default: aligned with the body")
    steps: list[RowModel] = Field(min_length=1)
    repeat: bool = True

    @model_validator(mode="after")
    def _builds(self):
        schedule_of(self.steps, self.repeat, self.start_deg)
        return self

    def to_mechanism(self, body_att0_deg=None) -> Mechanism:
        """The mechanism; a navigation-referenced one starts aligned with the body's initial
        attitude `body_att0_deg` unless start_deg is given."""
        start = self.start_deg
        if start is None and self.reference == "navigation":
            start = body_att0_deg
        return Mechanism(schedule_of(self.steps, self.repeat, start), self.reference)


class OutputConfig(Model):
    rate_hz: float | Literal["full"] | None = Field(
        None, description="rate of the stored series; 'full' = every sample; default: every "
        f"sample for runs up to {FULL_RATE_UP_TO_S:g} s, else 1 Hz")

    @model_validator(mode="after")
    def _positive(self):
        if isinstance(self.rate_hz, float | int) and not self.rate_hz > 0:
            raise ValueError(f"rate_hz: must be > 0 or 'full', got {self.rate_hz}")
        return self

    def stride(self, imu_rate_hz: float, duration_s: float) -> int:
        """Samples per stored row; ValueError unless the IMU rate is a multiple of the rate."""
        rate = self.rate_hz
        if rate is None:
            rate = "full" if duration_s <= FULL_RATE_UP_TO_S else min(1.0, imu_rate_hz)
        if rate == "full":
            return 1
        k = imu_rate_hz / float(rate)
        if abs(k - round(k)) > 1e-9 or round(k) < 1:
            raise ValueError(f"output.rate_hz: {rate:g} Hz does not divide the IMU rate "
                             f"{imu_rate_hz:g} Hz; allowed: IMU rate / n for a whole n, or 'full'")
        return int(round(k))
