"""IMU recordings of any layout, to increments in gcalign's conventions plus what was assumed.

One small function per format turns a file into raw columns (time, gyro, accel in the
file's axes and units); :func:`read_recording` then does, once for all formats:

1. units: rates become increments by the rectangular rule ``Δθ_k = ω_k · T`` (a sampled
   rate held over its interval), increments stay increments;
2. time: stamps at the *begin* of an increment are moved to its end (``t + T``), GNSS
   seconds of week are unwrapped over a week rollover;
3. timing: jitter up to :data:`JITTER` of the interval is accepted (a warning above
   :data:`JITTER_WARN`); a longer step is a gap, refused with its time unless
   ``max_gap_s`` covers it, when the missing samples are filled with the mean increments
   of the two samples around it (the rate held across the gap);
4. axes: ``v_rfu = C @ v_file`` with ``C`` from the declared axes
   (:func:`gcalign.io.recorded.axes.rotation_to_rfu`);
5. gravity: the mean specific force over the first :data:`GRAVITY_WINDOW_S` must point up
   in the RFU body (within 60°) and be about 1 g: otherwise the axes or the units are wrong,
   and the error names the likely ones.

The result is an :class:`~gcalign.sim.imu.ImuData` (``t`` end times, s; ``dtheta`` rad and
``dv`` m/s in RFU) whose ``meta["recording"]`` is the record of all of the above (format,
axes, units, time origin, rate, gaps, gravity check, warnings): plain JSON-able values,
stored in results files (``/recording``) and shown by ``gcalign validate``.

==============  ===========================================================================
format          layout (columns in file order; see spec 005)
==============  ===========================================================================
``psins``       PSINS ``.imu``: header rows, integer counts (RFU, stamps implicit, end)
``psins-mat``   MATLAB file, an ``[wm(3) vm(3) t]`` array: rad, m/s, time last (RFU, end)
``i2nav``       text ``t(sow) dθx dθy dθz dvx dvy dvz``: rad, m/s, GNSS seconds of week
                (FRD, end) -- KF-GINS, OB_GINS, awesome-gins-datasets
``csv``         text with declared ``columns`` (default ``t gx gy gz ax ay az``), units
                (default rad, m/s), axes (default RFU) and time (default end); comma or
                whitespace separated, ``#``/``%`` comments, an optional header row
==============  ===========================================================================
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from gcalign.errors import ScenarioError, clip
from gcalign.io.imu_files import (
    _HDF5_MAGIC,
    ImuFileError,
    _data_lineno,
    _fields,
    _increasing,
    _is_number,
    _parse_block,
    check_increments,
    guess_format,
    read_bytes,
    read_psins_imu,
    text_of,
)
from gcalign.io.recorded import consistency, mat
from gcalign.io.recorded.axes import axes_text, rotation_to_rfu
from gcalign.io.recorded.consistency import GYRO_UNITS
from gcalign.sim.imu import ImuData

__all__ = ["FORMATS", "Layout", "read_recording", "GYRO_UNITS", "ACCEL_UNITS"]

G_STANDARD = 9.80665  #: m/s² per g for accelerometer data in g (sensor data sheets' g)

#: accelerometer units -> (SI factor, quantity)
ACCEL_UNITS = {
    "m/s": (1.0, "increments"), "m/s^2": (1.0, "rates"), "g": (G_STANDARD, "rates"),
}
_ACCEL_ALIASES = {"m/s2": "m/s^2", "m/s²": "m/s^2", "mps2": "m/s^2", "mps": "m/s"}

JITTER = 0.05  #: a step within ±5 % of the interval is jitter, accepted
JITTER_WARN = 1e-3  #: jitter above 0.1 % of the interval is reported as a warning
GRAVITY_WINDOW_S = 2.0  #: the first seconds whose mean specific force is checked
GRAVITY_TILT_DEG = 60.0  #: the specific force must lie within this of the body's up axis

COLUMN_NAMES = ("t", "gx", "gy", "gz", "ax", "ay", "az")
_COLUMN_ALIASES = {"time": "t", "dtheta_x": "gx", "dtheta_y": "gy", "dtheta_z": "gz",
                   "dv_x": "ax", "dv_y": "ay", "dv_z": "az"}
_SKIP = ("-", "_", "skip")


@dataclass(frozen=True)
class FormatInfo:
    """What a format fixes and what it leaves to be declared."""

    axes: str
    time: str  # "end" or "begin" of each increment
    origin: str  # what the time column counts
    gyro: str
    accel: str
    declarable: frozenset[str] = frozenset()  # keys a user may declare for this format


_ALL = frozenset({"axes", "columns", "units", "quantity", "time", "rate_hz"})
FORMATS = {
    "psins": FormatInfo("RFU", "end", "header t0 + k·interval", "rad", "m/s",
                        declarable=frozenset({"axes"})),
    "psins-mat": FormatInfo("RFU", "end", "seconds, the array's last column", "rad", "m/s",
                            frozenset({"axes", "variable", "rate_hz"})),
    "i2nav": FormatInfo("FRD", "end", "GNSS seconds of week", "rad", "m/s",
                        declarable=frozenset({"axes", "rate_hz"})),
    "csv": FormatInfo("RFU", "end", "seconds, the file's time column", "rad", "m/s",
                      declarable=_ALL),
}
FORMAT_NAMES = (*FORMATS, "auto")


@dataclass(frozen=True)
class Layout:
    """How to read a recording. None means the format's own (:data:`FORMATS`).

    format : psins | psins-mat | i2nav | csv | auto (by the file's suffix)
    axes : the file's body axes (letters or a 3x3 matrix, :mod:`~.axes`)
    columns : names of the file's columns in order (csv): t, gx, gy, gz, ax, ay, az;
        ``-`` skips a column
    gyro_units, accel_units : see :data:`GYRO_UNITS`, :data:`ACCEL_UNITS`
    quantity : increments | rates (must agree with the units; implied by them)
    time : end | begin -- what each stamp marks of its increment
    variable : the MAT variable to read (psins-mat; default the one 7-column array)
    rate_hz : the sample rate (default: the median step of the time column)
    max_gap_s : the longest gap filled (s); longer ones are refused
    check_gravity : refuse a start whose specific force does not point up
    check_consistency : refuse gyros that contradict the accelerometers or, at rest with a
        known latitude, the earth rate (:mod:`~.consistency`)
    """

    format: str = "auto"
    axes: str | tuple | None = None
    columns: tuple[str, ...] | None = None
    gyro_units: str | None = None
    accel_units: str | None = None
    quantity: str | None = None
    time: str | None = None
    variable: str | None = None
    rate_hz: float | None = None
    max_gap_s: float = 0.0
    check_gravity: bool = True
    check_consistency: bool = True

    def declared(self) -> set[str]:
        """The keys this layout sets (to check them against the format)."""
        out = {k for k in ("axes", "columns", "quantity", "time", "variable", "rate_hz")
               if getattr(self, k) is not None}
        if self.gyro_units is not None or self.accel_units is not None:
            out.add("units")
        return out


@dataclass
class _Raw:
    """A file's columns before conversion: time (N,), gyro and accel (N, 3) in the file's
    axes and units; where(k) names data row k in messages."""

    t: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    where: object
    ts: float | None = None  # an interval the file states (PSINS header)
    header: ImuData | None = None
    notes: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- formats


def _text_lines(name: str, data: bytes) -> list[str]:
    """Lines with ``#`` and ``%`` comments cut off (line numbers kept); ImuFileError for
    what is not text (:func:`~gcalign.io.imu_files.text_of`)."""
    return [_uncommented(line) for line in text_of(name, data).splitlines()]


def _uncommented(line: str) -> str:
    cut = min((i for i in (line.find("#"), line.find("%")) if i >= 0), default=-1)
    return line if cut < 0 else line[:cut]


def _header(first: str) -> list[str] | None:
    """The fields of a table's first line if it is a header row of names (letters, and not
    every field a number), else None."""
    parts = _fields(first, "," if "," in first else None)
    return parts if any(c.isalpha() for c in first) and not all(map(_is_number, parts)) else None


def _table(name: str, lines: list[str], ncols: int, labels
           ) -> tuple[np.ndarray, tuple[list[str] | None, Callable[[int], str]]]:
    """Numeric rows of a text table (an optional header row of names skipped), the header
    row's names and where(k), the file line of data row k."""
    i = 0
    while i < len(lines) and not lines[i].strip():
        i += 1
    if i == len(lines):
        raise ImuFileError(f"{name}: no data rows, expected {ncols} columns "
                           f"({', '.join(labels)})")
    first = lines[i].strip()
    delimiter = "," if "," in first else None
    header = _header(first)
    if header is not None:
        i += 1
    data = _parse_block(name, lines, i, ncols, "\x00", delimiter, tuple(labels))
    start = i
    return data, (header, lambda k: f":{_data_lineno(lines, start, chr(0), k)}")


