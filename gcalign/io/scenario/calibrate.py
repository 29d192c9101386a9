"""The `calibrate` and `observability` sections of a scenario (seed 002; spec 002 §2, §4).

::

    calibrate:
      measure: velocity          # velocity | position | both (seed eqs. 5-7)
      sigma_v_mps: 0.2           # DGNSS velocity σ (R = σ², seed §5.2)
      sigma_p_m: 1.0             # DGNSS position σ, metres north and east
      p0_scale: 10               # P0 = (p0_scale · listed σ)², the seed's "×10"
      # p0: {attitude_arcsec: [20, 20, 1800], velocity_enu_mps: 0.2, ...}  # the listed σ
      q: {arw_dprh: 0.001, vrw_ugrhz: 10}   # the filter's white-noise densities (Q), and
                                 # the sensor states' processes (random constants without):
                                 # gyro_bias_gm: {std_dph, tau_s}, gyro_bias_rw_dphrh,
                                 # gyro_scale_gm: {std_ppm, tau_s}, accel_bias_gm: {std_ug,
                                 # tau_s}, accel_bias_rw_ughrh, accel_scale_gm (the imu keys)
      navigation_rate_hz: 25     # the IMU rate / a whole n (n increments per step)
      filter_rate_hz: 1          # navigation rate / a whole number
      feedback: true             # closed loop; false: feed-forward (linearised KF)
      discretization: accumulated   # or van_loan (on the mean F of the filter step)
      smoother: false            # also run the RTS smoother (post-flight)
      truth: scenario            # scenario: imu biases/scale factors + initial_error;
                                 # draw: all 21 errors drawn from P0 with the run's seed
      initial_error: {attitude_arcsec: [20, -20, 1800]}  # φ ENU; velocity_enu_mps, position_enu_m
      gnss_noise: true           # add DGNSS noise of σ to the simulated measurements
      aiding: auto               # dgnss (simulated truth) | zero-velocity (a parked vehicle)
                                 # | file (recorded: files: {velocity: {path, format,
                                 #   lever_arm_m}, position: {path, format, lever_arm_m}})
      components: auto           # horizontal (the seed's eqs. 5-7) | 3d (with the vertical);
                                 # auto: 3d for files, horizontal otherwise
      max_gap_s: null            # fixes further apart are an outage (listed, drawn); default
                                 # twice the file's median interval
      output_rate_hz: null       # the solution stored at this rate; default every navigation
                                 # step
      coarse: {method: none}     # none (start from truth + initial_error; on recorded data
                                 # from initial:, the reference or the file's header)
                                 # | analytic | inertial
      start_s: 0                 # data time at which the calibration (or coarse) window opens
      # duration_s: 400          # default: to the end of the data
      conventional_segments: 6   # --compare: the conventional take-off = the first n segments

    observability:
      measure: velocity          # the seed's Table 1 is velocity matching
      scaling: p0                # p0 (columns × initial σ, the default) | none (the paper)
      piece_s: 1                 # PWCS piece length
      rank_rtol: 1.0e-12         # singular values ≤ rank_rtol · σ_max count as zero
      null_tol: 1.0e-9           # the null-space condition of seed eq. (12) holds below this
      covariance: true           # also the covariance degree σ(0)/σ(t) (PSINS kfstat)

User units in the keys (″, m/s, m, °/h, µg, ppm, °/√h, µg/√Hz); :meth:`CalibrateConfig.settings`
converts them once to the SI :class:`gcalign.calibrate.Settings`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from gcalign import units as u
from gcalign.errors import ScenarioError
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model, NonNeg3, PerAxis, Pos3, Vec3, vector
from gcalign.io.scenario.sensors import (
    AccelGaussMarkov,
    GyroGaussMarkov,
    ScaleGaussMarkov,
    gauss_markov_si,
)
from gcalign.nav.earth import EarthModel


def _enu_m_to_si(enu, lat: float, h: float, earth: EarthModel) -> np.ndarray:
    """Metres [east, north, up] -> the states [δL, δλ, δh] (rad, rad, m) at lat, h."""
    r_m, r_n = earth.radii(lat)
    e, n, up = (float(v) for v in enu)
    return np.array([n / (r_m + h), e / ((r_n + h) * np.cos(lat)), up])


class P0Sigma(Model):
    """The listed initial σ before ``p0_scale`` (default: the seed's §5.2 list)."""

    attitude_arcsec: Annotated[Pos3, B.P0_ATTITUDE_ARCSEC] = vector(
        (20.0, 20.0, 1800.0), description="φ [E, N, U]; the seed's 20″, 20″, 30′")
    velocity_enu_mps: Annotated[Pos3, B.P0_VELOCITY_MPS] = vector(0.2)
    position_enu_m: Annotated[Pos3, B.P0_POSITION_M] = vector(1.0)
    gyro_bias_dph: Annotated[Pos3, B.P0_GYRO_BIAS_DPH] = vector(0.01)
    accel_bias_ug: Annotated[Pos3, B.P0_ACCEL_BIAS_UG] = vector(50.0)
    gyro_scale_ppm: Annotated[Pos3, B.P0_SCALE_PPM] = vector(100.0)
    accel_scale_ppm: Annotated[Pos3, B.P0_SCALE_PPM] = vector(100.0)

    def to_si(self, lat: float, h: float, earth: EarthModel) -> np.ndarray:
        """(21,) SI σ in the state order."""
        return np.concatenate([
            np.asarray(self.attitude_arcsec) * u.ARCSEC, np.asarray(self.velocity_enu_mps),
            _enu_m_to_si(self.position_enu_m, lat, h, earth),
            np.asarray(self.gyro_bias_dph) * u.DPH, np.asarray(self.accel_bias_ug) * u.UG,
            np.asarray(self.gyro_scale_ppm) * u.PPM, np.asarray(self.accel_scale_ppm) * u.PPM])


class ProcessNoise(Model):
    """The filter's Q: white-noise densities (spec 002 §2 [X]: the seed lost its Q) and the
    sensor states' processes, in the keys of the ``imu`` section (KF-GINS's ``imunoise``:
    arw, vrw, gbstd, abstd, gsstd, asstd, corrtime). A sensor state without a process is a
    random constant (the seed)."""

    arw_dprh: Annotated[float, B.ARW_DPRH] = Field(
        0.001, ge=0, description="gyro angle random walk")
    vrw_ugrhz: Annotated[float, B.VRW_UGRHZ] = Field(
        10.0, ge=0, description="accelerometer velocity random walk")
    gyro_bias_gm: GyroGaussMarkov | None = Field(
        None, description="gyro biases as first-order Gauss–Markov processes")
    gyro_bias_rw_dphrh: Annotated[NonNeg3, B.GYRO_BIAS_RW_DPHRH] | None = Field(
        None, description="gyro biases as random walks (rate random walk, °/h/√h)")
    accel_bias_gm: AccelGaussMarkov | None = Field(
        None, description="accelerometer biases as first-order Gauss–Markov processes")
    accel_bias_rw_ughrh: Annotated[NonNeg3, B.ACCEL_BIAS_RW_UGRH] | None = Field(
        None, description="accelerometer biases as random walks (µg/√h)")
    gyro_scale_gm: ScaleGaussMarkov | None = Field(
        None, description="gyro scale factors as first-order Gauss–Markov processes")
    accel_scale_gm: ScaleGaussMarkov | None = Field(
        None, description="accelerometer scale factors as first-order Gauss–Markov processes")

    @model_validator(mode="after")
    def _one_process_per_state(self):
        for what, rw in (("gyro", self.gyro_bias_rw_dphrh), ("accel", self.accel_bias_rw_ughrh)):
            if getattr(self, f"{what}_bias_gm") is not None and rw is not None:
                raise ValueError(f"{what}_bias_gm: a bias is one process; give "
                                 f"{what}_bias_gm or the random walk, not both")
        return self

    def processes(self):
        """The SI :class:`gcalign.estimation.ins_error.SensorProcesses` of the 12 sensor
        states, or None when every one is a random constant."""
        from gcalign.estimation.ins_error import SensorProcesses

        groups = [(self.gyro_bias_gm, u.DPH, self.gyro_bias_rw_dphrh, u.DPH / math.sqrt(u.HOUR)),
                  (self.accel_bias_gm, u.UG, self.accel_bias_rw_ughrh, u.UG / math.sqrt(u.HOUR)),
                  (self.gyro_scale_gm, u.PPM, None, 0.0), (self.accel_scale_gm, u.PPM, None, 0.0)]
        if all(gm is None and rw is None for gm, _, rw, _ in groups):
            return None
        kinds: list[str] = []
        std, tau, dens = [], [], []
        for gm, unit, rw, rw_unit in groups:  # one process per state (the validator)
            kinds += ["gauss-markov" if gm is not None else "constant" if rw is None
                      else "random-walk"] * 3
            gm_std, gm_tau = gauss_markov_si(gm, unit)  # zeros and inf without a process
            std += gm_std.tolist()
            tau += gm_tau.tolist()
            dens += [0.0] * 3 if rw is None else [float(x) * rw_unit for x in rw]
        return SensorProcesses.of(kinds, std, tau, dens)


class InitialError(Model):
    """The INS's initial errors in a simulation with ``truth: scenario`` (spec 002 §2 [X])."""

    attitude_arcsec: PerAxis = vector((20.0, -20.0, 1800.0), description="misalignment φ [E, N, U]")
    velocity_enu_mps: PerAxis = vector()
    position_enu_m: PerAxis = vector()

    def to_si(self, lat: float, h: float, earth: EarthModel) -> np.ndarray:
        """(9,) SI: [φ, δv, δL, δλ, δh]."""
        return np.concatenate([np.asarray(self.attitude_arcsec) * u.ARCSEC,
                               np.asarray(self.velocity_enu_mps, float),
                               _enu_m_to_si(self.position_enu_m, lat, h, earth)])


class Coarse(Model):
    method: Literal["none", "analytic", "inertial"] = Field(
        "none", description="none: start from the truth plus initial_error (simulation)")
    duration_s: float = Field(60.0, gt=0, description="coarse window at the start")


LeverArm = Annotated[Vec3, B.LEVER_ARM_M]
_LEVER_HELP = ("the point the file measures (a GNSS antenna, a reference INS) from the IMU, "
               "body axes x right, y forward, z up, m; the filter applies it")
_INTERVAL_HELP = ("use only the epochs at whole multiples of this many seconds (a 10 Hz "
                  "solution as 1 Hz fixes); default every epoch")


class _AidingFile(Model):
    """The keys of a velocity and a position file (their formats differ)."""

    path: Path
    format: str
    columns: list[str] | None = None
    variable: str | None = None
    lever_arm_m: LeverArm = vector(description=_LEVER_HELP)
    interval_s: float | None = Field(None, gt=0, description=_INTERVAL_HELP)


class VelocityFile(_AidingFile):
    """A measured velocity: a velocity CSV (ENU/NED) or a reference solution's velocity."""

    format: Literal["velocity-enu", "velocity-ned", "psins-mat", "i2nav-nav",
                    "reference-csv"]


class PositionFile(_AidingFile):
    """Measured positions: GNSS fixes (KF-GINS text, RTKLIB .pos, CSV) or a reference
    solution's positions (the formats of a velocity file's reference). R is each fix's own
    σ where the file states them (KF-GINS σN σE σD, RTKLIB sdn sde sdu, declared CSV
    columns), else ``calibrate.sigma_p_m``."""

    format: Literal["i2nav-gnss", "rtklib-pos", "csv", "psins-mat", "i2nav-nav",
                    "reference-csv"] = "i2nav-gnss"


class AidingFiles(Model):
    """``calibrate.files`` (``aiding: file``): what the filter measures on recorded data."""

    velocity: VelocityFile | None = None
    position: PositionFile | None = None


def _divided(key: str, what: str, rate: float, sub: float, ks: range, whole: bool = True) -> int:
    """The whole number `rate` / `sub`; else ScenarioError naming ``calibrate.key``, with
    the rates `rate` / k for k in `ks` (with `whole`, those that are whole numbers) as
    examples."""
    k = rate / sub
    if round(k) >= 1 and abs(k - round(k)) <= 1e-9 * k:
        return int(round(k))
    ok = [f"{rate / j:g}" for j in ks if not whole or (rate / j).is_integer()][:6]
    raise ScenarioError(f"calibrate.{key}: must be the {what} rate {rate:g} Hz divided by a "
                        f"whole number (e.g. {', '.join(ok)} Hz), got {sub:g}")


class CalibrateConfig(Model):
    measure: Literal["velocity", "position", "both"] = "velocity"
    sigma_v_mps: Annotated[float, B.SIGMA_V_MPS] = Field(0.2,
                                                        description="DGNSS velocity σ; R = σ²")
    sigma_p_m: Annotated[float, B.SIGMA_P_M] = Field(
        1.0, description="DGNSS position σ (north, east); R = σ²")
    p0_scale: Annotated[float, B.P0_SCALE] = Field(10.0, description="P0 = (p0_scale · listed σ)²")
    p0: P0Sigma = Field(default_factory=P0Sigma)
    q: ProcessNoise = Field(default_factory=ProcessNoise)
    navigation_rate_hz: float | None = Field(None, gt=0, description="default: the IMU rate")
    filter_rate_hz: float = Field(1.0, gt=0)
    feedback: bool = True
    discretization: Literal["accumulated", "van_loan"] = "accumulated"
    smoother: bool = False
    truth: Literal["scenario", "draw"] = "scenario"
    initial_error: InitialError = Field(default_factory=InitialError)
    gnss_noise: bool | None = Field(None, description="add simulated DGNSS noise of σ to "
                                    "the reference; default: on for simulations, off for "
                                    "recordings")
    aiding: Literal["auto", "dgnss", "zero-velocity", "file"] = "auto"
    files: AidingFiles | None = Field(None, description="aiding file: the measured velocity "
                                      "and/or position files")
    components: Literal["auto", "horizontal", "3d"] = Field(
        "auto", description="horizontal (the seed's eqs. 5-7) or 3d (with the vertical "
        "velocity and height); auto: 3d for files, horizontal otherwise")
    max_gap_s: float | None = Field(None, gt=0, description="fixes further apart are an "
                                    "outage; default twice the file's median interval")
    output_rate_hz: float | None = Field(None, gt=0, description="the rate the solution is "
                                         "stored at; default every navigation step")
    coarse: Coarse = Field(default_factory=Coarse)
    start_s: float = Field(0.0, ge=0)
    duration_s: float | None = Field(None, gt=0)
    conventional_segments: int = Field(6, ge=1)

    # ------------------------------------------------------------------ rates

    def subsamples(self, imu_rate: float) -> int:
        """IMU increments per navigation step; ScenarioError naming the field."""
        return _divided("navigation_rate_hz", "IMU", imu_rate,
                        self.navigation_rate_hz or imu_rate, range(1, 6), whole=False)

    def steps_per_update(self, imu_rate: float) -> int:
        """Navigation steps per filter step; ScenarioError naming the field."""
        nav = imu_rate / self.subsamples(imu_rate)
        return _divided("filter_rate_hz", "navigation", nav, self.filter_rate_hz,
                        range(1, int(nav) + 1))

    # ------------------------------------------------------------------ checks

    def recorded(self, sc) -> bool:
        return sc.imu_file is not None

    def aiding_for(self, sc) -> str:
        if self.aiding != "auto":
            return self.aiding
        return "zero-velocity" if self.recorded(sc) else "dgnss"

    def check(self, sc) -> None:
        """Checks that need the rest of the scenario; ScenarioError naming the field."""
        if self.files is None and self.max_gap_s is not None:
            raise ScenarioError("calibrate.max_gap_s: finds the outages of aiding files "
                                "(aiding: file); this run has none (remove it)")
        if (self.aiding == "file") != (self.files is not None):
            raise ScenarioError("calibrate.files: goes with aiding 'file' (and it needs them); "
                                f"got aiding {self.aiding!r}"
                                + ("" if self.files is not None else " without files"))
        if self.aiding == "file":
            need = ["velocity", "position"] if self.measure == "both" else [self.measure]
            assert self.files is not None
            for key in need:
                if getattr(self.files, key) is None:
                    raise ScenarioError(f"calibrate.files.{key}: missing; measure "
                                        f"{self.measure!r} needs it")
            for key in ("velocity", "position"):
                if key not in need and getattr(self.files, key) is not None:
                    raise ScenarioError(f"calibrate.files.{key}: cannot matter with measure "
                                        f"{self.measure!r}; remove it or measure both")
            if not self.recorded(sc):
                raise ScenarioError("calibrate.aiding: 'file' measures recorded data "
                                    "(imu_file); a simulation takes 'dgnss'")
            if self.gnss_noise:
                raise ScenarioError("calibrate.gnss_noise: adds simulated noise to measured "
                                    "files; remove it (or set it false) with aiding 'file'")
        if self.recorded(sc):
            if self.aiding == "dgnss":
                raise ScenarioError("calibrate.aiding: 'dgnss' compares with the simulated "
                                    "truth; recorded data support 'zero-velocity' or 'file' "
                                    "(or auto)")
            if self.coarse.method != "none" and (sc.initial is not None
                                                 or sc.reference is not None):
                key = "initial" if sc.initial is not None else "reference"
                raise ScenarioError(f"calibrate.coarse.method: {self.coarse.method!r} cannot "
                                    f"matter: the start comes from {key}; remove one (a coarse "
                                    "alignment needs a vehicle parked at the start)")

            if self.truth == "draw":
                raise ScenarioError("calibrate.truth: 'draw' injects errors into simulated "
                                    "data; recorded data carry their own (use scenario)")
            return
        if sc.motion is None:
            raise ScenarioError("motion: missing; calibrate needs 'motion' or 'imu_file'")
        rate = sc.imu.rate_hz
        self.steps_per_update(rate)
        duration = sc.motion.duration()
        self.window(duration, 1.0 / rate)

    def window(self, duration: float, ts: float) -> tuple[float, float, float]:
        """``(start, coarse end, end)`` of the calibration window in data time (s);
        ScenarioError when it does not fit the data (`duration` s)."""
        start = self.start_s
        coarse = self.coarse.duration_s if self.coarse.method != "none" else 0.0
        end = duration if self.duration_s is None else start + self.duration_s
        if end > duration + 1e-9:
            raise ScenarioError(f"calibrate.duration_s: the window ends at {end:g} s, after the "
                                f"end of the data ({duration:g} s)")
        if start + coarse >= end - ts:
            field = "coarse.duration_s" if coarse else "start_s"
            raise ScenarioError(f"calibrate.{field}: nothing left to calibrate: the window is "
                                f"[{start:g}, {end:g}] s and the coarse alignment takes "
                                f"{coarse:g} s of it")
        return start, start + coarse, end

    # ------------------------------------------------------------------ SI

    def components_for(self, sc) -> str:
        """``horizontal`` or ``3d``: auto is 3d for files (a receiver measures height),
        the seed's horizontal form otherwise."""
        if self.components != "auto":
            return self.components
        return "3d" if self.aiding_for(sc) == "file" else "horizontal"

    def settings(self, site_si, earth: EarthModel, measure: str | None = None, sc=None):
        """The SI :class:`gcalign.calibrate.Settings` at the site ``[lat, lon, h]``; with the
        scenario `sc`, its measurement components and the P0 of ``initial.sigma`` (the
        navigation states' σ as given, not scaled by p0_scale)."""
        from gcalign.calibrate import Settings

        lat, h = float(site_si[0]), float(site_si[2])
        sigma = self.p0.to_si(lat, h, earth)
        given = None if sc is None or sc.initial is None else sc.initial.sigma
        if given is not None:
            k = self.p0_scale  # P0 = (p0_scale σ)²: the given σ enter divided by it
            if given.phi_enu_deg is not None:
                sigma[0:3] = np.asarray(given.phi_enu_deg) * u.DEG / k
            if given.v_enu_mps is not None:
                sigma[3:6] = np.asarray(given.v_enu_mps, float) / k
            if given.pos_enu_m is not None:
                sigma[6:9] = _enu_m_to_si(given.pos_enu_m, lat, h, earth) / k
        return Settings(
            measure=measure or self.measure, sigma_v=self.sigma_v_mps, sigma_p=self.sigma_p_m,
            p0_scale=self.p0_scale, p0_sigma=tuple(sigma),
            arw=self.q.arw_dprh * u.DPSH, vrw=self.q.vrw_ugrhz * u.UGPSHZ,
            filter_rate=self.filter_rate_hz, discretization=self.discretization,
            feedback=self.feedback, smoother=self.smoother,
            gnss_noise=self.gnss_noise if self.gnss_noise is not None
            else (sc is None or not self.recorded(sc)),
            components="horizontal" if sc is None else self.components_for(sc),
            processes=self.q.processes())

    def output_stride(self, nav_rate: float) -> int:
        """Navigation steps per stored row of the solution; ScenarioError naming the field."""
        if self.output_rate_hz is None:
            return 1
        return _divided("output_rate_hz", "navigation", nav_rate, self.output_rate_hz,
                        range(1, 11))

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        rows = [
            ("calibrate.measure", self.measure,
             f"R = diag({self.sigma_v_mps:g} m/s, {self.sigma_p_m:g} m)²"),
            ("calibrate.p0_scale", f"{self.p0_scale:g}", "P0 = (p0_scale · listed σ)²"),
            ("calibrate.q", f"ARW {self.q.arw_dprh:g} °/√h, VRW {self.q.vrw_ugrhz:g} µg/√Hz",
             f"{self.q.arw_dprh * u.DPSH:.6g} rad/√s, {self.q.vrw_ugrhz * u.UGPSHZ:.6g} m/s/√s"),
            ("calibrate.truth", self.truth, "imu biases, scale factors + initial_error"
             if self.truth == "scenario" else "all 21 errors ~ N(0, P0), the run's seed"),
            ("calibrate.aiding", self.aiding_for(sc), "" if self.files is None else "; ".join(
                f"{k} {f.path.name} ({f.format})" for k, f in (
                    ("velocity", self.files.velocity), ("position", self.files.position))
                if f is not None)),
            ("calibrate.feedback", str(self.feedback), "closed loop" if self.feedback
             else "feed-forward"),
            ("calibrate.discretization", self.discretization, ""),
            ("calibrate.smoother", str(self.smoother), ""),
            ("calibrate.components", self.components_for(sc), "horizontal: the seed's eqs. "
             "5-7; 3d: with the vertical velocity and height"),
        ]
        procs = [k for k in ProcessNoise.model_fields if k not in ("arw_dprh", "vrw_ugrhz")
                 and getattr(self.q, k) is not None]
        rows.append(("calibrate.q processes", ", ".join(procs) or "none",
                     "the other sensor states are random constants"))
        if self.files is not None:
            rows.append(("calibrate.max_gap_s", "twice the file's median interval"
                         if self.max_gap_s is None else f"{self.max_gap_s:g} s",
                         "fixes further apart are an outage"))
        if not self.recorded(sc):
            rate = sc.imu.rate_hz
            n = self.subsamples(rate)
            rows += [("calibrate.navigation_rate_hz", f"{rate / n:g} Hz",
                      f"{n} IMU increment(s) per step"),
                     ("calibrate.filter_rate_hz", f"{self.filter_rate_hz:g} Hz",
                      f"{self.steps_per_update(rate)} navigation steps per update")]
        return rows


class ObservabilityConfig(Model):
    """``observability``: the PWCS/SVD table of a flight's manoeuvres (seed 002), or of a
    transfer-alignment run (``align.mode: transfer``, spec 006: its matching is
    ``align.transfer.matching``, its rows windows of ``window_s``)."""

    measure: Literal["velocity", "position", "both"] = "velocity"
    scaling: Literal["none", "p0"] = "p0"  # docs/decisions/013
    piece_s: float = Field(1.0, gt=0)
    window_s: float = Field(10.0, gt=0, description="transfer alignment: the table's windows")
    rank_rtol: float = Field(1e-12, gt=0, lt=1)
    null_tol: float = Field(1e-9, gt=0)
    covariance: bool = True

    def check(self, sc) -> None:
        if _transfer(sc):
            return  # the run's inputs: the align command's transfer check
        if sc.motion is None:
            raise ScenarioError("motion: missing; the observability table needs a simulated "
                                "motion (its truth), or a transfer-alignment scenario "
                                "(align.mode: transfer)")
        if sc.calibrate is not None:
            sc.calibrate.check(sc)

    def unused(self, sc) -> list[str]:
        """Keys that cannot matter, one line each (shown as warnings)."""
        fields = self.model_fields_set
        if not _transfer(sc):
            return (["observability.window_s: cannot matter for a flight (its rows are the "
                     "motion's segments); it cuts a transfer-alignment run"]
                    if "window_s" in fields else [])
        out = []
        if "measure" in fields:
            out.append("observability.measure: cannot matter in transfer alignment (the "
                       "matching is align.transfer.matching: --matching)")
        if "covariance" in fields:
            out.append("observability.covariance: cannot matter in transfer alignment (the "
                       "filter's run gives the table its F, so its covariance comes with it)")
        return out

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        transfer = _transfer(sc)
        rows = [("observability.measure", sc.align.transfer.matching,
                 "align.transfer.matching") if transfer else
                ("observability.measure", self.measure, ""),
                ("observability.scaling", self.scaling, "unscaled states (the paper)"
                 if self.scaling == "none" else "columns × initial σ"),
                ("observability.piece_s", f"{self.piece_s:g} s", "")]
        if transfer:
            rows.append(("observability.window_s", f"{self.window_s:g} s", "the table's windows"))
        return rows + [("observability.rank_rtol", f"{self.rank_rtol:g}", "")]


def _transfer(sc) -> bool:
    return sc.align is not None and sc.align.mode == "transfer"
