"""Readers (and a CSV writer) for recorded IMU increments.

Two text formats arrive from outside gcalign (DESIGN "Truth and IMU simulation"):

* PSINS ``.imu`` (Yan Gongmin's toolbox, e.g. ``shared/data/lasergyro.imu``): ``%``
  comment lines, three header rows, then one row of six integer counts per sample::

      pitch0 roll0 yaw0 (deg)  VE0 VN0 VU0 (m/s)          nominal initial state
      lat lon (deg)  h (m)  t0 (s)  interval (ms)  g (m/s²)
      gyro scale ×3 (arcsec/count)  accel scale ×3 (µg·s/count)
      gx gy gz ax ay az                                     counts, one row per sample

  Conversion: ``Δθ = counts · scale_arcsec · ARCSEC`` (rad) and
  ``Δv = counts · scale_ugs · 1e-6 · g`` (m/s) with ``g`` from header 2 (9.780327 in
  lasergyro.imu, 2.3e-8 relative from :data:`gcalign.units.G0`). Body axes x right,
  y forward, z up and ENU navigation, as in gcalign, so no axis change is needed.
* Plain text/CSV of ``t, Δθx, Δθy, Δθz, Δvx, Δvy, Δvz`` (s, rad, m/s), comma or
  whitespace separated, ``#`` comments, an optional header line of column names.

Both may be compressed (``.gz``, ``.xz``). Other layouts -- PSINS MAT arrays, KF-GINS text,
rates, declared columns and body axes -- are read by :mod:`gcalign.io.recorded`, which
builds on these two. HDF5 files written by ``gcalign simulate`` are read by the results
layer, not here.
Every reading problem raises :class:`ImuFileError` with one line that names the file,
the line (and field) and what was expected.

>>> import os, tempfile
>>> import numpy as np
>>> from gcalign.sim.imu import ImuData
>>> imu = ImuData(t=np.array([0.01, 0.02, 0.03]), dtheta=np.zeros((3, 3)),
...               dv=np.tile([0.0, 0.0, 0.098], (3, 1)), ts=0.01)
>>> path = os.path.join(tempfile.mkdtemp(), "imu.csv")
>>> write_csv_imu(path, imu)
>>> back = read_imu_file(path)
>>> len(back), back.ts, back.dv[0].tolist()
(3, 0.01, [0.0, 0.0, 0.098])
>>> try:
...     read_imu_file(os.path.join(os.path.dirname(path), "missing.imu"))
... except ImuFileError as exc:
...     print(str(exc).endswith("missing.imu: file not found"))
True
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.io.paths import not_a_file
from gcalign.sim.imu import ImuData
from gcalign.units import ARCSEC, DEG

__all__ = [
    "COMPRESSED",
    "ImuFileError",
    "data_suffix",
    "read_bytes",
    "read_psins_imu",
    "read_csv_imu",
    "read_imu_file",
    "write_csv_imu",
]

_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"
_CSV_COLUMNS = ("t", "dtheta_x", "dtheta_y", "dtheta_z", "dv_x", "dv_y", "dv_z")
_PSINS_HEADERS = (
    ("initial state", ("pitch0_deg", "roll0_deg", "yaw0_deg", "VE0", "VN0", "VU0")),
    ("site and timing", ("lat_deg", "lon_deg", "height_m", "t0_s", "interval_ms", "g")),
    ("scale factors", ("gx_arcsec", "gy_arcsec", "gz_arcsec", "ax_ugs", "ay_ugs", "az_ugs")),
)


class ImuFileError(ScenarioError):
    """An IMU file that cannot be read; the message is one line naming file, line and field.

    A :class:`ValueError` (through :class:`gcalign.errors.ScenarioError`), so the command
    line reports it as bad input (exit code 2) without a traceback.
    """


# --------------------------------------------------------------------------- helpers


#: Compressed recordings (``x.imu.xz``), opened by the standard library.
COMPRESSED = {".gz": "gzip", ".xz": "lzma"}


def data_suffix(path: str | os.PathLike[str]) -> str:
    """The suffix that says what a file holds, under a compression suffix (x.imu.xz: .imu)."""
    suffixes = [x.lower() for x in Path(os.fspath(path)).suffixes]
    if suffixes and suffixes[-1] in COMPRESSED:
        suffixes = suffixes[:-1]
    return suffixes[-1] if suffixes else ""


#: The first bytes of each compressed format, to tell a damaged file from a misnamed one.
_MAGIC = {"gzip": b"\x1f\x8b", "lzma": b"\xfd7zXZ\x00"}
_SUFFIX_OF = {"gzip": ".gz", "lzma": ".xz"}
_BLOCK = 1 << 24  #: bytes decompressed at a time (the size limit is checked between blocks)
#: memory of a text table while it is parsed, per byte of text (measured: 3.5 for a 154 MB
#: CSV of IMU rows read by read_recording)
TEXT_PARSE_BYTES = 4.0


def _input_limit(name: str, size: float) -> None:
    """ScenarioError naming GCALIGN_MAX_INPUT_MB when `size` bytes exceed it."""
    from gcalign import limits

    limits.MAX_INPUT_MB.check(size / 2**20, name, "read a part of it, or split it")


def read_bytes(path, head: int | None = None, text: bool = False) -> tuple[str, bytes]:
    """``(name, content)`` of `path`, decompressed when it ends in ``.gz`` or ``.xz`` (the
    first `head` bytes only, when given).

    The size is bounded before anything is held: a file larger than
    ``GCALIGN_MAX_INPUT_MB`` is refused from its size on disk, a compressed one after at
    most that much has been decompressed, in blocks. With `text` (a table is expected), a
    NUL byte refuses the file at the block that holds it, and the memory the parse will
    take is held against ``GCALIGN_MAX_MEMORY_MB`` (:func:`text_of`): a 2 GB sparse file, or
    a small file of compressed zeros, is refused in seconds, naming the variable. Missing,
    unreadable, damaged or misnamed files (gzip data named ``.xz``, text named ``.gz``) are
    ImuFileError naming the file and what is wrong."""
    import importlib

    name = os.fspath(path)
    p = Path(name)
    if not p.is_file() and not p.is_dir():
        raise ImuFileError(f"{name}: {not_a_file(p)}")
    if p.is_dir():
        raise ImuFileError(f"{name}: is a directory, expected an IMU data file")
    compression = COMPRESSED.get(p.suffix.lower())
    try:
        if head is None:
            _input_limit(name, p.stat().st_size)
        with open(p, "rb") as raw:
            if compression is None:
                data = raw.read(-1 if head is None else head)
                if text and head is None:
                    _no_nul(name, data, 0)
                return name, data
            start = raw.read(8)
            raw.seek(0)
            _check_magic(name, compression, start)
            cap = head if head is not None else int(_max_input_bytes()) + 1
            out = bytearray()
            with importlib.import_module(compression).open(raw, "rb") as fh:
                while len(out) < cap:
                    block = fh.read(min(_BLOCK, cap - len(out)))
                    if not block:
                        break
                    if text and head is None:
                        _no_nul(name, block, len(out))
                    out += block
            if head is None and len(out) >= cap:
                _input_limit(f"{name} (decompressed, at least)", len(out))
            return name, bytes(out)
    except (ScenarioError, MemoryError):  # ours (the limits), or out of memory
        raise
    except Exception as exc:  # noqa: BLE001 - what a damaged compressed stream raises varies
        # (EOFError, lzma.LZMAError, zlib.error, gzip.BadGzipFile: an OSError without errno)
        if isinstance(exc, OSError) and (compression is None or exc.errno is not None):
            raise ImuFileError(f"{name}: cannot read file ({exc.strerror or exc})") from None
        if compression is None and not isinstance(exc, (EOFError, ValueError)):
            raise
        raise ImuFileError(f"{name}: damaged {_SUFFIX_OF[compression or 'lzma']} data, "
                           f"cannot decompress ({_why(exc)})") from None


def _no_nul(name: str, data: bytes, offset: int) -> None:
    if offset == 0 and data.startswith(_HDF5_MAGIC):
        raise ImuFileError(f"{name}: is an HDF5 file, not text (a gcalign results file is "
                           "read without format; a MAT v7.3 file: format psins-mat)")
    nul = data.find(b"\x00")
    if nul >= 0:
        raise ImuFileError(f"{name}: binary data (a NUL byte at offset {offset + nul}), not a "
                           "text table")


def _why(exc: BaseException) -> str:
    return (str(exc).splitlines() or [type(exc).__name__])[0][:80] or type(exc).__name__


def _max_input_bytes() -> float:
    from gcalign import limits

    return limits.MAX_INPUT_MB.value() * 2**20


def _check_magic(name: str, compression: str, start: bytes) -> None:
    """A file named ``.gz``/``.xz`` must start as that format does; one that starts as
    the other is misnamed, one that starts as neither is not compressed."""
    if start.startswith(_MAGIC[compression]):
        return
    other = next((c for c, m in _MAGIC.items() if start.startswith(m)), None)
    if other is not None:
        raise ImuFileError(f"{name}: holds {other} ({_SUFFIX_OF[other]}) data, not "
                           f"{_SUFFIX_OF[compression]}: rename it "
                           f"{Path(name).stem}{_SUFFIX_OF[other]}")
    if not start:
        raise ImuFileError(f"{name}: an empty file, not {_SUFFIX_OF[compression]} data")
    raise ImuFileError(f"{name}: not {_SUFFIX_OF[compression]} data (it starts with "
                       f"{start[:8]!r}); an uncompressed file is named without "
                       f"{_SUFFIX_OF[compression]}")


def text_of(name: str, data: bytes) -> str:
    """`data` as the text of a table: ImuFileError for binary content (a NUL byte: a
    sparse or binary file named as text), ScenarioError naming GCALIGN_MAX_MEMORY_MB when
    parsing it would need more memory than allowed."""
    from gcalign import limits

    _no_nul(name, data, 0)
    limits.MAX_MEMORY_MB.check(len(data) * TEXT_PARSE_BYTES / 2**20,
                               f"{name}: parsing {len(data) / 2**20:.4g} MB of text",
                               "read a part of it")
    return data.decode("utf-8", errors="replace")


def _read_lines(path) -> tuple[str, list[str]]:
    """Text lines of `path` (without line ends, decompressed if ``.gz``/``.xz``); missing
    or unreadable files -> ImuFileError."""
    name, data = read_bytes(path, text=True)
    return name, text_of(name, data).splitlines()


def _strip(line: str, comment: str) -> str:
    """The line without its trailing comment and surrounding blanks."""
    i = line.find(comment)
    return (line if i < 0 else line[:i]).strip()


def _fields(line: str, delimiter: str | None) -> list[str]:
    return [f.strip() for f in line.split(delimiter)] if delimiter else line.split()


def _to_float(name: str, lineno: int, col: int, what: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ImuFileError(
            f"{name}:{lineno}: field {col} ({what}) must be a number, got {text!r}"
        ) from None


def _diagnose(name, lines, start, ncols, comment, delimiter, labels) -> ImuFileError:
    """Find the first bad data line after a fast parse failed and describe it (slow path)."""
    for i in range(start, len(lines)):
        body = _strip(lines[i], comment)
        if not body:
            continue
        parts = _fields(body, delimiter)
        if len(parts) != ncols:
            return ImuFileError(
                f"{name}:{i + 1}: expected {ncols} columns ({', '.join(labels)}), got {len(parts)}"
            )
        for col, (part, label) in enumerate(zip(parts, labels, strict=True), start=1):
            _to_float(name, i + 1, col, label, part)
    return ImuFileError(f"{name}: cannot parse the data rows (no single bad line found)")


def _parse_block(name, lines, start, ncols, comment, delimiter, labels) -> np.ndarray:
    """Rows ``lines[start:]`` as an (N, ncols) float array; errors name the offending line."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data": ours below
            data = np.loadtxt(
                lines[start:], comments=comment, delimiter=delimiter, ndmin=2, dtype=float
            )
    except ValueError:
        raise _diagnose(name, lines, start, ncols, comment, delimiter, labels) from None
    if data.size == 0:
        raise ImuFileError(f"{name}: no data rows after line {start}, expected {ncols} columns")
    if data.shape[1] != ncols:
        # Consistent but wrong column count everywhere: report the first data line.
        raise _diagnose(name, lines, start, ncols, comment, delimiter, labels)
    _finite(name, data, labels, lambda k: f":{_data_lineno(lines, start, comment, k)}")
    return data