_BLOCK_BYTES = 1 << 22  #: text parsed at a time by :func:`_table_of` (4 MiB)


def _table_of(name: str, data: bytes, ncols: int, labels
              ) -> tuple[np.ndarray, tuple[list[str] | None, Callable[[int], str]]]:
    """:func:`_table` of a file's bytes, parsed a block of lines at a time into one array
    (a 50 MB text costs its rows, not a list of its lines: 3.5 bytes of memory a byte of
    text before). The same rows; anything that is not a clean table of finite numbers
    (wrong columns, a bad field, no rows) goes to the line-by-line :func:`_table`, whose
    message names the line."""
    rows = None
    try:
        rows = _blocks(name, data, ncols)
    except ValueError:
        pass
    if rows is None:
        return _table(name, _text_lines(name, data), ncols, labels)
    table, header = rows

    def where(k: int) -> str:  # the file line of data row k, found when a message needs it
        return _table(name, _text_lines(name, data), ncols, labels)[1][1](k)

    return table, (header, where)


def _blocks(name: str, data: bytes, ncols: int):
    """``(rows, header)`` of a clean numeric table, or None when it is not one (the caller
    then takes the line-by-line route)."""
    import io

    if data.startswith(_HDF5_MAGIC) or b"\x00" in data[:4096]:
        return None
    text_start, header = 0, None
    while text_start < len(data):  # the first line with content: a header of names?
        end = data.find(b"\n", text_start)
        end = len(data) if end < 0 else end
        first = _uncommented(data[text_start:end].decode("utf-8", errors="replace")).strip()
        if first:
            header = _header(first)
            if header is not None:
                text_start = end + 1
            break
        text_start = end + 1
    # the rows after the header, parsed in place (offsets into `data`: a slice would copy it)
    sample = data[text_start:text_start + 4096].decode("utf-8", errors="replace")
    delimiter = "," if "," in sample else None
    out = np.empty((data.count(b"\n", text_start) + 1, ncols))
    n, pos = 0, text_start
    while pos < len(data):
        end = data.rfind(b"\n", pos, pos + _BLOCK_BYTES) if pos + _BLOCK_BYTES < len(data) \
            else len(data)
        end = len(data) if end <= pos else end
        chunk = data[pos:end].decode("utf-8", errors="strict")
        pos = end + 1
        block = np.loadtxt(io.StringIO(chunk), comments=("#", "%"), delimiter=delimiter,
                           ndmin=2, dtype=float)
        if block.size == 0:
            continue
        if block.shape[1] != ncols or not np.isfinite(block).all():
            return None
        out[n:n + len(block)] = block
        n += len(block)
    if n == 0:
        return None
    return out[:n], header


