"""Aiding files: GNSS positions with their σ, velocities, odometer speed (spec 005).

==================  =======================================================================
format              layout
==================  =======================================================================
``i2nav-gnss``      text (KF-GINS ``GNSS-RTK.txt``): GNSS seconds of week, lat, lon (deg),
                    h (m), σ north, east, down (m)
``rtklib-pos``      RTKLIB ``.pos``: ``%`` header whose last line names the columns; time
                    as ``week sow`` or ``yyyy/mm/dd hh:mm:ss.sss`` (GPST or UTC), latitude,
                    longitude (deg), height (m), Q, ns, sdn, sde, sdu (m), ...
``csv``             declared ``columns`` (default ``t lat lon h sn se sd``), lat/lon in deg
``velocity csv``    ``t`` and the velocity, ``frame`` ENU (``t ve vn vu``) or NED
                    (``t vn ve vd``), m/s
``odometer csv``    ``t speed`` (m/s) along a body axis (default forward)
==================  =======================================================================

Every reader returns arrays in SI and ENU (position ``[lat (rad), lon (rad), h (m)]``, σ as
``[east, north, up]``) plus a record of what it read (format, first and last epoch, σ, time
origin, lever arm). :func:`overlap` picks the epochs inside an IMU run and refuses a file
with none, naming both spans. A GNSS antenna's lever arm (body RFU, m) is recorded with the
fixes; applying it is the filter's work.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from datetime import datetime, timezone

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.gaps import default_max_gap
from gcalign.io.imu_files import ImuFileError, _finite, _increasing, read_bytes, text_of
from gcalign.io.recorded.axes import _DIRECTIONS
from gcalign.io.recorded.rows import _columns, _read_columns
from gcalign.units import DEG

__all__ = ["PositionFixes", "Velocities", "read_gnss", "read_velocity", "read_odometer",
           "overlap", "GNSS_FORMATS", "VELOCITY_FORMATS", "read_velocity_aiding",
           "velocity_at"]

GNSS_FORMATS = ("i2nav-gnss", "rtklib-pos", "csv")
#: Velocity aiding files: a velocity CSV (ENU or NED), an odometer's speed, or the velocity
#: of a reference solution (:mod:`gcalign.io.recorded.reference`; ``reference-csv`` is its
#: ``csv``).
VELOCITY_FORMATS = ("velocity-enu", "velocity-ned", "odometer", "psins-mat", "i2nav-nav",
                    "reference-csv")
_GNSS_COLUMNS = ("t", "lat", "lon", "h", "sn", "se", "sd")
_WEEK_S = 604800.0
_GPS_EPOCH = datetime(1980, 1, 6, tzinfo=timezone.utc)


@dataclass(frozen=True)
class PositionFixes:
    """GNSS positions: t (N,) s; pos (N, 3) [lat rad, lon rad, h m]; sigma_enu (N, 3) m;
    lever_arm_b (3,) antenna in body RFU, m; record: what was read."""

    t: np.ndarray
    pos: np.ndarray
    sigma_enu: np.ndarray
    lever_arm_b: np.ndarray = field(default_factory=lambda: np.zeros(3))
    record: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Velocities:
    """Velocity aiding: t (N,) s; v_n (N, 3) ENU m/s, or for an odometer the speed along
    ``axis_b`` (RFU unit vector) in ``speed`` (N,); record: what was read."""

    t: np.ndarray
    v_n: np.ndarray | None = None
    speed: np.ndarray | None = None
    axis_b: np.ndarray | None = None
    record: dict = field(default_factory=dict)


def read_gnss(path, format: str = "i2nav-gnss", columns=None, lever_arm_b=(0.0, 0.0, 0.0)
              ) -> PositionFixes:
    """GNSS positions with σ from `path` in `format` (:data:`GNSS_FORMATS`; module
    docstring); ScenarioError naming the file, row and what is allowed."""
    name = os.fspath(path)
    if format not in GNSS_FORMATS:
        raise ScenarioError(f"aiding.format: {format!r} is not a GNSS format; allowed: "
                            f"{', '.join(GNSS_FORMATS)}")
    lever = np.asarray(lever_arm_b, dtype=float)
    if lever.shape != (3,) or not np.isfinite(lever).all() or np.abs(lever).max() > 100:
        raise ScenarioError(f"aiding.lever_arm_m: must be 3 finite numbers (body x right, y "
                            f"forward, z up; m, within 100), got {lever.tolist()}")
    data = read_bytes(name, text=True)[1]
    if format == "rtklib-pos":
        t, lat, lon, h, s_enu, origin = _rtklib(name, data)
    else:
        cols = _GNSS_COLUMNS if format == "i2nav-gnss" else _columns(columns, _GNSS_COLUMNS)
        c, where = _read_columns(name, data, cols, _GNSS_COLUMNS)
        t, lat, lon, h = c["t"], c["lat"], c["lon"], c["h"]
        s_enu = np.column_stack([c["se"], c["sn"], c["sd"]])
        origin = "GNSS seconds of week" if format == "i2nav-gnss" else "the file's time column"
        _ranges(name, lat, lon, s_enu, where)
    pos = np.column_stack([lat * DEG, lon * DEG, h])
    record = {"format": format, "path": name, "epochs": int(len(t)),
              **{end: {"t_s": float(t[k]), "lat_deg": float(lat[k]), "lon_deg": float(lon[k]),
                       "h_m": float(h[k]), "sigma_enu_m": s_enu[k].tolist()}
                 for end, k in (("first", 0), ("last", -1))},
              "sigma_enu_median_m": np.median(s_enu, axis=0).tolist(),
              "time_origin": origin, "lever_arm_b_m": lever.tolist()}
    return PositionFixes(t, pos, s_enu, lever, record)


def _ranges(name, lat, lon, sigma, where) -> None:
    for label, a, lo, hi in (("latitude, deg", lat, -90, 90), ("longitude, deg", lon, -180,
                                                                   360)):
        bad = (a < lo) | (a > hi)
        if bad.any():
            k = int(np.argmax(bad))
            raise ImuFileError(f"{name}{where(k)}: {label} must lie in [{lo}, {hi}], got "
                               f"{float(a[k])!r}")
    bad = (sigma <= 0).any(1)
    if bad.any():
        k = int(np.argmax(bad))
        raise ImuFileError(f"{name}{where(k)}: σ must be > 0 m, got {sigma[k].tolist()}")


def _rtklib(name: str, data: bytes):
    """RTKLIB .pos: the last ``%`` line before the data names the columns."""
    lines = text_of(name, data).splitlines()
    header = [ln for ln in lines if ln.startswith("%")]
    body = [(i + 1, ln.split()) for i, ln in enumerate(lines) if ln.strip()
            and not ln.startswith("%")]
    if not header or not body:
        raise ImuFileError(f"{name}: not an RTKLIB .pos file (a '%' header naming the columns, "
                           "then the solutions)")
    names = header[-1].lstrip("%").split()
    if not names or names[0] not in ("GPST", "UTC", "JST") or "latitude(deg)" not in names:
        raise ImuFileError(f"{name}: RTKLIB header {header[-1].strip()!r}: need time (GPST or "
                           "UTC) and latitude(deg)/longitude(deg)/height(m) columns (set the "
                           "output to lat/lon/height in degrees, not d'm\"s or xyz)")
    system = names[0]
    date_time = "/" in body[0][1][0]
    shift = 1  # time takes two fields either way: "week sow" or "date time"
    idx = {n: i + shift for i, n in enumerate(names)}
    need = ["latitude(deg)", "longitude(deg)", "height(m)", "sdn(m)", "sde(m)", "sdu(m)"]
    missing = [n for n in need if n not in idx]
    if missing:
        raise ImuFileError(f"{name}: RTKLIB header lacks {', '.join(missing)}")
    t = np.empty(len(body))
    values = np.empty((len(body), 6))
    for k, (lineno, parts) in enumerate(body):
        try:
            if date_time:
                when = datetime.strptime(f"{parts[0]} {parts[1]}", "%Y/%m/%d %H:%M:%S.%f")
                seconds = (when.replace(tzinfo=timezone.utc) - _GPS_EPOCH).total_seconds()
                t[k] = seconds % _WEEK_S
            else:
                t[k] = float(parts[1])
            values[k] = [float(parts[idx[n]]) for n in need]
        except (ValueError, IndexError):
            raise ImuFileError(f"{name}:{lineno}: expected {system} time and "
                               f"{', '.join(need)}, got {' '.join(parts)[:80]!r}") from None
    where = lambda k: f":{body[k][0]}"  # noqa: E731
    _finite(name, values, need, where)
    _increasing(name, t, where, got="")
    lat, lon, h = values[:, 0], values[:, 1], values[:, 2]
    s_enu = values[:, [4, 3, 5]]
    _ranges(name, lat, lon, s_enu, where)
    origin = f"{system} seconds of week" + ("" if system == "GPST" else
                                            " (not GPST: leap seconds not applied)")
    return t, lat, lon, h, s_enu, origin


def read_velocity(path, frame: str = "ENU", columns=None) -> Velocities:
    """Velocities from a CSV/text file: ``t ve vn vu`` (ENU) or ``t vn ve vd`` (NED), m/s,
    or the names of `columns`; ENU out."""
    name = os.fspath(path)
    frame = frame.upper()
    if frame not in ("ENU", "NED"):
        raise ScenarioError(f"aiding.frame: {frame!r}; allowed: ENU, NED")
    default = ("t", "ve", "vn", "vu") if frame == "ENU" else ("t", "vn", "ve", "vd")
    cols = _columns(columns, default)
    c = _read_columns(name, read_bytes(name, text=True)[1], cols, default)[0]
    v = (np.column_stack([c["ve"], c["vn"], c["vu"]]) if frame == "ENU"
         else np.column_stack([c["ve"], c["vn"], -c["vd"]]))
    return Velocities(c["t"], v_n=v, record={"format": f"velocity csv ({frame})", "path": name,
                                             "epochs": int(len(v)), "t_first_s": float(c["t"][0]),
                                             "t_last_s": float(c["t"][-1])})


def read_odometer(path, axis: str = "F", columns=None) -> Velocities:
    """Odometer speed ``t speed`` (m/s) along a body `axis` (one letter of
    :mod:`~gcalign.io.recorded.axes`: F forward by default)."""
    name = os.fspath(path)
    letter = str(axis).strip().upper()
    if letter not in "FBRLUD" or len(letter) != 1:
        raise ScenarioError(f"aiding.axis: {axis!r}; allowed: one of F, B, R, L, U, D")
    i, sign = _DIRECTIONS[letter]
    axis_b = np.zeros(3)
    axis_b[i] = sign
    cols = _columns(columns, ("t", "speed"))
    c = _read_columns(name, read_bytes(name, text=True)[1], cols, ("t", "speed"))[0]
    t = c["t"]
    return Velocities(t, speed=c["speed"], axis_b=axis_b,
                      record={"format": "odometer csv", "path": name, "axis": letter,
                              "epochs": int(len(t)), "t_first_s": float(t[0]),
                              "t_last_s": float(t[-1])})


def overlap(t_aid: np.ndarray, t_imu: np.ndarray, name: str, what: str = "aiding"
            ) -> np.ndarray:
    """Boolean mask of the aiding epochs inside the IMU run ``[t_imu[0] - T, t_imu[-1]]``;
    ScenarioError naming both spans when none is."""
    t_aid, t_imu = np.asarray(t_aid, float), np.asarray(t_imu, float)
    ts = float(np.median(np.diff(t_imu))) if len(t_imu) > 1 else 0.0
    start, end = float(t_imu[0]) - ts, float(t_imu[-1])
    inside = (t_aid >= start) & (t_aid <= end)
    if not inside.any():
        raise ScenarioError(
            f"{what}: {name} covers {t_aid[0]:.3f} .. {t_aid[-1]:.3f} s and the IMU "
            f"{start:.3f} .. {end:.3f} s: no common time; both must count the same seconds "
            "(GNSS seconds of week, or seconds of the recording)")
    return inside


def read_velocity_aiding(path, format: str, columns=None, variable: str | None = None,
                         axis: str = "F") -> Velocities:
    """Velocity aiding from `path` in one of :data:`VELOCITY_FORMATS`: ENU m/s in ``v_n``,
    or an odometer's speed along ``axis_b``."""
    from gcalign.io.recorded.reference import check_keys

    check_keys(format, variable, columns, "aiding")
    if format == "velocity-enu" or format == "velocity-ned":
        return read_velocity(path, format.removeprefix("velocity-"), columns)
    if format == "odometer":
        return read_odometer(path, axis, columns)
    if format not in VELOCITY_FORMATS:
        raise ScenarioError(f"align.aiding.format: {format!r}; allowed: "
                            f"{', '.join(VELOCITY_FORMATS)}")
    from gcalign.io.recorded.reference import read_reference

    ref = read_reference(path, "csv" if format == "reference-csv" else format, variable,
                         columns)
    return Velocities(ref.t, v_n=ref.v_n,
                      record={**ref.record, "format": f"{format} (the reference's velocity)"})


