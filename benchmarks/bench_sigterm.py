"""How promptly a SIGTERM ends a command: the raising handler against a flag-only one.

The command line's handler (``gcalign.cli.base._terminate``) sets
``errors.TERMINATE_REQUESTED`` and raises ``Terminated`` wherever the main thread is; the
alternative weighed here only sets the flag, and the run ends at the next point that asks
(``errors.check_terminated``: each commit of a file, the journal). Both see the same cases,
in turn:

* ``simulate`` of 3000 s, signalled once its temporary file exists (in its write);
* ``align`` of the built-in §5.3 case with 41 passes (a numba kernel call each) on 2000 s of
  data, signalled ``--delay`` s after start (in its passes);
* ``batch`` of 200 seeds on 2 workers, signalled once the journal holds 2 lines.

For each: seconds from the signal to the end of the process, its exit code, temporary files
left and whether a results file exists under the name. Medians over ``--repeat`` turns.

Run: ``python benchmarks/bench_sigterm.py [--repeat 5]``
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes

RUN = ("import sys\n"
       "import gcalign.cli.base as base\n"
       "from gcalign.errors import TERMINATE_REQUESTED\n"
       "if sys.argv[1] == 'flag-only':\n"
       "    def flag(signum, frame):\n"
       "        TERMINATE_REQUESTED[0] = True\n"
       "    base._terminate = flag\n"
       "from gcalign.cli import main\n"
       "sys.argv = ['gcalign', *sys.argv[2:]]\n"
       "main()\n")
SCENARIO = resources.files("gcalign.scenarios").joinpath("seed000_moving_full_cycle.yaml")


def case(name: str, folder: Path, delay: float) -> tuple[list[str], callable, Path]:
    base = Path(str(SCENARIO)).resolve()
    if name == "simulate":
        args = ["simulate", str(base), "--set", "motion.duration_s=3000", "-o", "out.h5"]

        def ready() -> bool:
            return bool([p for p in folder.iterdir() if p.name.startswith(".out.h5")])
    elif name == "align":
        args = ["align", str(base), "--passes", "41", "--set", "motion.duration_s=2100",
                "--t2", "2000", "--t3", "2010", "-o", "out.h5"]
        t0 = time.monotonic()

        def ready() -> bool:
            return time.monotonic() - t0 >= delay
    else:
        (folder / "SW.yaml").write_text(f"name: sw\nbase: {base}\nseeds: 200\n"
                                        "metrics: [error_t3_deg]\n")
        args = ["batch", "SW.yaml", "-w", "2", "-o", "out.h5"]

        def ready() -> bool:
            j = folder / "out.h5.journal.jsonl"
            return j.exists() and len(j.read_text().splitlines()) >= 2
    return args, ready, folder / "out.h5"


def one(name: str, handler: str, delay: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        args, ready, out = case(name, folder, delay)
        p = subprocess.Popen([sys.executable, "-c", RUN, handler, *args], cwd=folder,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        while not ready() and p.poll() is None:
            time.sleep(0.005)
        if p.poll() is not None:
            return {"latency": float("nan"), "code": p.returncode, "left": [],
                    "file": out.exists(), "note": "ended before the signal"}
        t0 = time.monotonic()
        p.send_signal(signal.SIGTERM)
        _, err = p.communicate(timeout=600)
        latency = time.monotonic() - t0
        left = [q.name for q in folder.iterdir() if q.name.startswith(".out.h5.")]
        return {"latency": latency, "code": p.returncode, "left": left, "file": out.exists(),
                "note": err.strip().splitlines()[-1] if err.strip() else ""}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1 if SMOKE else 5)
    ap.add_argument("--delay", type=float, default=4.0)
    # smoke: the batch only (a flag-only handler ends simulate and align about a minute late)
    ap.add_argument("--cases", default="batch" if SMOKE else "simulate,align,batch")
    args = ap.parse_args()
    for name in args.cases.split(","):
        seen: dict[str, list[dict]] = {"raising": [], "flag-only": []}
        for _ in range(args.repeat):
            for handler in seen:  # interleaved
                seen[handler].append(one(name, handler, args.delay))
        for handler, rows in seen.items():
            lat = statistics.median(r["latency"] for r in rows)
            codes = sorted({r["code"] for r in rows})
            left = sum(bool(r["left"]) for r in rows)
            files = sum(r["file"] for r in rows)
            print(f"{name:9s} {handler:9s} signal -> exit: median {lat:6.2f} s "
                  f"(max {max(r['latency'] for r in rows):6.2f}), exit codes {codes}, "
                  f"temporary files left {left}/{len(rows)}, file under the name "
                  f"{files}/{len(rows)}; last line: {rows[-1]['note'][:70]!r}", flush=True)


if __name__ == "__main__":
    main()