def _read_psins(name: str, path) -> _Raw:
    imu = read_psins_imu(path)  # header, counts, implicit regular times (end of increments)
    header = replace(imu, source=name)
    return _Raw(imu.t, imu.dtheta, imu.dv, lambda k: f": sample {k + 1}", imu.ts, header,
                {"header": {k: v for k, v in imu.meta.items() if k != "format"}})


def _read_psins_mat(name: str, data: bytes, layout: Layout) -> _Raw:
    arrays = mat.arrays(name, data)
    if layout.variable is not None:
        if layout.variable not in arrays:
            raise ImuFileError(f"{name}: variable: {layout.variable!r} is not a numeric array "
                               f"of the file; it holds {', '.join(sorted(arrays)) or 'none'}")
        key = layout.variable
    else:
        seven = sorted(k for k, v in arrays.items() if v.ndim == 2 and v.shape[1] == 7
                       and v.shape[0] >= 2)
        if len(seven) != 1:
            shapes = ", ".join(f"{k} {arrays[k].shape}" for k in sorted(arrays)) or "none"
            raise ImuFileError(
                f"{name}: variable: {'no' if not seven else 'more than one'} array of 7 "
                f"columns [wm(3) vm(3) t] in the file ({shapes}); name one with variable:")
        key = seven[0]
    a = np.asarray(arrays[key], dtype=float)
    if a.ndim != 2 or a.shape[1] != 7:
        raise ImuFileError(f"{name}: variable {key!r} has shape {a.shape}; an IMU array is "
                           "N x 7, [wm(3) vm(3) t] (rad, m/s, s; time last)")
    bad = ~np.isfinite(a)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise ImuFileError(f"{name}: {key} row {row + 1} column {col + 1} must be finite, got "
                           f"{a[row, col]!r}")
    return _Raw(a[:, 6].copy(), a[:, 0:3].copy(), a[:, 3:6].copy(),
                lambda k: f": {key} row {k + 1}", notes={"variable": key})