def _finite(name: str, a: np.ndarray, labels: Sequence[str], where: Callable[[int], str]
            ) -> None:
    """ImuFileError naming the row (`where(k)`) and the field of the first value of the
    table `a` that is not finite."""
    bad = ~np.isfinite(a)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise ImuFileError(f"{name}{where(int(row))}: field {col + 1} ({labels[col]}) must be "
                           f"finite, got {float(a[row, col])!r}")


def _data_lineno(lines: list[str], start: int, comment: str, row: int) -> int:
    """1-based file line of data row `row` (counting only non-blank, non-comment lines)."""
    k = -1
    for i in range(start, len(lines)):
        if _strip(lines[i], comment):
            k += 1
            if k == row:
                return i + 1
    return len(lines)


# --------------------------------------------------------------------------- checks

TS_RANGE_S = (1e-7, 10.0)  #: sample intervals accepted (10 MHz .. 0.1 Hz)
REGULAR_TOL = 0.05  #: each time step within ±5 % of the interval (jitter, not gaps)
MAX_DTHETA_RAD = math.pi  #: more than half a turn in one sample is aliasing, not data
MAX_DV_MPS = 1000.0  #: 1000 m/s in one sample is 100 000 g at 100 Hz


def check_increments(name: str, t, dtheta, dv, ts, where=None) -> None:
    """Recorded increments validated like a scenario: shapes, finite values, a positive
    interval in :data:`TS_RANGE_S`, time strictly increasing and regular within
    :data:`REGULAR_TOL`, increments within physical bounds.

    `where(k)` names data row k after the file name in messages (``:LINE`` for text files;
    default ``: row K``). Raises :class:`ImuFileError` naming the file and the row.
    """
    where = where or (lambda k: f": row {k + 1}")
    lo, hi = TS_RANGE_S
    if not (isinstance(ts, (int, float, np.floating)) and math.isfinite(ts) and lo <= ts <= hi):
        raise ImuFileError(f"{name}: sample interval must lie in [{lo:g}, {hi:g}] s, got "
                           f"{ts!r}")
    t, dtheta, dv = np.asarray(t), np.asarray(dtheta), np.asarray(dv)
    for label, a, shape in (("t", t, "(N,)"), ("dtheta", dtheta, "(N, 3)"),
                            ("dv", dv, "(N, 3)")):
        if a.dtype.kind not in "fiu":
            raise ImuFileError(f"{name}: {label} must hold numbers, got {a.dtype}")
        ok = a.ndim == 1 if shape == "(N,)" else (a.ndim == 2 and a.shape[1] == 3)
        if not ok or len(a) != len(t):
            raise ImuFileError(f"{name}: {label} must have shape {shape} with N = {len(t)} "
                               f"(the time stamps), got {a.shape}")
    if len(t) < 2:
        raise ImuFileError(f"{name}: {len(t)} sample(s); need at least 2")
    for label, a, bound, unit in (("t", t[:, None], None, "s"),
                                  ("dtheta", dtheta, MAX_DTHETA_RAD, "rad"),
                                  ("dv", dv, MAX_DV_MPS, "m/s")):
        bad = ~np.isfinite(a).all(1)
        if bad.any():
            k = int(np.argmax(bad))
            raise ImuFileError(f"{name}{where(k)}: {label} must be finite, got "
                               f"{a[k].tolist()}")
        if bound is not None:
            big = (np.abs(a) > bound).any(1)
            if big.any():
                k = int(np.argmax(big))
                raise ImuFileError(f"{name}{where(k)}: {label} {a[k].tolist()} exceeds "
                                   f"{bound:g} {unit} in one sample")
    _increasing(name, t, where)
    dt = np.diff(t.astype(float))
    off = np.abs(dt - ts) > REGULAR_TOL * ts
    if off.any():
        k = int(np.argmax(off)) + 1
        raise ImuFileError(
            f"{name}{where(k)}: time jumps from {float(t[k - 1])!r} to {float(t[k])!r} s, a step "
            f"of {float(dt[k - 1]):.6g} s where the interval is {ts:.6g} s (gaps and jitter "
            f"over {REGULAR_TOL:.0%} are not supported: split the file at the gap)")


