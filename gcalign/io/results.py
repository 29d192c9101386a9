"""The HDF5 results file: one schema, written atomically, readable without gcalign.

Layout (docs: Reference, Results file): root attributes ``gcalign_version``, ``kind`` (the command),
``command_line``, ``scenario_yaml`` (the scenario text), ``seed``, ``created_utc`` and
``summary_json`` (what ``gcalign show`` prints); groups ``/truth``, ``/imu``, ``/navigate``,
``/align``, ``/northfind``, ``/batch``. Every dataset carries a ``units`` attribute and,
where it applies, a ``frame`` attribute. Arrays are SI, time along axis 0.
"""

from __future__ import annotations

import errno
import json
import math
import os
import re
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from gcalign._version import __version__
from gcalign.errors import GcalignError, ScenarioError, check_terminated, clip
from gcalign.io.paths import not_a_file
from gcalign.limits import SEED_MAX
from gcalign.schema import ATT_FRAME as ATT_FRAME  # the frame texts, for the writers
from gcalign.schema import PHI_FRAME as PHI_FRAME
from gcalign.sim.imu import ImuData
from gcalign.sim.motions import Truth

HDF5_SUFFIXES = {".h5", ".hdf5", ".hdf"}  #: file names read as our results files


TMP_SUFFIX = ".gcalign-tmp"  #: temporary files: .NAME.PID.RANDOM.gcalign-tmp
_TMP_NAME = re.compile(r"^\..+\.(\d+)\.[^.]+" + re.escape(TMP_SUFFIX) + "$")
_OLD_TMP_NAME = re.compile(r"^\..+\.h5\.(\d+)\.tmp$")  # before mkstemp: .NAME.PID.tmp
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_WRITE_ERRNOS = {errno.ENOSPC, errno.EFBIG, errno.EDQUOT, errno.EIO}


def check_output(path, what: str = "--output") -> Path:
    """`path` as the name of a new results file; ScenarioError (exit 2) before any work if it
    names a directory (``-o ''`` and ``-o .`` included), a special file, or lies under a
    file."""
    p = Path(path)
    if not str(path).strip() or p.name in ("", ".", ".."):
        raise ScenarioError(f"{what}: {str(path)!r} is not a file name; give one such as "
                            "runs/result.h5")
    if p.is_dir():
        raise ScenarioError(f"{what}: {p} is a directory; give a file name (e.g. "
                            f"{p / 'result.h5'})")
    if p.exists() and not p.is_file() and not p.is_symlink():
        raise ScenarioError(f"{what}: {p} exists and is not a regular file")
    parent = _existing(p.parent)
    if parent.exists() and not parent.is_dir():
        raise ScenarioError(f"{what}: {parent} is not a directory, so {p} cannot be written")
    return p


def check_output_dir(path, what: str = "--output") -> Path:
    """`path` as a folder for figures (made if missing); ScenarioError (exit 2) if it, or a
    folder above it, exists and is not a folder, or it cannot be made."""
    p = Path(path)
    if not str(path).strip():
        raise ScenarioError(f"{what}: an empty path; give a folder for the figures")
    if p.exists() and not p.is_dir():
        raise ScenarioError(f"{what}: {p} exists and is not a folder; give a folder for the "
                            "figures")
    parent = _existing(p)
    if not parent.is_dir():
        raise ScenarioError(f"{what}: {parent} is not a folder, so {p} cannot be made")
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise write_error(p, err) from None
    return p


def _existing(p: Path) -> Path:
    """`p`, or the nearest folder above it that exists (the root at the latest)."""
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_stale_temps(folder: Path) -> list[Path]:
    """Remove our temporary files in `folder` whose process is gone (SIGKILL, power loss);
    files of live processes are kept. Returns what was removed."""
    removed: list[Path] = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    for p in entries:
        m = _TMP_NAME.match(p.name) or _OLD_TMP_NAME.match(p.name)
        if m and int(m.group(1)) != os.getpid() and not _alive(int(m.group(1))):
            try:
                if p.is_file() and not p.is_symlink() and (
                        p.name.endswith(TMP_SUFFIX) or is_hdf5(p)):
                    p.unlink()
                    removed.append(p)
            except OSError:
                pass
    return removed