def _read_i2nav(name: str, data: bytes, layout: Layout) -> _Raw:
    labels = ("seconds of week", "dtheta x", "dtheta y", "dtheta z", "dv x", "dv y", "dv z")
    rows, (_, where) = _table_of(name, data, 7, labels)
    return _Raw(rows[:, 0].copy(), rows[:, 1:4].copy(), rows[:, 4:7].copy(), where)


def _columns(layout: Layout) -> tuple[str, ...]:
    cols = tuple(layout.columns or COLUMN_NAMES)
    names = []
    for c in cols:
        c = _COLUMN_ALIASES.get(str(c).strip().lower(), str(c).strip().lower())
        if c not in COLUMN_NAMES and c not in _SKIP:
            raise ScenarioError(f"imu_file.columns: unknown column {c!r}; allowed: "
                                f"{', '.join(COLUMN_NAMES)} (and '-' to skip one)")
        names.append(c)
    missing = [c for c in COLUMN_NAMES if c not in names]
    twice = sorted({c for c in names if c not in _SKIP and names.count(c) > 1})
    if missing or twice:
        what = f"misses {', '.join(missing)}" if missing else f"names {', '.join(twice)} twice"
        raise ScenarioError(f"imu_file.columns: {list(cols)} {what}; give each of "
                            f"{', '.join(COLUMN_NAMES)} once")
    return tuple(names)


#: Header-row names of the columns (``gyro_x (deg/s)``, as gnss-ins-sim writes them).
_HEADER_NAMES = {
    "t": "t", "time": "t", "timestamp": "t", "sow": "t",
    **{f"{p}{a}": f"g{a}" for p in ("gyro_", "gyr_", "g", "w", "wm_", "dtheta_", "omega_")
       for a in "xyz"},
    **{f"{p}{a}": f"a{a}" for p in ("accel_", "acc_", "a", "f", "vm_", "dv_") for a in "xyz"},
}
_HEADER_UNITS = {"deg/s": "deg/s", "°/s": "deg/s", "dps": "deg/s", "rad/s": "rad/s",
                 "deg/h": "deg/h", "°/h": "deg/h", "rad": "rad", "deg": "deg", "°": "deg",
                 "m/s^2": "m/s^2", "m/s2": "m/s^2", "m/s²": "m/s^2", "g": "g", "m/s": "m/s",
                 "s": "s", "sec": "s"}
_NAME_UNIT = re.compile(r"^\s*([A-Za-z_][\w]*)\s*(?:[(\[]\s*([^)\]]+?)\s*[)\]])?\s*$")


def _header_layout(header: list[str] | None) -> tuple[tuple[str, ...], dict] | None:
    """Columns and units a header row names (``time (s), gyro_x (deg/s), ...``), or None
    if it does not name all seven columns (then it is only skipped)."""
    if not header:
        return None
    cols: list[str] = []
    units: dict[str, set[str]] = {}
    for text in header:
        m = _NAME_UNIT.match(text)
        col = _HEADER_NAMES.get(m.group(1).lower()) if m else None
        cols.append(col or "-")
        unit = _HEADER_UNITS.get(m.group(2).strip().lower()) if m and m.group(2) else None
        if col and m and m.group(2) and unit is None:
            raise ImuFileError(f"header row: column {text!r}: unit {m.group(2)!r} unknown; "
                               f"allowed: {', '.join(sorted(set(_HEADER_UNITS)))}")
        if col and unit and col != "t":
            units.setdefault("gyro" if col[0] == "g" else "accel", set()).add(unit)
    if sorted(c for c in cols if c != "-") != sorted(COLUMN_NAMES):
        return None
    for sensor, found in units.items():
        if len(found) > 1:
            raise ImuFileError(f"header row: the {sensor} columns have different units "
                               f"({', '.join(sorted(found))})")
    return tuple(cols), {k: v.pop() for k, v in units.items()}


