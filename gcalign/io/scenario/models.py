"""Scenario models: site, IMU grade, motion of the base (YAML keys carry their units)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    Field,
    field_validator,
    model_serializer,
    model_validator,
)

from gcalign import units as u
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.align import AlignConfig
from gcalign.io.scenario.allan import AllanConfig
from gcalign.io.scenario.base import FILE_KEYS, Model, PerAxis, span, vector
from gcalign.io.scenario.calibrate import CalibrateConfig, ObservabilityConfig
from gcalign.io.scenario.modulate import ModulateConfig
from gcalign.io.scenario.motion import MotionModel
from gcalign.io.scenario.navigation import MechanismConfig, NavigationConfig, OutputConfig
from gcalign.io.scenario.northfind import NorthfindConfig
from gcalign.io.scenario.realtime import RealtimeConfig
from gcalign.io.scenario.recording import ImuLayout, Initial, ReferenceFile, split_imu_file
from gcalign.io.scenario.sensors import (
    AccelGaussMarkov,
    GyroGaussMarkov,
    Noise,
    ScaleGaussMarkov,
    gauss_markov_si,
    per_axis,
)
from gcalign.nav.earth import MODELS, EarthModel
from gcalign.sim.errors import ImuErrors, SensorErrors


def _misalignment(m) -> np.ndarray:
    return np.asarray(m, dtype=float) * u.ARCSEC


def _check_misalignment(m):
    if m is None:
        return m
    a = np.asarray(m, dtype=float)
    if a.shape != (3, 3):
        raise ValueError(f"must be a 3x3 matrix of arc-seconds, got shape {a.shape}")
    if np.any(np.diag(a) != 0):
        raise ValueError("the diagonal must be zero (scale errors go in scale_ppm)")
    return m


Misalignment = Annotated[list[list[float]] | None, AfterValidator(_check_misalignment)]


class Site(Model):
    lat_deg: float = Field(description="geodetic latitude, deg, within (-90, 90)")
    lon_deg: float = Field(ge=-180, le=360, description="longitude, deg")
    height_m: float = Field(0.0, ge=-1000, le=1e5, description="height above the ellipsoid, m")

    @field_validator("lat_deg")
    @classmethod
    def _not_a_pole(cls, v):
        if not -90 < v < 90:
            raise ValueError(f"must be within (-90, 90) deg (the ENU frame is undefined at "
                             f"the poles), got {v}")
        return v

    def to_si(self) -> np.ndarray:
        """``[lat (rad), lon (rad), h (m)]``."""
        return np.array([self.lat_deg * u.DEG, self.lon_deg * u.DEG, self.height_m])


def _span(v: list[float] | None) -> tuple[float, float] | None:
    return None if v is None else (float(v[0]), float(v[1]))


TauRange = Annotated[list[Annotated[float, B.CORRELATION_TIME_S]] | None, AfterValidator(span)]
INSTABILITY_TAU = ("τ range (s) over which the bias instability's Allan deviation is flat "
                   "(its Gauss–Markov sum, gcalign.sim.errors), from 10 samples on; default 1 s "
                   "(or 10 samples) to the run's duration")
_ASYM = "asymmetric scale factor: + for positive input, − negative"
_SCALE_GM = "a scale-factor error that wanders (added to scale_ppm)"
_RANDOM_WALK = "random walk, the bias's std after t hours is this · √t"
_INSTABILITY = ("the flat part of the Allan deviation / 0.664 (flicker noise, simulated as a "
                "sum of Gauss–Markov processes)")


class Gyro(Model):
    bias_dph: Annotated[PerAxis, B.GYRO_BIAS_DPH] = vector()
    arw_dprh: Annotated[Noise, B.ARW_DPRH] = vector()
    scale_ppm: Annotated[PerAxis, B.SCALE_PPM] = vector()
    misalignment_arcsec: Misalignment = None
    quantum_arcsec: float = Field(0.0, ge=0)
    asym_ppm: Annotated[PerAxis, B.SCALE_PPM] = vector(description=_ASYM)
    bias_gm: GyroGaussMarkov | None = Field(
        None, description="a bias that wanders: first-order Gauss–Markov (added to bias_dph)")
    bias_rw_dphrh: Annotated[Noise, B.GYRO_BIAS_RW_DPHRH] = vector(
        description=f"rate {_RANDOM_WALK}")
    scale_gm: ScaleGaussMarkov | None = Field(None, description=_SCALE_GM)
    bias_instability_dph: Annotated[Noise, B.GYRO_BIAS_DPH] = vector(
        description=f"bias instability B, °/h: {_INSTABILITY}")
    bias_instability_tau_s: TauRange = Field(None, description=INSTABILITY_TAU)

    def to_si(self) -> SensorErrors:
        return _sensor_si(self, u.DPH, u.DPSH, self.bias_dph, self.arw_dprh,
                          self.quantum_arcsec * u.ARCSEC, self.bias_rw_dphrh,
                          self.bias_instability_dph)


class Accel(Model):
    bias_ug: Annotated[PerAxis, B.ACCEL_BIAS_UG] = vector()
    vrw_ugrhz: Annotated[Noise, B.VRW_UGRHZ] = vector()
    scale_ppm: Annotated[PerAxis, B.SCALE_PPM] = vector()
    misalignment_arcsec: Misalignment = None
    quantum_ugs: float = Field(0.0, ge=0, description="velocity quantum, µg·s (PSINS header unit)")
    asym_ppm: Annotated[PerAxis, B.SCALE_PPM] = vector(description=_ASYM)
    bias_gm: AccelGaussMarkov | None = Field(
        None, description="a bias that wanders: first-order Gauss–Markov (added to bias_ug)")
    bias_rw_ughrh: Annotated[Noise, B.ACCEL_BIAS_RW_UGRH] = vector(
        description=f"acceleration {_RANDOM_WALK}")
    scale_gm: ScaleGaussMarkov | None = Field(None, description=_SCALE_GM)
    bias_instability_ug: Annotated[Noise, B.ACCEL_BIAS_UG] = vector(
        description=f"bias instability B, µg: {_INSTABILITY}")
    bias_instability_tau_s: TauRange = Field(None, description=INSTABILITY_TAU)

    def to_si(self) -> SensorErrors:
        return _sensor_si(self, u.UG, u.UGPSHZ, self.bias_ug, self.vrw_ugrhz,
                          self.quantum_ugs * u.UG, self.bias_rw_ughrh, self.bias_instability_ug)


def _sensor_si(sensor: Gyro | Accel, unit: float, noise_unit: float, bias, noise,
               quantum: float, bias_rw, instability) -> SensorErrors:
    """A triad's errors in SI: `bias`, its random walk `bias_rw` (per √h) and its
    `instability` in the sensor's `unit`, `noise` in `noise_unit`, `quantum` in SI."""
    bias_std, bias_tau = gauss_markov_si(sensor.bias_gm, unit)
    scale_std, scale_tau = gauss_markov_si(sensor.scale_gm, u.PPM)
    return SensorErrors(
        bias=per_axis(bias) * unit, noise=per_axis(noise) * noise_unit, quantum=quantum,
        scale=per_axis(sensor.scale_ppm) * u.PPM,
        misalignment=_misalignment(sensor.misalignment_arcsec or np.zeros((3, 3))),
        asym=per_axis(sensor.asym_ppm) * u.PPM,
        bias_gm_std=bias_std, bias_gm_tau=bias_tau,
        bias_rw=per_axis(bias_rw) * unit / math.sqrt(u.HOUR),
        scale_gm_std=scale_std, scale_gm_tau=scale_tau,
        instability=per_axis(instability) * unit,
        instability_tau=_span(sensor.bias_instability_tau_s),
    )


