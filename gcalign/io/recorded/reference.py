"""Reference solutions (a master INS, a post-processed trajectory) and the initial state.

==============  ===========================================================================
format          layout
==============  ===========================================================================
``psins-mat``   MATLAB file, an ``avp`` array ``[att(3) v(3) lat lon h t]``: rad, m/s ENU,
                rad, m, s (PSINS's ``avp``, ``fogavp``; ``variable`` names one of several);
                where the caller allows it, a ``vp`` array ``[v(3) lat lon h t]`` of 7
                columns, a reference without attitude
``i2nav-nav``   text (KF-GINS result): week, seconds of week, lat, lon (deg), h (m),
                vN, vE, vD (m/s), roll, pitch, yaw (deg; NED, FRD: yaw is the heading)
``csv``         declared ``columns`` (default ``t pitch roll yaw ve vn vu lat lon h``),
                angles in deg, ENU, RFU conventions
==============  ===========================================================================

:func:`reference_at` interpolates a reference to the IMU's times: attitude on the rotation
group (spherical linear interpolation of ``q_nb`` between neighbours: the geodesic, so a yaw
from 179° to -179° passes 180°, not 0°), velocity and position linearly. A reference that
does not cover the times asked for is refused, naming both spans. :func:`initial_state`
takes the attitude and velocity to start from: keys, else the reference at the start time,
else the recording's header; with none of them the refusal lists the three.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.gaps import Outage, default_max_gap, find_outages
from gcalign.io.imu_files import ImuFileError, _finite, _increasing, read_bytes
from gcalign.io.recorded import mat
from gcalign.io.recorded.imu import _table_of
from gcalign.io.recorded.rows import _columns
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm
from gcalign.units import DEG

__all__ = ["Reference", "read_reference", "reference_at", "reference_gaps",
           "initial_state", "REFERENCE_FORMATS", "reference_format_of"]

REFERENCE_FORMATS = ("psins-mat", "i2nav-nav", "csv")
_CSV_COLUMNS = ("t", "pitch", "roll", "yaw", "ve", "vn", "vu", "lat", "lon", "h")
_NAV_LABELS = ("week", "seconds of week", "lat", "lon", "h", "vN", "vE", "vD", "roll",
               "pitch", "yaw")


@dataclass(frozen=True)
class Reference:
    """t (N,) s; att (N, 3) [pitch, roll, yaw] rad (ENU, RFU), None for a reference without
    attitude (read only where the caller allows one); v_n (N, 3) ENU m/s;
    pos (N, 3) [lat rad, lon rad, h m]; record: what was read."""

    t: np.ndarray
    att: np.ndarray | None
    v_n: np.ndarray
    pos: np.ndarray
    record: dict = field(default_factory=dict)


def reference_format_of(path) -> str:
    """The reference format a file's suffix implies (``--reference FILE``): ``.mat``
    psins-mat, ``.csv`` csv, anything else (``.nav``, ``.txt``) i2nav-nav."""
    suffixes = [x.lower() for x in os.path.basename(os.fspath(path)).split(".")[1:]]
    suffixes = [x for x in suffixes if x not in ("gz", "xz")]
    last = suffixes[-1] if suffixes else ""
    return {"mat": "psins-mat", "csv": "csv"}.get(last, "i2nav-nav")


def read_reference(path, format: str = "psins-mat", variable: str | None = None,
                   columns=None, attitude_optional: bool = False) -> Reference:
    """A reference solution from `path` in `format` (module docstring); ScenarioError
    naming the file, row and what is allowed. `attitude_optional`: a psins-mat `variable`
    of 7 columns ``[v(3) lat lon h t]`` is read too, with ``att`` None (a master that
    gives velocity only)."""
    name = os.fspath(path)
    if format not in REFERENCE_FORMATS:
        raise ScenarioError(f"reference.format: {format!r} is not a reference format; "
                            f"allowed: {', '.join(REFERENCE_FORMATS)}")
    check_keys(format, variable, columns, "reference")
    data = read_bytes(name, text=format != "psins-mat")[1]
    notes: dict = {}
    if format == "psins-mat":
        a, key, where = _avp(name, data, variable, attitude_optional)
        a0 = a.shape[1] - 7  # 3 with attitude, 0 without
        t, v, pos = a[:, -1], a[:, a0:a0 + 3], a[:, a0 + 3:a0 + 6]
        att = a[:, 0:3] if a0 else None
        notes["variable"] = key
        origin = "seconds, the avp array's last column"
    elif format == "i2nav-nav":
        rows, (_, where) = _table_of(name, data, 11, _NAV_LABELS)
        t = rows[:, 1]
        att = np.column_stack([rows[:, 9], rows[:, 8], -rows[:, 10]]) * DEG  # yaw = -heading
        v = np.column_stack([rows[:, 6], rows[:, 5], -rows[:, 7]])
        pos = np.column_stack([rows[:, 2] * DEG, rows[:, 3] * DEG, rows[:, 4]])
        origin = "GNSS seconds of week"
        notes["week"] = int(rows[0, 0])
    else:
        cols = _columns(columns, _CSV_COLUMNS)
        rows, (_, where) = _table_of(name, data, len(cols), cols)
        c = {k: rows[:, cols.index(k)] for k in _CSV_COLUMNS}
        t = c["t"]
        att = np.column_stack([c["pitch"], c["roll"], c["yaw"]]) * DEG
        v = np.column_stack([c["ve"], c["vn"], c["vu"]])
        pos = np.column_stack([c["lat"] * DEG, c["lon"] * DEG, c["h"]])
        origin = "the file's time column"
    _increasing(name, t, where, got="")
    if len(t) < 2:
        raise ImuFileError(f"{name}: {len(t)} epoch(s); a reference needs at least 2")
    if att is not None:
        _angles(name, att, where, format)
    record = {"format": format, "path": name, "epochs": int(len(t)), "t_first_s": float(t[0]),
              "t_last_s": float(t[-1]), "time_origin": origin,
              "rate_hz": float(1.0 / np.median(np.diff(t))), **notes}
    # columns of the table are copied (so the table can go); the text formats' att, v,
    # pos are new arrays already and are not copied again (a long reference held once)
    att = None if att is None else np.ascontiguousarray(att)
    return Reference(np.array(t), att, np.ascontiguousarray(v), np.ascontiguousarray(pos),
                     record)


def _angles(name: str, att: np.ndarray, where, format: str) -> None:
    """Euler angles within their ranges (pitch within ±90°, roll and yaw within ±360°): a
    psins-mat avp in degrees, read as radians, has angles of tens of radians."""
    unit, scale = ("rad", 1.0) if format == "psins-mat" else ("deg", 1.0 / DEG)
    for col, label, bound in ((0, "pitch", np.pi / 2), (1, "roll", 2 * np.pi),
                              (2, "yaw", 2 * np.pi)):
        bad = np.abs(att[:, col]) > bound * (1 + 1e-9)
        if bad.any():
            k = int(np.argmax(bad))
            hint = (": it looks like degrees, and psins-mat takes radians"
                    if format == "psins-mat" else "")
            raise ImuFileError(f"{name}{where(k)}: {label} {att[k, col] * scale:.6g} {unit} "
                               f"is beyond ±{bound * scale:g} {unit}{hint}")


def check_keys(format: str, variable, columns, where: str) -> None:
    """A MAT variable names an array of a psins-mat file, columns the layout of a CSV: for
    any other format they cannot matter, and are refused rather than ignored (a CSV
    reference's variable was dropped in silence, while an imu_file's was refused)."""
    if variable is not None and format != "psins-mat":
        raise ScenarioError(f"{where}.variable: names an array of a MAT file; format "
                            f"{format!r} has none (remove it), got {variable!r}")
    if columns is not None and format not in ("csv", "reference-csv", "velocity-enu",
                                              "velocity-ned", "odometer"):
        raise ScenarioError(f"{where}.columns: names the columns of a CSV file; format "
                            f"{format!r} fixes its own (remove it), got {list(columns)}")


def _avp(name: str, data: bytes, variable: str | None, attitude_optional: bool = False):
    arrays = {k: v for k, v in mat.arrays(name, data).items() if v.ndim == 2}
    if variable is None:
        ten = sorted(k for k, v in arrays.items() if v.shape[1] == 10 and v.shape[0] >= 2)
        if len(ten) != 1:
            raise ImuFileError(f"{name}: variable: {'no' if not ten else 'more than one'} "
                               "avp array [att(3) v(3) lat lon h t] of 10 columns "
                               f"({', '.join(f'{k} {arrays[k].shape}' for k in sorted(arrays))}"
                               "); name one with variable:")
        variable = ten[0]
    widths = (10, 7) if attitude_optional else (10,)
    if variable not in arrays or arrays[variable].shape[1] not in widths:
        what = ("an N x 10 avp array [att(3) v(3) lat lon h t] or an N x 7 [v(3) lat lon h "
                "t]" if attitude_optional else "an N x 10 avp array")
        held = ", ".join(f"{k} {arrays[k].shape}" for k in sorted(arrays)) or "none"
        raise ImuFileError(f"{name}: variable {variable!r} is not {what}; the file holds "
                           f"{held}")
    a = np.asarray(arrays[variable], dtype=float)
    labels = ("pitch", "roll", "yaw", "vE", "vN", "vU", "lat", "lon", "h", "t")[10 - a.shape[1]:]
    where = lambda k: f": {variable} row {k + 1}"  # noqa: E731
    _finite(name, a, labels, where)
    return a, variable, where


def _covers(ref: Reference, t: np.ndarray, tol: float) -> None:
    lo, hi = float(ref.t[0]), float(ref.t[-1])
    if t[0] < lo - tol or t[-1] > hi + tol:
        raise ScenarioError(
            f"reference: {ref.record.get('path', 'the reference')} covers {lo:.3f} .. "
            f"{hi:.3f} s, the run needs {float(t[0]):.3f} .. {float(t[-1]):.3f} s: a "
            "reference must cover the whole run (start later, stop earlier, or give a "
            "longer reference)")


def reference_gaps(ref: Reference, max_gap: float | None = None) -> tuple[Outage, ...]:
    """The stretches of a reference longer than `max_gap` (s; default twice its median
    interval) without an epoch: no error is given against it there (an interpolation
    across a gap is not a measurement)."""
    gap = default_max_gap(ref.t) if max_gap is None else max_gap
    return find_outages(ref.t, float(ref.t[0]), float(ref.t[-1]), gap)


def reference_at(ref: Reference, t, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray,
                                                                 np.ndarray]:
    """``(att, v_n, pos)`` of `ref` at times `t` (M,): attitude by slerp of q_nb between
    the neighbouring epochs, velocity and position linearly (longitude unwrapped).
    ScenarioError if `t` leaves ``[t_first - tol, t_last + tol]``."""
    from scipy.spatial.transform import Rotation, Slerp

    t = np.atleast_1d(np.asarray(t, dtype=float))
    if ref.att is None:
        raise ScenarioError(f"reference: {ref.record.get('path', 'the reference')} has no "
                            "attitude (7 columns [v lat lon h t]); an avp of 10 columns "
                            "[att v lat lon h t] is needed here")
    _covers(ref, t, tol)
    tq = np.clip(t, ref.t[0], ref.t[-1])
    # only the epochs that bracket a query: each is interpolated between its two
    # neighbours, so the rest cannot matter (and a long reference costs nothing more)
    j = np.clip(np.searchsorted(ref.t, tq, side="right"), 1, len(ref.t) - 1)
    rows = np.unique(np.concatenate([j - 1, j]))
    rt, ratt = ref.t[rows], ref.att[rows]
    slerp = Slerp(rt, Rotation.from_matrix(euler_to_dcm(ratt)))
    att = dcm_to_euler(slerp(tq).as_matrix())
    v = np.column_stack([np.interp(tq, rt, ref.v_n[rows, i]) for i in range(3)])
    lon = np.unwrap(ref.pos[rows, 1])
    pos = np.column_stack([np.interp(tq, rt, ref.pos[rows, 0]), np.interp(tq, rt, lon),
                           np.interp(tq, rt, ref.pos[rows, 2])])
    pos[:, 1] = (pos[:, 1] + np.pi) % (2 * np.pi) - np.pi
    return att, v, pos


def initial_state(name: str, t0: float, *, att_deg=None, v_enu_mps=None,
                  reference: Reference | None = None, header_att=None, header_v=None
                  ) -> tuple[np.ndarray, np.ndarray, str]:
    """``(att rad, v_n m/s, source)`` to start navigating at data time `t0`: the keys
    (``initial: {att_deg, v_enu_mps}``), else the reference at `t0`, else the recording's
    header (PSINS); ScenarioError listing the three ways when none is given."""
    if att_deg is not None:
        att = np.radians(np.asarray(att_deg, dtype=float))
        v = np.zeros(3) if v_enu_mps is None else np.asarray(v_enu_mps, dtype=float)
        return att, v, "keys initial.att_deg, initial.v_enu_mps"
    if reference is not None:
        att, v, _ = reference_at(reference, [t0], tol=0.5 / reference.record.get(
            "rate_hz", 1.0))
        return att[0], v[0], f"reference {reference.record.get('path', '')} at {t0:g} s"
    if header_att is not None:
        v = np.zeros(3) if header_v is None else np.asarray(header_v, dtype=float)
        return np.asarray(header_att, dtype=float), v, "the file's header"
    raise ScenarioError(
        f"initial: {name} gives no initial attitude and velocity; give one of: a file "
        "whose header has them (PSINS .imu), a reference covering the start (reference: "
        "{path, format}, --reference), or the keys initial: {att_deg: [pitch, roll, yaw], "
        "v_enu_mps: [ve, vn, vu]}")