def _read_csv(name: str, data: bytes, layout: Layout) -> _Raw:
    lines = _text_lines(name, data)
    cols = _columns(layout)
    first = next((ln.strip() for ln in lines if ln.strip()), "")
    parts = [p.strip() for p in first.split(",")] if "," in first else first.split()
    named = None
    if layout.columns is None and not all(_is_number(p) for p in parts):
        try:
            named = _header_layout(parts)
        except ImuFileError as err:
            raise ImuFileError(f"{name}: {err}") from None
        if named is not None:
            cols = named[0]
        elif layout.gyro_units is None and layout.accel_units is None:
            # an unrecognised header row would otherwise be read as rad and m/s increments
            raise ImuFileError(
                f"{name}: header row {clip(first, 60)!r} does not name the columns as gcalign "
                "knows them (time, gyro_x (deg/s), ..., accel_z (m/s^2)); declare the "
                "layout in a scenario: imu_file: {path: ..., columns: [t, gx, gy, gz, ax, "
                "ay, az], units: {gyro: "
                f"{' | '.join(GYRO_UNITS)}, accel: {' | '.join(ACCEL_UNITS)}}}}}")
    rows, (header, where) = _table(name, lines, len(cols), cols)
    idx = {c: i for i, c in enumerate(cols)}
    pick = [idx[c] for c in ("gx", "gy", "gz")], [idx[c] for c in ("ax", "ay", "az")]
    notes: dict = {"columns": list(cols), "columns_source": "declared" if layout.columns
                   else "header row" if named else "csv default", "header_row": header}
    if named is not None and named[1]:
        notes["header_units"] = named[1]
    return _Raw(rows[:, idx["t"]].copy(), rows[:, pick[0]], rows[:, pick[1]], where,
                notes=notes)


_READERS = {"psins-mat": _read_psins_mat, "i2nav": _read_i2nav, "csv": _read_csv}


# --------------------------------------------------------------------------- conversion


def _units(fmt: str, info: FormatInfo, layout: Layout,
           header: dict | None = None) -> tuple[str, str, str]:
    """(gyro units, accel units, quantity), checked to agree: declared, else named by the
    file's header row, else the format's."""
    header = header or {}
    gyro = (layout.gyro_units or header.get("gyro") or info.gyro).strip().lower().replace(
        "°", "deg")
    accel = (layout.accel_units or header.get("accel") or info.accel).strip().lower()
    accel = _ACCEL_ALIASES.get(accel, accel)
    if gyro not in GYRO_UNITS:
        raise ScenarioError(f"imu_file.units.gyro: {gyro!r} is not a unit; allowed: "
                            f"{', '.join(GYRO_UNITS)}")
    if accel not in ACCEL_UNITS:
        raise ScenarioError(f"imu_file.units.accel: {accel!r} is not a unit; allowed: "
                            f"{', '.join(ACCEL_UNITS)}")
    qg, qa = GYRO_UNITS[gyro][1], ACCEL_UNITS[accel][1]
    if qg != qa:
        raise ScenarioError(f"imu_file.units: gyro {gyro!r} ({qg}) and accel {accel!r} ({qa}) "
                            "must both be increments (rad, deg, arcsec; m/s) or both rates "
                            "(rad/s, deg/s, deg/h; m/s^2, g)")
    if layout.quantity is not None and layout.quantity != qg:
        raise ScenarioError(f"imu_file.quantity: {layout.quantity!r} contradicts the units "
                            f"{gyro!r}, {accel!r} ({qg}); give one or make them agree")
    return gyro, accel, qg