def _increasing(name: str, t: np.ndarray, where: Callable[[int], str], got: str = "t = "
                ) -> None:
    """ImuFileError naming the row (`where(k)`) where the times `t` stop increasing."""
    dt = np.diff(t)
    if (dt <= 0).any():
        k = int(np.argmax(dt <= 0)) + 1
        raise ImuFileError(f"{name}{where(k)}: time must increase strictly, got {got}"
                           f"{float(t[k])!r} after {float(t[k - 1])!r}")


def _check_range(name: str, row: int, col: int, what: str, v: float, lo: float, hi: float,
                 open_ends: bool = False) -> None:
    ok = (lo < v < hi) if open_ends else (lo <= v <= hi)
    if not (math.isfinite(v) and ok):
        span = f"({lo:g}, {hi:g})" if open_ends else f"[{lo:g}, {hi:g}]"
        raise ImuFileError(f"{name}: header row {row} field {col} ({what}) must lie in "
                           f"{span}, got {v!r}")


# --------------------------------------------------------------------------- PSINS


def read_psins_imu(path) -> ImuData:
    """Read a PSINS text ``.imu`` file of integer increment counts.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    ImuData
        ``t`` (N,) s: ``t0 + ts · (1..N)``, end time of each increment; ``dtheta`` (N, 3)
        rad; ``dv`` (N, 3) m/s; ``ts`` s; ``site = [lat (rad), lon (rad), h (m)]``;
        ``att0 = [pitch, roll, yaw]`` (rad) and ``v0_n`` (ENU, m/s) from header 1 (the
        file calls them nominal, "maybe inaccurate"); ``source`` the path; ``meta`` all
        header values in the file's own units plus ``format="psins"``.

    Raises
    ------
    ImuFileError
        Missing file, a header row without six numbers, interval or g not positive,
        a sample row without six numbers, no samples.
    """
    name, lines = _read_lines(path)
    header: list[list[float]] = []
    i = 0
    while len(header) < 3 and i < len(lines):
        body = _strip(lines[i], "%")
        i += 1
        if not body:
            continue
        what, labels = _PSINS_HEADERS[len(header)]
        parts = body.split()
        if len(parts) != 6:
            raise ImuFileError(
                f"{name}:{i}: PSINS header row {len(header) + 1} ({what}) must have 6 numbers "
                f"({', '.join(labels)}), got {len(parts)}"
            )
        header.append([_to_float(name, i, c + 1, labels[c], s) for c, s in enumerate(parts)])
    if len(header) < 3:
        raise ImuFileError(
            f"{name}: PSINS file ends after {len(header)} of 3 header rows "
            "(initial state; site and timing; scale factors)"
        )
    (pitch, roll, yaw, ve, vn, vu), (lat, lon, h, t0, interval_ms, g), scales = header
    lo, hi = TS_RANGE_S
    for row, col, what, v, a, b, open_ends in (
            (1, 1, "pitch, deg", pitch, -90, 90, True), (1, 2, "roll, deg", roll, -180, 180,
                                                         False),
            (1, 3, "yaw, deg", yaw, -360, 360, False), (1, 4, "VE, m/s", ve, -1e4, 1e4, False),
            (1, 5, "VN, m/s", vn, -1e4, 1e4, False), (1, 6, "VU, m/s", vu, -1e4, 1e4, False),
            (2, 1, "latitude, deg", lat, -90, 90, True),
            (2, 2, "longitude, deg", lon, -180, 360, False),
            (2, 3, "height, m", h, -1000, 1e5, False), (2, 4, "t0, s", t0, -1e9, 1e9, False),
            (2, 5, "sampling interval, ms", interval_ms, lo * 1e3, hi * 1e3, False),
            (2, 6, "g, m/s²", g, 9.0, 10.5, False)):
        _check_range(name, row, col, what, v, a, b, open_ends)
    for col, v in enumerate(scales, start=1):
        _check_range(name, 3, col, "scale factor", v, 0, 1e6, open_ends=True)

    labels = ("gyro x", "gyro y", "gyro z", "accel x", "accel y", "accel z")
    counts = _parse_block(name, lines, i, 6, "%", None, labels)
    gyro_scale = np.asarray(scales[:3]) * ARCSEC  # rad per count
    accel_scale = np.asarray(scales[3:]) * 1e-6 * g  # µg·s per count -> m/s per count
    dtheta = counts[:, :3] * gyro_scale
    dv = counts[:, 3:] * accel_scale
    ts = interval_ms * 1e-3
    n = len(counts)
    t = t0 + ts * np.arange(1, n + 1)
    check_increments(name, t, dtheta, dv, ts, lambda k: f":{_data_lineno(lines, i, '%', k)}")
    meta = {
        "format": "psins",
        "att0_deg": [pitch, roll, yaw],
        "v0_n": [ve, vn, vu],
        "lat_deg": lat,
        "lon_deg": lon,
        "height_m": h,
        "t0_s": t0,
        "interval_ms": interval_ms,
        "g": g,
        "gyro_scale_arcsec": list(scales[:3]),
        "accel_scale_ugs": list(scales[3:]),
    }
    return ImuData(
        t=t,
        dtheta=dtheta,
        dv=dv,
        ts=ts,
        site=np.array([lat * DEG, lon * DEG, h]),
        att0=np.array([pitch, roll, yaw]) * DEG,
        v0_n=np.array([ve, vn, vu], dtype=float),
        source=name,
        meta=meta,
    )


