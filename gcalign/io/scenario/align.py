"""The `align` section of a scenario (seed 000; docs: Reference, Scenario keys).

One key per quantity: the coarse window is ``[start_s, t1_s]`` (no separate duration), the
method ``given`` takes ``error_deg`` and the measuring methods ``offset_deg``, and the pass
count is the sum of the stages' ``passes``. Two kinds of keys that cannot matter:

* a key contradicting the method of its own mapping (``coarse: {method: analytic,
  error_deg: …}``) is an error: it was written together with what makes it void;
* a key a mode makes void (``compensation`` in real-time conventional mode, the stage pass
  counts of conventional mode, ``realtime`` in the cycle modes, ``aiding.noise_mps``
  without aiding) is reported by :meth:`AlignConfig.unused`: the command shows it on
  stderr, in its table and in the JSON ``warnings`` (a ``--mode`` option must not make a
  scenario invalid).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from gcalign.align.stages import Stage
from gcalign.io.recorded.aiding import VELOCITY_FORMATS
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario import transfer as transfer_section
from gcalign.io.scenario.base import Model, Vec3, vector

#: Passes in all when the last stage does not say: 3 forward + 2 reverse in the cycle
#: modes (seed 000 §5.3), one forward pass in conventional mode.
DEFAULT_PASSES = {"conventional": 1, "full-cycle": 5, "half-cycle": 5}


def _removed(key: str, instead: str) -> Any:
    """A model's check of a key that was dropped: say what replaced it (pydantic would say
    'unknown key')."""
    def check(cls, data):
        if isinstance(data, dict) and key in data:
            raise ValueError(f"{key}: removed; {instead}")
        return data
    return model_validator(mode="before")(check)


class Coarse(Model):
    method: Literal["given", "analytic", "inertial"] = "given"
    error_deg: Vec3 = vector((1.0, 1.0, 10.0),
                             description="method given: added to the true attitude at T1")
    offset_deg: Vec3 = vector(description="methods analytic and inertial: added to their "
                              "result (studies of the initial error on recorded data)")

    _one_window = _removed("duration_s", "the coarse window is [start_s, t1_s]: set "
                           "align.t1_s (and align.start_s for a later window)")

    @model_validator(mode="after")
    def _one_error_key(self):
        """The other method's key, set to anything but its default, is a mistake (a dump of
        a model with its defaults still loads)."""
        given = self.method == "given"
        if given and self.offset_deg != [0.0, 0.0, 0.0]:
            raise ValueError("offset_deg: cannot matter with method 'given', which takes "
                             "error_deg (the error added to the true attitude at T1)")
        if not given and self.error_deg != [1.0, 1.0, 10.0]:
            raise ValueError(f"error_deg: cannot matter with method {self.method!r}; it is "
                             "the error of method 'given' (offset_deg adds a fixed error to "
                             f"the {self.method} result)")
        return self


class Aiding(Model):
    """The reference velocity of the loops: none (a still or swinging base), simulated from
    the truth (``odometer``, ``nav``), or read from a ``file`` (``path``, ``format``: a
    velocity CSV ENU/NED, an odometer's speed, or a reference solution's velocity;
    :func:`gcalign.io.recorded.aiding.read_velocity_aiding`)."""

    source: Literal["none", "odometer", "nav", "file"] = "none"
    noise_mps: Annotated[float, B.NOISE_MPS] = Field(
        0.0, ge=0, description="white noise std of each reference sample")
    path: Path | None = Field(None, description="source file: the aiding file")
    format: Literal[VELOCITY_FORMATS] | None = Field(  # type: ignore[valid-type]
        None, description=f"source file: one of {', '.join(VELOCITY_FORMATS)}")
    columns: list[str] | None = None
    variable: str | None = Field(None, description="psins-mat: the avp array to read")
    axis: str = Field("F", description="odometer: the body axis of its speed (F, B, R, L, U, D)")
    max_gap_s: float | None = Field(None, gt=0, description="source file: epochs further "
                                    "apart are a gap the window may not contain; default "
                                    "twice the file's median interval")

    @model_validator(mode="after")
    def _file_keys(self):
        keys = [k for k in ("path", "format", "columns", "variable", "max_gap_s")
                if getattr(self, k) is not None]
        if self.source == "file":
            missing = [k for k in ("path", "format") if getattr(self, k) is None]
            if missing:
                raise ValueError(f"{missing[0]}: missing; source 'file' needs path and format "
                                 f"({', '.join(VELOCITY_FORMATS)})")
        elif keys:
            raise ValueError(f"{keys[0]}: applies to source 'file' only, got source "
                             f"{self.source!r}")
        return self

    @property
    def body(self) -> bool:
        """The reference velocity is in the body frame (an odometer)."""
        return self.source == "odometer" or (self.source == "file" and self.format == "odometer")

    def read(self):
        """The aiding file (:class:`gcalign.io.recorded.aiding.Velocities`)."""
        from gcalign.io.recorded.aiding import read_velocity_aiding

        assert self.path is not None and self.format is not None
        return read_velocity_aiding(self.path, self.format, self.columns, self.variable,
                                    self.axis)


class StageModel(Model):
    t_xy_s: float = Field(20.0, gt=0)
    t_z_s: float = Field(100.0, gt=0)
    xi: float = Field(0.707, gt=0, lt=1)
    passes: int | None = Field(
        None, ge=1, description="passes this stage covers; the last stage may omit it and "
        "takes the rest of the mode's default (5 in the cycle modes)")


class AlignConfig(Model):
    coarse: Coarse = Field(default_factory=Coarse)
    mode: Literal["conventional", "full-cycle", "half-cycle", "transfer"] = "full-cycle"
    start_s: float = Field(0.0, ge=0, description="offset from the first sample taken as t = 0 "
                           "(data windows)")
    t1_s: float = Field(10.0, ge=0, description="end of the coarse window [0, T1]")
    t2_s: float = Field(300.0, gt=0)
    t3_s: float | Literal["measured"] = 330.0
    realtime: bool = Field(True, description="conventional mode: run the loop through T3 in "
                           "real time; false stops it at T2 and carries the attitude to T3 by "
                           "the compensation (seed §5.2)")
    compensation: Literal["none", "one-off", "continued"] = "continued"
    azimuth_poles: Literal["double-oscillator", "oscillator-overdamped"] | None = None
    aiding: Aiding = Field(default_factory=Aiding)
    level_s: float | None = Field(None, ge=0, description="level-only phase; default 3·T_xy")
    stages: list[StageModel] = Field(default_factory=lambda: [StageModel()], min_length=1)
    transfer: transfer_section.TransferConfig | None = None  # mode transfer (spec 006)

    _one_pass_count = _removed("passes", "the pass count is the sum of the stages' passes: "
                               "set align.stages.N.passes on the last stage (or --passes N)")

    @model_validator(mode="after")
    def _timeline(self):
        if self.mode == "transfer" or self.transfer is not None:
            return transfer_section.check_align_mode(self)
        if self.t2_s <= self.t1_s:
            raise ValueError(f"t2_s: must be greater than t1_s ({self.t1_s} s), got {self.t2_s}")
        if self.t3_s != "measured" and self.t3_s < self.t2_s:
            raise ValueError(f"t3_s: must be at least t2_s ({self.t2_s} s) or 'measured', got "
                             f"{self.t3_s}")
        if self.coarse.method != "given" and self.t1_s <= 0:
            raise ValueError(f"t1_s: coarse method {self.coarse.method!r} needs data before T1, "
                             f"got t1_s = {self.t1_s}")
        if any(s.passes is None for s in self.stages[:-1]):
            raise ValueError("stages: only the last stage may omit 'passes' (it takes the rest)")
        if self.mode != "conventional":
            last = self.stages[-1]
            earlier = sum(s.passes or 0 for s in self.stages[:-1])
            if last.passes is None and earlier >= DEFAULT_PASSES[self.mode]:
                raise ValueError(
                    f"stages.{len(self.stages) - 1}.passes: missing, and the earlier stages "
                    f"take all {DEFAULT_PASSES[self.mode]} passes of the default; give this "
                    "stage's passes")
            passes = self.pass_count
            if passes < 3 or passes % 2 == 0:
                counts = " + ".join(str(s.passes) for s in self.stage_list())
                raise ValueError(f"stages: mode {self.mode!r} needs an odd number of passes ≥ 3 "
                                 f"in all (forward, reverse, …, forward), the stages give "
                                 f"{passes} ({counts})")
        if self.level_phase_s >= self.t2_s - self.t1_s:
            raise ValueError(f"level_s: the level phase ({self.level_phase_s} s) must be shorter "
                             f"than the fine block t2_s - t1_s ({self.t2_s - self.t1_s} s)")
        return self

    @property
    def realtime_conventional(self) -> bool:
        """One forward pass over live data to T3: nothing to compensate."""
        return self.mode == "conventional" and self.realtime

    def stage_list(self) -> list[Stage]:
        """The stages with their pass counts resolved (conventional: one pass, stage 1)."""
        if self.mode == "conventional":
            s = self.stages[0]
            return [Stage(s.t_xy_s, s.t_z_s, s.xi, 1)]
        out: list[Stage] = []
        for s in self.stages:  # only the last may omit its count: the rest of the default
            n = s.passes if s.passes is not None else DEFAULT_PASSES[self.mode] - sum(
                int(o.passes or 0) for o in out)
            out.append(Stage(s.t_xy_s, s.t_z_s, s.xi, n))
        return out

    @property
    def pass_count(self) -> int:
        return sum(int(s.passes or 0) for s in self.stage_list())

    @property
    def level_phase_s(self) -> float:
        return 3.0 * self.stages[0].t_xy_s if self.level_s is None else self.level_s

    def poles_for(self, motion_kind: str | None) -> str:
        """Azimuth pole method: configured, else method b on a swing or static base and
        method a on a moving base (seed §4)."""
        if self.azimuth_poles is not None:
            return self.azimuth_poles
        return "double-oscillator" if motion_kind == "moving" else "oscillator-overdamped"

    def unused(self, sc=None) -> list[str]:
        """Keys set in the scenario that this mode makes void, one line each (shown as
        warnings; see the module docstring)."""
        if self.mode == "transfer":
            return transfer_section.unused(self)
        out = []
        if self.realtime_conventional and "compensation" in self.model_fields_set:
            out.append(f"align.compensation: {self.compensation!r} cannot matter in real-time "
                       "conventional mode (the loop runs on live data to T3); set "
                       "align.realtime: false to stop at T2 and compensate")
        if self.mode != "conventional" and "realtime" in self.model_fields_set:
            out.append(f"align.realtime: cannot matter in mode {self.mode!r} (it applies to "
                       "conventional mode only)")
        if self.mode == "conventional":
            if len(self.stages) > 1:
                out.append(f"align.stages: {len(self.stages)} stages, but conventional mode "
                           "runs one pass, on stage 1; the others cannot matter")
            elif self.stages[0].passes not in (None, 1):
                out.append(f"align.stages.0.passes: {self.stages[0].passes} cannot matter in "
                           "conventional mode (one forward pass)")
        if self.aiding.source in ("none", "file") and "noise_mps" in \
                self.aiding.model_fields_set and self.aiding.noise_mps:
            out.append(f"align.aiding.noise_mps: cannot matter with aiding source "
                       f"{self.aiding.source!r} (it adds noise to a simulated reference)")
        return out

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        if self.mode == "transfer":
            return transfer_section.resolved_rows(self)
        kind = sc.motion.kind if sc.motion is not None else None
        realtime = self.realtime_conventional
        c = self.coarse
        if c.method == "given":
            coarse = (f"given: truth at T1 + error {c.error_deg} °",
                      str(np.radians(c.error_deg).round(6).tolist()) + " rad")
        else:
            coarse = (f"{c.method} over [0, {self.t1_s:g}] s, + offset {c.offset_deg} °",
                      str(np.radians(c.offset_deg).round(6).tolist()) + " rad")
        rows = [
            ("align.mode", self.mode, f"{self.pass_count} pass(es)"),
            ("align.realtime", str(self.realtime), "loop runs to T3 on live data" if realtime
             else "stops at T2, then compensation" if self.mode == "conventional"
             else "(unused by the cycle modes)"),
            ("align.start_s", f"{self.start_s} s", "offset of t = 0 from the first sample"),
            ("align.coarse", *coarse),
            ("align.t1_s / t2_s / t3_s", f"{self.t1_s} / {self.t2_s} / {self.t3_s} s", ""),
            ("align.compensation", self.compensation,
             "(unused: real-time conventional)" if realtime else ""),
            ("align.azimuth_poles", self.poles_for(kind), ""),
            ("align.aiding", f"file {self.aiding.path} ({self.aiding.format})"
             if self.aiding.source == "file" else
             f"{self.aiding.source}, {self.aiding.noise_mps} m/s", ""),
            ("align.level_s", f"{self.level_phase_s} s", ""),
        ]
        stages = self.stage_list()
        for i, s in enumerate(self.stages):
            n = stages[i].passes if i < len(stages) else 0
            rows.append((f"align.stages.{i}", f"T_xy {s.t_xy_s} s, T_z {s.t_z_s} s, ξ {s.xi}",
                         f"stage {i + 1}: {n} pass(es)"))
        return rows