def _interval(name: str, t: np.ndarray, layout: Layout, stated: float | None) -> tuple[float,
                                                                                       str]:
    if stated is not None:
        return float(stated), "the file's header"
    if layout.rate_hz is not None:
        return 1.0 / float(layout.rate_hz), f"declared rate_hz {layout.rate_hz:g}"
    dt = np.diff(t)
    if len(dt) == 0:
        raise ImuFileError(f"{name}: one sample only; need at least 2")
    # The median step, rounded to the resolution of the stamps (8 ulps of the largest):
    # GNSS seconds of week 456300.01, 456300.02, ... differ by 0.0100000000093, which is
    # 0.01 within what such numbers can say.
    q = 10.0 ** math.floor(math.log10(8 * float(np.spacing(np.abs(t).max())) or 1e-300))
    ts = float(f"{round(float(np.median(dt)) / q) * q:.12g}")
    if not ts > 0:
        raise ImuFileError(f"{name}: the median time step is {ts!r} s; time must increase")
    return ts, "median time step"


def _unwrap_week(t: np.ndarray) -> tuple[np.ndarray, int]:
    """GNSS seconds of week continued over a week rollover (a step of about -604800 s)."""
    week = 604800.0
    back = np.diff(t) < -week / 2
    if not back.any():
        return t, 0
    return t + week * np.concatenate([[0], np.cumsum(back)]), int(back.sum())


def _regular(name: str, t, gyro, accel, ts: float, max_gap_s: float, where):
    """Check the steps (see the module docstring, point 3); fill accepted gaps. Returns
    (t, gyro, accel, jitter (max |step/ts - 1| of the accepted steps), gaps)."""
    _increasing(name, t, where)
    dt = np.diff(t)
    rel = dt / ts - 1.0
    short = rel < -JITTER
    if short.any():
        k = int(np.argmax(short)) + 1
        raise ImuFileError(f"{name}{where(k)}: a step of {float(dt[k - 1]):.6g} s from t = "
                           f"{float(t[k - 1])!r} s, shorter than the interval {ts:.6g} s by "
                           f"more than {JITTER:.0%} (duplicated or irregular samples)")
    long = np.flatnonzero(rel > JITTER)
    gaps = []
    for j in long:
        gap = float(dt[j] - ts)
        missing = round(dt[j] / ts) - 1
        if gap > max_gap_s or abs(dt[j] - (missing + 1) * ts) > JITTER * ts:
            why = (f"set imu_file max_gap_s: {math.ceil(round(gap, 9) * 1000) / 1000:g} to fill it "
                   "(the rate held across the gap), or split the file there"
                   if abs(dt[j] - (missing + 1) * ts) <= JITTER * ts else
                   "not a whole number of intervals, so it cannot be filled: split the file")
            raise ImuFileError(f"{name}{where(j + 1)}: time jumps from {float(t[j])!r} to "
                               f"{float(t[j + 1])!r} s, a gap of {gap:.6g} s (interval "
                               f"{ts:.6g} s, jitter up to {JITTER:.0%} accepted); {why}")
        gaps.append({"after_t_s": float(t[j]), "length_s": gap, "samples_filled": missing})
    jitter = float(np.abs(np.where(rel > JITTER, 0.0, rel)).max()) if len(rel) else 0.0
    if gaps:
        t, gyro, accel = _fill(t, gyro, accel, ts, long)
    return t, gyro, accel, jitter, gaps


def _fill(t, gyro, accel, ts, long):
    """Insert the missing samples of each gap: increments the mean of the two samples
    around it (the rate held), end times on the regular grid."""
    pieces_t, pieces_g, pieces_a = [], [], []
    start = 0
    for j in long:
        n = round((t[j + 1] - t[j]) / ts) - 1
        pieces_t += [t[start:j + 1], t[j] + ts * np.arange(1, n + 1)]
        mean_g, mean_a = (gyro[j] + gyro[j + 1]) / 2, (accel[j] + accel[j + 1]) / 2
        pieces_g += [gyro[start:j + 1], np.tile(mean_g, (n, 1))]
        pieces_a += [accel[start:j + 1], np.tile(mean_a, (n, 1))]
        start = j + 1
    pieces_t.append(t[start:])
    pieces_g.append(gyro[start:])
    pieces_a.append(accel[start:])
    return np.concatenate(pieces_t), np.concatenate(pieces_g), np.concatenate(pieces_a)


