"""Run the benchmarks: ``python -m benchmarks [--smoke] [NAME ...]``.

Each benchmark runs as its own script (``python benchmarks/bench_NAME.py``), one after the
other. ``--smoke`` gives each tiny sizes and one or two repeats (``GCALIGN_BENCH_SMOKE=1``
in its environment), a few seconds each: the figures mean nothing then, but every benchmark
must run to its end and print them, so that none can break unseen (CI runs this). Exit 1
if any fails, naming it.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
SMOKE_ENV = "GCALIGN_BENCH_SMOKE"


def scripts() -> list[Path]:
    return sorted([*HERE.glob("bench_*.py"), HERE / "fuzz_report.py"])


def main() -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="tiny sizes: does each one run?")
    ap.add_argument("names", nargs="*", help="benchmarks to run (bench_core or core …)")
    args = ap.parse_args()
    chosen = scripts()
    if args.names:
        wanted = {n if n.startswith(("bench_", "fuzz")) else f"bench_{n}" for n in args.names}
        unknown = wanted - {p.stem for p in chosen}
        if unknown:
            ap.error(f"no benchmark {sorted(unknown)}; there are {[p.stem for p in chosen]}")
        chosen = [p for p in chosen if p.stem in wanted]
    env = dict(os.environ)
    if args.smoke:
        env[SMOKE_ENV] = "1"
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(HERE.parent),
                                                      env.get("PYTHONPATH", "")]))
    failed = []
    for path in chosen:
        print(f"== {path.stem}", flush=True)
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, str(path)], env=env, cwd=HERE.parent,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        print(proc.stdout, end="" if proc.stdout.endswith("\n") else "\n")
        wall = time.perf_counter() - t0
        if proc.returncode != 0 or not proc.stdout.strip():
            failed.append(path.stem)
            print(f"!! {path.stem} failed (exit {proc.returncode}) after {wall:.1f} s")
        else:
            print(f"-- {path.stem}: {wall:.1f} s")
    if failed:
        print(f"benchmarks that failed: {', '.join(failed)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
