"""The `modulate` section: which rotation schemes ``gcalign modulate`` runs, and for how long.

::

    mechanism: {scheme: seed-12}          # the scheme under study (or steps: a table)
    modulate:
      compare: [fixed, seed-12, four-position-12, dual-16-improved]   # or "fixed,seed-12"
      hours: 72                           # default: the motion's duration
      linear: true                        # the linear error model beside each run

Each entry of ``compare`` is a built-in scheme (:data:`gcalign.modulate.schemes.BUILTIN_NAMES`)
or the name of the scenario's own table (``mechanism.name``, default ``table``). Built-in
entries take the timing of ``mechanism`` (``dwell_s``, ``accel_s``, ``const_s``,
``decel_s``, ``turn_s``, ``rate_dps``, ``axis``) and its lever arm, each with the scheme's
own reference frame; ``fixed`` runs without a mechanism (the IMU fixed to the body). Every
entry navigates the same motion with the same sensor errors and the same noise seed.

A static base lasts as long as ``hours`` asks; any other motion must be at least that long.
A table must return the IMU to its start at the end of its cycle (otherwise the cycle would
not repeat the same positions): it is refused with a line that says where it ends.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

import numpy as np
from pydantic import BeforeValidator, Field, ValidationError, field_validator

from gcalign.errors import ScenarioError
from gcalign.io.scenario.base import Model
from gcalign.io.scenario.navigation import MechanismConfig

if TYPE_CHECKING:
    from gcalign.modulate.schemes import Scheme

CYCLE_TOL = 1e-9  # rad: a table's cycle rotation below this returns the IMU to its start
MAX_HOURS = 1e6 / 3600.0  # the longest motion a scenario may have (1e6 s)
MIN_CYCLE_SAMPLES = 10  # a cycle shorter than this many IMU samples is not sampled at all


def default_rate_hz(duration_s: float, imu_rate_hz: float) -> float:
    """Stored-series rate without ``output.rate_hz``: 1 Hz up to 4 h, 0.1 Hz beyond."""
    return min(imu_rate_hz, 1.0 if duration_s <= 4 * 3600.0 else 0.1)


def _names(v):
    if isinstance(v, str):
        return [x.strip() for x in v.split(",") if x.strip()]
    return v


class ModulateConfig(Model):
    compare: Annotated[list[str], BeforeValidator(_names)] | None = Field(
        None, min_length=1, description="schemes to run on the same data (built-in names or "
        "the mechanism's table); default: the mechanism's scheme")
    hours: float | None = Field(None, gt=0, le=MAX_HOURS, description="how long to navigate, h "
                                "(default: the motion's duration)")
    linear: bool = Field(True, description="integrate the linear error model beside each "
                         "run (static base)")

    @field_validator("compare")
    @classmethod
    def _unique(cls, v):
        if v is not None and len(set(v)) != len(v):
            dup = next(x for x in v if v.count(x) > 1)
            raise ValueError(f"{dup!r} is named twice")
        return v

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        """What ``gcalign validate`` shows: each scheme with its reference and cycle."""
        p = plan_of(sc)
        rows = [("modulate.hours", f"{p.hours:g} h", f"{p.duration_s:g} s")]
        for e in p.entries:
            d = np.diag(e.scheme.schedule.dcm(np.array([0.0]))[0])
            rows.append((f"modulate.compare: {e.name}", f"{e.scheme.reference}, cycle "
                         f"{e.scheme.period / 60:.4g} min",
                         f"{e.scheme.period:g} s; C(0) diag {np.round(d, 6).tolist()}"))
        return rows


@dataclass(frozen=True)
class Entry:
    """One scheme to run: its name, :class:`gcalign.modulate.schemes.Scheme` (with the start
    orientation the run uses) and the mechanism section of its run (None: IMU on the body)."""

    name: str
    scheme: Scheme
    mechanism: MechanismConfig | None


@dataclass(frozen=True)
class Plan:
    entries: tuple[Entry, ...]
    hours: float
    duration_s: float


_TIMING = ("dwell_s", "accel_s", "const_s", "decel_s", "turn_s", "rate_dps", "axis",
           "lever_arm_cm")


def plan_of(sc) -> Plan:
    """The schemes of a scenario's modulate run (module docstring); ScenarioError names the
    field when something does not fit."""
    from gcalign.modulate.schemes import BUILTIN_NAMES, Scheme

    cfg = sc.modulate or ModulateConfig()
    if sc.motion is None:
        raise ScenarioError("motion: missing; gcalign modulate simulates the IMU on a "
                            "mechanism (recorded data carry their own sensor frame)")
    mech: MechanismConfig | None = sc.mechanism
    names = cfg.compare or ([mech.label] if mech is not None else None)
    if not names:
        raise ScenarioError("modulate.compare: nothing to run: give mechanism.scheme, "
                            "mechanism.steps or modulate.compare")
    own = mech.label if mech is not None else None
    att0 = sc.motion.attitude_deg
    entries = []
    for name in names:
        if name == own:
            assert mech is not None
            if mech.steps is not None:
                _check_cycle(mech)
            cfg_e = mech
        elif name in BUILTIN_NAMES:
            keys = _TIMING if mech is not None and mech.steps is None else ("lever_arm_cm",)
            kept = {} if mech is None else {k: getattr(mech, k) for k in keys
                                            if getattr(mech, k) is not None}
            try:
                cfg_e = MechanismConfig(scheme=name, **kept)
            except ValidationError as err:  # the mechanism's timing does not suit this scheme
                from gcalign.io.scenario.messages import scenario_errors

                raise ScenarioError(f"modulate.compare: {name} with the mechanism's timing: "
                                    f"{scenario_errors(err, at='mechanism')}") from None
        else:
            allowed = ", ".join(BUILTIN_NAMES) + (f", {own}" if own and own not in
                                                  BUILTIN_NAMES else "")
            raise ScenarioError(f"modulate.compare: unknown scheme {name!r}; allowed: "
                                f"{allowed}")
        schedule = cfg_e.schedule(att0)
        if not schedule.period >= MIN_CYCLE_SAMPLES * sc.imu.ts:
            key = "mechanism.steps" if cfg_e.steps is not None else "mechanism.dwell_s"
            raise ScenarioError(f"{key}: the cycle of {name} lasts {schedule.period:.4g} s, "
                                f"shorter than {MIN_CYCLE_SAMPLES} IMU samples "
                                f"({MIN_CYCLE_SAMPLES * sc.imu.ts:g} s at {sc.imu.rate_hz:g} "
                                "Hz): no mechanism turns that fast")
        if cfg_e.scheme is not None:
            base = cfg_e.scheme_of(cfg_e.scheme)
            scheme = Scheme(name, base.rows, schedule, cfg_e.resolved_reference,
                            base.description)
        else:
            scheme = Scheme(name, (), schedule, cfg_e.resolved_reference, "user table")
        plain = cfg_e.lever() is None and cfg_e.start_deg is None
        run_mech = None if name == "fixed" and plain else cfg_e
        entries.append(Entry(name, scheme, run_mech))
    motion_s = sc.motion.duration()
    if cfg.hours is None:
        hours = motion_s / 3600.0
    else:
        hours = float(cfg.hours)
        if sc.motion.kind != "static" and hours * 3600.0 > motion_s + 1e-9:
            raise ScenarioError(f"modulate.hours: {hours:g} h is longer than the motion "
                                f"({motion_s / 3600:g} h); shorten it or lengthen the motion")
    if not hours * 3600.0 * sc.imu.rate_hz >= 2:
        raise ScenarioError(f"modulate.hours: {hours:g} h holds fewer than 2 IMU samples at "
                            f"{sc.imu.rate_hz:g} Hz; navigate at least {2 / sc.imu.rate_hz:g} s")
    return Plan(tuple(entries), hours, hours * 3600.0)


def _check_cycle(mech: MechanismConfig) -> None:
    from gcalign.modulate.schemes import check_cycle_closes

    if not mech.repeat:
        raise ScenarioError("mechanism.repeat: gcalign modulate runs a table as a cycle; set "
                            "repeat: true")
    check_cycle_closes(mech.schedule(), "mechanism.steps", CYCLE_TOL)
