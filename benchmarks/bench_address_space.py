"""What the OpenBLAS import hook of ``gcalign.cli.address_space`` buys, measured.

``gcalign realtime`` (SciPy's OpenBLAS takes its buffer late, in ``expm``) under
``ulimit -v`` at limits from ``--low`` to ``--high`` MB, once with the command line as it is
and once with the hook taken out of ``sys.meta_path`` before anything imports SciPy (the
thread count and NumPy's early buffer kept). Each run is classed: ``ok`` (the file written),
``ours`` (exit 1, our one "out of memory" line), ``OpenBLAS`` (OpenBLAS's own message: it
ends the process itself, the temporary file left) or ``hang`` (no end within ``--timeout``).
Then the price of the alternative, SciPy's buffer taken at start-up under any limit: the
address space and CPU time that importing ``scipy.linalg`` and its first BLAS call cost a
command that never uses SciPy.

Run: ``python benchmarks/bench_address_space.py [--low 400] [--high 700] [--step 10]``
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

RUN = ("import sys; import gcalign.cli.address_space as A\n"
       "if sys.argv[1] == 'without':\n"
       "    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, A._WarmScipy)]\n"
       "from gcalign.cli import main\n"
       "sys.argv = ['gcalign', 'realtime', '-o', 'o.h5']\n"
       "main()\n")
EAGER = ("import time, gcalign.cli.address_space as A; m0 = A.mapped_bytes(); "
         "t = time.process_time(); import numpy as np; from scipy.linalg import blas; "
         "a = np.ones((2, 2)); blas.dgemm(1.0, a, a); "
         "print(A.mapped_bytes() - m0, time.process_time() - t)")


SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes


def limited(mb: int):
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (mb << 20, mb << 20))


def outcome(mb: int, hook: str, timeout: float) -> str:
    with tempfile.TemporaryDirectory() as tmp:
        try:
            res = subprocess.run([sys.executable, "-c", RUN, hook], cwd=tmp, text=True,
                                 capture_output=True, timeout=timeout, preexec_fn=limited(mb))
        except subprocess.TimeoutExpired:
            return "hang"
        if "OpenBLAS" in res.stderr:
            return "OpenBLAS"
        if res.returncode == 0 and (Path(tmp) / "o.h5").is_file():
            return "ok"
        if res.returncode == 1 and res.stderr.strip().startswith("error: out of memory"):
            return "ours"
        return f"exit {res.returncode}: {res.stderr.strip()[-80:]}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    # smoke: one limit where both run through (the hangs below 600 MB would take minutes)
    ap.add_argument("--low", type=int, default=700 if SMOKE else 400)
    ap.add_argument("--high", type=int, default=700)
    ap.add_argument("--step", type=int, default=10)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--repeat", type=int, default=1 if SMOKE else 5,
                    help="turns of the start-up price")
    args = ap.parse_args()
    print("limit MB   with the hook   without")
    counts: dict[str, dict[str, int]] = {"with": {}, "without": {}}
    for mb in range(args.low, args.high + 1, args.step):
        row = {}
        for hook in ("with", "without"):  # interleaved: both see the same load
            row[hook] = outcome(mb, hook, args.timeout)
            counts[hook][row[hook]] = counts[hook].get(row[hook], 0) + 1
        print(f"{mb:8d}   {row['with']:13s}   {row['without']}", flush=True)
    for hook, c in counts.items():
        print(f"{hook} the hook: " + ", ".join(f"{k} {v}" for k, v in sorted(c.items())))
    cost = [subprocess.run([sys.executable, "-c", EAGER], capture_output=True, text=True,
                           check=True, preexec_fn=limited(2000)).stdout.split()
            for _ in range(args.repeat)]
    mapped = statistics.median(float(c[0]) for c in cost) / 2**20
    cpu = statistics.median(float(c[1]) for c in cost)
    print(f"SciPy's buffer at start-up instead (under a 2000 MB limit, median of {args.repeat}): "
          f"{mapped:.0f} MB of address space and {cpu * 1e3:.0f} ms of CPU for every command")


if __name__ == "__main__":
    main()
