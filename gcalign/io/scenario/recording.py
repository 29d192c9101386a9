"""The ``imu_file`` key: a recording's path, or its path with its layout (spec 005).

``imu_file: data.imu`` keeps meaning what it always has (the format from the suffix, the
format's own axes and units). The long form names what the file does not say itself::

    imu_file:
      path: ride.txt
      format: csv                      # psins | psins-mat | i2nav | csv | auto
      axes: FRD                        # the file's x, y, z (gcalign.io.recorded.axes)
      columns: [t, gx, gy, gz, ax, ay, az]
      units: {gyro: deg/s, accel: m/s^2}
      time: end                        # each stamp marks the end (or begin) of its interval
      rate_hz: 200                     # default: the median time step
      max_gap_s: 0.05                  # gaps up to this long are filled, longer refused
      variable: mimu                   # psins-mat: the array to read

The scenario model keeps the path in ``Scenario.imu_file`` (a ``Path``, as before) and
the rest in ``Scenario.imu_layout``; it writes them back as one ``imu_file`` mapping.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationError, field_validator, model_validator

from gcalign.errors import ScenarioError
from gcalign.io.recorded.axes import rotation_to_rfu
from gcalign.io.recorded.imu import ACCEL_UNITS, FORMAT_NAMES, GYRO_UNITS, Layout
from gcalign.io.recorded.reference import REFERENCE_FORMATS
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import FILE_KEYS, Model, Pos3, Vec3, one_of, vector


class Units(Model):
    gyro: str | None = Field(None, description=f"one of {', '.join(GYRO_UNITS)}")
    accel: str | None = Field(None, description=f"one of {', '.join(ACCEL_UNITS)}")


class ImuLayout(Model):
    """Everything of ``imu_file`` but its path (see the module docstring)."""

    format: Annotated[str, one_of(FORMAT_NAMES, "format")] = "auto"
    axes: str | list[list[float]] | None = None
    columns: list[str] | None = None
    units: Units | None = None
    quantity: Literal["increments", "rates"] | None = None
    time: Literal["end", "begin"] | None = None
    variable: str | None = None
    rate_hz: float | None = Field(None, gt=0, le=1e5)
    max_gap_s: float = Field(0.0, ge=0, le=3600)
    check_gravity: bool = True
    check_consistency: bool = Field(
        True, description="refuse a recording that contradicts itself: gyros against the "
        "accelerometers and the earth rate, the forward axis against a velocity (wrong units "
        "or axes)")

    @field_validator("axes")
    @classmethod
    def _a_rotation(cls, v):
        if v is not None:
            try:
                rotation_to_rfu(v)
            except ScenarioError as err:
                raise ValueError(str(err).removeprefix("axes: ")) from None
        return v

    def to_layout(self) -> Layout:
        return Layout(
            format=self.format,
            axes=self.axes if isinstance(self.axes, str) or self.axes is None
            else tuple(tuple(r) for r in self.axes),
            columns=None if self.columns is None else tuple(self.columns),
            gyro_units=None if self.units is None else self.units.gyro,
            accel_units=None if self.units is None else self.units.accel,
            quantity=self.quantity, time=self.time, variable=self.variable,
            rate_hz=self.rate_hz, max_gap_s=self.max_gap_s, check_gravity=self.check_gravity,
            check_consistency=self.check_consistency)


class ReferenceFile(Model):
    """``reference: {path, format, variable, columns}``: a reference solution (a master
    INS, a post-processed trajectory; :mod:`gcalign.io.recorded.reference`)."""

    path: Path
    format: Annotated[str, one_of(REFERENCE_FORMATS, "reference format")] = "psins-mat"
    variable: str | None = None
    columns: list[str] | None = None
    max_gap_s: float | None = Field(None, gt=0, description="epochs further apart are a gap: "
                                    "no error is reported inside it; default twice the "
                                    "file's median interval")
    check_attitude: bool = Field(True, description="refuse an attitude that turns 57.3 times "
                                 "too little or too much against the gyros (radians read as "
                                 "degrees, or degrees as radians)")

    @model_validator(mode="after")
    def _keys_of_the_format(self):
        from gcalign.io.recorded.reference import check_keys

        try:
            check_keys(self.format, self.variable, self.columns, "reference")
        except ScenarioError as err:
            raise ValueError(str(err).removeprefix("reference.")) from None
        return self

    def read(self):
        from gcalign.io.recorded.reference import read_reference

        return read_reference(self.path, self.format, self.variable, self.columns)


class InitialSigma(Model):
    """``initial.sigma``: how well the initial state is known (1σ); the filter's P0 for the
    attitude, velocity and position (KF-GINS ``initattstd``, ``initvelstd``, ``initposstd``)."""

    phi_enu_deg: Pos3 | None = Field(
        None, description="misalignment σ: φ east, north (the tilts) and up (the heading), deg")
    v_enu_mps: Pos3 | None = Field(
        None, description="velocity σ east, north, up, m/s")
    pos_enu_m: Pos3 | None = Field(
        None, description="position σ east, north, up, m")


class Initial(Model):
    """``initial: {att_deg, v_enu_mps, lat_deg, lon_deg, height_m, sigma}``: the state a run
    on recorded data starts from (navigate, calibrate) when the file gives none, or to
    replace what it gives; the position keys go together."""

    att_deg: Vec3 = Field(description="[pitch, roll, yaw], deg (ENU, yaw CCW positive); "
                          "pitch within (-90, 90), roll and yaw within [-360, 360]")
    v_enu_mps: Annotated[Vec3, B.VELOCITY_MPS] = vector()
    lat_deg: float | None = Field(None, gt=-90, lt=90, description="start latitude, deg")
    lon_deg: float | None = Field(None, ge=-180, le=360, description="start longitude, deg")
    height_m: float | None = Field(None, ge=-1000, le=1e5, description="start height, m")
    sigma: InitialSigma | None = Field(None, description="1σ of the state: the filter's P0")

    @field_validator("att_deg")
    @classmethod
    def _euler_range(cls, v):
        """Pitch 100° is no Euler angle of ours (C_nb = Rz Rx Ry: pitch within ±90°); it
        was accepted and the navigation diverged."""
        if not -90.0 < v[0] < 90.0:
            raise ValueError(f"pitch must be within (-90, 90) deg, got {v[0]:g}")
        big = [x for x in v[1:] if not abs(x) <= 360.0]
        if big:
            raise ValueError(f"roll and yaw must be within [-360, 360] deg, got {big[0]:g}")
        return v

    @model_validator(mode="after")
    def _position_together(self):
        missing = [k for k in ("lat_deg", "lon_deg", "height_m") if getattr(self, k) is None]
        if 0 < len(missing) < 3:
            raise ValueError(f"{', '.join(missing)}: missing; the start position takes "
                             "lat_deg, lon_deg and height_m together")
        return self

    def position(self) -> np.ndarray | None:
        """``[L (rad), λ (rad), h (m)]``, or None without the position keys."""
        if self.lat_deg is None or self.lon_deg is None or self.height_m is None:
            return None
        return np.array([np.radians(self.lat_deg), np.radians(self.lon_deg), self.height_m])


def split_imu_file(data: Any) -> Any:
    """A scenario mapping whose ``imu_file`` is a mapping, as ``imu_file`` (its path) and
    ``imu_layout`` (the rest, validated); ValueError ``imu_file.KEY: ...`` otherwise."""
    if not isinstance(data, dict) or not isinstance(data.get("imu_file"), dict):
        return data
    spec = dict(data["imu_file"])
    if "path" not in spec:
        raise ValueError("imu_file.path: missing; imu_file takes a path, or a mapping "
                         "{path, format, axes, ...}")
    path = spec.pop("path")
    try:
        layout = ImuLayout.model_validate(spec)
    except ValidationError as err:
        e = err.errors()[0]
        loc = ".".join(str(x) for x in e["loc"] if not str(x).startswith(("list[", "str")))
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            msg = ("unknown key; imu_file takes path, " + ", ".join(ImuLayout.model_fields))
        raise ValueError(f"imu_file.{loc}: {msg}") from None
    return {**data, "imu_file": path, "imu_layout": layout}


def with_layout(imu_file: Any, layout: dict) -> dict:
    """A scenario's ``imu_file`` (a path or a mapping) with the keys of `layout` set
    (``--format``, ``--axes``); ScenarioError when there is no recording to describe."""
    if imu_file is None:
        options = ", ".join(f"--{k}" for k in layout)
        raise ScenarioError(f"{options}: describe a recording; give --imu-file FILE (or "
                            "imu_file in the scenario)")
    spec = dict(imu_file) if isinstance(imu_file, dict) else {"path": imu_file}
    spec.update(layout)
    return spec


#: What ``--imu-file X`` alone (no scenario file) runs with: no simulated aiding, the
#: inertial-frame coarse alignment over the file's first minute (it holds on a swaying or
#: disturbed base, where the static one does not), then one gyrocompass pass to 300 s with
#: the loop settings that align lasergyro.imu to -90.58° (DESIGN, "Gyrocompass").
RECORDED_DEFAULTS: dict[str, dict] = {
    "align": {"coarse": {"method": "inertial"}, "mode": "conventional", "t1_s": 60,
              "t2_s": 300, "t3_s": 300, "stages": [{"t_xy_s": 20, "t_z_s": 100, "xi": 0.707}]},
    # a recording alone is taken as parked: zero-velocity updates after an inertial-frame
    # coarse alignment (a driving one is warned about, with the evidence)
    "calibrate": {"aiding": "zero-velocity", "coarse": {"method": "inertial", "duration_s": 60},
                  "measure": "velocity", "gnss_noise": False},
}


def recorded_scenario(section: str, imu_file) -> dict:
    """The scenario of a recording given alone: named after the file (``ride.txt.xz`` ->
    ``ride``), with the recorded-data defaults of `section` (:data:`RECORDED_DEFAULTS`;
    a command without them gets its section's own defaults)."""
    import re
    from pathlib import Path

    stem = re.sub(r"[^A-Za-z0-9_.+-]", "_", Path(str(imu_file)).name.split(".")[0]) or "data"
    data: dict = {"name": stem}
    if section in RECORDED_DEFAULTS:
        data[section] = dict(RECORDED_DEFAULTS[section])
    return data


def absolute_paths(data: Any, folder) -> None:
    """In a scenario mapping (before validation), the relative paths of :data:`FILE_KEYS`
    made absolute from `folder`, in place (batch workers may run elsewhere)."""
    replace_paths(data, lambda p: str(p if p.is_absolute() else (Path(folder) / p).resolve()))


def replace_paths(data: Any, new: Callable[[Path], str]) -> None:
    """In a scenario mapping (before validation), each path of :data:`FILE_KEYS` replaced
    by ``new(path)``, in place."""
    for key in FILE_KEYS:
        *head, last = key.split(".")
        parent = data
        for k in head:
            parent = parent.get(k) if isinstance(parent, dict) else None
        node = parent.get(last) if isinstance(parent, dict) else None
        holder, field = (parent, last) if isinstance(node, str) and last != "aiding" else (
            node, "path")
        if isinstance(holder, dict) and isinstance(holder.get(field), str):
            holder[field] = new(Path(holder[field]))