# --------------------------------------------------------------------------- CSV


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def read_csv_imu(path, ts: float | None = None) -> ImuData:
    """Read ``t, Δθx, Δθy, Δθz, Δvx, Δvy, Δvz`` rows (s, rad, m/s) from a text/CSV file.

    Parameters
    ----------
    path : str or os.PathLike
        The file: comma- or whitespace-separated (decided from the first data line),
        ``#`` starts a comment, the first non-comment line may be a header of names.
    ts : float, optional
        Sample interval, s. Default: the median of the time differences (to 12
        significant digits).

    Returns
    -------
    ImuData
        ``t`` (N,) s as written (end time of each increment), ``dtheta`` (N, 3) rad,
        ``dv`` (N, 3) m/s, ``ts``; ``site``, ``att0``, ``v0_n`` are None; ``meta`` holds
        the header names (if any), the delimiter and the min/max time step.

    Raises
    ------
    ImuFileError
        Missing file, wrong column count, non-numeric or non-finite value, no data,
        time not strictly increasing, ``ts`` not positive, one row and no ``ts``.
    """
    name, lines = _read_lines(path)
    i = 0
    while i < len(lines) and not _strip(lines[i], "#"):
        i += 1
    if i == len(lines):
        raise ImuFileError(f"{name}: no data rows, expected 7 columns ({', '.join(_CSV_COLUMNS)})")
    first = _strip(lines[i], "#")
    delimiter = "," if "," in first else None
    names = None
    parts = _fields(first, delimiter)
    if any(c.isalpha() for c in first) and not any(map(_is_number, parts)):  # a header row
        names, i = parts, i + 1
    data = _parse_block(name, lines, i, 7, "#", delimiter, _CSV_COLUMNS)
    t = data[:, 0].copy()
    dt = np.diff(t)
    _increasing(name, t, lambda k: f":{_data_lineno(lines, i, '#', k)}")
    if ts is None:
        if len(t) < 2:
            raise ImuFileError(f"{name}: one sample only, cannot infer ts; pass ts explicitly")
        # Median step, rounded to 12 significant digits: decimal time stamps such as
        # 0.01, 0.02, ... give ts = 0.01 rather than 0.009999999999999998.
        ts = float(f"{np.median(dt):.12g}")
    ts = float(ts)
    if not (math.isfinite(ts) and ts > 0):
        raise ImuFileError(f"{name}: sample interval ts must be > 0 s, got {ts!r}")
    check_increments(name, t, data[:, 1:4], data[:, 4:7], ts,
                     lambda k: f":{_data_lineno(lines, i, '#', k)}")
    meta = {
        "format": "csv",
        "columns": names,
        "delimiter": delimiter or "whitespace",
        "dt_min": float(dt.min()) if len(dt) else ts,
        "dt_max": float(dt.max()) if len(dt) else ts,
    }
    return ImuData(
        t=t,
        dtheta=np.ascontiguousarray(data[:, 1:4]),
        dv=np.ascontiguousarray(data[:, 4:7]),
        ts=ts,
        source=name,
        meta=meta,
    )


