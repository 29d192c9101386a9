"""Faults: kill -9 and SIGTERM at random points, a full disk, a second batch on
the same output, symlinks at temporary names, and Dask schedulers that do not answer.

Runs are child processes (``python -m``-style, the real command line) so that they can be
killed; every Dask listener is started here on 127.0.0.1 and stops by itself.
"""

from __future__ import annotations

import json
import os
import random
import resource
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import fuzz_cases as F
import h5py
import numpy as np
import pytest

from gcalign.io import results

GCALIGN = [sys.executable, "-c", "import sys; from gcalign.cli import main; "
           "sys.argv[0] = 'gcalign'; main()"]
#: A hang, not a slow start: the README's 15 s for a scheduler that does not answer is
#: measured by benchmarks/bench_batch.py (a loaded machine would make it flaky here).
HANG_S = 120.0


def cli(args, cwd, env=None, limit_fsize=None, timeout=120, **kw):
    e = {**os.environ, **(env or {})}

    def pre():
        if limit_fsize is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_fsize, limit_fsize))

    return subprocess.run(GCALIGN + list(map(str, args)), cwd=cwd, env=e, capture_output=True,
                          text=True, timeout=timeout, preexec_fn=pre, **kw)


def spawn(args, cwd):
    return subprocess.Popen(GCALIGN + list(map(str, args)), cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def one_error_line(stderr: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr
    assert "Traceback" not in stderr
    return lines[0]


def temps(folder: Path) -> list[str]:
    return sorted(p.name for p in Path(folder).rglob("*") if p.name.endswith(results.TMP_SUFFIX))


def scenario(folder: Path, duration_s: float = 60.0, name: str = "S.yaml") -> Path:
    d = json.loads(json.dumps(F.S))
    d["motion"]["duration_s"] = duration_s
    p = folder / name
    p.write_text(F.emit(d))
    return p


def sweep(folder: Path, seeds: int = 20) -> Path:
    scenario(folder)
    p = folder / "SW.yaml"
    p.write_text(F.emit({**F.SWEEP, "seeds": seeds}))
    return p


def aggregate_of(path: Path) -> dict:
    with h5py.File(path, "r") as f:
        summary = json.loads(f.attrs["summary_json"])
        runs = sorted(zip(f["batch/runs/variant"][()].tolist(), f["batch/runs/seed"][()].tolist(),
                          strict=True))
    return {"variants": summary["variants"], "runs": runs}


# --------------------------------------------------------------------------- single runs


def layout(path: Path) -> dict[str, tuple[int, ...]]:
    """Every dataset of an HDF5 file with its shape: what a complete result has."""
    found: dict[str, tuple[int, ...]] = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: found.update({name: obj.shape})
                     if isinstance(obj, h5py.Dataset) else None)
    return found


@pytest.mark.slow  # several seconds of child processes
def test_kill_9_of_a_run_leaves_no_partial_file_and_the_next_run_removes_its_temp(tmp_path):
    """kill -9 of simulate at random points of its write (seeded): a file under the final name is
    only ever a complete one (the kill can land after the rename, in the interpreter's exit); a
    temp file may remain (nothing can remove it at SIGKILL), and the next run into the folder
    removes it; then that run completes."""
    rng = random.Random(14)
    scenario(tmp_path, duration_s=3000.0, name="L.yaml")
    assert cli(["simulate", "L.yaml", "-o", "ref/l.h5"], tmp_path).returncode == 0
    complete = layout(tmp_path / "ref/l.h5")
    in_flight = 0
    for _ in range(4):
        p = spawn(["simulate", "L.yaml", "-o", "out/l.h5"], tmp_path)
        deadline = time.monotonic() + 60
        while not temps(tmp_path / "out") and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.001)  # the temp file exists once the run has started writing
        # The write lasts ~0.3 s on an idle machine: kill within its first 50 ms.
        time.sleep(rng.uniform(0.0, 0.05))
        p.kill()
        p.wait()
        final = tmp_path / "out/l.h5"
        if final.exists():
            assert layout(final) == complete  # finished before the kill: whole, never partial
            final.unlink()
        else:
            in_flight += 1
    assert in_flight >= 1 and temps(tmp_path / "out")  # SIGKILL in flight leaves its temp file
    scenario(tmp_path)
    res = cli(["simulate", "S.yaml", "-o", "out/s.h5"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert temps(tmp_path / "out") == []
    assert (tmp_path / "out/s.h5").is_file() and not (tmp_path / "out/l.h5").exists()


@pytest.mark.slow  # child processes
def test_sigterm_of_a_run_removes_its_temp_file(tmp_path):
    scenario(tmp_path, duration_s=3000.0, name="L.yaml")
    p = spawn(["simulate", "L.yaml", "-o", "l.h5"], tmp_path)
    deadline = time.monotonic() + 60
    while not temps(tmp_path) and time.monotonic() < deadline:
        time.sleep(0.02)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143
    assert one_error_line(err) == "error: terminated (SIGTERM)"
    assert temps(tmp_path) == [] and not (tmp_path / "l.h5").exists()


class _RaisesOnFinalise:
    """Its finaliser runs the command line's SIGTERM handler: the exception it raises there
    cannot propagate (Python prints it as "Exception ignored" and goes on)."""

    def __del__(self):
        from gcalign.cli import _terminate

        _terminate(signal.SIGTERM, None)


def _lose_a_sigterm() -> None:
    _RaisesOnFinalise()  # freed on return: its exception is lost


def test_a_sigterm_lost_in_a_finaliser_still_keeps_the_file_from_its_name(tmp_path,
                                                                          monkeypatch):
    """The handler's exception swallowed by a finaliser (seen: a weakref callback inside
    h5py, after which the run wrote its file and exited 0): the commit point raises it."""
    from gcalign import errors

    monkeypatch.setattr(sys, "unraisablehook", lambda info: None)
    try:
        with pytest.raises(errors.Terminated), results.atomic_h5(tmp_path / "o.h5") as f:
            f.attrs["x"] = 1
            _lose_a_sigterm()
    finally:
        errors.TERMINATE_REQUESTED[0] = False
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("turned_into", [TypeError, OSError, "GcalignError"])
def test_a_sigterm_a_library_turned_into_its_own_error_is_still_exit_143(capsys, turned_into):
    """Seen: SIGTERM inside h5py's write, which raised "TypeError: Operation not defined for
    data type class" in its place; that was an internal error, exit 1, "a bug"."""
    import typer

    from gcalign import errors
    from gcalign.cli.base import user_errors

    error = errors.GcalignError if turned_into == "GcalignError" else turned_into

    @user_errors
    def write():
        try:
            signal.raise_signal(signal.SIGTERM)  # the command line's handler raises here
        except errors.Terminated:
            raise error("the library's own words") from None

    with pytest.raises(typer.Exit) as ex:
        write()
    assert ex.value.exit_code == 143
    assert capsys.readouterr().err == "error: terminated (SIGTERM)\n"
    assert errors.TERMINATE_REQUESTED[0]  # reset by the next command's wrapper
    errors.TERMINATE_REQUESTED[0] = False


@pytest.fixture(scope="module")
def small_nav(tmp_path_factory):
    """A 20 s navigate results file, made in this process."""
    from typer.testing import CliRunner

    from gcalign.cli import app

    d = tmp_path_factory.mktemp("nav")
    sc = scenario(d, duration_s=20.0)
    res = CliRunner().invoke(app, ["navigate", str(sc), "-o", str(d / "n.h5")])
    assert res.exit_code == 0, res.output
    return d / "n.h5"


@pytest.mark.parametrize("commit", ["export", "plot", "journal"])
def test_a_sigterm_lost_in_a_finaliser_keeps_every_other_commit_from_its_name(
        tmp_path, monkeypatch, small_nav, commit):
    """export's, plot's and the batch journal's renames ask for a lost SIGTERM too: nothing
    is left under the name, nor a temporary file beside it."""
    from matplotlib.figure import Figure

    from gcalign import errors
    from gcalign.app import export, readback
    from gcalign.app.batch.store import Journal

    def csv_then_lost(fh, *a):
        fh.write("t\n0\n")
        _lose_a_sigterm()

    def savefig_then_lost(self, p, **kw):
        Path(p).write_bytes(b"png")
        _lose_a_sigterm()

    monkeypatch.setattr(sys, "unraisablehook", lambda info: None)
    monkeypatch.setattr(export, "_csv", csv_then_lost)
    monkeypatch.setattr(Figure, "savefig", savefig_then_lost)
    out = tmp_path / "out"
    run = {"export": lambda: export.export(small_nav, "csv", out),
           "plot": lambda: readback.plot_file(small_nav, out),
           "journal": lambda: (_lose_a_sigterm(), Journal(out, {"v": 1}, [{"id": "a"}]))}
    try:
        with pytest.raises(errors.Terminated):
            run[commit]()
    finally:
        errors.TERMINATE_REQUESTED[0] = False
    assert not out.exists() or (out.is_dir() and list(out.iterdir()) == [])
    assert temps(tmp_path) == []


@pytest.mark.slow  # a child process
def test_a_sigterm_lost_in_a_finaliser_is_exit_143_one_line():
    """The same through the command line's wrapper, for a command that writes no file: exit
    143, the one error line and no "Exception ignored" traceback."""
    code = """if True:
        import sys, typer
        from test_faults import _lose_a_sigterm
        from gcalign.cli import user_errors
        try:
            user_errors(_lose_a_sigterm)()
        except typer.Exit as e:
            sys.exit(e.exit_code)
    """
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60, cwd=Path(__file__).parent)
    assert res.returncode == 143 and one_error_line(res.stderr) == "error: terminated (SIGTERM)"


class _Signal(BaseException):
    """What the SIGTERM handler raises (the command line's Terminated), anywhere."""


@pytest.mark.parametrize("where", ["fchmod", "_GuardedFile"])
def test_a_signal_right_after_the_temporary_file_exists_removes_it(tmp_path, monkeypatch,
                                                                   where):
    """The windows between creating the temporary file and the writer's cleanup (its mode
    set, its Python file object made): a SIGTERM landing there left the file behind."""
    def interrupted(*a, **k):
        raise _Signal

    if where == "fchmod":
        monkeypatch.setattr(results.os, "fchmod", interrupted)
    else:
        monkeypatch.setattr(results, "_GuardedFile", interrupted)
    with pytest.raises(_Signal), results.atomic_h5(tmp_path / "o.h5"):
        pass
    assert list(tmp_path.iterdir()) == []


def test_the_guard_is_silent_once_a_failed_run_closed_its_file(tmp_path):
    """A SIGTERM that lands inside h5py can leave HDF5 objects to be freed after the failed
    run closed and deleted its temporary file; freeing them writes and truncates through the
    guard, which must then do nothing instead of raising (printed as "Exception ignored", a
    traceback on stderr: seen once in the SIGTERM test above)."""
    guard = results._GuardedFile(os.open(tmp_path / "t", os.O_RDWR | os.O_CREAT))
    guard.write(b"abc")
    guard.close()
    assert guard.write(b"more") == 4 and guard.truncate(10) == 10
    guard.flush()
    assert (guard.read(), guard.readinto(bytearray(2)), guard.seek(5), guard.tell()) == (
        b"", 0, 0, 0)
    assert guard.error is None


@pytest.mark.slow
def test_a_symlink_at_a_temporary_name_is_not_followed(tmp_path):
    """The temp name is random (mkstemp): a symlink planted at the old predictable name, or
    at any other name, is neither followed nor removed."""
    target = tmp_path / "precious"
    target.write_bytes(b"keep me")
    scenario(tmp_path)
    for pid in range(os.getpid() - 5, os.getpid() + 50):
        (tmp_path / f".s.h5.{pid}.tmp").symlink_to(target)
    res = cli(["align", "S.yaml", "-o", "s.h5"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert target.read_bytes() == b"keep me"
    assert h5py.is_hdf5(tmp_path / "s.h5")


@pytest.mark.slow
def test_full_disk_is_exit_1_one_line_and_nothing_kept(tmp_path):
    """``ulimit -f`` (EFBIG; Python ignores SIGXFSZ) while a run writes: exit 1, one line
    naming the file, no file under the final name, no temp file."""
    d = json.loads(json.dumps(F.S))
    d["motion"]["duration_s"] = 600.0
    d["output"] = {"rate_hz": "full"}  # noisy increments at every sample: about 3 MB
    d["imu"].update(gyro={"arw_dprh": 0.01}, accel={"vrw_ugrhz": 50})
    (tmp_path / "S.yaml").write_text(F.emit(d))
    res = cli(["simulate", "S.yaml", "-o", "s.h5"], tmp_path, limit_fsize=200_000)
    assert res.returncode == 1, res.stderr
    line = one_error_line(res.stderr)
    assert "cannot write s.h5: File too large" in line
    assert not (tmp_path / "s.h5").exists() and temps(tmp_path) == []


@pytest.mark.slow
def test_output_that_names_a_directory_or_nothing_is_refused_before_the_run(tmp_path):
    scenario(tmp_path)
    (tmp_path / "adir").mkdir()
    for out in ("", ".", "adir", "S.yaml/x.h5"):
        res = cli(["align", "S.yaml", "-o", out], tmp_path)
        assert res.returncode == 2, (out, res.stderr)
        assert "--output" in one_error_line(res.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["S.yaml", "adir"]
    assert list((tmp_path / "adir").iterdir()) == []


# --------------------------------------------------------------------------- batches


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    d = tmp_path_factory.mktemp("ref")
    sweep(d)
    res = cli(["batch", "SW.yaml", "-o", "ref.h5", "-w", "2"], d)
    assert res.returncode == 0, res.stderr
    return aggregate_of(d / "ref.h5")


@pytest.mark.slow  # several seconds of child processes
def test_kill_9_of_a_batch_and_resume_give_every_run_once(tmp_path, uninterrupted):
    """kill -9 at random points (seeded), then --resume until complete: every (variant,
    seed) exactly once and the uninterrupted aggregate, to the bit."""
    rng = random.Random(2026)
    sweep(tmp_path)
    for attempt in range(3):
        p = spawn(["batch", "SW.yaml", "-o", "b.h5", "-w", "2"]
                  + (["--resume"] if attempt else []), tmp_path)
        time.sleep(rng.uniform(0.5, 4.0))
        p.kill()
        p.wait()
    res = cli(["batch", "SW.yaml", "-o", "b.h5", "-w", "2", "--resume"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert aggregate_of(tmp_path / "b.h5") == uninterrupted
    assert not (tmp_path / "b.h5.journal.jsonl").exists()
    assert temps(tmp_path) == [] and not (tmp_path / ".b.h5.lock").exists()


@pytest.mark.slow  # several seconds of child processes
def test_full_disk_during_a_batch_then_resume_completes(tmp_path, uninterrupted):
    """``ulimit -f`` small enough that the results file cannot be written: exit 1, one line;
    the journal keeps the finished runs; with the limit lifted, --resume completes with the
    uninterrupted aggregate."""
    sweep(tmp_path)
    res = cli(["batch", "SW.yaml", "-o", "b.h5", "-w", "1"], tmp_path, limit_fsize=6000)
    assert res.returncode == 1, res.stderr
    assert "cannot write" in one_error_line(res.stderr)
    assert temps(tmp_path) == []
    res = cli(["batch", "SW.yaml", "-o", "b.h5", "-w", "1", "--resume"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert aggregate_of(tmp_path / "b.h5") == uninterrupted


@pytest.mark.slow  # several seconds of child processes
def test_a_second_batch_on_the_same_output_is_refused(tmp_path):
    sweep(tmp_path, seeds=40)
    first = spawn(["batch", "SW.yaml", "-o", "b.h5", "-w", "1"], tmp_path)
    try:
        deadline = time.monotonic() + 60
        lock = tmp_path / ".b.h5.lock"
        while time.monotonic() < deadline and not (lock.exists() and lock.read_text()):
            time.sleep(0.02)  # its pid is written once the lock is taken
        first.send_signal(signal.SIGSTOP)  # holds the lock however fast it would finish
        res = cli(["batch", "SW.yaml", "-o", "b.h5", "-w", "1"], tmp_path)
        assert res.returncode == 1
        assert f"another batch (pid {first.pid})" in one_error_line(res.stderr)
    finally:
        first.kill()
        first.wait()
    res = cli(["batch", "SW.yaml", "-o", "b.h5", "-w", "1", "--resume"], tmp_path)
    assert res.returncode == 0, res.stderr  # the lock died with its holder


HOLDER = """
import os, sys, time
from gcalign.app.batch.store import OutputLock
with OutputLock(sys.argv[1]):
    if os.fork() == 0:  # a pool worker's place: a forked child that outlives its parent
        os.write(1, b"child\\n")  # the fork hooks have run by now (one write: no interleaving)
        time.sleep(30)
        os._exit(0)
    os.write(1, b"locked\\n")
    time.sleep(30)
"""


@pytest.mark.slow  # child processes
def test_the_batch_lock_dies_with_its_holder_not_with_its_forked_children(tmp_path):
    """A forked child does not inherit the lock, nor keep the lock file open: the moment
    the holder is killed with -9 the output is free, though its child still runs."""
    from gcalign.app.batch.store import OutputLock

    out = tmp_path / "b.h5"
    children: list[int] = []
    holder = subprocess.Popen([sys.executable, "-c", HOLDER, str(out)], stdout=subprocess.PIPE,
                              text=True)
    try:
        said = {holder.stdout.readline().strip(), holder.stdout.readline().strip()}
        assert said == {"locked", "child"}
        children += [int(p) for p in Path(f"/proc/{holder.pid}/task/{holder.pid}/children")
                    .read_text().split()]
        assert len(children) == 1
        fds = Path(f"/proc/{children[0]}/fd")
        assert not [p for p in fds.iterdir() if "lock" in os.path.realpath(p)]
        with pytest.raises(Exception, match=rf"another batch \(pid {holder.pid}\)"):
            OutputLock(out).__enter__()
        holder.kill()
        holder.wait()
        assert Path(f"/proc/{children[0]}").exists()  # the child lives on
        with OutputLock(out):
            pass
    finally:
        _kill_all(holder, children)


def test_a_second_lock_on_the_same_output_in_one_process_is_refused(tmp_path):
    from gcalign.app.batch.store import OutputLock
    from gcalign.errors import GcalignError

    with OutputLock(tmp_path / "b.h5"):
        with pytest.raises(GcalignError, match="this process"):
            OutputLock(tmp_path / "b.h5").__enter__()
    with OutputLock(tmp_path / "b.h5"):  # released: free again
        pass


# --------------------------------------------------------------------------- Dask


class Listener:
    """A TCP listener on 127.0.0.1 that accepts and then says nothing (or an HTTP reply);
    it stops by itself after `life_s`."""

    def __init__(self, http: bool = False, life_s: float = 40.0):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.http, self.life_s = http, life_s
        self.conns: list[socket.socket] = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        end = time.monotonic() + self.life_s
        while time.monotonic() < end:
            try:
                c, _ = self.sock.accept()
            except OSError:
                continue
            self.conns.append(c)
            if self.http:
                c.sendall(b"HTTP/1.1 200 OK\r\nContent-Length: 2\r\n\r\nok")
        for c in self.conns:
            c.close()
        self.sock.close()


def dask_cluster(workers: int = 0, life_s: float = 60.0) -> tuple[subprocess.Popen, str]:
    """A real Dask scheduler on 127.0.0.1 with `workers` one-thread workers, in a child
    process that ends after `life_s`: the process and the scheduler's address."""
    pytest.importorskip("distributed")
    code = ("import asyncio\nfrom contextlib import AsyncExitStack\n"
            "from distributed import Scheduler, Worker\n"
            "async def main():\n"
            "    async with Scheduler(host='127.0.0.1', port=0, dashboard_address=None) as s:\n"
            "        async with AsyncExitStack() as stack:\n"
            f"            for _ in range({workers}):\n"
            "                await stack.enter_async_context(Worker(s.address, nthreads=1))\n"
            "            print(s.address, flush=True)\n"
            f"            await asyncio.sleep({life_s})\n"
            "asyncio.run(main())\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                         stderr=subprocess.DEVNULL)
    address = p.stdout.readline().strip()  # type: ignore[union-attr]
    if not address.startswith("tcp://127.0.0.1:"):
        p.kill()
        p.wait()
        raise AssertionError(address)
    return p, address


@pytest.fixture
def zero_worker_scheduler():
    """A real Dask scheduler on 127.0.0.1 with no workers (a child process, stopped after)."""
    p, address = dask_cluster()
    try:
        yield address
    finally:
        p.kill()
        p.wait()


def _dask_fails_fast(tmp_path, address, expect: str, resume: bool = False):
    sweep(tmp_path)
    res = cli(["batch", "SW.yaml", "-o", "b.h5", "--scheduler", address]
              + (["--resume"] if resume else []), tmp_path, timeout=HANG_S)
    assert res.returncode == 1, res.stderr
    assert expect in one_error_line(res.stderr)
    return res


@pytest.mark.slow  # several seconds of child processes
@pytest.mark.parametrize("http", [False, True], ids=["plain-tcp", "http"])
def test_a_listener_that_is_not_dask_fails_within_the_bound(tmp_path, http):
    pytest.importorskip("distributed")
    srv = Listener(http=http)
    _dask_fails_fast(tmp_path, f"tcp://127.0.0.1:{srv.port}", "cannot reach the Dask scheduler")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["S.yaml", "SW.yaml"]


@pytest.mark.parametrize("address, why", [
    ("notaurl", "has no port"), ("tcp://127.0.0.1:0", "has the port '0'"),
    ("tcp://127.0.0.1:99999", "has the port '99999'"), ("tcp://127.0.0.1", "has no port"),
    ("http://127.0.0.1:8786", "has the scheme 'http'"),
    ("tcp://[::1:8786", "opens an IPv6 bracket and never closes it"),
    ("tcp://" + "h" * 5000 + ":8786", "does not name a host"), ("", "is empty"),
    ("tcp://::1:8786", "an IPv6 address without brackets")])
def test_a_bad_scheduler_address_is_exit_2_at_once(tmp_path, address, why):
    """They were exit 1 after 4 s of trying to connect (and '' ran locally in silence)."""
    from typer.testing import CliRunner

    from gcalign.cli import app

    sweep(tmp_path)
    t0 = time.perf_counter()
    res = CliRunner().invoke(app, ["batch", str(tmp_path / "SW.yaml"), "-o",
                                   str(tmp_path / "b.h5"), "--scheduler", address])
    assert res.exit_code == 2, res.output
    line = one_error_line(res.stderr)
    assert line.startswith("error: --scheduler: ") and why in line, line
    assert time.perf_counter() - t0 < 3.0  # not after Dask's 4 s of trying (a loaded CI: not 1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["S.yaml", "SW.yaml"]


def test_good_scheduler_addresses_are_taken_as_dask_writes_them():
    from gcalign.app.batch.backends import check_address

    assert check_address("tcp://10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert check_address(" 127.0.0.1:8786 ") == "tcp://127.0.0.1:8786"
    assert check_address("tls://[fe80::1]:8786") == "tls://[fe80::1]:8786"
    assert check_address("tcp://node-7.cluster.local:65535") == "tcp://node-7.cluster.local:65535"


@pytest.mark.slow  # a scheduler, a worker and a batch as child processes, about 20 s
def test_a_scheduler_that_dies_mid_batch_is_one_line(tmp_path):
    """Dask's client logged "distributed.client - ERROR - Failed to reconnect ..." before
    our line; only ours remains, and the journal keeps the finished runs."""
    cluster, address = dask_cluster(workers=1, life_s=120.0)
    try:
        sweep(tmp_path, seeds=200)
        p = subprocess.Popen(GCALIGN + ["batch", "SW.yaml", "-o", "b.h5", "--scheduler",
                                        address], cwd=tmp_path, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=_this_gcalign())
        journal = tmp_path / "b.h5.journal.jsonl"
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline and (not journal.exists()
                                               or len(journal.read_text().splitlines()) < 3):
            time.sleep(0.05)
        cluster.terminate()  # a scheduler shut down: the client tries to reconnect for 4 s
        _, err = p.communicate(timeout=HANG_S)
    finally:
        cluster.kill()
        cluster.wait()
    assert p.returncode == 1, err
    line = one_error_line(err)
    assert "Dask scheduler" in line and "--resume" in line, line
    assert journal.exists()


@pytest.mark.slow  # several seconds of child processes
def test_a_scheduler_without_workers_fails_within_the_bound(tmp_path, zero_worker_scheduler):
    _dask_fails_fast(tmp_path, zero_worker_scheduler, "has no workers")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["S.yaml", "SW.yaml"]


@pytest.mark.slow  # several seconds of child processes
def test_a_resumed_batch_keeps_its_journal_when_the_scheduler_fails(tmp_path,
                                                                     zero_worker_scheduler):
    sweep(tmp_path)
    p = spawn(["batch", "SW.yaml", "-o", "b.h5", "-w", "1"], tmp_path)
    deadline = time.monotonic() + 60
    journal = tmp_path / "b.h5.journal.jsonl"
    while time.monotonic() < deadline and (not journal.exists()
                                           or len(journal.read_text().splitlines()) < 3):
        time.sleep(0.02)
    p.kill()
    p.wait()
    before = journal.read_bytes()
    _dask_fails_fast(tmp_path, zero_worker_scheduler, "has no workers", resume=True)
    assert journal.read_bytes() == before


@pytest.mark.slow  # several seconds of child processes
def test_resume_rejects_damaged_records_and_reruns_them(tmp_path, uninterrupted):
    """A journal with garbage, records without metrics, NaN or short-list metrics: those
    lines are skipped (a note says how many) and their runs run again; the aggregate is the
    uninterrupted one."""
    sweep(tmp_path)
    good = cli(["batch", "SW.yaml", "-o", "ref.h5", "-w", "1"], tmp_path)
    assert good.returncode == 0
    header = json.dumps({"type": "header"})
    bad = [b"\x00\xff garbage", b'{"type": "run", "variant": 0, "seed": 1}',
           json.dumps({"type": "run", "variant": 0, "vkey": "x", "seed": 1, "status": "ok",
                       "metrics": {"error_t3_deg": [float("nan"), 0, 0]}}).encode(),
           json.dumps({"type": "run", "variant": 0, "vkey": "x", "seed": 2, "status": "ok",
                       "metrics": {"error_t3_deg": [0.1]}}).encode()]
    (tmp_path / "b.h5.journal.jsonl").write_bytes(header.encode() + b"\n" + b"\n".join(bad))
    res = cli(["batch", "SW.yaml", "-o", "b.h5", "-w", "1", "--resume"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert "skipped 4 line(s)" in res.stderr
    assert aggregate_of(tmp_path / "b.h5") == uninterrupted
    assert np.isfinite(np.asarray(aggregate_of(tmp_path / "b.h5")["runs"])).all()


@pytest.mark.slow
def test_plot_into_an_existing_file_or_under_one_is_one_line(tmp_path):
    scenario(tmp_path)
    assert cli(["align", "S.yaml", "-o", "s.h5"], tmp_path).returncode == 0
    (tmp_path / "afile").write_text("x")
    for out in ("afile", "afile/figs"):
        res = cli(["plot", "s.h5", "-o", out], tmp_path)
        assert res.returncode == 2, res.stderr
        assert "--output" in one_error_line(res.stderr)
    assert (tmp_path / "afile").read_text() == "x"


def test_stale_temps_of_dead_processes_are_removed_and_live_ones_kept(tmp_path):
    """Temporary files of processes that are gone (this version's names and the older
    ``.NAME.PID.tmp`` of HDF5 files) are removed by the next run into the folder; those of
    a live process, and files that only look like them, are kept."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    live = str(os.getpid())
    hdf5 = b"\x89HDF\r\n\x1a\n" + b"\0" * 100
    files = {f".a.h5.{dead}.x1y2{results.TMP_SUFFIX}": b"", f".b.h5.{dead}.tmp": hdf5,
             f".c.h5.{live}.x1y2{results.TMP_SUFFIX}": b"", f".d.h5.{dead}.tmp": b"not hdf5",
             f"e.h5.{dead}.tmp": hdf5}
    for name, body in files.items():
        (tmp_path / name).write_bytes(body)
    removed = {p.name for p in results.clean_stale_temps(tmp_path)}
    assert removed == {f".a.h5.{dead}.x1y2{results.TMP_SUFFIX}", f".b.h5.{dead}.tmp"}
    assert {p.name for p in tmp_path.iterdir()} == set(files) - removed


@pytest.mark.slow
def test_a_terminated_pool_worker_dies_even_under_the_commands_sigterm_handler(tmp_path):
    """The command's SIGTERM handler raises (so that it can remove its temporary files);
    forked pool workers inherit it. ``close(cancel=True)`` terminates the workers: they must
    die, not send the exception back through a queue no one reads (which hung the process
    that ran the batch in-process, at its exit). The second worker is held 0.5 s after its
    fork, before the pool's initializer resets the handler: terminated there, it must die
    too (it lived on, exit code 1 or None). In a fresh process: a pool is forked only from a
    process with a single thread."""
    code = """if True:
        import os, signal, sys, time
        from gcalign.app.batch.backends import local_workers
        from gcalign.cli import _terminate
        signal.signal(signal.SIGTERM, _terminate)
        forks = [0]
        os.register_at_fork(after_in_parent=lambda: forks.__setitem__(0, forks[0] + 1),
                            after_in_child=lambda: forks[0] == 1 and time.sleep(0.5))
        backend = local_workers(2, "simulate")
        assert backend.start_method == "fork", backend.start_method
        procs = list(backend.executor._processes.values())
        assert len(procs) == 2 and all(p.is_alive() for p in procs)
        backend.close(cancel=True)
        deadline = time.monotonic() + 10
        while any(p.is_alive() for p in procs) and time.monotonic() < deadline:
            time.sleep(0.05)
        print([p.exitcode for p in procs])
    """
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    # killed by the signal, or (not held) already gone on the pool's own shutdown sentinel
    codes = json.loads(res.stdout)
    assert codes[1] == -signal.SIGTERM and codes[0] in (-signal.SIGTERM, 0), codes
    assert res.stderr == ""  # no exception raised in a worker (it exits 0 then, logged)


_DIES_AT_SEED_2 = """
import json, os
import gcalign.app.batch.backends as K
from gcalign.app.batch.engine import run_batch
from gcalign.app.batch.sweep import load_sweep

real = K.run_chunk


def dies(tasks):
    if any(t["seed"] == 2 for t in tasks):
        os._exit(3)  # a worker that crashes (a segfault, the OOM killer) on this run
    return real(tasks)


K.run_chunk = dies
res = run_batch(load_sweep("SW.yaml"), "b.h5", workers=2, chunk_size=3)
print(json.dumps(res.summary))
"""


@pytest.mark.slow  # a batch with a real pool, in a child process
def test_a_worker_that_dies_breaks_the_local_pool_and_the_batch_goes_on(tmp_path):
    """A real pool whose worker dies on seed 2 of each variant (chunks of 3 runs): the pool
    is broken, every chunk in flight lost; a new pool runs each lost run again, alone. The
    crashers are recorded failed; every other run either finished with the uninterrupted
    run's numbers or, lost a second time beside a crasher, is recorded failed too; each run
    once."""
    sweep(tmp_path, seeds=6)
    res = subprocess.run([sys.executable, "-c", _DIES_AT_SEED_2], cwd=tmp_path, timeout=300,
                         capture_output=True, text=True, env=_this_gcalign())
    assert res.returncode == 0, res.stderr
    s = json.loads(res.stdout)
    crashed = {(f["variant"], f["seed"]) for f in s["failures"]}
    assert {(0, 2), (1, 2)} <= crashed
    assert all("worker process died" in f["error"] for f in s["failures"])
    assert s["ok"] + s["failed"] == s["runs"] == 12 and s["ok"] >= 1
    with h5py.File(tmp_path / "b.h5", "r") as f:
        keys = list(zip(f["batch/runs/variant"][()].tolist(), f["batch/runs/seed"][()].tolist(),
                        strict=True))
        got = f["batch/runs/metrics/error_t3_deg"][()]
        status = [x.decode() for x in f["batch/runs/status"][()]]
    assert sorted(keys) == [(v, k) for v in (0, 1) for k in range(1, 7)]
    ref_dir = tmp_path / "ref"
    ref_dir.mkdir()
    sweep(ref_dir, seeds=6)
    assert cli(["batch", "SW.yaml", "-o", "ref.h5", "-w", "1"], ref_dir).returncode == 0
    with h5py.File(ref_dir / "ref.h5", "r") as f:
        ref = dict(zip(zip(f["batch/runs/variant"][()].tolist(),
                           f["batch/runs/seed"][()].tolist(), strict=True),
                       f["batch/runs/metrics/error_t3_deg"][()], strict=True))
    for k, row, st in zip(keys, got, status, strict=True):
        if st == "ok":
            np.testing.assert_array_equal(row, ref[k])


def test_results_files_have_ordinary_permissions(tmp_path):
    """The temporary file is private (mkstemp); the file under the final name is not."""
    mask = os.umask(0o022)
    try:
        with results.atomic_h5(tmp_path / "r.h5") as f:
            f.attrs["x"] = 1
    finally:
        os.umask(mask)
    assert (tmp_path / "r.h5").stat().st_mode & 0o777 == 0o644


@pytest.mark.slow
@pytest.mark.parametrize("limit", [30_000, 51_200, 120_000])
def test_full_disk_during_modulate_is_exit_1_one_line_and_nothing_kept(tmp_path, limit):
    """modulate streams its series into the results file as it navigates (its sink): a
    write refused there (``ulimit -f``) goes through the same guard as every other
    command's: exit 1, one line naming the file, neither the file nor its temporary."""
    d = json.loads(json.dumps(F.MODULATE))
    d["modulate"]["hours"] = 1.0
    d["output"] = {"rate_hz": 10}
    (tmp_path / "M.yaml").write_text(F.emit(d))
    res = cli(["modulate", "M.yaml", "-o", "o.h5"], tmp_path, limit_fsize=limit)
    assert res.returncode == 1, res.stderr[-2000:]
    assert "cannot write o.h5: File too large" in one_error_line(res.stderr)
    assert not (tmp_path / "o.h5").exists() and temps(tmp_path) == []


@pytest.mark.slow  # child processes
def test_stdout_that_refuses_writes_is_exit_1_one_line(tmp_path):
    """``> /dev/full`` and a closed stdout: exit 1, "cannot write to stdout" (they were
    internal errors)."""
    with open("/dev/full", "w") as full:
        res = subprocess.run(GCALIGN + ["example", "calibrate"], cwd=tmp_path, stdout=full,
                             stderr=subprocess.PIPE, text=True, timeout=120)
    assert res.returncode == 1
    assert one_error_line(res.stderr) == ("error: cannot write to stdout: No space left on "
                                          "device")
    res = subprocess.run(["bash", "-c", 'exec "$@" >&-', "_", *GCALIGN, "example", "calibrate"],
                         cwd=tmp_path, capture_output=False, stderr=subprocess.PIPE, text=True,
                         timeout=120)
    assert res.returncode == 1
    assert one_error_line(res.stderr) == "error: cannot write to stdout: it is closed"


@pytest.mark.slow
@pytest.mark.parametrize("command, limit_mb", [("align", 300)])
def test_address_space_limit_is_out_of_memory_not_a_bad_output(tmp_path, command, limit_mb):
    """``ulimit -v``: a shared library that cannot be mapped (numba's llvmlite, OpenBLAS) or
    a MemoryError is exit 1 "out of memory" (it was "--output: cannot write ...
    libllvmlite.so", exit 2), and the temporary file is gone."""
    lim = limit_mb * 2**20

    def pre():
        resource.setrlimit(resource.RLIMIT_AS, (lim, lim))

    res = subprocess.run(GCALIGN + [command, "-o", "o.h5"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300, preexec_fn=pre)
    assert res.returncode == 1, res.stderr
    assert one_error_line(res.stderr).startswith("error: out of memory")
    assert not (tmp_path / "o.h5").exists() and temps(tmp_path) == []


def _limited(limit_mb: int):
    lim = limit_mb * 2**20
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (lim, lim))


@pytest.mark.slow
@pytest.mark.parametrize("limit_mb", [600, 540, 520, 480, 450])
def test_openblas_under_an_address_space_limit_is_never_its_own_message(tmp_path, limit_mb):
    """``ulimit -v`` and the real-time run (SciPy's OpenBLAS takes its buffer late, in
    expm): OpenBLAS printed "Memory allocation still failed after 10 retries, giving up"
    and called exit(1) at 600 and 540 MB (the temporary file stayed), and retried without
    end at 500 MB. With one OpenBLAS thread and the buffers taken when the libraries load,
    the run succeeds or is exit 1, our one "out of memory" line; nothing is left. 520 and
    480 MB: NumPy's first LAPACK solve (``lfilter_zi``) took a buffer of its own after the
    product that had warmed it (OpenBLAS's message at 520, no end at 480); a solve warms it
    now."""
    res = subprocess.run(GCALIGN + ["realtime", "-o", "o.h5"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300,
                         preexec_fn=_limited(limit_mb))
    assert "OpenBLAS" not in res.stderr, res.stderr
    assert temps(tmp_path) == []
    if res.returncode == 0:
        assert (tmp_path / "o.h5").is_file() and res.stderr.strip() == "wrote o.h5"
    else:
        assert res.returncode == 1, res.stderr
        assert one_error_line(res.stderr).startswith("error: out of memory")
        assert not (tmp_path / "o.h5").exists()


@pytest.mark.slow  # child processes
def test_an_address_space_limit_gives_one_openblas_thread_unless_one_is_asked_for(tmp_path):
    """Under a limit the command line sets OPENBLAS_NUM_THREADS=1 before NumPy loads (each
    further thread maps a buffer and a stack of its own); a count the user set stays, and
    without a limit nothing is set."""
    probe = ("import os, gcalign.cli, numpy; "
             "print(os.environ.get('OPENBLAS_NUM_THREADS'))")

    def threads(limit_mb: int | None, **env) -> str:
        e = {k: v for k, v in os.environ.items() if not k.endswith("NUM_THREADS")} | env
        res = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=e,
                             capture_output=True, text=True, timeout=120,
                             preexec_fn=None if limit_mb is None else _limited(limit_mb))
        assert res.returncode == 0, res.stderr
        return res.stdout.strip()

    assert threads(2000) == "1"
    assert threads(2000, OPENBLAS_NUM_THREADS="2") == "2"
    assert threads(None) == "None"


@pytest.mark.slow  # a child process
def test_no_room_for_numpys_openblas_buffer_is_one_line(tmp_path):
    """A limit that leaves too little room for NumPy's OpenBLAS buffer at start-up: exit 1,
    one "out of memory" line naming the limit (OpenBLAS itself would end the process or
    retry without end)."""
    from gcalign.cli.address_space import BUFFER_BYTES, mapped_bytes

    probe = ("import resource, sys; from gcalign.cli.address_space import mapped_bytes; "
             f"import numpy; lim = mapped_bytes() + {BUFFER_BYTES // 2}; "
             "resource.setrlimit(resource.RLIMIT_AS, (lim, lim)); "
             "sys.modules.pop('gcalign.cli.address_space'); "
             "import gcalign.cli.address_space")
    assert mapped_bytes() > 0  # Linux
    res = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 1, res.stderr
    line = one_error_line(res.stderr)
    assert line.startswith("error: out of memory: the address-space limit (ulimit -v, ")
    assert "numpy's OpenBLAS needs 48 MB" in line


#: A C call that keeps the GIL, as a numba kernel does for a whole run: the watcher thread
#: of a worker inside it never runs. Each worker first leaves a file named by its id.
_HOLD_THE_GIL = """
import ctypes, os

def hold(*args):
    open(f"running.{os.getpid()}", "w").close()
    ctypes.PyDLL(None).sleep(120)
    return []
"""


def _running_workers(p: subprocess.Popen, folder: Path, n: int, wait_s: float) -> list[int]:
    """The ids of the `n` workers of `p` once each is inside ``hold`` (waits on their files,
    not on a clock: a loaded machine may take many seconds to start them)."""
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline and p.poll() is None:
        pids = [int(f.name.split(".")[1]) for f in folder.glob("running.*")]
        if len(pids) == n:
            return pids
        time.sleep(0.05)
    raise AssertionError(f"{n} workers did not start within {wait_s:g} s "
                         f"(batch exit code {p.poll()})")


def _outlive(pids: list[int], grace_s: float) -> list[int]:
    """Those of `pids` still alive (not zombies) after up to `grace_s` s."""
    deadline = time.monotonic() + grace_s
    alive = pids
    while alive and time.monotonic() < deadline:
        time.sleep(0.05)
        alive = [q for q in pids if _alive(q)]
    return alive


def _kill_all(p: subprocess.Popen, pids: list[int]) -> None:
    p.kill()
    p.wait()
    for q in pids:
        try:
            os.kill(q, signal.SIGKILL)
        except ProcessLookupError:
            pass


@pytest.mark.slow  # child processes, a few seconds
def test_pool_workers_die_with_a_killed_batch_even_inside_a_long_kernel(tmp_path):
    """kill -9 of a batch: its workers must not compute on as orphans. A worker inside a
    long numba kernel holds the GIL, so its watcher thread never ran: a killed batch left its
    pool (three processes, 450 MB) running for nine minutes. Here each worker holds the GIL
    in a C call for 120 s (what a kernel does) when the batch process is killed."""
    code = _HOLD_THE_GIL + """
import time
from gcalign.app.batch.backends import local_workers

backend = local_workers(2, "simulate")
futures = [backend.executor.submit(hold) for _ in range(2)]
time.sleep(120)
"""
    p = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path, env=_this_gcalign())
    pids: list[int] = []
    try:
        pids = _running_workers(p, tmp_path, 2, wait_s=120.0)
        p.kill()
        p.wait()
        assert _outlive(pids, 10.0) == [], "workers outlived the killed batch"
    finally:
        _kill_all(p, pids)


@pytest.mark.slow  # a batch as a child process, a few seconds
def test_a_gcalign_batch_killed_with_sigkill_leaves_no_worker_running(tmp_path):
    """The command line itself (``gcalign batch SW.yaml -w 2``), killed with SIGKILL while
    both its workers are inside a run that holds the GIL (the function each worker runs is
    replaced by one, before the pool forks): the workers die with it, within 10 s (at once:
    the kernel kills them); before, they ran their runs to the end as orphans."""
    sweep(tmp_path)
    code = _HOLD_THE_GIL + """
import sys
import gcalign.app.batch.backends as B
from gcalign.cli import main

B.run_chunk = hold
sys.argv = ["gcalign", "batch", "SW.yaml", "-o", "b.h5", "-w", "2"]
main()
"""
    p = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path, env=_this_gcalign(),
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    pids: list[int] = []
    try:
        pids = _running_workers(p, tmp_path, 2, wait_s=120.0)
        assert all(_parent(q) == p.pid for q in pids)  # the batch's own pool
        p.kill()
        p.wait()
        assert _outlive(pids, 10.0) == [], "workers outlived the killed batch"
        assert not (tmp_path / "b.h5").exists()
    finally:
        _kill_all(p, pids)


def _parent(pid: int) -> int:
    with open(f"/proc/{pid}/stat") as f:
        return int(f.read().split(") ", 1)[1].split()[1])


def _alive(pid: int) -> bool:
    """Alive and not a zombie (an orphan reaped by init leaves no entry)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ", 1)[1][0] != "Z"
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False


def _this_gcalign() -> dict:
    """The environment of a child process that imports the gcalign under test (the one this
    process imported), wherever the child's working folder is."""
    import gcalign

    return {**os.environ, "PYTHONPATH": str(Path(gcalign.__file__).parents[1])}