#: Proper axis layouts tried, in this order, to name the likely one when gravity is wrong.
_COMMON_AXES = ("RFU", "FRD", "FLU", "RBD", "LFD", "BLU", "FRU", "URF", "DRB", "UFL")


def _gravity(name: str, dv: np.ndarray, ts: float, C: np.ndarray, declared: str,
             g_units: str) -> dict:
    """Mean specific force over the first seconds in RFU; ScenarioError if it does not
    point up or is not about 1 g (see the module docstring, point 5)."""
    m = max(1, min(len(dv), int(round(GRAVITY_WINDOW_S / ts))))
    f = dv[:m].sum(axis=0) / (m * ts)
    norm = float(np.linalg.norm(f))
    window = f"{m * ts:g} s"
    if not 0.5 * G_STANDARD < norm < 1.5 * G_STANDARD:
        raise ScenarioError(
            f"imu_file: {name}: the specific force over the first {window} is {norm:.4g} "
            f"m/s², not about 9.8 (gravity): check the accelerometer units (declared "
            f"{g_units!r}; allowed {', '.join(ACCEL_UNITS)}) and whether the file holds "
            "increments or rates")
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, f[2] / norm))))
    if tilt > GRAVITY_TILT_DEG:
        f_file = C.T @ f
        j = int(np.argmax(np.abs(f_file)))
        sign = 1.0 if f_file[j] > 0 else -1.0
        likely = next((a for a in _COMMON_AXES if _up_axis(a) == (j, sign)), None)
        where = f"file {'xyz'[j]} points {'up' if sign > 0 else 'down'}"
        hint = f"looks like {likely}" if likely else "the declared axes are wrong"
        raise ScenarioError(
            f"imu_file: {name}: with axes {declared} the specific force over the first "
            f"{window} is {f[2]:+.2f} m/s² along z (up), {tilt:.0f}° from up; {where} "
            f"({f_file[j]:+.2f} m/s²): {hint} (give axes / --axes; a start tilted past "
            f"{GRAVITY_TILT_DEG:g}° takes check_gravity: false)")
    return {"window_s": m * ts, "specific_force_rfu_mps2": f.tolist(), "tilt_deg": tilt}


def _up_axis(letters: str) -> tuple[int, float]:
    C = rotation_to_rfu(letters)
    j = int(np.argmax(np.abs(C[2])))
    return j, float(C[2, j])


# --------------------------------------------------------------------------- reading

def read_recording(path, layout: Layout | None = None) -> ImuData:
    """Read a recording of any supported layout (module docstring) into increments in RFU.

    Parameters
    ----------
    path : str or os.PathLike
        The file; ``.gz``/``.xz`` compressed too.
    layout : Layout, optional
        Format and declarations; default: the format implied by the file name, with that
        format's axes, units and time.

    Returns
    -------
    ImuData
        ``t`` (N,) end time of each increment in the file's own time (s; GNSS seconds of
        week for i2nav), ``dtheta`` (N, 3) rad, ``dv`` (N, 3) m/s in body RFU, ``ts`` s;
        ``site``, ``att0``, ``v0_n`` from a PSINS header; ``meta["recording"]`` the record
        of what was assumed (JSON-able). Nothing is kept: a run reads its file once and
        passes what it read along (:class:`gcalign.app.command.Inputs`).

    Raises
    ------
    ScenarioError
        One line naming the file (and row, or key) and what is allowed.
    """
    return _read(os.fspath(path), layout or Layout())


