"""The reproductions of the third hostile-input round's leftovers (realtime settings, read-back
of a damaged compressed block, scheduler addresses, export, scenario values, a killed
batch's workers), each run as a user would from a terminal: a new ``gcalign`` process in an
empty folder, timed, with its exit code, its first stderr line and the files it left.

    python benchmarks/hostile_reproductions.py [--src DIR] [--timeout 90] [--json out.json]

``--src`` puts another checkout's ``gcalign`` first on the path (``git archive COMMIT | tar
-x -C DIR``), to measure a version without the fixes. Each case says what a right answer
is (``want``); a case is ``ok`` when it gets it, else its outcome is printed as it is. The
inputs that must be made by a working gcalign (a results file to damage) are made by this
checkout's, so both versions read the same bytes.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import fuzz_cases as F  # noqa: E402

LASERGYRO = ROOT / "tests" / "data" / "lasergyro.imu.xz"
TRANSFER = ROOT / "configs" / "psins_transfer_fog_mems.yaml"
MAT = ROOT / "tests" / "data" / "transfer_align_fog_mems.mat"
PY = [sys.executable, "-c", "import sys; from gcalign.cli import main; "
      "sys.argv[0] = 'gcalign'; main()"]


@dataclass
class Outcome:
    code: int | None
    seconds: float
    line: str
    lines: int
    left: list[str] = field(default_factory=list)
    note: str = ""


@dataclass(frozen=True)
class Case:
    item: str
    name: str
    argv: tuple
    want: str  # "exit 2", "exit 1 one line", "exit 0 same", "ScenarioError", "no orphans"
    files: Callable[[Path], None] = lambda d: None
    env: tuple = ()


def _write(name: str, data: dict) -> Callable[[Path], None]:
    return lambda d: (d / name).write_text(F.emit(data))


def _realtime(pulses: dict | None = None) -> dict:
    rt = {**F.REALTIME["realtime"]}
    if pulses is not None:
        rt["pulses"] = pulses
    return {**F.REALTIME, "realtime": rt}


def _sweep(d: Path) -> None:
    (d / "S.yaml").write_text(F.emit(F.S))
    (d / "SW.yaml").write_text(F.emit(F.SWEEP))


def _reference_csv(d: Path) -> None:
    """The MAT file's own FOG solution as a CSV reference (deg, ENU): a valid file, so
    that a key it cannot use is the only thing wrong."""
    import numpy as np
    import scipy.io

    avp = scipy.io.loadmat(MAT)["fogavp"]
    rows = np.column_stack([avp[:, 9], np.degrees(avp[:, :3]), avp[:, 3:6],
                            np.degrees(avp[:, 6:8]), avp[:, 8]])
    np.savetxt(d / "ref.csv", rows, fmt="%.10g", delimiter=",",
               header="t,pitch,roll,yaw,ve,vn,vu,lat,lon,h", comments="")


def cases(damaged: Path, nav: Path) -> list[Case]:
    C = Case
    addresses = {"port 0": "tcp://127.0.0.1:0", "port 99999": "tcp://127.0.0.1:99999",
                 "no port": "tcp://127.0.0.1", "http://": "http://127.0.0.1:8786",
                 "IPv6 bracket unclosed": "tcp://[::1:8786",
                 "host of 5000 characters": "tcp://" + "h" * 5000 + ":8786", "empty": ""}
    out = [
        C("5", "realtime.filter.nav_order=1000000",
          ("realtime", "RT.yaml", "--set", "realtime.filter.nav_order=1000000", "-o", "o.h5"),
          "exit 2", _write("RT.yaml", F.REALTIME)),
        C("5", "jitter_us=1e12, asynchronous", ("realtime", "RT.yaml", "-o", "o.h5"), "exit 2",
          _write("RT.yaml", _realtime({"mode": "async", "rate_hz": 100, "jitter_us": 1e12}))),
        C("5", "jitter_us=5 in mode solution", ("realtime", "RT.yaml", "-o", "o.h5"), "exit 2",
          _write("RT.yaml", _realtime({"mode": "solution", "rate_hz": 100, "jitter_us": 5}))),
        C("5", "show, corrupted compressed block", ("show", str(damaged)), "exit 2"),
        C("5", "plot, corrupted compressed block", ("plot", str(damaged), "-o", "figs"),
          "exit 2"),
    ]
    out += [C("6", f"--scheduler {label}", ("batch", "SW.yaml", "-o", "b.h5", "--scheduler",
                                              addr), "exit 2", _sweep)
            for label, addr in addresses.items()]
    out += [
        C("6", "Dask scheduler dies mid-batch", ("scheduler-dies",), "exit 1 one line", _sweep),
        C("6", "export past GCALIGN_MAX_OUTPUT_MB=0.001",
          ("export", str(nav), "--format", "csv", "-o", "x.csv"), "exit 2",
          env=(("GCALIGN_MAX_OUTPUT_MB", "0.001"),)),
        C("6", "MAT export twice, 1.1 s apart", ("export-twice",), "exit 0 same"),
        C("6", "initial pitch 100 deg", ("navigate", "--imu-file", str(LASERGYRO), "--set",
                                          'initial={"att_deg": [100, 0, 0]}', "-o", "n.h5"),
          "exit 2"),
        C("6", "initial velocity 1e9 m/s",
          ("navigate", "--imu-file", str(LASERGYRO), "--set",
           'initial={"att_deg": [1, 0, -90], "v_enu_mps": [1e9, 0, 0]}', "-o", "n.h5"),
          "exit 2"),
        C("6", "transfer lever arm 1e9 m", ("align", str(TRANSFER), "--set",
                                             "align.transfer.lever_arm_m=[1e9, 0, 0]", "-o",
                                             "t.h5"), "exit 2"),
        C("6", "reference.variable on a CSV reference",
          ("navigate", "--imu-file", str(MAT), "--start", "1", "--set",
           'reference={"path": "ref.csv", "format": "csv", "variable": "fogavp"}', "-o",
           "n.h5"), "exit 2", _reference_csv),
        C("6", "NaN assigned to a loaded scenario (API)", ("api-nan",), "ScenarioError"),
        C("6", "imu_file: and no align: section", ("align-defaults",), "exit 0 same",
          _write("lg.yaml", {"name": "lg", "imu_file": str(LASERGYRO)})),
        C("6", "local batch -w 2 killed with SIGKILL", ("batch-kill",), "no orphans", _sweep),
    ]
    return out


def _env(src: str | None, extra: tuple = ()) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("GCALIGN_")}
    env.update(extra)
    if src:
        env["PYTHONPATH"] = src
    return env


def _run(argv, d: Path, env: dict, timeout: float) -> tuple[int | None, str, str]:
    try:
        p = subprocess.run(PY + [str(a) for a in argv], cwd=d, env=env, capture_output=True,
                           text=True, timeout=timeout, stdin=subprocess.DEVNULL)
        return p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired as exc:
        err = exc.stderr.decode() if isinstance(exc.stderr, bytes) else (exc.stderr or "")
        return None, "", err


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ", 1)[1][0] != "Z"
    except (OSError, IndexError):
        return False


#: ``gcalign batch SW.yaml -w 2`` whose workers each run a C call that keeps the GIL for
#: 120 s, as a long numba kernel does (the align and modulate kernels of these sweeps are
#: chunked: between chunks a worker's watcher thread runs, so they cannot show it)
_HOLDING_BATCH = """
import ctypes, os, sys
import gcalign.app.batch.backends as B
from gcalign.cli import main

