"""The `northfind` section of a scenario (seed 001; DESIGN.md "North-finding").

A multi-position strapdown gyro north-finder on an indexing turntable::

    name: seed001-simulation
    site: {lat_deg: 40, lon_deg: 116, height_m: 0}
    imu:
      rate_hz: 100
      seed: 1
      gyro:  {bias_dph: 0.02, arw_dprh: 0.0026}
      accel: {bias_ug: 20, vrw_ugrhz: 155}
    northfind:
      positions: 24              # n >= 3 equally spaced table positions per turn
      dwell_s: 60                # dwell per position (> 0)
      azimuth_deg: 48.0          # true azimuth of the reference axis, clockwise from north
      # sweep: {start_deg: 0, stop_deg: 355, step_deg: 5}   # instead of azimuth_deg
      tilt_deg: 10               # angle between the table normal and the vertical, [0, 90)
      tilt_direction_deg: 0      # azimuth toward which the table surface descends
      tilt_reference: table      # north: ζ is a true azimuth; table: ζ from the reference axis
      # pitch_deg / roll_deg     # instead of tilt_deg / tilt_direction_deg (implies table)
      methods: [coordinate, vector, naive, none]  # or vector_literal (eq. 10 as printed)
      repeats: 1                 # independent determinations per azimuth (seed Table 1: 7)
      index_error_arcsec: 0      # 1σ table indexing error (truth only)
      samples: false             # true: simulate every sample, not the exact dwell means

Rules
-----
* Exactly one of ``azimuth_deg`` and ``sweep``. A sweep runs from ``start_deg`` to
  ``stop_deg`` *inclusive* in steps of ``step_deg > 0``, except that a stop equal to
  ``start_deg + 360`` is excluded (it is the start again): ``{0, 360, 30}`` gives 12 azimuths,
  ``{0, 355, 5}`` 72. A stop below the start is an empty sweep (an error).
* ``site`` is required; ``|site.lat_deg| < 90`` (north is undefined at the poles).
  ``site.height_m`` sets gravity; ``imu.rate_hz`` the sampling rate; ``imu.seed`` (or
  ``--seed``) the random stream.
* IMU errors — one rule: the table frame is the IMU body frame at table position 1
  (x right, y = the north-finder's reference axis, z = table normal). The single in-plane
  gyro is the **body-y gyro**: ``imu.gyro.bias_dph[1]``, ``arw_dprh[1]``, ``scale_ppm[1]``.
  The two accelerometers are **body x and y**: ``imu.accel.bias_ug[0:2]`` and
  ``vrw_ugrhz`` (x and y must be equal; the simulator has one density for both). The
  z-axis values are unused. A constant bias cancels (it is the R of seed eq. 4); the
  scatter of the azimuth comes from the white noise, whose dwell mean has the standard
  deviation ``arw/√dwell`` (gyro) and ``vrw/√dwell`` (accelerometers). Terms the
  north-finder model does not have (misalignment, quantisation, accelerometer scale,
  asymmetry, bias instability, random walks and Gauss–Markov processes, :data:`UNMODELLED`)
  must be zero or absent: a non-zero value is an error rather than silently ignored.

Converted once to :class:`gcalign.northfind.NorthfindSetup` (SI, radians) by
:meth:`NorthfindConfig.to_setup`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import BaseModel, Field, field_validator, model_validator

from gcalign import limits
from gcalign import units as u
from gcalign.errors import ScenarioError
from gcalign.io.scenario.base import Model
from gcalign.io.scenario.sensors import per_axis

if TYPE_CHECKING:  # the capability loads when a north-finding is set up, not at start-up
    from gcalign.northfind import NorthfindSetup

MethodName = Literal["coordinate", "vector", "naive", "none", "vector_literal"]
DEFAULT_METHODS: list[MethodName] = ["coordinate", "vector", "naive", "none"]
MAX_AZIMUTHS = 100_000
_TOL = 1e-9


#: the IMU keys the north-finder's sensor model has no place for (it simulates one in-plane
#: gyro and two accelerometers with bias, scale factor and white noise): refused unless zero
UNMODELLED = tuple(f"{s}.{k}" for s, keys in (
    ("gyro", ("misalignment_arcsec", "quantum_arcsec", "asym_ppm", "bias_gm", "bias_rw_dphrh",
              "scale_gm", "bias_instability_dph")),
    ("accel", ("misalignment_arcsec", "scale_ppm", "quantum_ugs", "asym_ppm", "bias_gm",
               "bias_rw_ughrh", "scale_gm", "bias_instability_ug"))) for k in keys)


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def axis(value, i: int) -> float:
    """Component `i` of an IMU per-axis value (a scalar default stands for all three axes)."""
    return float(per_axis(value)[i])


class Sweep(Model):
    """True azimuths ``start_deg, start_deg + step_deg, …`` up to ``stop_deg`` (see module)."""

    start_deg: float = 0.0
    stop_deg: float = 360.0
    step_deg: float = Field(gt=0, le=360)

    @model_validator(mode="after")
    def _not_empty(self):
        if self.stop_deg < self.start_deg:
            raise ValueError(f"stop_deg: empty sweep, stop_deg {_fmt(self.stop_deg)} is below "
                             f"start_deg {_fmt(self.start_deg)}; allowed: stop_deg >= start_deg")
        if self._count() > MAX_AZIMUTHS:
            raise ValueError(f"step_deg: the sweep would hold {self._count()} azimuths, at most "
                             f"{MAX_AZIMUTHS} allowed; got step_deg {_fmt(self.step_deg)}")
        return self

    def _count(self) -> int:
        return int(np.floor((self.stop_deg - self.start_deg) / self.step_deg + _TOL)) + 1

    def azimuths_deg(self) -> np.ndarray:
        """The swept azimuths (deg), shape (M,), M >= 1."""
        count = self._count()
        az = self.start_deg + self.step_deg * np.arange(count)
        full_turn = abs(self.stop_deg - self.start_deg - 360.0) < _TOL
        if full_turn and count > 1 and abs(az[-1] - self.stop_deg) < 1e-6:
            az = az[:-1]  # stop = start + 360 is the start again
        return az

    def label(self) -> str:
        return f"{_fmt(self.start_deg)}:{_fmt(self.stop_deg)}:{_fmt(self.step_deg)}"


class NorthfindConfig(Model):
    """Multi-position north-finding (seed 001); see the module docstring for the rules."""

    positions: int = Field(24, ge=3, le=100_000, description="table positions per turn")
    dwell_s: float = Field(60.0, gt=0, le=1e6, description="dwell, s")
    azimuth_deg: float | None = Field(None, description="true azimuth of the reference axis, deg")
    sweep: Sweep | None = None
    tilt_deg: float | None = Field(None, description="table normal from the vertical, deg; "
                                   "default 0")
    tilt_direction_deg: float | None = Field(None, description="azimuth of descent, deg; "
                                             "default 0")
    tilt_reference: Literal["north", "table"] | None = Field(
        None, description="north (fixed to the earth, default) or table (fixed to the table)")
    pitch_deg: float | None = Field(None, gt=-90, lt=90, description="PSINS pitch of the table")
    roll_deg: float | None = Field(None, gt=-90, lt=90, description="PSINS roll of the table")
    methods: list[MethodName] = Field(default_factory=lambda: list(DEFAULT_METHODS), min_length=1)
    repeats: int = Field(1, ge=1, le=1_000_000, description="independent determinations")
    index_error_arcsec: float = Field(0.0, ge=0)
    samples: bool = False

    @field_validator("tilt_deg")
    @classmethod
    def _tilt_range(cls, v):
        if v is not None and not 0.0 <= v < 90.0:
            raise ValueError(f"the angle between the table normal and the vertical must "
                             f"satisfy 0 <= tilt_deg < 90, got {_fmt(v)}")
        return v

    @field_validator("methods")
    @classmethod
    def _unique(cls, v):
        dup = sorted({m for m in v if v.count(m) > 1})
        if dup:
            raise ValueError(f"each method at most once, got {dup[0]!r} twice")
        return v

    @model_validator(mode="after")
    def _choices(self):
        if self.azimuth_deg is None and self.sweep is None:
            raise ValueError("azimuth_deg: missing; give the true azimuth (azimuth_deg) or a "
                             "sweep ({start_deg, stop_deg, step_deg})")
        if self.azimuth_deg is not None and self.sweep is not None:
            raise ValueError(f"sweep: give either azimuth_deg or sweep, not both (got "
                             f"azimuth_deg {_fmt(self.azimuth_deg)} and sweep "
                             f"{self.sweep.label()})")
        attitude = self.pitch_deg is not None or self.roll_deg is not None
        if attitude and (self.tilt_deg is not None or self.tilt_direction_deg is not None):
            raise ValueError("pitch_deg: give the tilt either as tilt_deg/tilt_direction_deg or "
                             "as pitch_deg/roll_deg, not both")
        if attitude and self.tilt_reference == "north":
            raise ValueError("tilt_reference: pitch_deg/roll_deg describe the table itself (tilt "
                             "fixed to the table); allowed: 'table' or omit it, got 'north'")
        return self

    # ---------------------------------------------------------------- resolved values

    @property
    def reference(self) -> str:
        """Effective tilt reference: 'table' with pitch/roll, else as given (default north)."""
        if self.pitch_deg is not None or self.roll_deg is not None:
            return "table"
        return self.tilt_reference or "north"

    def tilt_rad(self) -> tuple[float, float]:
        """``(tilt ε, tilt direction ζ)`` in rad; ζ relative to `reference`."""
        if self.pitch_deg is not None or self.roll_deg is not None:
            from gcalign.northfind import tilt_from_pitch_roll

            eps, zeta = tilt_from_pitch_roll((self.pitch_deg or 0.0) * u.DEG,
                                             (self.roll_deg or 0.0) * u.DEG)
            return float(eps), float(zeta)
        return (self.tilt_deg or 0.0) * u.DEG, (self.tilt_direction_deg or 0.0) * u.DEG

    def azimuths_deg(self) -> np.ndarray:
        """True azimuths (deg), shape (M,)."""
        if self.sweep is not None:
            return self.sweep.azimuths_deg()
        assert self.azimuth_deg is not None  # the model validator requires one of the two
        return np.array([float(self.azimuth_deg)])

    def check(self, sc) -> None:
        """Checks that need the rest of the scenario; ScenarioError naming the field."""
        if sc.site is None:
            raise ScenarioError("site: missing; north-finding needs the site latitude "
                                "(site: {lat_deg, lon_deg, height_m})")
        if sc.imu_file is not None:  # (the site's latitude is within (-90, 90): Site)
            raise ScenarioError(f"imu_file: northfind simulates the turntable; recorded data is "
                                f"not supported, got {str(sc.imu_file)!r} (remove imu_file)")
        n = round(self.dwell_s * sc.imu.rate_hz)
        readings = self.azimuths_deg().size * self.repeats * self.positions
        limits.MAX_NORTHFIND_READINGS.check(
            readings, "northfind.repeats", f"azimuths × repeats × positions, repeats "
            f"{self.repeats}")
        if self.samples:
            limits.MAX_NORTHFIND_SAMPLES.check(
                readings * n, "northfind.samples", "use samples: false (exact dwell means, "
                "statistically identical)")
        if n < 1:
            raise ScenarioError(f"northfind.dwell_s: {_fmt(self.dwell_s)} s holds no sample at "
                                f"imu.rate_hz {_fmt(sc.imu.rate_hz)} Hz; allowed: dwell_s >= "
                                "1/rate_hz")
        vrw = per_axis(sc.imu.accel.vrw_ugrhz).tolist()
        if vrw[0] != vrw[1]:
            raise ScenarioError(f"imu.accel.vrw_ugrhz: the north-finder's x and y accelerometers "
                                f"share one noise density; x and y must be equal, got {vrw}")
        for key in UNMODELLED:
            sensor, name = key.split(".")
            value = getattr(getattr(sc.imu, sensor), name)
            used = per_axis(value)[:2] if name == "scale_ppm" else value  # x and y only
            process = isinstance(value, BaseModel)  # a Gauss-Markov process is set
            if process or (used is not None and np.any(np.asarray(used, float) != 0)):
                raise ScenarioError(f"imu.{key}: not modelled by the north-finder (one in-plane "
                                    "gyro, two accelerometers with bias and white noise); "
                                    f"allowed: {'none' if process else 0}, got "
                                    f"{value.model_dump() if process else value}")

    def to_setup(self, sc) -> NorthfindSetup:
        """The SI setup for :func:`gcalign.northfind.run_northfind` (runs :meth:`check`)."""
        from gcalign.northfind import NorthfindSetup

        self.check(sc)
        g, a = sc.imu.gyro, sc.imu.accel
        tilt, direction = self.tilt_rad()
        try:
            return NorthfindSetup(
                azimuths=self.azimuths_deg() * u.DEG, lat=sc.site.lat_deg * u.DEG,
                positions=self.positions, dwell_s=self.dwell_s, rate_hz=sc.imu.rate_hz,
                tilt=tilt, tilt_direction=direction, tilt_direction_ref=self.reference,
                repeats=self.repeats, height=sc.site.height_m,
                gyro_bias=axis(g.bias_dph, 1) * u.DPH,  # the in-plane gyro is body y
                gyro_arw=axis(g.arw_dprh, 1) * u.DPSH, gyro_scale=axis(g.scale_ppm, 1) * u.PPM,
                accel_bias=np.array([axis(a.bias_ug, 0), axis(a.bias_ug, 1)]) * u.UG,  # x, y
                accel_vrw=axis(a.vrw_ugrhz, 0) * u.UGPSHZ,
                index_error=self.index_error_arcsec * u.ARCSEC)
        except ValueError as err:  # a combination the checks above did not foresee
            raise ScenarioError(f"northfind: {err}") from None

    def resolved_rows(self, sc) -> list[tuple[str, str, str]]:
        """Rows for `gcalign validate` (runs the cross-section checks too)."""
        setup = self.to_setup(sc)
        az = self.azimuths_deg()
        az_text = (f"sweep {self.sweep.label()} °: {az.size} azimuths" if self.sweep is not None
                   else f"{_fmt(az[0])} °")
        tilt, direction = self.tilt_rad()
        dwell_sigma = setup.gyro_arw / np.sqrt(setup.n_samples / setup.rate_hz)
        accel_sigma = setup.accel_vrw / np.sqrt(setup.n_samples / setup.rate_hz)
        return [
            ("northfind.positions", str(self.positions),
             f"θ_i = (i-1)·{_fmt(360.0 / self.positions)} °"),
            ("northfind.dwell_s", f"{_fmt(self.dwell_s)} s", f"{setup.n_samples} samples"),
            ("northfind.azimuth", az_text, f"{az.size} × {self.repeats} determinations"),
            ("northfind.tilt", f"{_fmt(np.degrees(tilt))} ° toward {_fmt(np.degrees(direction))} °"
             f" ({self.reference})", f"{_fmt(tilt)} rad, {_fmt(direction)} rad"),
            ("northfind.methods", ", ".join(self.methods), ""),
            ("northfind.gyro (body y)",
             f"bias {_fmt(axis(sc.imu.gyro.bias_dph, 1))} °/h, "
             f"ARW {_fmt(axis(sc.imu.gyro.arw_dprh, 1))} °/√h",
             f"dwell-mean σ {_fmt(dwell_sigma / u.DPH)} °/h"),
            ("northfind.accel (body x, y)",
             f"bias {_fmt(axis(sc.imu.accel.bias_ug, 0))}, "
             f"{_fmt(axis(sc.imu.accel.bias_ug, 1))} µg, "
             f"VRW {_fmt(axis(sc.imu.accel.vrw_ugrhz, 0))} µg/√Hz",
             f"dwell-mean σ {_fmt(accel_sigma / u.UG)} µg"),
            ("northfind.index_error_arcsec", f"{_fmt(self.index_error_arcsec)} ″",
             f"{_fmt(setup.index_error)} rad"),
            ("northfind.samples", "every sample" if self.samples else "exact dwell means", ""),
        ]
