"""The `align` section of a scenario (seed 000; README "Scenario format")."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from gcalign.align.stages import Stage, stage_of_passes
from gcalign.io.scenario.base import Model, Vec3


class Coarse(Model):
    method: Literal["given", "analytic", "inertial"] = "given"
    duration_s: float | None = Field(
        None, gt=0, description="coarse window ending at T1; default T1"
    )
    error_deg: Vec3 = Field(
        default_factory=lambda: [1.0, 1.0, 10.0],
        description="method given: added to the true attitude at T1",
    )
    offset_deg: Vec3 = Field(
        default_factory=lambda: [0.0, 0.0, 0.0],
        description="added to the coarse result of any method (studies of "
        "the initial error on recorded data)",
    )


class Aiding(Model):
    source: Literal["none", "odometer", "nav"] = "none"
    noise_mps: float = Field(0.0, ge=0, description="white noise std of each reference sample")


class StageModel(Model):
    t_xy_s: float = Field(20.0, gt=0)
    t_z_s: float = Field(100.0, gt=0)
    xi: float = Field(0.707, gt=0, lt=1)
    passes: int | None = Field(None, ge=1)

    def to_stage(self) -> Stage:
        return Stage(self.t_xy_s, self.t_z_s, self.xi, self.passes)


class AlignConfig(Model):
    coarse: Coarse = Field(default_factory=Coarse)
    mode: Literal["conventional", "full-cycle", "half-cycle"] = "full-cycle"
    start_s: float = Field(
        0.0, ge=0, description="offset from the first sample taken as t = 0 (data windows)"
    )
    t1_s: float = Field(10.0, ge=0)
    t2_s: float = Field(300.0, gt=0)
    t3_s: float | Literal["measured"] = 330.0
    passes: int = Field(5, ge=1, le=101)
    realtime: bool = Field(
        True,
        description="conventional mode: run the loop through T3 in real time; false stops "
        "it at T2 and carries the attitude to T3 by the compensation (seed §5.2)",
    )
    compensation: Literal["none", "one-off", "continued"] = "continued"
    azimuth_poles: Literal["double-oscillator", "oscillator-overdamped"] | None = None
    aiding: Aiding = Field(default_factory=Aiding)
    level_s: float | None = Field(None, ge=0, description="level-only phase; default 3·T_xy")
    stages: list[StageModel] = Field(default_factory=lambda: [StageModel()], min_length=1)

    @model_validator(mode="after")
    def _timeline(self):
        if self.t2_s <= self.t1_s:
            raise ValueError(f"t2_s: must be greater than t1_s ({self.t1_s} s), got {self.t2_s}")
        if self.t3_s != "measured" and self.t3_s < self.t2_s:
            raise ValueError(
                f"t3_s: must be at least t2_s ({self.t2_s} s) or 'measured', got {self.t3_s}"
            )
        if self.coarse.duration_s is not None and self.coarse.duration_s > self.t1_s:
            raise ValueError(
                f"coarse.duration_s: must not exceed t1_s ({self.t1_s} s), "
                f"got {self.coarse.duration_s}"
            )
        if self.coarse.method != "given" and self.t1_s <= 0:
            raise ValueError(
                f"t1_s: coarse method {self.coarse.method!r} needs data before T1, "
                f"got t1_s = {self.t1_s}"
            )
        if self.mode != "conventional":
            if self.passes < 3 or self.passes % 2 == 0:
                raise ValueError(
                    f"passes: mode {self.mode!r} needs an odd number of passes ≥ 3 (forward, "
                    f"reverse, …, forward), got {self.passes}"
                )
        passes = self.pass_count
        covered = stage_of_passes([s.to_stage() for s in self.stages], passes)
        for i in range(len(self.stages)):
            if i not in covered:
                raise ValueError(
                    f"stages: stage {i} covers no pass ({passes} pass(es) in mode {self.mode!r}, "
                    f"earlier stages take them all); remove it or lower an earlier 'passes'"
                )
        if any(s.passes is None for s in self.stages[:-1]):
            raise ValueError("stages: only the last stage may omit 'passes' (it takes the rest)")
        if self.level_phase_s >= self.t2_s - self.t1_s:
            raise ValueError(
                f"level_s: the level phase ({self.level_phase_s} s) must be shorter "
                f"than the fine block t2_s - t1_s ({self.t2_s - self.t1_s} s)"
            )
        return self

    @property
    def pass_count(self) -> int:
        return 1 if self.mode == "conventional" else self.passes

    @property
    def level_phase_s(self) -> float:
        return 3.0 * self.stages[0].t_xy_s if self.level_s is None else self.level_s

    def poles_for(self, motion_kind: str | None) -> str:
        """Azimuth pole method: configured, else method b on a swing or static base and
        method a on a moving base (seed §4)."""
        if self.azimuth_poles is not None:
            return self.azimuth_poles
        return "double-oscillator" if motion_kind == "moving" else "oscillator-overdamped"

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        kind = sc.motion.kind if sc.motion is not None else None
        realtime = self.mode == "conventional" and self.realtime
        rows = [
            ("align.mode", self.mode, f"{self.pass_count} pass(es)"),
            (
                "align.realtime",
                str(self.realtime),
                "loop runs to T3 on live data"
                if realtime
                else (
                    "stops at T2, then compensation"
                    if self.mode == "conventional"
                    else "(unused by the cycle modes)"
                ),
            ),
            ("align.start_s", f"{self.start_s} s", "offset of t = 0 from the first sample"),
            (
                "align.coarse",
                f"{self.coarse.method}, error {self.coarse.error_deg} °",
                str(np.radians(self.coarse.error_deg).round(6).tolist()) + " rad",
            ),
            ("align.t1_s / t2_s / t3_s", f"{self.t1_s} / {self.t2_s} / {self.t3_s} s", ""),
            (
                "align.compensation",
                self.compensation,
                "(unused: real-time conventional)" if realtime else "",
            ),
            ("align.azimuth_poles", self.poles_for(kind), ""),
            ("align.aiding", f"{self.aiding.source}, {self.aiding.noise_mps} m/s", ""),
            ("align.level_s", f"{self.level_phase_s} s", ""),
        ]
        for i, s in enumerate(self.stages):
            rows.append(
                (
                    f"align.stages.{i}",
                    f"T_xy {s.t_xy_s} s, T_z {s.t_z_s} s, ξ {s.xi}",
                    f"passes {s.passes or 'rest'}",
                )
            )
        return rows