def _read(name: str, layout: Layout) -> ImuData:
    fmt = layout.format if layout.format != "auto" else guess_format(name)
    if fmt not in FORMATS:
        raise ScenarioError(f"imu_file.format: {fmt!r} is not a format; allowed: "
                            f"{', '.join(FORMAT_NAMES)}")
    info = FORMATS[fmt]
    extra = sorted(layout.declared() - info.declarable)
    if extra:
        raise ScenarioError(f"imu_file.{extra[0]}: cannot matter with format {fmt!r}, which "
                            f"fixes it; {fmt} declares only "
                            f"{', '.join(sorted(info.declarable)) or 'nothing'}")
    declared_axes = layout.axes if layout.axes is not None else info.axes
    C = rotation_to_rfu(declared_axes)
    if fmt == "psins":
        raw = _read_psins(name, name)
    else:
        raw = _READERS[fmt](name, read_bytes(name, text=fmt != "psins-mat")[1], layout)
    gyro_units, accel_units, quantity = _units(fmt, info, layout, raw.notes.get("header_units"))
    ts, ts_rule = _interval(name, raw.t, layout, raw.ts)
    t, weeks = (_unwrap_week(raw.t) if fmt == "i2nav" else (raw.t, 0))
    time = layout.time or info.time
    gyro_si = raw.gyro * GYRO_UNITS[gyro_units][0]
    accel_si = raw.accel * ACCEL_UNITS[accel_units][0]
    if quantity == "rates":  # rectangular rule: the sampled rate held over its interval
        gyro_si, accel_si = gyro_si * ts, accel_si * ts
    if time == "begin":
        t = t + ts
    t, gyro_si, accel_si, jitter, gaps = _regular(name, t, gyro_si, accel_si, ts,
                                                  layout.max_gap_s, raw.where)
    identity = np.array_equal(C, np.eye(3))
    dtheta = gyro_si if identity else gyro_si @ C.T  # v_rfu = C v_file, row by row
    dv = accel_si if identity else accel_si @ C.T
    check_increments(name, t, dtheta, dv, ts, raw.where)  # type: ignore[arg-type]
    warnings = []
    if jitter > JITTER_WARN:
        warnings.append(f"imu_file: {name}: time steps jitter by up to {jitter:.2%} of the "
                        f"interval {ts:g} s (accepted up to {JITTER:.0%}); the increments "
                        "are used as recorded")
    for gap in gaps:
        warnings.append(f"imu_file: {name}: a gap of {gap['length_s']:.6g} s after t = "
                        f"{gap['after_t_s']!r} s filled with {gap['samples_filled']} "
                        "sample(s) of the mean rate around it (max_gap_s)")
    gravity = (_gravity(name, dv, ts, C, axes_text(declared_axes), accel_units)
               if layout.check_gravity else None)
    gyros: dict | str = "off (check_consistency: false)"
    if layout.check_consistency:
        gyros = consistency.check_gyros(name, dtheta, dv, ts, gyro_units=gyro_units,
                                        C_rfu_file=C, fmt=fmt)
        if gyros.get("warning"):
            warnings.append(gyros["warning"])
        if raw.header is not None and raw.header.site is not None:
            gyros["at_rest"] = consistency.earth_rate_at_rest(
                name, dtheta, dv, ts, float(raw.header.site[0]), gyro_units=gyro_units,
                fmt=fmt)
    record = {
        "format": fmt,
        "path": name,
        "axes": axes_text(declared_axes),
        "axes_source": "declared" if layout.axes is not None else f"{fmt} default",
        "C_rfu_file": C.tolist(),
        "quantity": quantity,
        "units": {"gyro": gyro_units, "accel": accel_units},
        "units_source": ("declared" if layout.gyro_units or layout.accel_units else
                         "header row" if raw.notes.get("header_units") else f"{fmt} default"),
        "rate_rule": ("rectangular: increment = rate x interval" if quantity == "rates"
                      else "increments as recorded"),
        "g_mps2": G_STANDARD if accel_units == "g" else None,
        "time_stamp": f"{time} of each increment" + (" (moved to its end)"
                                                     if time == "begin" else ""),
        "time_origin": info.origin,
        "week_rollovers": weeks,
        "t_first_s": float(t[0]),
        "t_last_s": float(t[-1]),
        "samples": int(len(t)),
        "ts_s": ts,
        "rate_hz": 1.0 / ts,
        "ts_rule": ts_rule,
        "jitter_max": jitter,
        "gaps": gaps,
        "gravity_check": gravity if gravity is not None else "off (check_gravity: false)",
        "gyro_check": gyros,
        "warnings": warnings,
        **raw.notes,
    }
    if raw.header is not None:
        return replace(raw.header, t=t, dtheta=dtheta, dv=dv, ts=ts,
                       meta={**raw.header.meta, "recording": record})
    return ImuData(t=t, dtheta=np.ascontiguousarray(dtheta), dv=np.ascontiguousarray(dv),
                   ts=ts, source=name, meta={"format": fmt, "recording": record})