def is_hdf5(p: Path) -> bool:
    """Whether the file at `p` starts with the HDF5 signature."""
    with open(p, "rb") as f:
        return f.read(8) == _HDF5_SIGNATURE


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def make_temp(path: Path) -> tuple[int, Path]:
    """A new, exclusively created temporary file beside `path` (mkstemp: a random name, so
    nothing placed there beforehand, a symlink say, is followed); stale ones of dead
    processes are removed first. OSError as GcalignError/ScenarioError (one line)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        clean_stale_temps(path.parent)
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=TMP_SUFFIX,
                                    dir=path.parent)
        try:  # mkstemp makes it private (0600); the renamed file is an ordinary one
            os.fchmod(fd, 0o666 & ~_umask())
        except BaseException:  # SIGTERM raises here too: leave no temporary file
            os.close(fd)
            os.unlink(name)
            raise
    except OSError as err:
        raise write_error(path, err) from None
    return fd, Path(name)


def write_error(path: Path, err: BaseException) -> GcalignError:
    """One line for a failure to write `path`: exit 1 for a full disk, a file-size limit
    or an I/O error (the run was fine; free space and rerun), exit 2 for a path that cannot
    be written (permissions, read-only file system, name too long)."""
    code = getattr(err, "errno", None)
    if code is None:  # h5py wraps the C library's errno in the message
        m = re.search(r"errno = (\d+)", str(err))
        code = int(m.group(1)) if m else None
    reason = os.strerror(code) if code else (str(err).splitlines() or ["write failed"])[0]
    if code in _WRITE_ERRNOS or code is None:
        return GcalignError(f"cannot write {path}: {reason}; nothing was kept under that name")
    return ScenarioError(f"--output: cannot write {path}: {reason}")


class _GuardedFile:
    """The temporary file as HDF5 sees it (h5py's ``fileobj`` driver), written with
    ``pwrite``/``pread`` through the descriptor that mkstemp created (so no other file can be
    written instead).

    A write the file system refuses (full disk, ``ulimit -f``) is recorded and reported to
    HDF5 as success: HDF5 reports an error met halfway only while freeing objects, or by
    crashing. From then on the file as HDF5 sees it is the part on disk overlaid by the
    pages written since (held in memory), so that what HDF5 reads back is what it wrote: it
    read zero bytes of metadata it believed written and crashed (``observability`` under
    ``ulimit -f 256``: a segmentation fault). :func:`atomic_h5` raises the recorded error
    once HDF5 is done, and :func:`check_writes`, called by every writer of this module
    (:func:`put`, :class:`Series`, :func:`write_header`, :func:`write_recording`) and by
    :func:`gcalign.io.stored.write_fields` at each group, stops the run at its next write,
    so that the pages held stay about one dataset. Reads past the end are zeros, as HDF5's
    own POSIX driver gives them."""

    PAGE = 1 << 16

    def __init__(self, fd: int):
        self.fd = fd
        self.pos = 0
        self.error: OSError | None = None
        self.closed = False
        self._pages: dict[int, bytearray] = {}
        self._size = 0  # the file's size as HDF5 sees it, once a write was refused

    # Once a failed run has closed (and deleted) the file, HDF5 may still free objects that
    # write or truncate through here (a SIGTERM landing inside h5py): nothing to do then,
    # and an exception would only be printed as "Exception ignored".

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            os.close(self.fd)

    def _refuse(self, err: OSError) -> None:
        if self.error is None:
            self.error = err
            self._size = os.fstat(self.fd).st_size

    def write(self, b) -> int:
        data = memoryview(b).cast("B")
        n = len(data)
        if self.closed:
            return n
        done = 0
        while self.error is None and done < n:
            try:
                k = os.pwrite(self.fd, data[done:], self.pos + done)
            except OSError as err:
                self._refuse(err)
                break
            if k <= 0:
                self._refuse(OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)))
                break
            done += k
        if done < n:
            self._hold(self.pos + done, data[done:])
        self.pos += n
        return n

    def _page(self, k: int) -> bytearray:
        page = self._pages.get(k)
        if page is None:
            page = bytearray(self.PAGE)
            self._from_disk(k * self.PAGE, memoryview(page))
            self._pages[k] = page
        return page

    def _from_disk(self, offset: int, out: memoryview) -> int:
        """Read into `out` from the disk at `offset`; zeros past the end (or if the disk
        refuses). Returns len(out)."""
        done = 0
        while done < len(out):
            try:
                k = os.preadv(self.fd, [out[done:]], offset + done)
            except OSError:
                k = 0
            if k <= 0:
                out[done:] = bytes(len(out) - done)
                break
            done += k
        return len(out)

    def _hold(self, offset: int, data: memoryview) -> None:
        end = offset + len(data)
        while offset < end:
            k, at = divmod(offset, self.PAGE)
            m = min(self.PAGE - at, end - offset)
            self._page(k)[at:at + m] = data[:m]
            data = data[m:]
            offset += m
        self._size = max(self._size, end)

    def readinto(self, b) -> int:
        out = memoryview(b).cast("B")
        if self.closed:
            return 0
        n = len(out)
        if self.error is None:
            self._from_disk(self.pos, out)
        else:
            offset, done = self.pos, 0
            while done < n:
                k, at = divmod(offset + done, self.PAGE)
                m = min(self.PAGE - at, n - done)
                page = self._pages.get(k)
                if page is None:
                    self._from_disk(offset + done, out[done:done + m])
                else:
                    out[done:done + m] = page[at:at + m]
                done += m
            past = min(max(self._size - offset, 0), n)  # what lies past the end is zeros
            out[past:] = bytes(n - past)
        self.pos += n
        return n

    def read(self, n=-1) -> bytes:
        if self.closed:
            return b""
        if n is None or n < 0:
            n = max(self._end() - self.pos, 0)
        buf = bytearray(n)
        self.readinto(buf)
        return bytes(buf)

    def _end(self) -> int:
        return self._size if self.error is not None else os.fstat(self.fd).st_size

    def seek(self, offset, whence=0) -> int:
        if self.closed:
            return 0
        base = {0: 0, 1: self.pos, 2: self._end()}[whence]
        self.pos = base + offset
        return self.pos

    def tell(self) -> int:
        return 0 if self.closed else self.pos

    def truncate(self, size=None):
        size = self.pos if size is None else size
        if self.closed:
            return size
        if self.error is None:
            try:
                os.ftruncate(self.fd, size)
                return size
            except OSError as err:
                self._refuse(err)
        self._size = size
        for k in [k for k in self._pages if k * self.PAGE >= size]:
            del self._pages[k]
        k, at = divmod(size, self.PAGE)
        if k in self._pages:  # a later write past a gap must find zeros there
            self._pages[k][at:] = bytes(self.PAGE - at)
        return size

    def flush(self) -> None:
        """Nothing is buffered here (``pwrite``)."""


#: (path, guard) of the results files open for writing in this process (atomic_h5)
_WRITING: list[tuple[Path, _GuardedFile]] = []


def check_writes() -> None:
    """Stop a run whose results file the file system refused: the write error (one line,
    exit 1) if a file open by :func:`atomic_h5` met one. Every writer of this module asks
    before it writes, so that a full disk ends the run at its next dataset, not after it."""
    for path, guard in _WRITING:
        if guard.error is not None:
            raise write_error(path, guard.error)


@contextmanager
def atomic_h5(path: Path) -> Iterator[h5py.File]:
    """Open `path` for writing under a temporary name; rename on success, delete on failure.

    An interrupted or failed run therefore never leaves a truncated file under the final
    name, and never a temporary file either (a SIGKILL's is removed by the next run into
    that folder). The temporary file is created exclusively (:func:`make_temp`) and written
    through its own descriptor (:class:`_GuardedFile`); a write refused by the file system
    (full disk, ``ulimit -f``) becomes one line (:func:`write_error`), whatever HDF5 was
    doing when it met it.
    """
    path = check_output(path)
    fd, tmp = make_temp(path)
    guard: _GuardedFile | None = None
    f = None
    try:  # everything after the file exists, so that a SIGTERM anywhere removes it
        guard = _GuardedFile(fd)
        _WRITING.append((path, guard))
        f = h5py.File(guard, "w")
        yield f
        f.close()
        f = None
        guard.close()
        if guard.error is not None:
            raise guard.error
        check_terminated()  # a SIGTERM whose exception a finaliser swallowed
        os.replace(tmp, path)
    except BaseException as err:
        try:
            if f is not None:
                f.close()  # HDF5 flushes into the guard: consistent even after a refusal
        except Exception:  # noqa: BLE001 - the file is deleted anyway
            pass
        if guard is None:
            os.close(fd)
        else:
            guard.close()
        tmp.unlink(missing_ok=True)
        refused = guard.error if guard is not None else None
        if isinstance(err, (GcalignError, KeyboardInterrupt, SystemExit)):
            raise
        if refused is not None:
            raise write_error(path, refused) from None
        if isinstance(err, OSError) and err.errno in _WRITE_ERRNOS:
            raise write_error(path, err) from None
        raise
    finally:
        if guard is not None:
            _WRITING.remove((path, guard))


class _RefusableStream:
    """A file of :func:`atomic_file` as its writers see it: a write, flush or close that the
    file system refuses raises :func:`write_error` (one line), not an OSError that would
    read as a bug."""

    def __init__(self, fh, path: Path):
        self._fh = fh
        self._path = path

    def _call(self, name: str, *args):
        try:
            return getattr(self._fh, name)(*args)
        except OSError as err:
            raise write_error(self._path, err) from None

    def write(self, data):
        return self._call("write", data)

    def flush(self) -> None:
        self._call("flush")

    def close(self) -> None:
        self._call("close")

    def seek(self, *args):
        return self._call("seek", *args)

    def tell(self):
        return self._call("tell")

    def __getattr__(self, name: str):
        return getattr(self._fh, name)


@contextmanager
def atomic_file(path, mode: str = "wb") -> Iterator:
    """A results file other than HDF5 (export's CSV, MAT and text files), written as
    :func:`atomic_h5` writes HDF5: under a temporary name made by :func:`make_temp`, through
    its descriptor, renamed on success and removed on any failure; a write the file system
    refuses (full disk, ``ulimit -f``) is one line (:func:`write_error`). `mode` is ``wb``
    or ``w`` (UTF-8 text)."""
    path = check_output(path)
    fd, tmp = make_temp(path)
    try:
        fh = os.fdopen(fd, mode, encoding=None if "b" in mode else "utf-8")
    except BaseException:
        os.close(fd)
        tmp.unlink(missing_ok=True)
        raise
    stream = _RefusableStream(fh, path)
    try:
        yield stream
        stream.close()
        check_terminated()  # a SIGTERM whose exception a finaliser swallowed
        os.replace(tmp, path)
    except BaseException:
        try:
            fh.close()
        except OSError:
            pass
        tmp.unlink(missing_ok=True)
        raise


def finite_summary(summary, where: str) -> None:
    """GcalignError (exit 1) naming the first quantity of a run summary that is NaN or
    infinite: a result that is not finite is a failure, never a silent exit 0."""
    stack: list[tuple[str, object]] = [("", summary)]
    while stack:
        key, x = stack.pop()
        if isinstance(x, float) and not math.isfinite(x):
            raise GcalignError(f"{where}: the result {key or 'value'} is {x} (not finite); the "
                               "computation diverged (check the loop settings and the sensor "
                               "errors, or the data)")
        if isinstance(x, dict):
            stack.extend((f"{key}.{k}" if key else str(k), v) for k, v in reversed(x.items()))
        elif isinstance(x, (list, tuple)):
            stack.extend((f"{key}.{i}" if key else str(i), v) for i, v in
                         reversed(list(enumerate(x))))


def put(group: h5py.Group, name: str, data, units: str, frame: str | None = None,
        create: Any = None, **attrs):
    """Write one dataset with its units (and frame) attributes; `create`: h5py's
    ``create_dataset`` options (compression, …)."""
    check_writes()
    ds = group.create_dataset(name, data=np.asarray(data), **(create or {}))
    ds.attrs["units"] = units
    if frame:
        ds.attrs["frame"] = frame
    ds.attrs.update(attrs)
    return ds


def write_segments(f: h5py.File, truth, segments) -> None:
    """/truth/segment_names: the manoeuvres that /truth/segment indexes."""
    if "truth" not in f or truth is None:
        return
    check_writes()
    f["truth"].create_dataset("segment_names", data=np.array([s.name for s in segments],
                                                             dtype=h5py.string_dtype()))


class Series:
    """Datasets that grow block by block: chunked, compressed (gzip + shuffle), resizable
    along axis 0, each with its units (and frame) attribute. ``append(name=array, …)``
    adds rows to every named dataset; ``flush()`` (required once, after the last append)
    writes what is still held.

    Rows are held until a whole chunk is ready, so each chunk is compressed and written
    once: appending a few hundred rows at a time straight to the file recompresses the
    open chunk on every resize (4.3 s instead of 0.4 s for 259 200 rows of three columns).
    Memory is bounded by one chunk per dataset; the file never holds a run's series in
    memory."""

    def __init__(self, group: h5py.Group, spec: dict[str, tuple[int | None, str, str | None]],
                 chunk_rows: int = 4096, **attrs):
        self.group = group
        self.chunk_rows = chunk_rows
        self._held: dict[str, list[np.ndarray]] = {name: [] for name in spec}
        self._datasets: dict[str, h5py.Dataset] = {}
        for name, (width, units, frame) in spec.items():
            shape = (0,) if width is None else (0, width)
            self._datasets[name] = put(group, name, np.empty(shape), units, frame, create={
                "maxshape": (None,) + shape[1:], "chunks": (chunk_rows,) + shape[1:],
                "compression": "gzip", "compression_opts": 4, "shuffle": True})
        group.attrs.update(attrs)

    def append(self, **arrays) -> None:
        for name, a in arrays.items():
            self._held[name].append(np.array(a, dtype=float))
            if sum(map(len, self._held[name])) >= self.chunk_rows:
                self._write(name, whole_chunks=True)

    def flush(self) -> None:
        for name in self._held:
            self._write(name, whole_chunks=False)

    def _write(self, name: str, whole_chunks: bool) -> None:
        held = self._held[name]
        if not held:
            return
        check_writes()
        rows = np.concatenate(held) if len(held) > 1 else held[0]
        n = len(rows) - len(rows) % self.chunk_rows if whole_chunks else len(rows)
        ds = self._datasets[name]
        m = ds.shape[0]
        ds.resize(m + n, axis=0)
        ds[m:] = rows[:n]
        self._held[name] = [rows[n:]] if n < len(rows) else []


def write_header(f: h5py.File, kind: str, scenario_yaml: str, seed: int | None, summary: dict):
    """Root attributes; GcalignError if the summary holds a number that is not finite."""
    check_writes()
    finite_summary(summary, kind)
    if seed is not None and not 0 <= int(seed) <= SEED_MAX:
        raise ScenarioError(f"seed: must be within [0, 2^63), got {_short(seed)}")
    f.attrs["gcalign_version"] = __version__
    f.attrs["kind"] = kind
    f.attrs["command_line"] = " ".join(["gcalign", *sys.argv[1:]])
    f.attrs["scenario_yaml"] = scenario_yaml
    f.attrs["seed"] = -1 if seed is None else int(seed)
    f.attrs["created_utc"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
    f.attrs["summary_json"] = json.dumps(summary)


def write_recording(f: h5py.File, record: dict) -> None:
    """``/recording``: what the reader of a recorded file assumed (format, axes, units, time
    origin, rate, gaps, gravity check; :func:`gcalign.io.recorded.read_recording`), one
    attribute per entry (text, number, or JSON for lists and mappings) and the whole
    record as ``record_json``."""
    check_writes()
    g = f.create_group("recording")
    for key, value in record.items():
        if isinstance(value, (str, int, float)) and not isinstance(value, bool):
            g.attrs[key] = value
        elif value is not None:
            g.attrs[key] = json.dumps(value)
    g.attrs["record_json"] = json.dumps(record)


def _raised_in_h5py(err: BaseException) -> bool:
    """Whether `err` was raised inside h5py or HDF5 (its last frame is h5py's)."""
    tb = err.__traceback__
    last = None
    while tb is not None:
        last = tb.tb_frame.f_code.co_filename
        tb = tb.tb_next
    return last is not None and re.search(r"(^|[/\\])h5py[/\\]", last) is not None


def _damaged_file(path: Path, err: BaseException) -> ScenarioError:
    why = (str(err).splitlines() or [type(err).__name__])[0][:100]
    return ScenarioError(f"{path}: a damaged HDF5 file: {type(err).__name__}: {why} (not as "
                         "gcalign wrote it; write it again)")


class _ResultsFile(h5py.File):
    """A results file open for reading: what HDF5 raises while it reads a damaged file
    (a corrupt object header, a block past the end: RuntimeError, OSError, KeyError from
    inside h5py) leaves the ``with`` as one ScenarioError naming the file, not as an
    internal error. Errors of ours, and any not raised inside h5py, pass unchanged."""

    _gcalign_path: Path

    def __exit__(self, *exc):
        super().__exit__(*exc)
        err = exc[1]
        if (isinstance(err, Exception) and not isinstance(err, (GcalignError, MemoryError))
                and _raised_in_h5py(err)):
            raise _damaged_file(self._gcalign_path, err) from None


#: Files whose metadata a child process read through: (resolved path, mtime, size)
_PROBED: set[tuple[str, int, int]] = set()
PROBE_S = 5.0  #: the metadata probe's time, plus 1 s per 100 MB of file


def _touch(f: h5py.File) -> None:
    """Read what HDF5 keeps beside the numbers: every object header, every attribute, every
    dataset of text (vlen strings live in the global heap), every dataset's shape."""
    def visit(_, obj):
        for key in obj.attrs:
            obj.attrs[key]
        if isinstance(obj, h5py.Dataset):
            _ = obj.shape
            if obj.dtype.kind == "O" or h5py.check_string_dtype(obj.dtype) is not None:
                obj[()]

    visit("/", f)
    f.visititems(visit)


def _probe(path: Path) -> None:
    """Read the metadata of `path` once in a forked child with a time limit: a damaged
    global heap sent HDF5 into an endless loop while it read one attribute (a length field
    of ~2^64), which no Python code can interrupt, and a damaged file may crash HDF5. The
    parent reads the file only if the child got through; otherwise ScenarioError naming the
    file. Errors HDF5 raises are left to the reader that meets them (one line, by
    :class:`_ResultsFile`)."""
    import signal
    import time

    st = path.stat()
    key = (str(path.resolve()), st.st_mtime_ns, st.st_size)
    if key in _PROBED or not hasattr(os, "fork"):
        return
    limit = PROBE_S + st.st_size / 100e6
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        try:
            with h5py.File(path, "r") as f:
                _touch(f)
        except BaseException:  # noqa: BLE001 - an error is the parent's to meet and report
            pass
        os._exit(0)
    try:
        deadline = time.monotonic() + limit
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                break
            if time.monotonic() > deadline:
                raise ScenarioError(f"{path}: a damaged HDF5 file: HDF5 did not get through "
                                    f"its metadata in {limit:.3g} s (not as gcalign wrote it; "
                                    "write it again)")
            time.sleep(0.005)
    finally:
        if not done:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        raise ScenarioError(f"{path}: a damaged HDF5 file: HDF5 crashed reading its metadata "
                            f"(signal {os.WTERMSIG(status)}; not as gcalign wrote it)")
    _PROBED.add(key)


def open_results(path: Path) -> h5py.File:
    """Open a gcalign results file for reading; ScenarioError if it is missing or not ours,
    if its metadata cannot be read through in time (:func:`_probe`), and, used in a
    ``with``, if HDF5 meets damage while reading it (:class:`_ResultsFile`)."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: {not_a_file(path)}")
    if is_hdf5(path):
        _probe(path)
    try:
        f = _ResultsFile(path, "r")
    except OSError:
        raise ScenarioError(f"{path}: not an HDF5 file (expected a gcalign results file)") from None
    f._gcalign_path = path
    try:
        ours = "gcalign_version" in f.attrs
    except Exception as err:  # noqa: BLE001 - a damaged root object, raised by HDF5
        f.close()
        if isinstance(err, MemoryError) or not _raised_in_h5py(err):
            raise
        raise _damaged_file(path, err) from None
    if not ours:
        f.close()
        raise ScenarioError(
            f"{path}: an HDF5 file, but not a gcalign results file (no 'gcalign_version' attribute)"
        )
    return f


def _short(value, n: int = 60) -> str:
    return clip(repr(value), n)


def text_attr(obj, name: str, path: Path) -> str:
    """A text attribute of a results file (root or group); ScenarioError naming the file and
    the attribute when it is missing or not text."""
    where = "root" if obj.name == "/" else obj.name
    if name not in obj.attrs:
        raise ScenarioError(f"{path}: {where} attribute {name!r} missing (a damaged or "
                            "incomplete gcalign results file)")
    v = obj.attrs[name]
    if isinstance(v, bytes):
        try:
            v = v.decode("utf-8")
        except UnicodeDecodeError:
            raise ScenarioError(f"{path}: {where} attribute {name!r} is not UTF-8 text") from None
    if not isinstance(v, str):
        raise ScenarioError(f"{path}: {where} attribute {name!r} must be text, got "
                            f"{_short(v)}")
    return v


def read_summary(path: Path) -> tuple[str, dict, dict]:
    """``(kind, summary, root attributes)`` of a results file; ScenarioError naming the file
    and the attribute if ``kind`` or ``summary_json`` is missing or invalid."""
    with open_results(path) as f:
        kind = text_attr(f, "kind", path)
        text = text_attr(f, "summary_json", path)
        attrs = {k: (v.decode("utf-8", "replace") if isinstance(v, bytes) else v)
                 for k, v in f.attrs.items()}
    if not re.fullmatch(r"[a-z][a-z_0-9-]{0,40}", kind):
        raise ScenarioError(f"{path}: root attribute 'kind' must name a command, got "
                            f"{_short(kind)}")
    try:
        summary = json.loads(text)
    except ValueError as err:
        raise ScenarioError(f"{path}: root attribute 'summary_json' is not valid JSON "
                            f"({getattr(err, 'msg', err)})") from None
    if not isinstance(summary, dict):
        raise ScenarioError(f"{path}: root attribute 'summary_json' must be a JSON object, got "
                            f"{type(summary).__name__}")
    return kind, summary, attrs


def check_layout(path: Path, kind: str, groups: tuple[str, ...], strict: bool = True) -> None:
    """The reader check of a results file of `kind`: ScenarioError naming the file and the
    dataset when a group the kind writes (`groups`, its command's ``layout``; ``/truth`` may
    be absent) is missing, or a dataset under them is damaged: numbers without their
    ``units`` attribute (every dataset gcalign writes has one; text has none or ``none``),
    text or other types where numbers were written, values that are not finite, a time
    ``t`` that is not strictly monotonic (a zeroed chunk). Without `strict` (kinds that
    store NaN, and whose groups have readers of their own: ``/imu``, ``/truth``), only the
    groups and the types are checked."""
    with open_results(path) as f:
        for name in groups:
            g = f.get(name)
            if not isinstance(g, h5py.Group):
                if name == "truth" and g is None:
                    continue
                have = ", ".join(k for k in f if isinstance(f[k], h5py.Group)) or "none"
                raise ScenarioError(f"{path}: a {kind!r} results file needs its /{name} group; "
                                    f"it has {have}")
            problem: list[str] = []

            def visit(_: str, ds, problem=problem) -> None:
                if problem or not isinstance(ds, h5py.Dataset):
                    return
                why = _damaged(ds, strict)
                if why:
                    problem.append(f"{path}: dataset {ds.name} {why}")

            g.visititems(visit)
            if problem:
                raise ScenarioError(problem[0])


_TIMES = ("t", "t0", "t1")  #: datasets of times, strictly monotonic


def _damaged(ds: h5py.Dataset, strict: bool) -> str:
    """What is wrong with one dataset of a results file ('' when nothing is)."""
    units = ds.attrs.get("units")
    if h5py.check_string_dtype(ds.dtype) is not None or ds.dtype.kind == "O":
        return "" if units in (None, "", "none", b"", b"none") else (
            f"must hold numbers (units {_short(units)}), got text")
    if ds.dtype.kind not in "fiub":
        return f"must hold numbers, got {ds.dtype}"
    if not strict:
        if ds.compression is None or not ds.size:
            return ""
        try:  # a compressed block that does not decompress fails only when read
            ds[()]
        except OSError as err:
            return _unreadable(err)
        return ""
    if units is None:
        return "has no 'units' attribute (not as gcalign wrote it)"
    if ds.dtype.kind == "f" and ds.size:
        try:
            a = ds[()]
        except OSError as err:
            return _unreadable(err)
        if not np.isfinite(a).all():
            bad = np.argwhere(~np.isfinite(np.atleast_1d(a)))[0].tolist()
            return f"holds a value that is not finite at {bad}"
        step = np.sign(np.diff(a)) if a.ndim == 1 else None
        if ds.name.rsplit("/", 1)[-1] in _TIMES and step is not None and len(step) and (
                step[0] == 0 or np.any(step != step[0])):  # a reverse pass runs backwards
            i = int(np.argmax(step != step[0])) if step[0] else 0
            return (f"(time) is not strictly monotonic at row {i + 1}: {float(a[i])!r} then "
                    f"{float(a[i + 1])!r}")
    return ""


def _unreadable(err: OSError) -> str:
    """The words for a dataset HDF5 cannot read back (a damaged compressed block)."""
    why = (str(err).splitlines() or ["read failed"])[0]
    return f"cannot be read: its stored data is damaged ({why[:80]})"


def read_dataset(ds: h5py.Dataset, path) -> np.ndarray:
    """``ds[()]``; ScenarioError naming the file and the dataset when HDF5 cannot read it
    (a compressed block that does not decompress: "internal error" before)."""
    try:
        return ds[()]
    except OSError as err:
        raise ScenarioError(f"{path}: dataset {ds.name} {_unreadable(err)}") from None


def _dataset(g, name: str, path: Path) -> np.ndarray:
    if name not in g or not isinstance(g[name], h5py.Dataset):
        raise ScenarioError(f"{path}: dataset {g.name}/{name} missing")
    ds = g[name]
    if ds.dtype.kind not in "fiu":
        raise ScenarioError(f"{path}: dataset {ds.name} must hold numbers, got {ds.dtype}")
    return read_dataset(ds, path)


def _vector_attr(g, name: str, path: Path, n: int = 3) -> np.ndarray | None:
    if name not in g.attrs:
        return None
    try:
        a = np.asarray(g.attrs[name], dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{path}: attribute {g.name} {name!r} must be {n} numbers") from None
    if a.shape != (n,) or not np.isfinite(a).all():
        raise ScenarioError(f"{path}: attribute {g.name} {name!r} must be {n} finite numbers, "
                            f"got {_short(a.tolist())}")
    return a


def _imu_group(f: h5py.File, path: Path) -> tuple[h5py.Group, float]:
    """The ``/imu`` group of a results file and its sample interval (s); ScenarioError when
    the group is missing or its attribute ``ts`` is not a positive number."""
    g = f.get("imu")
    if not isinstance(g, h5py.Group):
        raise ScenarioError(f"{path}: holds no /imu group (write one with 'gcalign simulate')")
    ts = g.attrs.get("ts")
    try:
        ts = float(np.asarray(ts).reshape(()))
    except (TypeError, ValueError):
        pass
    if not (isinstance(ts, float) and math.isfinite(ts) and ts > 0):
        raise ScenarioError(f"{path}: /imu attribute 'ts' (sample interval, s) must be a "
                            f"positive number, got {_short(ts) if 'ts' in g.attrs else 'nothing'}")
    return g, ts


def imu_series(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, str]:
    """``(t, dtheta, dv, ts, frame)`` of the ``/imu`` group for a figure (decimated sums
    allowed, unlike :func:`read_imu`); ScenarioError naming the dataset or attribute when
    they are missing, not numbers or of mismatched shapes."""
    with open_results(path) as f:
        g, ts = _imu_group(f, path)
        t, dtheta, dv = (_dataset(g, k, path) for k in ("t", "dtheta", "dv"))
        n = len(t) if t.ndim == 1 else -1
        for k, a, shape in (("t", t, (n,)), ("dtheta", dtheta, (n, 3)), ("dv", dv, (n, 3))):
            if n < 1 or a.shape != shape:
                raise ScenarioError(f"{path}: dataset /imu/{k} must have shape "
                                    f"{(len(t),) + shape[1:]}, got {a.shape}")
        frame = _text(g["dtheta"].attrs.get("frame", "body"))
    return t, dtheta, dv, ts, frame.split(":")[0]


def read_truth(path: Path) -> Truth | None:
    """The stored truth, or None; ScenarioError naming the dataset if it is damaged."""
    with open_results(path) as f:
        if "truth" not in f:
            return None
        g = f["truth"]
        t = _dataset(g, "t", path)
        arrays = {k: _dataset(g, k, path) for k in ("att", "v_n", "pos")}
        for k, a in arrays.items():
            if a.shape != (len(t), 3) or not np.isfinite(a).all():
                raise ScenarioError(f"{path}: dataset /truth/{k} must be finite, shape "
                                    f"({len(t)}, 3), got shape {a.shape}")
        seg = _dataset(g, "segment", path).astype(np.int64) if "segment" in g else None
        return Truth(t=t, att=arrays["att"], v_n=arrays["v_n"], pos=arrays["pos"], segment=seg)


def read_imu(path: Path) -> ImuData:
    """The IMU block stored by ``gcalign simulate`` (so the same data feeds several runs),
    validated like recorded data (:func:`gcalign.io.imu_files.check_increments`)."""
    from gcalign.io.imu_files import check_increments

    scenario = read_scenario(path)
    with open_results(path) as f:
        g, ts = _imu_group(f, path)
        if "summed_from_ts" in g.attrs:
            raise ScenarioError(
                f"{path}: /imu holds increments summed to {1 / ts:g} Hz "
                f"(output.rate_hz); navigation needs every sample (coning and sculling are "
                f"lost in sums): simulate again with output: {{rate_hz: full}}")
        t, dtheta, dv = (_dataset(g, k, path) for k in ("t", "dtheta", "dv"))
        check_increments(f"{path}: /imu", t, dtheta, dv, ts)
        extra: dict = {k: _vector_attr(g, k, path) for k in ("site", "att0", "v0_n")
                       if k in g.attrs}
        for key, what in (("site", "latitude"), ("att0", "pitch")):
            if key in extra and not abs(extra[key][0]) < math.pi / 2:
                raise ScenarioError(f"{path}: /imu attribute {key!r}: {what} must lie within "
                                    f"(-pi/2, pi/2) rad, got {extra[key][0]!r}")
        motion = scenario.get("motion") if isinstance(scenario, dict) else None
        kind = motion.get("kind") if isinstance(motion, dict) else None
        q_bs = None
        if "q_bs" in g:
            q_bs = _dataset(g, "q_bs", path)
            if q_bs.shape != (len(t), 4) or not np.isfinite(q_bs).all():
                raise ScenarioError(f"{path}: dataset /imu/q_bs must be finite, shape "
                                    f"({len(t)}, 4), got {q_bs.shape}")
        return ImuData(
            t=t, dtheta=dtheta, dv=dv, ts=ts, source=str(path),
            meta=({"motion_kind": kind} if isinstance(kind, str) else {})
            | ({"q_bs0": _vector_attr(g, "q_bs0", path, 4)} if "q_bs0" in g.attrs else {}),
            q_bs=q_bs,
            **extra,
        )


def read_scenario(path: Path):
    """The scenario stored in a results file, parsed safely (a mapping, or None)."""
    from gcalign.io.scenario.loader import loads

    with open_results(path) as f:
        text = text_attr(f, "scenario_yaml", path)
    data = loads(text, f"{path}: root attribute 'scenario_yaml'")
    if data is not None and not isinstance(data, dict):
        raise ScenarioError(f"{path}: root attribute 'scenario_yaml' must be a YAML mapping, "
                            f"got {type(data).__name__}")
    return data


def read_scenario_yaml(path: Path) -> str:
    """The scenario text stored in a results file; checked to parse safely (no alias bomb,
    no duplicate key), so that callers may ``yaml.safe_load`` it."""
    with open_results(path) as f:
        text = text_attr(f, "scenario_yaml", path)
    from gcalign.io.scenario.loader import loads

    loads(text, f"{path}: root attribute 'scenario_yaml'")
    return text


# --------------------------------------------------------------------------- series out


def add_dimension_scales(f: h5py.File) -> None:
    """Make every group's time ``t`` an HDF5 dimension scale, attached to axis 0 of the
    time series of that group and of its subgroups without a ``t`` of their own
    (``/navigate/error``), and give their other axes a scale of their size (``component`` =
    0, 1, 2 for the width 3 of a vector, in the group of ``t``), so that netCDF readers
    (``xarray.open_dataset(path, group="navigate")``) see a time coordinate and named
    dimensions instead of ``phony_dim``. Datasets that are not series of ``t`` are left
    as they are."""
    groups: list[h5py.Group] = [f]
    f.visititems(lambda _, obj: groups.append(obj) if isinstance(obj, h5py.Group) else None)
    for g in groups:
        owner = g
        while not _is_time(owner.get("t")) and owner.name != "/":
            owner = owner.parent
        t = owner.get("t")
        if not _is_time(t):
            continue
        if not t.is_scale:
            t.make_scale("t")
        for ds in list(g.values()):
            if (not isinstance(ds, h5py.Dataset) or ds.is_scale or ds.ndim == 0
                    or ds.shape[0] != len(t) or ds.dims[0]):
                continue
            ds.dims[0].attach_scale(t)
            for axis, size in enumerate(ds.shape[1:], start=1):
                name = "component" if size == 3 else f"component{size}"
                ds.dims[axis].attach_scale(_index_scale(owner, name, size))


def _is_time(t) -> bool:
    return isinstance(t, h5py.Dataset) and t.ndim == 1 and len(t) > 1 and t.dtype.kind == "f"


def _index_scale(g: h5py.Group, name: str, size: int) -> h5py.Dataset:
    """A dimension scale 0 .. size-1 named `name` in `g` (made once)."""
    if name in g:
        return g[name]
    ds = g.create_dataset(name, data=np.arange(size, dtype=np.int64))
    ds.attrs["units"] = "1"
    ds.make_scale(name)
    return ds


#: Component names of a series by its frame attribute (first match).
_COMPONENTS = (("[pitch, roll, yaw]", ("pitch", "roll", "yaw")),
               ("Euler differences", ("pitch", "roll", "yaw")),
               ("[latitude, longitude, height]", ("lat", "lon", "h")),
               ("ENU", ("e", "n", "u")), ("body", ("x", "y", "z")))


def timed_groups(path: Path, under: str = "") -> list[str]:
    """The groups at or below `under` that hold time series (a 1-D float ``t``), in the
    file's order (``align/pass_01``, …, ``align/pass_05``)."""
    with open_results(path) as f:
        top = f.get(under.strip("/")) if under.strip("/") else f
        if not isinstance(top, h5py.Group):
            return []
        found = [top.name.strip("/")] if _is_time(top.get("t")) else []
        top.visititems(lambda n, o: found.append(o.name.strip("/"))
                       if isinstance(o, h5py.Group) and _is_time(o.get("t")) else None)
        return found


def _timed(f: h5py.File, group: str, path: Path) -> list[tuple[str, h5py.Dataset]]:
    """``(name, dataset)`` of the time series of `group`: ``t`` first, then every numeric
    dataset of its length (:func:`_time_datasets`). ScenarioError naming the file and group
    when there is no such group or it has no time ``t``."""
    g = f.get(group.strip("/"))
    if not isinstance(g, h5py.Group):
        have = [k for k in f if isinstance(f[k], h5py.Group)]
        raise ScenarioError(f"--group: {path} has no group {group!r}; it has "
                            f"{', '.join(have) or 'none'}")
    t = g.get("t")
    if not (isinstance(t, h5py.Dataset) and t.ndim == 1 and t.dtype.kind == "f"):
        timed: list[str] = []
        f.visititems(lambda n, o: timed.append(n) if isinstance(o, h5py.Group)
                     and _is_time(o.get("t")) else None)
        raise ScenarioError(f"--group: {path}: /{group.strip('/')} has no time series "
                            f"(no 1-D dataset 't'); groups that have: "
                            f"{', '.join(timed[:8]) or 'none'}")
    return [("t", t), *_time_datasets(g, len(t))]


def series(path: Path, group: str = "navigate") -> dict[str, tuple[np.ndarray, str]]:
    """The time series of a group of a results file: ``{name: (array, units)}``, ``t``
    first, then every dataset of the same length along axis 0 (attitude, velocity,
    position, errors, ...), as stored (SI; time along axis 0). ScenarioError naming the
    file and group when there is no such group or it has no time ``t``."""
    with open_results(path) as f:
        return {name: (read_dataset(ds, path), _text(ds.attrs.get("units", "")))
                for name, ds in _timed(f, group, path)}


def _time_datasets(g: h5py.Group, n: int, prefix: str = ""):
    """``(name, dataset)`` of the numeric series of length `n` in `g` and in its subgroups
    without a time of their own (``error/att`` as ``error_att``)."""
    for name, obj in g.items():
        if isinstance(obj, h5py.Group) and "t" not in obj:
            yield from _time_datasets(obj, n, f"{prefix}{name}_")
        elif (name != "t" and isinstance(obj, h5py.Dataset) and not obj.is_scale
              and obj.ndim in (1, 2) and obj.shape[0] == n and obj.dtype.kind in "fiu"):
            yield prefix + name, obj


def _text(v) -> str:
    return v.decode() if isinstance(v, bytes) else str(v)


def _list_attr(obj, name: str) -> list[str]:
    v = _text(obj.attrs.get(name, ""))
    return [p.strip() for p in v.split(",")] if v else []


def _components(ds: h5py.Dataset) -> tuple[tuple[str, ...], list[str]]:
    """Column labels of an (N, k) series and its units per component (or []):
    ``att -> (pitch, roll, yaw)``, ``v_n -> (e, n, u)``, ``pos -> (lat, lon, h)``; a series
    with a ``names`` attribute by those names (``innovation -> (dvE, dvN)``), one in the
    order of its group's ``states`` attribute by the states (``estimate -> (phiE, …,
    dKaz)``), otherwise ``0, 1, ...``."""
    k = ds.shape[1]
    names = _list_attr(ds, "names")
    if len(names) == k:
        return tuple(names), []
    frame = str(ds.attrs.get("frame", ""))
    labels = next((c for key, c in _COMPONENTS if key in frame and len(c) == k), None)
    if labels is not None:
        return labels, []
    parent = ds.parent
    while parent.name != "/":  # the 'states' of the nearest group that lists them
        states = _list_attr(parent, "states")
        if states:
            if len(states) == k:
                units = _list_attr(parent, "state_units")
                return tuple(states), units if len(units) == k else []
            break
        parent = parent.parent
    return tuple(str(i) for i in range(k)), []


def columns(path: Path, group: str = "navigate") -> list[tuple[str, np.ndarray, str]]:
    """The group's series as flat columns ``(name, values (N,), units)``: ``t``, then each
    vector series by component (``att_pitch``, ``v_n_e``, ``pos_lat``, ``estimate_ebx``,
    ...; :func:`_components`), each with its own unit where the file gives one per
    component."""
    out = []
    with open_results(path) as f:
        for name, ds in _timed(f, group, path):
            a, units = read_dataset(ds, path), _text(ds.attrs.get("units", ""))
            if a.ndim == 1:
                out.append((name, a, units))
                continue
            labels, own = _components(ds)
            parts = own or [p.strip() for p in units.split(",")]
            out.extend((f"{name}_{label}", a[:, j], parts[j] if len(parts) == a.shape[1]
                        else units) for j, label in enumerate(labels))
    return out


def dataframe(path: Path, group: str = "navigate"):
    """The group's series as a pandas DataFrame indexed by ``t`` (s), one column per
    component (:func:`columns`), units in ``df.attrs["units"]``; ImportError naming pandas
    when it is not installed."""
    try:
        import pandas as pd
    except ImportError:
        raise ImportError("dataframe() needs pandas (pip install pandas); series() gives "
                          "the same arrays without it") from None
    cols = columns(path, group)
    df = pd.DataFrame({name: a for name, a, _ in cols[1:]},
                      index=pd.Index(cols[0][1], name="t"))
    df.attrs["units"] = {name: units for name, _, units in cols}
    return df