class Imu(Model):
    rate_hz: float = Field(100.0, gt=0, le=1e5)
    seed: int = Field(1, ge=0)
    gyro: Gyro = Field(default_factory=Gyro)
    accel: Accel = Field(default_factory=Accel)

    @property
    def ts(self) -> float:
        return 1.0 / self.rate_hz

    @model_validator(mode="after")
    def _instability_after_ten_samples(self):
        for name, sensor in (("gyro", self.gyro), ("accel", self.accel)):
            span = sensor.bias_instability_tau_s
            if span is not None and span[0] < 10.0 / self.rate_hz * (1 - 1e-9):
                raise ValueError(
                    f"{name}.bias_instability_tau_s: starts at {span[0]:g} s, under 10 samples "
                    f"at {self.rate_hz:g} Hz ({10.0 / self.rate_hz:g} s): faster than that the "
                    "Gauss–Markov sum is white noise, not a flat Allan deviation")
        return self

    def errors(self) -> ImuErrors:
        return ImuErrors(gyro=self.gyro.to_si(), accel=self.accel.to_si())


#: The commands that use the recorded-data keys ``reference`` and ``initial``.
#: (align and calibrate: the site when the file has none, and whether the base is at rest.)
USED_BY: dict[str, tuple[str, ...]] = {"reference": ("navigation", "align", "calibrate",
                                                     "allan"),
                                       "initial": ("navigation", "calibrate")}


