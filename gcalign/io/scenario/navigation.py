"""The `navigation`, `mechanism` and `output` sections of a scenario.

``navigation`` says how ``gcalign navigate`` runs (vertical channel, where it starts);
``mechanism`` turns the IMU inside the body (the sensor frame, seed 004); ``output`` says at
what rate long series are stored.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Annotated, Literal

from pydantic import Field, model_validator

from gcalign.errors import ScenarioError
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model, Vec3
from gcalign.io.scenario.schedule import RowModel, quat_of, schedule_of
from gcalign.sim.mechanism import Mechanism
from gcalign.sim.schedule import Schedule

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


#: Longest mechanism cycle (s): its invariants are integrated over one cycle.
MAX_CYCLE_S = 1e6


class MechanismConfig(Model):
    """The IMU on a mechanism: a built-in rotation scheme (``scheme``, with its timing
    overridable) or a table of rows (``steps``), referenced to the body or to the navigation
    frame. ::

        mechanism: {scheme: four-position-12, dwell_s: 200}           # seed 004 timing else
        mechanism: {scheme: seed-12, turn_s: 10, accel_s: 3}          # 3 + 4 + 3 s turns
        mechanism: {reference: body, steps: [{axis: z, profile: trapezoid, ...}, ...]}
    """

    scheme: str | None = Field(
        None, description="a built-in scheme (gcalign.modulate.schemes): fixed, single-4, "
        "dual-16, dual-16-improved, seed-12, four-position-12, four-position-24, continuous; "
        "instead of steps")
    name: str | None = Field(None, pattern=r"^[A-Za-z0-9_.+-]+$",
                             description="name of a steps table in results (default: table)")
    reference: Literal["body", "navigation"] | None = Field(
        None, description="body: C_s^b from the rows (single/dual axis); navigation: C_s^n "
        "(a three-axis mechanism that isolates the carrier). Default: the scheme's own "
        "(seed-12 and four-position: navigation), body for steps")
    start_deg: Vec3 | None = Field(
        None, description="[pitch, roll, yaw] of the sensor frame at t = 0 relative to the "
        "reference; default: aligned with the body")
    steps: list[RowModel] | None = Field(None, min_length=1)
    repeat: bool = True
    dwell_s: float | None = Field(None, ge=0, description="scheme: dwell after each turn, s "
                                  "(default 300; fixed: 3600)")
    accel_s: float | None = Field(None, gt=0, description="scheme: acceleration of each "
                                  "turn, s (default 4)")
    const_s: float | None = Field(None, ge=0, description="scheme: constant-rate part, s "
                                  "(default 4)")
    decel_s: float | None = Field(None, gt=0, description="scheme: deceleration, s "
                                  "(default: accel_s)")
    turn_s: float | None = Field(None, gt=0, description="scheme: whole turn, s, instead of "
                                 "const_s (const = turn - accel - decel)")
    rate_dps: Annotated[float | None, B.RATE_DPS] = Field(
        None, gt=0, description="continuous: rate, °/s (default 6)")
    axis: Literal["x", "y", "z", "-x", "-y", "-z"] | None = Field(
        None, description="continuous: the sensor axis it turns about (default z)")
    lever_arm_cm: Vec3 | None = Field(
        None, description="accelerometers from the rotation centre, sensor frame, cm")

    @model_validator(mode="after")
    def _builds(self):
        timing = [k for k in ("dwell_s", "accel_s", "const_s", "decel_s", "turn_s",
                              "rate_dps", "axis") if getattr(self, k) is not None]
        if (self.scheme is None) == (self.steps is None):
            raise ValueError("scheme: give either a built-in scheme or steps (a table of "
                             "rows), not " + ("both" if self.scheme else "neither"))
        if self.steps is not None:
            if timing:
                raise ValueError(f"{timing[0]}: applies to a built-in scheme; a steps table "
                                 "gives its own timing in each row")
            period = schedule_of(self.steps, self.repeat).period
            where = "steps"
        else:
            if self.name is not None:
                raise ValueError("name: names a steps table; a built-in scheme has its name")
            if not self.repeat:
                raise ValueError("repeat: a built-in scheme is a cycle (repeat: true)")
            period = self.scheme_of(self.scheme).schedule.period  # type: ignore[arg-type]
            where = next((k for k in timing if k.endswith("_s")), "dwell_s")
        if not period <= MAX_CYCLE_S:  # the invariants integrate over one cycle
            raise ValueError(f"{where}: the mechanism's cycle is {period:.4g} s; at most "
                             f"{MAX_CYCLE_S:g} s ({MAX_CYCLE_S / 86400:.3g} days) allowed")
        return self

    @property
    def label(self) -> str:
        """The scheme's name, or the table's."""
        return self.scheme or self.name or "table"

    def turn(self):
        """The turn timing of a built-in scheme (:class:`gcalign.modulate.schemes.Turn`);
        ValueError when the turn is shorter than its acceleration plus deceleration."""
        from gcalign.modulate.schemes import SEED_TURN, Turn

        ta = SEED_TURN.t_accel if self.accel_s is None else self.accel_s
        td = ta if self.decel_s is None else self.decel_s
        if self.turn_s is not None:
            if self.const_s is not None:
                raise ValueError("turn_s: give turn_s or const_s, not both")
            if self.turn_s < ta + td:
                raise ValueError(f"turn_s: the turn ({self.turn_s:g} s) is shorter than its "
                                 f"acceleration plus deceleration ({ta:g} + {td:g} s)")
            return Turn(ta, self.turn_s - ta - td, td)
        return Turn(ta, SEED_TURN.t_const if self.const_s is None else self.const_s, td)

    def scheme_of(self, name: str, q0=(1.0, 0.0, 0.0, 0.0)):
        """Built-in scheme `name` with this section's timing, starting at `q0` (its
        :class:`gcalign.modulate.schemes.Scheme`); ValueError names what is wrong."""
        from gcalign.errors import ScenarioError
        from gcalign.modulate.schemes import builtin_scheme
        from gcalign.units import DEG

        try:
            s = builtin_scheme(name, dwell=self.dwell_s, turn=self.turn(),
                               rate=(6.0 if self.rate_dps is None else self.rate_dps) * DEG,
                               axis=self.axis or "z")
        except ScenarioError as err:
            raise ValueError(str(err).removeprefix("scheme ")) from None  # "dwell_s: …"
        if q0 != (1.0, 0.0, 0.0, 0.0):
            s = replace(s, schedule=replace(s.schedule, q0=q0))
        return s

    def _q0(self, body_att0_deg=None) -> tuple[float, float, float, float]:
        start = self.start_deg
        if start is None and self.resolved_reference == "navigation":
            start = body_att0_deg
        return quat_of(start)

    @property
    def resolved_reference(self) -> str:
        if self.reference is not None:
            return self.reference
        if self.scheme is not None:
            from gcalign.modulate.schemes import builtin_reference

            return builtin_reference(self.scheme)
        return "body"

    def lever(self) -> tuple[float, float, float] | None:
        """The lever arm in m, or None."""
        if self.lever_arm_cm is None or not any(self.lever_arm_cm):
            return None
        x, y, z = (0.01 * float(v) for v in self.lever_arm_cm)
        return (x, y, z)

    def schedule(self, body_att0_deg=None, scheme: str | None = None) -> Schedule:
        """The schedule of built-in `scheme` (default: this section's) with this section's
        timing, or of the steps; a navigation-referenced one starts aligned with the body's
        initial attitude `body_att0_deg` unless start_deg is given."""
        q0 = self._q0(body_att0_deg)
        name = scheme or self.scheme
        if name is not None:
            return self.scheme_of(name, q0).schedule
        assert self.steps is not None
        return schedule_of(self.steps, self.repeat, q0)

    def to_mechanism(self, body_att0_deg=None) -> Mechanism:
        """The mechanism (see :meth:`schedule`)."""
        return Mechanism(self.schedule(body_att0_deg), self.resolved_reference, self.lever())


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
        """Samples per stored row; ScenarioError unless the IMU rate is a multiple of the rate."""
        rate = self.rate_hz
        if rate is None:
            rate = "full" if duration_s <= FULL_RATE_UP_TO_S else min(1.0, imu_rate_hz)
        if rate == "full":
            return 1
        k = imu_rate_hz / float(rate)
        if abs(k - round(k)) > 1e-9 or round(k) < 1:
            raise ScenarioError(f"output.rate_hz: {rate:g} Hz does not divide the IMU rate "
                                f"{imu_rate_hz:g} Hz; allowed: IMU rate / n for a whole n, "
                                "or 'full'")
        return int(round(k))