def velocity_at(vel: Velocities, t, what: str = "aiding",
                hint: str = "move align.start_s, shorten align.t2_s / t3_s",
                max_gap: float | None = None) -> tuple[np.ndarray, bool]:
    """The aiding velocity at times `t` (M,), linearly interpolated between its epochs:
    ``(v (M, 3), body)``, ENU m/s, or (``body`` True) the odometer's speed times its body
    axis. ScenarioError (one line) when the file shares no time with `t`
    (:func:`overlap`), does not cover all of it, or has a gap longer than `max_gap` (s;
    default twice its median interval) inside it: no line is drawn across a gap, naming
    both spans or the gap and, in `hint`, the keys that move the run."""
    t = np.asarray(t, dtype=float)
    name = vel.record.get("path", "the aiding file")
    overlap(vel.t, t, name, what)
    lo, hi = float(vel.t[0]), float(vel.t[-1])
    tol = 1e-6 * (float(t[1] - t[0]) if len(t) > 1 else 1.0)
    if t[0] < lo - tol or t[-1] > hi + tol:
        raise ScenarioError(
            f"{what}: {name} covers {lo:.3f} .. {hi:.3f} s, the run needs "
            f"{float(t[0]):.3f} .. {float(t[-1]):.3f} s (data time): every sample it aids "
            f"must lie inside the file ({hint})")
    if len(vel.t) > 1:
        gap = default_max_gap(vel.t) if max_gap is None else float(max_gap)
        a = max(int(np.searchsorted(vel.t, t[0], side="right")) - 1, 0)
        b = min(int(np.searchsorted(vel.t, t[-1], side="left")) + 1, len(vel.t))
        span = vel.t[a:b]
        d = np.diff(span)
        if len(d) and d.max() > gap + tol:
            k = int(np.argmax(d))
            raise ScenarioError(
                f"{what}: {name} has no epoch for {d[k]:.3f} s after {span[k]:.3f} s (data "
                f"time), longer than max_gap_s {gap:g} s: the run would aid its samples "
                f"there with a velocity drawn across the gap ({hint}, or set "
                f"{what}.max_gap_s if the gap is harmless)")
    tq = np.clip(t, lo, hi)
    if vel.speed is not None:
        assert vel.axis_b is not None
        return np.interp(tq, vel.t, vel.speed)[:, None] * vel.axis_b[None, :], True
    assert vel.v_n is not None
    return np.column_stack([np.interp(tq, vel.t, vel.v_n[:, i]) for i in range(3)]), False