def hold(*args):
    open(f"running.{os.getpid()}", "w").close()
    ctypes.PyDLL(None).sleep(120)
    return []

B.run_chunk = hold
sys.argv = ["gcalign", "batch", "SW.yaml", "-o", "b.h5", "-w", "2"]
main()
"""


def _batch_kill(d: Path, env: dict, timeout: float) -> tuple[int | None, str, str]:
    """A batch with two workers, killed with SIGKILL once both are inside a run: how many
    workers live 5 s later (they were seen computing on for nine minutes)."""
    p = subprocess.Popen([sys.executable, "-c", _HOLDING_BATCH], cwd=d, env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + timeout
    workers: list[int] = []
    while time.monotonic() < deadline and len(workers) < 2 and p.poll() is None:
        workers = [int(f.name.split(".")[1]) for f in d.glob("running.*")]
        time.sleep(0.05)
    p.send_signal(signal.SIGKILL)
    p.wait()
    t0 = time.monotonic()
    while any(_alive(w) for w in workers) and time.monotonic() - t0 < 5.0:
        time.sleep(0.05)
    alive = [w for w in workers if _alive(w)]
    gone = time.monotonic() - t0
    for w in alive:
        os.kill(w, signal.SIGKILL)
    return -9, "", (f"{len(alive)} of {len(workers)} workers alive 5 s after the kill" if alive
                    else f"0 of {len(workers)} workers alive {gone:.2f} s after the kill")


_CLUSTER = """
import asyncio
from contextlib import AsyncExitStack
from distributed import Scheduler, Worker