class Scenario(Model):
    """A whole scenario file. Either `motion` (simulated data) or `imu_file` (recorded data)."""

    name: str = Field("scenario", min_length=1, pattern=r"^[A-Za-z0-9_.+-]+$")
    site: Site | None = None
    earth: Literal["wgs84", "seed004"] = "wgs84"
    imu: Imu = Field(default_factory=Imu)
    motion: MotionModel | None = None
    mechanism: MechanismConfig | None = None
    imu_file: Path | None = None
    imu_layout: ImuLayout | None = Field(None, exclude=True, description=(
        "written as imu_file: {path, format, axes, ...}; see gcalign.io.scenario.recording"))
    reference: ReferenceFile | None = None
    initial: Initial | None = None
    navigation: NavigationConfig | None = None
    output: OutputConfig = Field(default_factory=OutputConfig)
    align: AlignConfig | None = None
    northfind: NorthfindConfig | None = None
    calibrate: CalibrateConfig | None = None
    observability: ObservabilityConfig | None = None
    realtime: RealtimeConfig | None = None
    modulate: ModulateConfig | None = None
    allan: AllanConfig | None = None

    @property
    def earth_model(self) -> EarthModel:
        return MODELS[self.earth]

    @model_validator(mode="before")
    @classmethod
    def _imu_file_mapping(cls, data):
        """``imu_file: {path, format, ...}``: the path and its layout (the plain path keeps
        its meaning)."""
        return split_imu_file(data)

    @model_serializer(mode="wrap")
    def _imu_file_as_written(self, handler):
        """The layout goes back under ``imu_file`` as the scenario file writes it."""
        out = handler(self)
        if self.imu_layout is not None and isinstance(out, dict) and "imu_file" in out:
            layout = self.imu_layout.model_dump(mode="json", exclude_unset=True)
            out["imu_file"] = {"path": out["imu_file"], **layout}
        return out

    def resolve_paths(self, folder) -> None:
        """The relative file paths (:data:`~gcalign.io.scenario.base.FILE_KEYS`) taken
        from `folder` (the scenario file's)."""
        for key in FILE_KEYS:
            *head, last = key.split(".")
            parent: Any = self
            for k in head:
                parent = getattr(parent, k, None)
            node = getattr(parent, last, None)
            holder, name = (parent, last) if isinstance(node, Path) else (node, "path")
            path = getattr(holder, name, None)
            if path is not None and not path.is_absolute():
                setattr(holder, name, (Path(folder) / path).resolve())

    @property
    def reads_own_recording(self) -> bool:
        """Whether the run reads `imu_file` itself rather than through the generic reader
        (transfer alignment: slave and master from one MAT file, spec 006), so neither the
        extent check nor the results file's /recording record read it."""
        return self.align is not None and self.align.mode == "transfer"

    def recording_layout(self):
        """How to read `imu_file` (:class:`gcalign.io.recorded.Layout`); in transfer
        alignment the slave's MAT variable is ``align.transfer.imu_variable`` unless the
        layout names one."""
        from dataclasses import replace

        from gcalign.io.recorded import Layout

        layout = Layout() if self.imu_layout is None else self.imu_layout.to_layout()
        if self.reads_own_recording and self.align is not None \
                and self.align.transfer is not None and layout.variable is None:
            layout = replace(layout, variable=self.align.transfer.imu_variable)
        return layout

    @model_validator(mode="after")
    def _source(self):
        if self.motion is not None and self.imu_file is not None:
            raise ValueError("imu_file: give either 'motion' (simulated) or 'imu_file' (recorded)")
        if self.motion is not None and self.site is None:
            raise ValueError("site: missing; a simulated scenario needs a site")
        if self.motion is not None:
            n = self.motion.duration() * self.imu.rate_hz
            if not math.isfinite(n):  # e.g. a turn of 1e308 degrees
                raise ValueError(f"motion: a duration of {self.motion.duration():g} s at "
                                 f"{self.imu.rate_hz:g} Hz is not a number of samples")
            if round(n) < 2:
                raise ValueError(f"motion.duration_s: {self.motion.duration():g} s holds fewer "
                                 f"than 2 samples at {self.imu.rate_hz} Hz")
        if self.imu_file is None and (self.reference is not None or self.initial is not None):
            key = "reference" if self.reference is not None else "initial"
            raise ValueError(f"{key}: applies to recorded data (imu_file); a simulation has "
                             "its truth and its motion's initial state")
        if self.imu_layout is not None and self.imu_file is None:
            raise ValueError("imu_file.path: missing; a layout needs the file it describes")
        if self.mechanism is not None and self.imu_file is not None:
            raise ValueError("mechanism: recorded data carry their own sensor frame; a "
                             "mechanism applies to simulated motion only (remove it)")
        return self

    def unused(self, section: str | None = None) -> list[str]:
        """Keys set in the scenario that cannot matter to the run, one line each: the
        simulated IMU with recorded data, and what the command's `section` reports itself
        (its ``unused(sc)``). The commands show them as warnings (stderr, table, JSON)."""
        out = []
        model = getattr(self, section, None) if section else None  # a section of the file
        if self.imu_file is not None:
            keys = _set_keys(self.imu, "imu")
            if keys:
                out.append(f"{', '.join(keys)}: cannot matter with recorded data (imu_file): "
                           "the recording carries its own rate and sensor errors")
        for key in ("reference", "initial"):
            if getattr(self, key) is not None and model is not None and section not in USED_BY[key]:
                out.append(f"{key}: read and checked (gcalign validate shows it), but "
                           f"{section} does not use it yet")
        if self.initial is not None and self.initial.sigma is not None and section == "navigation":
            out.append("initial.sigma: cannot matter to navigate (no filter); it is the P0 "
                       "of calibrate")
        if model is not None and hasattr(model, "unused"):
            out += model.unused(self)
        return out


def _set_keys(model: Model, prefix: str) -> list[str]:
    """The dotted keys the scenario set explicitly below `model`."""
    out = []
    for name in model.model_fields_set:
        value = getattr(model, name)
        if isinstance(value, Model):
            out += _set_keys(value, f"{prefix}.{name}")
        else:
            out.append(f"{prefix}.{name}")
    return sorted(out)