def write_csv_imu(path, imu: ImuData) -> None:
    """Write `imu` as CSV ``t, Δθx, Δθy, Δθz, Δvx, Δvy, Δvz`` with a header line.

    Values are written with 17 significant digits, so :func:`read_csv_imu` gives back
    the same float64 numbers bit for bit.
    """
    data = np.column_stack([imu.t, imu.dtheta, imu.dv])
    with open(os.fspath(path), "w", encoding="utf-8") as fh:
        fh.write(
            "# gcalign IMU increments: t s, dtheta rad, dv m/s; body x right, y forward, z up; "
            f"ts = {imu.ts!r}; source = {imu.source}\n"
        )
        fh.write(",".join(_CSV_COLUMNS) + "\n")
        np.savetxt(fh, data, fmt="%.17g", delimiter=",")


# --------------------------------------------------------------------------- dispatch


def read_imu_file(path, ts: float | None = None) -> ImuData:
    """Read IMU increments from a PSINS ``.imu`` or a text/CSV file, plain or compressed
    (``.gz``, ``.xz``: ``lasergyro.imu.xz``).

    Dispatch as :func:`guess_format` (``.imu`` or a ``%`` first line: :func:`read_psins_imu`;
    otherwise :func:`read_csv_imu`); HDF5 (by extension or signature) ->
    :class:`ImuFileError` (read by the results layer). `ts` is passed to the CSV reader only
    (PSINS files carry their own interval). Other layouts (MAT files, KF-GINS text, rates,
    other body axes) are read by :func:`gcalign.io.recorded.read_recording`.
    """
    name = os.fspath(path)
    p = Path(name)
    suffix = data_suffix(p)
    if suffix in (".h5", ".hdf5", ".hdf"):
        raise ImuFileError(
            f"{name}: HDF5 IMU files (from `gcalign simulate`) are read by the results "
            "module, not by read_imu_file; expected a PSINS .imu or a .csv/.txt file"
        )
    if suffix not in (".imu", ".csv", ".txt") and p.is_file() and \
            read_bytes(p, head=8)[1].startswith(_HDF5_MAGIC):
        raise ImuFileError(
            f"{name}: is an HDF5 file; HDF5 IMU data is read by the results module, "
            "expected a PSINS .imu or a .csv/.txt file"
        )
    return read_psins_imu(p) if guess_format(p) == "psins" else read_csv_imu(p, ts=ts)


def guess_format(path: str | os.PathLike[str]) -> str:
    """The format a file's name (or signature) implies: ``.imu`` psins, ``.mat`` psins-mat,
    otherwise csv (a ``%`` first line: psins)."""
    suffix = data_suffix(path)
    if suffix == ".imu":
        return "psins"
    if suffix == ".mat":
        return "psins-mat"
    if suffix in (".csv", ".txt"):
        return "csv"
    try:
        _, head = read_bytes(path, head=4096)
    except ImuFileError:
        return "csv"
    first = next((ln.strip() for ln in head[:4096].decode("utf-8", "replace").splitlines()
                  if ln.strip()), "")
    return "psins" if first.startswith("%") else "csv"