async def main():
    async with Scheduler(host="127.0.0.1", port=0, dashboard_address=None) as s:
        async with AsyncExitStack() as stack:
            await stack.enter_async_context(Worker(s.address, nthreads=1))
            print(s.address, flush=True)
            await asyncio.sleep(120)

asyncio.run(main())
"""


def _scheduler_dies(d: Path, env: dict, timeout: float) -> tuple[int | None, str, str]:
    """A batch on a real Dask scheduler (one worker) whose scheduler is terminated after
    the batch's third result: the batch's stderr."""
    (d / "SW.yaml").write_text(F.emit({**F.SWEEP, "seeds": 200}))
    cluster = subprocess.Popen([sys.executable, "-c", _CLUSTER], stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True)
    try:
        address = cluster.stdout.readline().strip()  # type: ignore[union-attr]
        p = subprocess.Popen(PY + ["batch", "SW.yaml", "-o", "b.h5", "--scheduler", address],
                             cwd=d, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True)
        journal = d / "b.h5.journal.jsonl"
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and p.poll() is None and (
                not journal.exists() or len(journal.read_text().splitlines()) < 3):
            time.sleep(0.05)
        cluster.terminate()
        try:
            _, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            p.kill()
            _, err = p.communicate()
            return None, "", err
        return p.returncode, "", err
    finally:
        cluster.kill()
        cluster.wait()


def run(case: Case, src: str | None, timeout: float) -> Outcome:
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        case.files(d)
        before = set(os.listdir(d))
        env = _env(src, case.env)
        t0 = time.perf_counter()
        note = ""
        if case.argv == ("export-twice",):
            outs = []
            for i in range(2):
                if i:
                    time.sleep(1.1)
                code, _, err = _run(["export", case_nav, "--format", "mat", "-o", f"{i}.mat"],
                                    d, env, timeout)
                outs.append((d / f"{i}.mat").read_bytes() if code == 0 else b"")
            note = "same bytes" if outs[0] == outs[1] and outs[0] else "different bytes"
        elif case.argv == ("api-nan",):
            scenario = str(ROOT / "configs" / "seed000_moving_conventional.yaml")
            code_text = ("import math, gcalign\n"
                         f"sc = gcalign.load({scenario!r})\n"
                         "try:\n    sc.align.t2_s = math.nan\n"
                         "except Exception as e:\n"
                         "    print(type(e).__module__ + '.' + type(e).__name__, '|',"
                         " str(e).splitlines()[0], '|', len(str(e).splitlines()))\n"
                         "else:\n    print('accepted')\n")
            p = subprocess.run([sys.executable, "-c", code_text], cwd=d, env=env,
                               capture_output=True, text=True, timeout=timeout)
            code, err = p.returncode, p.stdout + p.stderr
            note = "ScenarioError" if "errors.ScenarioError" in p.stdout else "other"
        elif case.argv == ("align-defaults",):
            code, out1, err = _run(["align", "lg.yaml", "--json", "-o", "a.h5"], d, env,
                                   timeout)
            code2, out2, err2 = _run(["align", "--imu-file", LASERGYRO, "--json", "-o",
                                      "b.h5"], d, env, timeout)
            yaw = [json.loads(o)["attitude_t3_deg"][2] if c == 0 else None
                   for c, o in ((code, out1), (code2, out2))]
            note = f"yaw {yaw[0]} vs --imu-file {yaw[1]}"
            note = ("same " if yaw[0] == yaw[1] else "different ") + note
        elif case.argv == ("scheduler-dies",):
            code, _, err = _scheduler_dies(d, env, timeout)
            first = (err.strip().splitlines() or [""])[0]
            note = "ours first" if first.startswith("error: ") else "Dask's first"
        elif case.argv == ("batch-kill",):
            code, _, note = _batch_kill(d, env, timeout)
            err = ""
        else:
            code, _, err = _run(case.argv, d, env, timeout)
        seconds = time.perf_counter() - t0
        lines = err.strip().splitlines()
        left = sorted(f for f in set(os.listdir(d)) - before - {"0.mat", "1.mat", "a.h5", "b.h5"}
                      if not f.startswith("running."))
        if code is None:
            note = f"no answer within {timeout:g} s"
        return Outcome(code, seconds, lines[0][:160] if lines else "", len(lines), left, note)


def verdict(case: Case, out: Outcome) -> str:
    one_line = out.lines == 1 and out.line.startswith("error: ")
    if case.want == "exit 2":
        ok = out.code == 2 and one_line and not out.left
    elif case.want == "exit 1 one line":
        ok = out.code == 1 and one_line
    elif case.want == "exit 0 same":
        ok = out.code == 0 and out.note.startswith("same")
    elif case.want == "ScenarioError":
        return "ok" if out.note == "ScenarioError" else "broken"  # not a command line
    else:  # no orphans
        ok = out.note.startswith("0 of 2")
    if ok:
        return "ok"
    return "exit-0-wrong" if out.code == 0 else "broken"


case_nav = ""


def main(argv: list[str] | None = None) -> int:
    global case_nav
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--src", default=None)
    ap.add_argument("--timeout", type=float, default=90.0)
    ap.add_argument("--json", default=None)
    ap.add_argument("-k", default="", help="only the cases whose name contains this")
    args = ap.parse_args(argv)
    import results_bytes as RB

    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "FL.yaml").write_text(F.emit(F.FLIGHT))
        code, _, err = _run(["navigate", "FL.yaml", "-o", "nav.h5"], d, _env(None), 300)
        assert code == 0, err
        nav = d / "nav.h5"
        case_nav = str(nav)
        damaged = RB.damaged(nav, RB.offsets(nav, "navigate")[0], d / "damaged.h5")
        rows = []
        for case in cases(damaged, nav):
            if args.k not in case.name:
                continue
            out = run(case, args.src, args.timeout)
            v = verdict(case, out)
            rows.append({"item": case.item, "case": case.name, "exit": out.code,
                         "seconds": round(out.seconds, 2), "lines": out.lines,
                         "line": out.line, "left": out.left, "note": out.note, "verdict": v})
            print(f"{case.item} | {case.name} | exit {out.code} | {out.seconds:.2f} s | "
                  f"{v} | {out.note} {out.line}".rstrip(), flush=True)
    counts = {v: sum(r["verdict"] == v for r in rows) for v in ("ok", "broken", "exit-0-wrong")}
    print(f"{len(rows)} cases: " + ", ".join(f"{n} {v}" for v, n in counts.items()))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0 if counts["ok"] == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
