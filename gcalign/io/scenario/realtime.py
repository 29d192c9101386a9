"""The `realtime` section of a scenario (seed 003; spec 003): attitude at external sync
pulses, the filter delay, and its prediction.

Either a list of turntable cases (the seed's Table 1 is one file,
``configs/seed003_table1.yaml``) or one case from the scenario's own turntable motion
(``motion.kind: turntable``; ``configs/seed003_rate20_async.yaml``)::

    name: seed003-table1
    site: {lat_deg: 34.25, lon_deg: 108.9, height_m: 400}   # sets the earth rate sensed
    imu: {seed: 2027}                 # only the seed: the gyro model is realtime.sensor
    realtime:
      semi_physical: true             # the seed's §3.2 setting (see below)
      solution_hz: 1000               # attitude solution rate f2
      delay_ms: null                  # T the predictors use; null: the chain's group delay
      predictors: [none, taylor, kalman-ls]
      filter: {fs_hz: 5000, chain: navigation, nav_order: 40, nav_cutoff_hz: 200,
               align_order: 180, align_cutoff_hz: 100, notch_hz: 400, notch_q: 10,
               window: hamming}
      sensor: {quantum_arcsec: 0.1, arw_dprh: 0.0005, dither_arcsec: 100, dither_hz: 400}
      tracker: {qc_rad2ps5: 1, r_std_arcsec: 0.03, p0_theta_arcsec: 0.03,
                p0_omega_dps: 20, p0_alpha_dps2: 20}
      pulses: {mode: solution, rate_hz: 1000, offset_us: 0}   # or mode: async (below)
      settle_s: 1                     # start of each case not scored
      warmup_s: 0.2                   # gyros and filters run at rest before t = 0
      corner_ms: 50                   # ± window around steps in α, reported apart
      cases:
        - name: rate 5°/s
          seed_before: 72″            # the seed's Table 1 entries, shown beside ours
          seed_after: < 0.3″
          steps: [{axis: z, profile: rate, rate_dps: 5, duration_s: 12}]
        - name: accel 5°/s²
          steps: [{profile: rest, duration_s: 1},
                  {axis: z, profile: ramp, accel_dps2: 5, rate_dps: 15, duration_s: 11}]
        - name: swing 10° 0.1 Hz
          steps: [{axis: z, profile: swing, amplitude_deg: 10, frequency_hz: 0.1,
                   duration_s: 12}]
        - name: rate 20°/s async      # a case may bring its own pulse train
          steps: [{axis: z, profile: rate, rate_dps: 20, duration_s: 12}]
          pulses: {mode: async, rate_hz: 100, offset_us: null, jitter_us: 2,
                   drift_ppm: 100, resolution_us: 1}

Rules
-----
* ``semi_physical: true`` is the seed's semi-physical setting: T fixed at 4 ms (n = 4
  solution intervals), pulses on every solution instant (Δt = 0), and the reference of the
  reported errors is the INS's own output T later (the seed's metric). ``delay_ms`` and
  ``pulses`` then do not apply (an error if given); a case's own ``pulses`` still does.
  ``false``: T = ``delay_ms`` or the chain's low-frequency group delay, pulses as given,
  errors against the true attitude at the pulse time. Both references are always in the
  summary.
* Rows are the turntable rows of ``motion.kind: turntable`` (``rate | ramp (jerk_dps3) |
  swing | trapezoid | rest``, any axis, each about an axis of the body itself); a case
  lasts its rows' total (or ``duration_s``), from ``attitude_deg`` at rest before t = 0.
* ``pulses.offset_us``: ``solution`` mode, the pulse's fixed distance after each solution
  instant (Δt, < 1/solution_hz); ``async``, the first edge (null: uniform random in
  [0, 1/rate_hz)). ``resolution_us``: the Δt counter's resolution (0: exact).
* ``site`` is required (the earth rate the gyros sense, removed by the INS). The ``imu``
  section gives only ``seed``: its error terms must be zero and ``imu.rate_hz``, if given,
  equal to ``filter.fs_hz``. No ``mechanism``, no ``imu_file``.

Converted once to :class:`gcalign.realtime.settings.Settings` and
:class:`gcalign.realtime.cases.Case` (SI) by :meth:`RealtimeConfig.to_settings` and
:meth:`RealtimeConfig.cases_of`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from gcalign import limits
from gcalign import units as u
from gcalign.errors import ScenarioError
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model, Vec3, one_of, vector
from gcalign.io.scenario.schedule import RowModel, steps_of
from gcalign.realtime.settings import (
    FilterSettings,
    PulseSettings,
    SensorSettings,
    Settings,
    TrackerSettings,
    seed_semi_physical,
)

if TYPE_CHECKING:  # the cases module builds seed 003's table at import: where it is used
    from gcalign.realtime.cases import Case

PredictorName = Literal["none", "taylor", "kalman-ls"]
DEFAULT_PREDICTORS: list[PredictorName] = ["none", "taylor", "kalman-ls"]  # = core PREDICTORS
SEED_DELAY_MS = 4.0  #: the seed's T (§3.2: n = 4 solution intervals of 1 ms)
MAX_CASES = 100


def _us(x: float | None) -> float | None:
    return None if x is None else x * 1e-6


#: The scipy.signal windows that take no parameter (a test holds scipy to this list).
FIR_WINDOWS = ("hamming", "hann", "blackman", "boxcar", "triang", "parzen", "bohman", "nuttall",
               "blackmanharris", "flattop", "bartlett", "barthann", "cosine", "exponential",
               "tukey", "taylor", "lanczos")
#: A window scipy.signal's design would refuse, refused by its key (the orders and
#: frequencies are checked by FilterSettings): by name, so that validating a scenario does
#: not import scipy.
FirWindow = Annotated[str, one_of(FIR_WINDOWS, "scipy.signal window without parameters")]


class FilterConfig(Model):
    fs_hz: Annotated[float, B.SENSOR_RATE_HZ] = Field(
        5000.0, gt=0, description="sensor sampling and filter rate f1")
    chain: Literal["navigation", "alignment"] = "navigation"
    nav_order: int = Field(40, description="FIR order (taps − 1) of the navigation chain")
    nav_cutoff_hz: float = 200.0
    align_order: int = Field(180, description="FIR order of the alignment chain")
    align_cutoff_hz: float = 100.0
    notch_hz: float | None = Field(400.0, description="IIR notch (null: none)")
    notch_q: float = Field(10.0, gt=0)
    window: FirWindow = Field("hamming", description="FIR window: a scipy.signal window "
                              "that takes no parameter (hamming, hann, blackman, boxcar, ...)")

    def to_settings(self) -> FilterSettings:
        return FilterSettings(**self.model_dump())  # the same keys, in Hz as they are


class SensorConfig(Model):
    quantum_arcsec: float = Field(0.1, ge=0, description="angle per count (0: none)")
    arw_dprh: Annotated[float, B.ARW_DPRH] = Field(0.0005, ge=0, description="angle random walk")
    dither_arcsec: float = Field(100.0, ge=0, description="dither peak in the sensed angle")
    dither_hz: float = Field(400.0, gt=0)

    def to_settings(self) -> SensorSettings:
        return SensorSettings(quantum=self.quantum_arcsec * u.ARCSEC,
                              arw=self.arw_dprh * u.DPSH,
                              dither_amplitude=self.dither_arcsec * u.ARCSEC,
                              dither_hz=self.dither_hz)


class TrackerConfig(Model):
    qc_rad2ps5: float = Field(1.0, gt=0, description="white-jerk intensity Qc, rad²/s⁵")
    r_std_arcsec: Annotated[float, B.ATTITUDE_SIGMA_ARCSEC] = Field(
        0.03, description="σ of the attitude observation, R = σ²")
    p0_theta_arcsec: Annotated[float, B.P0_ANGLE_ARCSEC] = 0.03
    p0_omega_dps: Annotated[float, B.P0_RATE_DPS] = 20.0
    p0_alpha_dps2: Annotated[float, B.P0_ANGULAR_ACCEL_DPS2] = 20.0

    def to_settings(self) -> TrackerSettings:
        return TrackerSettings(qc=self.qc_rad2ps5, r=(self.r_std_arcsec * u.ARCSEC) ** 2,
                               sigma0=(self.p0_theta_arcsec * u.ARCSEC,
                                       self.p0_omega_dps * u.DEG, self.p0_alpha_dps2 * u.DEG))


class PulsesConfig(Model):
    mode: Literal["solution", "async"] = "solution"
    rate_hz: float = Field(1000.0, gt=0)
    offset_us: float | None = Field(0.0, ge=0, description="null: random first edge (async)")
    jitter_us: float = Field(0.0, ge=0)
    drift_ppm: Annotated[float, B.CLOCK_DRIFT_PPM] = 0.0
    resolution_us: float = Field(0.0, ge=0, description="Δt counter resolution (0: exact)")

    @model_validator(mode="after")
    def _jitter(self):
        """In mode ``solution`` the pulses fall on solution instants: a jitter or a clock
        drift cannot matter there, and is refused by its key rather than dropped. In mode
        ``async`` the jitter (1σ) is bounded by a tenth of the pulse period: a larger one
        reorders the pulses (1e12 µs left no pulse in the run, an internal error)."""
        if self.mode == "solution":
            for key in ("jitter_us", "drift_ppm"):
                if getattr(self, key) != 0:
                    raise ValueError(f"{key}: mode 'solution' puts the pulses on solution "
                                     f"instants, so it cannot matter; remove it or use mode "
                                     f"async, got {getattr(self, key):g}")
        bound = 0.1e6 / self.rate_hz
        if not self.jitter_us <= bound:
            raise ValueError(f"jitter_us: must be at most a tenth of the pulse period "
                             f"({bound:g} µs at {self.rate_hz:g} Hz; a larger jitter reorders "
                             f"the pulses), got {self.jitter_us:g}")
        return self

    def check_offset(self, where: str, solution_hz: float) -> None:
        """Mode ``solution``: ``offset_us`` is the pulse's fixed distance after each solution
        instant, within one solution interval; ValueError naming `where`.offset_us in µs
        (the core's check names its own offset_s, in s)."""
        interval_us = 1e6 / solution_hz
        if self.mode == "solution" and (self.offset_us is None
                                        or not self.offset_us < interval_us):
            got = "null" if self.offset_us is None else f"{self.offset_us:g}"
            raise ValueError(f"{where}.offset_us: mode 'solution' puts each pulse this far "
                             f"after a solution instant: within [0, {interval_us:g}) µs at "
                             f"{solution_hz:g} Hz (null, a random first edge, is for mode "
                             f"async), got {got}")

    def to_settings(self) -> PulseSettings:
        return PulseSettings(mode=self.mode, rate_hz=self.rate_hz,
                             offset_s=_us(self.offset_us), jitter_s=self.jitter_us * 1e-6,
                             drift_ppm=self.drift_ppm, resolution_s=self.resolution_us * 1e-6)


class CaseConfig(Model):
    name: str = Field(min_length=1)
    attitude_deg: Vec3 = vector(description="[pitch, roll, yaw] at rest before t = 0")
    steps: list[RowModel] = Field(min_length=1)
    duration_s: float | None = Field(None, gt=0, description="default: the rows' total")
    pulses: PulsesConfig | None = None
    seed_before: str = ""
    seed_after: str = ""

    def to_case(self) -> Case:
        return case_of(self.name, self.steps, self.attitude_deg, self.duration_s,
                       None if self.pulses is None else self.pulses.to_settings(),
                       self.seed_before, self.seed_after)


def case_of(name: str, rows: list[RowModel], attitude_deg, duration_s: float | None,
            pulses: PulseSettings | None = None, seed_before: str = "",
            seed_after: str = "") -> Case:
    """A core :class:`Case` from validated rows (ValueError names the row)."""
    from gcalign.realtime.cases import Case

    a = np.radians(np.asarray(attitude_deg, dtype=float))
    return Case(name=name, steps=steps_of(rows), att0=(float(a[0]), float(a[1]), float(a[2])),
                duration_s=duration_s, pulses=pulses, seed_before=seed_before,
                seed_after=seed_after)


def _check_case(case: Case, settings: Settings, where: str, filter_where: str = "") -> None:
    """The core's checks of a case (its keys named under `where`) and of the filter for it
    (named after `filter_where`); ValueError."""
    from gcalign.realtime.cases import check_case, check_filter

    for check, prefix in ((check_case, f"{where}."), (check_filter, filter_where)):
        try:
            check(case, settings)
        except ValueError as err:
            raise ValueError(f"{prefix}{err}") from None


class RealtimeConfig(Model):
    """Real-time attitude at sync pulses (seed 003); see the module docstring."""

    semi_physical: bool = False
    solution_hz: float = Field(1000.0, gt=0)
    delay_ms: float | None = Field(None, ge=0, description="T used; null: the chain's delay")
    predictors: list[PredictorName] = Field(default_factory=lambda: list(DEFAULT_PREDICTORS),
                                            min_length=1)
    filter: FilterConfig = Field(default_factory=FilterConfig)
    sensor: SensorConfig = Field(default_factory=SensorConfig)
    tracker: TrackerConfig = Field(default_factory=TrackerConfig)
    pulses: PulsesConfig = Field(default_factory=PulsesConfig)
    settle_s: float = Field(1.0, ge=0)
    warmup_s: float = Field(0.2, ge=0)
    corner_ms: float = Field(50.0, ge=0)
    cases: list[CaseConfig] | None = Field(None, min_length=1, max_length=MAX_CASES)

    @model_validator(mode="after")
    def _consistent(self):
        if len(set(self.predictors)) != len(self.predictors):
            raise ValueError(f"predictors: each at most once, got {self.predictors}")
        if self.semi_physical and self.delay_ms is not None:
            raise ValueError(f"delay_ms: semi_physical: true fixes T at the seed's "
                             f"{SEED_DELAY_MS:g} ms; remove delay_ms or set semi_physical: "
                             f"false, got {self.delay_ms:g}")
        if self.semi_physical and "pulses" in self.model_fields_set:
            raise ValueError("pulses: semi_physical: true puts the pulses on every solution "
                             "instant (Δt = 0); remove realtime.pulses (a case may still "
                             "bring its own) or set semi_physical: false")
        self.pulses.check_offset("pulses", self.solution_hz)
        for i, c in enumerate(self.cases or ()):
            if c.pulses is not None:
                c.pulses.check_offset(f"cases.{i}.pulses", self.solution_hz)
        settings = self.to_settings()  # the core's checks, one line naming the setting
        for i, c in enumerate(self.cases or ()):
            _check_case(c.to_case(), settings, f"cases.{i}")
        return self

    def unused(self, sc=None) -> list[str]:
        """Keys of the chain that ``filter.chain`` does not run, one line (shown as a
        warning): the alignment FIR's with the navigation chain; the navigation FIR's and
        the notch with the alignment chain, which has none (an align_order of 1e6 beside
        the navigation chain was accepted in silence)."""
        f = self.filter
        other = (("align_order", "align_cutoff_hz") if f.chain == "navigation"
                 else ("nav_order", "nav_cutoff_hz", "notch_hz", "notch_q"))
        keys = [f"realtime.filter.{k}" for k in other if k in f.model_fields_set]
        return [f"{', '.join(keys)}: cannot matter with filter.chain {f.chain!r} (only its "
                f"own FIR{' and notch' if f.chain == 'navigation' else ''} run)"] if keys else []

    # ---------------------------------------------------------------- resolved values

    @property
    def reference(self) -> str:
        """What the reported errors are against: ``seed`` (the INS's output T later, the
        seed's semi-physical metric) or ``truth`` (the attitude at the pulse time)."""
        return "seed" if self.semi_physical else "truth"

    def to_settings(self) -> Settings:
        """The core's :class:`Settings` (SI); ValueError from its checks."""
        s = Settings(solution_hz=self.solution_hz, filter=self.filter.to_settings(),
                     sensor=self.sensor.to_settings(), pulses=self.pulses.to_settings(),
                     tracker=self.tracker.to_settings(),
                     delay_s=None if self.delay_ms is None else self.delay_ms * 1e-3,
                     settle_s=self.settle_s, warmup_s=self.warmup_s,
                     corner_s=self.corner_ms * 1e-3, predictors=tuple(self.predictors))
        if self.semi_physical:
            s = seed_semi_physical(s)
            assert s.delay_s == SEED_DELAY_MS * 1e-3
        return s

    def cases_of(self, sc) -> list[Case]:
        """The cases to run (runs :meth:`check`)."""
        self.check(sc)
        return self._cases(sc)

    def _cases(self, sc) -> list[Case]:
        if self.cases is not None:
            return [c.to_case() for c in self.cases]
        mo = sc.motion
        return [case_of(sc.name, mo.steps, mo.attitude_deg, mo.duration_s)]

    def check(self, sc) -> None:
        """Checks that need the rest of the scenario; ScenarioError naming the field."""
        if sc.site is None:
            raise ScenarioError("site: missing; the turntable's site sets the earth rate the "
                                "gyros sense (site: {lat_deg, lon_deg, height_m})")
        if sc.imu_file is not None:
            raise ScenarioError(f"imu_file: realtime simulates the turntable; recorded data is "
                                f"not supported, got {str(sc.imu_file)!r} (remove imu_file)")
        if sc.mechanism is not None:
            raise ScenarioError("mechanism: the realtime chain has its gyros fixed to the "
                                "body (remove mechanism)")
        mo = sc.motion
        if self.cases is not None and mo is not None:
            raise ScenarioError("realtime.cases: give the cases either as realtime.cases or "
                                "as one turntable motion (motion.kind: turntable), not both")
        if self.cases is None:
            if mo is None or mo.kind != "turntable":
                raise ScenarioError(
                    f"motion.kind: realtime needs turntable cases: realtime.cases, or a "
                    f"turntable motion; got {'no motion' if mo is None else repr(mo.kind)}")
            if mo.repeat:
                raise ScenarioError("motion.repeat: a realtime case runs its rows once; "
                                    "allowed: false, got true")
            case = case_of(sc.name, mo.steps, mo.attitude_deg, mo.duration_s)
            try:
                _check_case(case, self.to_settings(), "motion", "realtime.")
            except ValueError as err:
                raise ScenarioError(str(err)) from None
        imu = sc.imu
        if "rate_hz" in imu.model_fields_set and imu.rate_hz != self.filter.fs_hz:
            raise ScenarioError(f"imu.rate_hz: the realtime gyros are sampled at "
                                f"realtime.filter.fs_hz = {self.filter.fs_hz:g} Hz; omit "
                                f"imu.rate_hz or set it equal, got {imu.rate_hz:g}")
        for name, sensor in (("gyro", imu.gyro), ("accel", imu.accel)):
            for key, value in sensor.model_dump().items():  # a process (a mapping) is set
                if isinstance(value, dict) or (value is not None
                                               and np.any(np.asarray(value, dtype=float) != 0)):
                    raise ScenarioError(
                        f"imu.{name}.{key}: not used by realtime (its gyro model is "
                        f"realtime.sensor: quantum, ARW, dither); allowed: 0, got {value}")
        limits.MAX_REALTIME_SAMPLES.check(self.samples(sc), "realtime.cases",
                                          "shorten the cases")

    def samples(self, sc) -> int:
        """Sensor samples of all cases together (at the filter rate)."""
        return sum(round(c.duration * self.filter.fs_hz) for c in self._cases(sc))

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        """Rows for `gcalign validate` (runs the cross-section checks too)."""
        cases = self.cases_of(sc)
        s = self.to_settings()
        f = s.filter
        t_text = (f"{SEED_DELAY_MS:g} ms (the seed's, semi-physical)" if self.semi_physical
                  else f"{self.delay_ms:g} ms" if self.delay_ms is not None
                  else "the chain's low-frequency group delay")
        chain = (f"notch {f.notch_hz:g} Hz Q {f.notch_q:g} + " if f.notch_hz and
                 f.chain == "navigation" else "") + (
            f"FIR order {f.nav_order} at {f.nav_cutoff_hz:g} Hz" if f.chain == "navigation"
            else f"FIR order {f.align_order} at {f.align_cutoff_hz:g} Hz")
        rows = [
            ("realtime.semi_physical", str(self.semi_physical),
             f"errors against {'the INS T later' if self.semi_physical else 'the truth'}"),
            ("realtime.rates", f"{f.fs_hz:g} Hz sensor, {s.solution_hz:g} Hz solution",
             f"{s.samples_per_solution} sub-increments per update"),
            ("realtime.delay (T)", t_text, ""),
            ("realtime.filter", f"{f.chain}: {chain}", f"window {f.window}"),
            ("realtime.sensor", f"quantum {self.sensor.quantum_arcsec:g} ″, ARW "
             f"{self.sensor.arw_dprh:g} °/√h, dither {self.sensor.dither_arcsec:g} ″ @ "
             f"{self.sensor.dither_hz:g} Hz", f"ARW {s.sensor.arw:.4g} rad/√s"),
            ("realtime.tracker", f"Qc {s.tracker.qc:g} rad²/s⁵, R = "
             f"({self.tracker.r_std_arcsec:g} ″)²", f"R {s.tracker.r:.4g} rad²"),
            ("realtime.pulses", f"{s.pulses.mode}, {s.pulses.rate_hz:g} Hz", ""),
            ("realtime.predictors", ", ".join(s.predictors), ""),
        ]
        for i, c in enumerate(cases):
            rows.append((f"realtime.cases.{i}", f"{c.name}: {c.kind}, {c.duration:g} s"
                         + (f", pulses {c.pulses.mode} {c.pulses.rate_hz:g} Hz"
                            if c.pulses else ""),
                         f"{round(c.duration * f.fs_hz)} samples"))
        return rows
