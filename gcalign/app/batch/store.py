"""The journal and the HDF5 results file of a batch, and what a resume reads back.

DESIGN.md "Results file". Every finished run is appended to a journal next to the output
(``FILE.journal.jsonl``: one JSON line per run, flushed and fsync'd per batch of results).
The HDF5 file is rebuilt from the journal under a temporary name and renamed
(:func:`gcalign.io.results.atomic_h5`) every few seconds and at the end, so a SIGKILL never
leaves a corrupt file, and ``resume=True`` runs only what is missing (from the journal, or
from the HDF5 file if the journal is gone). Runs are identified by their variant's key
(:attr:`~gcalign.app.batch.sweep.Sweep.keys`) and seed, so a resumed sweep with more seeds
or more grid values reuses every run it already has, also from another folder.
"""

from __future__ import annotations

import errno
import hashlib
import json
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from gcalign.app.batch.aggregate import STATS, components, metric_units
from gcalign.app.batch.sweep import Sweep
from gcalign.errors import GcalignError, ScenarioError, check_terminated

JOURNAL_SUFFIX = ".journal.jsonl"


def journal_path(output: Path) -> Path:
    output = Path(output)
    return output.with_name(output.name + JOURNAL_SUFFIX)


def _checksum(record: dict) -> str:
    body = {k: v for k, v in record.items() if k != "check"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _journal_error(path: Path, err: OSError) -> GcalignError:
    return GcalignError(f"cannot write the journal {path}: {err.strerror or err}; the runs "
                        "journaled so far are kept: free space and rerun with --resume")


class Journal:
    """Append-only JSON lines, each record with a checksum; each batch of lines is flushed
    and fsync'd.

    The file is created at the first :meth:`append` (a batch that fails before any run
    finished leaves none), from a clean start: header + the records kept from a resume,
    written under a temporary name and renamed, so that a torn last line from a SIGKILL is
    never appended to. A failing write (full disk) is one line, exit 1; the lines written
    before it stay valid.
    """

    def __init__(self, path: Path, header: dict, keep: Iterable[dict] = ()):
        self.path = Path(path)
        self.header = header
        self.keep = [_signed(r) for r in keep]
        self._f: TextIO | None = None
        if self.keep:
            self._open()

    def _open(self) -> None:
        from gcalign.io.results import make_temp

        fd, tmp = make_temp(self.path)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                for obj in (self.header, *self.keep):
                    f.write(json.dumps(obj) + "\n")
                f.flush()
                os.fsync(f.fileno())
            check_terminated()
            os.replace(tmp, self.path)
            self._f = open(self.path, "a", encoding="utf-8")  # noqa: SIM115
        except BaseException as err:  # a SIGTERM too: no temporary file left
            tmp.unlink(missing_ok=True)
            if isinstance(err, OSError):
                raise _journal_error(self.path, err) from None
            raise

    @property
    def exists(self) -> bool:
        return self._f is not None

    def append(self, records: Iterable[dict]) -> None:
        records = list(records)
        if not records:
            return
        if self._f is None:
            self._open()
        assert self._f is not None
        try:
            for r in records:
                self._f.write(json.dumps(_signed({"type": "run", **r})) + "\n")
            self._f.flush()
            os.fsync(self._f.fileno())
        except OSError as err:
            raise _journal_error(self.path, err) from None

    def close(self) -> None:
        if self._f is not None:
            try:
                self._f.close()
            except OSError:
                pass


_HELD_LOCKS: dict[int, Path] = {}  # descriptor -> lock file, of the locks this process holds


def _forget_locks_in_child() -> None:  # pragma: no cover - runs in forked children
    """A forked child (a pool worker) closes its copies of the lock descriptors: the lock
    is the batch process's, and a child must not keep the file open after it dies."""
    for fd in _HELD_LOCKS:
        try:
            os.close(fd)
        except OSError:
            pass
    _HELD_LOCKS.clear()


os.register_at_fork(after_in_child=_forget_locks_in_child)


class OutputLock:
    """An exclusive lock on a batch output while the batch runs: a POSIX record lock
    (``lockf``) on ``.NAME.lock`` beside it, which the kernel releases when the process
    that took it dies (SIGKILL included). A second batch into the same output is refused
    with one line (exit 1) instead of discarding the first one's journal. The lock file is
    removed on release.

    Not ``flock``: an ``flock`` belongs to the open file, which forked pool workers share,
    so a batch killed with -9 stayed locked until its last worker had exited. A record lock
    belongs to the process and is not inherited by ``fork``; because a process does not
    conflict with its own record locks, a second lock on the same file in this process is
    refused from the table of held ones."""

    def __init__(self, output: Path):
        self.output = Path(output)
        self.path = self.output.with_name(f".{self.output.name}.lock")
        self.fd: int | None = None

    def __enter__(self) -> OutputLock:
        import fcntl

        from gcalign.io.results import write_error

        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise write_error(self.output, err) from None
        if self.path.resolve() in _HELD_LOCKS.values():
            raise GcalignError(f"{self.output}: another batch (pid {os.getpid()}, this "
                               "process) is writing it; wait for it to finish, or give "
                               "another -o")
        for _ in range(100):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
            except OSError as err:
                raise write_error(self.output, err) from None
            try:
                fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as err:
                if err.errno not in (errno.EACCES, errno.EAGAIN):
                    os.close(fd)
                    raise write_error(self.output, err) from None
                holder = os.read(fd, 32).decode("ascii", "replace").strip() or "?"
                os.close(fd)
                raise GcalignError(f"{self.output}: another batch (pid {holder}) is writing it; "
                                   "wait for it to finish, or give another -o") from None
            try:  # the previous holder may have removed the file between open and flock
                same = os.stat(self.path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                try:  # the holder's pid, for the message of a second batch
                    os.ftruncate(fd, 0)
                    os.write(fd, f"{os.getpid()}\n".encode())
                except OSError as err:  # a full disk: no lock file left either
                    self.path.unlink(missing_ok=True)
                    os.close(fd)
                    raise write_error(self.output, err) from None
                self.fd = fd
                _HELD_LOCKS[fd] = self.path.resolve()
                return self
            os.close(fd)
        raise GcalignError(f"{self.output}: cannot take the lock {self.path}")

    def __exit__(self, *exc) -> None:
        if self.fd is not None:
            self.path.unlink(missing_ok=True)
            _HELD_LOCKS.pop(self.fd, None)
            os.close(self.fd)
            self.fd = None


def _signed(record: dict) -> dict:
    r = {k: v for k, v in record.items() if k != "check"}
    r["check"] = _checksum(r)
    return r


def valid_record(r, metrics: Iterable[str] | None = None) -> bool:
    """Whether a journal line is a run record this version wrote: its fields and types,
    its checksum (a torn, edited or foreign line fails it), finite metric values."""
    if not isinstance(r, dict) or r.get("type") != "run" or r.get("check") != _checksum(r):
        return False
    if not (isinstance(r.get("variant"), int) and isinstance(r.get("seed"), int)
            and isinstance(r.get("vkey"), str) and r.get("status") in ("ok", "failed")
            and isinstance(r.get("metrics"), dict)):
        return False
    if r["status"] == "ok":
        for m in (metrics if metrics is not None else r["metrics"]):
            if not _finite_metric(r["metrics"].get(m)):
                return False
    return True


def _finite_metric(v) -> bool:
    if isinstance(v, bool):
        return False
    if isinstance(v, (int, float)):
        return math.isfinite(v)
    return isinstance(v, list) and bool(v) and all(_finite_metric(x) and not isinstance(x, list)
                                                   for x in v)


def read_journal(path: Path, metrics: Iterable[str] | None = None,
                 log=None) -> list[dict]:
    """Run records of a journal. Lines that are not valid records (torn by a SIGKILL,
    garbage, edited, NaN or missing metrics) are skipped, and `log` is told how many."""
    metrics = list(metrics) if metrics is not None else None
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = [line for line in f if line.strip()]
    except OSError as err:
        raise ScenarioError(f"{path}: cannot read the journal ({err.strerror or err})") from None
    records = [r for r in map(_loads, lines) if not (isinstance(r, dict)
                                                    and r.get("type") == "header")]
    out = [r for r in records if valid_record(r, metrics)]
    if len(out) < len(records) and log is not None:
        log(f"{path}: skipped {len(records) - len(out)} line(s) that are not valid run records "
            "(torn, damaged or edited); those runs run again")
    return out


def _loads(line: str) -> Any:
    try:
        return json.loads(line)
    except ValueError:  # (not a record: skipped)
        return None


def read_runs_h5(path: Path) -> list[dict]:
    """Run records from a batch results file (``/batch/runs``)."""
    from gcalign.app.plots import _s
    from gcalign.io import results

    try:
        with results.open_results(path) as f:
            if "batch/runs" not in f:
                raise ScenarioError(f"{path}: not a batch results file (no /batch/runs)")
            g = f["batch/runs"]
            metrics = {m: g["metrics"][m][()] for m in g["metrics"]}
            lengths = g["metrics"].attrs
            recs = []
            for i in range(g["seed"].shape[0]):
                status = _s(g["status"][i])
                vals = {}
                if status == "ok":
                    for m, arr in metrics.items():
                        n = int(lengths.get(m + ".length", -1))
                        vals[m] = float(arr[i]) if n < 0 else [float(v) for v in arr[i][:n]]
                recs.append({"variant": int(g["variant"][i]), "vkey": _s(g["vkey"][i]),
                             "seed": int(g["seed"][i]), "status": status, "metrics": vals,
                             "error": _s(g["error"][i]), "wall_s": float(g["wall_s"][i])})
    except (KeyError, TypeError, ValueError, IndexError, OSError) as err:
        # (the refusals of open_results and of a file without /batch/runs too)
        raise ScenarioError(f"{path}: /batch/runs is damaged ({type(err).__name__}: "
                            f"{str(err)[:60]})") from None
    return recs


def write_batch_h5(output: Path, sweep: Sweep, records: dict, summary: dict) -> None:
    """(Re)build the whole results file from the run records, atomically."""
    import h5py

    from gcalign.io import results

    keys = [k for k in sweep.run_keys() if k in records]
    recs = [records[k] for k in keys]
    by_index = {v.index: v for v in sweep.variants}
    scenario_text = sweep.text + f"\n# base scenario: {sweep.base_source}\n" + "".join(
        f"# {line}\n" for line in sweep.base_text.splitlines())
    with results.atomic_h5(output) as f:
        results.write_header(f, "batch", scenario_text, None, summary)
        b = f.create_group("batch")
        b.attrs["command"] = sweep.command
        b.attrs["sweep"] = sweep.name
        b.attrs["seeds"], b.attrs["seed_start"] = sweep.seeds, sweep.seed_start
        b.attrs["metrics"] = json.dumps(list(sweep.metrics))
        b.attrs["grid_json"] = json.dumps(sweep.grid, default=str)
        b.attrs["cases_json"] = json.dumps(sweep.cases, default=str)
        b.attrs["base_yaml"] = sweep.base_text
        b.attrs["fingerprint"] = sweep.fingerprint
        b.attrs["complete"] = bool(summary["complete"])
        r = b.create_group("runs")
        r.attrs["description"] = ("one row per finished run, sorted by (variant, seed); "
                                  "metric values NaN where the run failed")
        results.put(r, "variant", np.array([k[0] for k in keys], dtype=np.int32), "1")
        results.put(r, "seed", np.array([k[1] for k in keys], dtype=np.int64), "1")
        for name, what in (("status", "ok | failed"), ("error", "error message ('' if ok)"),
                           ("vkey", "hash of the variant's command, metrics and scenario")):
            results.put(r, name, np.array([x[name] for x in recs], dtype=object), "none",
                        create={"dtype": h5py.string_dtype()}, description=what)
        results.put(r, "wall_s", np.array([x.get("wall_s", np.nan) for x in recs]), "s")
        mg = r.create_group("metrics")
        for m in sweep.metrics:
            vals = [x["metrics"].get(m) if x["status"] == "ok" else None for x in recs]
            lens = {len(v) for v in vals if isinstance(v, list)}
            if lens:
                k = max(lens)
                arr = np.full((len(recs), k), np.nan)
                for i, v in enumerate(vals):
                    if isinstance(v, list):
                        arr[i, : len(v)] = v
                mg.attrs[m + ".length"] = k
            else:
                arr = np.array(vals, dtype=float)  # (None as NaN)
            ds = results.put(mg, m, arr, metric_units(m))
            comps = components(sweep.command, m, arr.shape[1] if arr.ndim == 2 else None)
            if comps:
                ds.attrs["components"] = ", ".join(comps)
        a = b.create_group("aggregate")
        for entry in summary["variants"]:
            v = by_index[entry["index"]]
            g = a.create_group(f"v{v.index:03d}")
            g.attrs["index"], g.attrs["label"] = v.index, v.label
            g.attrs["overrides_json"] = json.dumps(v.overrides, default=str)
            g.attrs["ok"], g.attrs["failed"] = entry["ok"], entry["failed"]
            for key, value in v.overrides.items():
                g.attrs[key] = _attr(value)
            for m, st in entry["stats"].items():
                mg = g.create_group(m)
                mg.attrs["n"] = st["n"]
                if st.get("components"):
                    mg.attrs["components"] = ", ".join(st["components"])
                for s in STATS:  # (None, in a list too, as NaN)
                    results.put(mg, s, np.array(st[s], dtype=float), metric_units(m))


def _attr(value):
    """An override value as an HDF5 attribute (JSON text where HDF5 has no type for it)."""
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                       for x in value):
        return np.asarray(value, dtype=float)
    return json.dumps(value, default=str)


def previous_records(sweep: Sweep, output: Path, log=None) -> tuple[dict, str]:
    """Finished runs of an earlier batch into `output` that this sweep still contains:
    from the journal, else from the HDF5 file. Failed runs are not kept (they run again),
    nor records that are damaged or hold metrics that are not finite."""
    jpath = journal_path(output)  # (a journal that is not a file is refused by run_batch)
    if jpath.is_file():
        recs, where = read_journal(jpath, sweep.metrics, log), str(jpath)
    elif Path(output).is_file():
        recs, where = read_runs_h5(output), str(output)
    else:
        return {}, ""
    index = {key: vi for vi, key in enumerate(sweep.keys)}
    seeds = set(sweep.seed_values)
    kept: dict[tuple[int, int], dict] = {}
    for r in recs:  # a later record of the same run wins
        vi = index.get(str(r.get("vkey")))
        if vi is None or r.get("seed") not in seeds or r.get("status") != "ok" or not all(
                _finite_metric(r["metrics"].get(m)) for m in sweep.metrics):
            continue
        r = {k: v for k, v in r.items() if k != "type"}
        r["variant"] = vi
        kept[(vi, r["seed"])] = r
    return kept, where

