"""``gcalign batch`` on a local pool against a Dask cluster, this checkout against another.

Seeds of the built-in §5.3 case (``seed000_moving_full_cycle.yaml``) as one batch: with
``--workers 2`` (a local process pool) and with ``--scheduler`` on a Dask cluster of two
one-thread worker processes on this machine (started once beforehand, one cluster per
checkout, each importing its own tree), for each size of ``--sizes``; then ``--big`` seeds
with ``--workers 2``. With ``--before DIR`` every configuration runs on DIR's tree too, the
two trees in turn (before, after, before, ...) so that both see the same load. Reported:
the batch's own wall time (``wall_s`` of its summary: pool or connection, runs, journal,
file) and the command's end to end, medians over ``--repeat`` turns; and whether every
batch of a size gave the same aggregate (trees and executors alike).

Run: ``python benchmarks/bench_executor.py [--before DIR] [--repeat 5]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes

HERE = Path(__file__).resolve().parents[1]
CLUSTER = ("import sys\n"
           "from distributed import LocalCluster\n"
           "c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,\n"
           "                 host='127.0.0.1', dashboard_address=None)\n"
           "print(c.scheduler_address, flush=True)\n"
           "sys.stdin.read()\n"
           "c.close()\n")


def env_for(tree: Path) -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(tree), "GCALIGN_PROGRESS": "0"}


def sweep_file(folder: Path, seeds: int) -> Path:
    base = resources.files("gcalign.scenarios").joinpath("seed000_moving_full_cycle.yaml")
    path = folder / f"mc{seeds}.yaml"
    path.write_text(f"name: mc\nbase: {Path(str(base)).resolve()}\nseeds: {seeds}\n"
                    "metrics: [error_t3_deg, error_t2_deg]\n", encoding="utf-8")
    return path


def batch(tree: Path, sweep: Path, out: Path, where: list[str]) -> tuple[float, dict]:
    cmd = [sys.executable, "-c", "from gcalign.cli import main; main()", "batch",
           str(sweep), *where, "-o", str(out), "--json"]
    out.unlink(missing_ok=True)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env_for(tree), cwd=tree)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(f"gcalign batch {' '.join(where)} on {tree} failed ({proc.returncode}):\n"
                 f"{proc.stderr}")
    return wall, json.loads(proc.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", type=Path)
    ap.add_argument("--sizes", default="4" if SMOKE else "200,400")
    ap.add_argument("--big", type=int, default=8 if SMOKE else 1000)
    ap.add_argument("--repeat", type=int, default=1 if SMOKE else 5)
    args = ap.parse_args()
    trees = {"after": HERE}
    if args.before:
        trees = {"before": args.before.resolve(), "after": HERE}
    sizes = [int(x) for x in args.sizes.split(",")]
    clusters = {}
    try:
        for name, tree in trees.items():
            p = subprocess.Popen([sys.executable, "-c", CLUSTER], stdin=subprocess.PIPE,
                                 stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                 text=True, env=env_for(tree), cwd=tree)
            clusters[name] = (p, p.stdout.readline().strip())  # type: ignore[union-attr]
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            sweeps = {n: sweep_file(folder, n) for n in (*sizes, args.big, 8)}
            configs = {"local": lambda name: ["--workers", "2"],
                       "dask": lambda name: ["--scheduler", clusters[name][1]]}
            for name, tree in trees.items():  # JIT caches and Dask workers warmed
                for where in configs.values():
                    batch(tree, sweeps[8], folder / "warm.h5", where(name))
            seen: dict[tuple, list[tuple[float, float]]] = {}
            aggregates: dict[int, list[str]] = {}
            plan = [(n, c) for n in sizes for c in configs] + [(args.big, "local")]
            for turn in range(args.repeat):
                for n, c in plan:
                    for name, tree in trees.items():
                        wall, s = batch(tree, sweeps[n], folder / "b.h5", configs[c](name))
                        seen.setdefault((n, c, name), []).append((s["wall_s"], wall))
                        aggregates.setdefault(n, []).append(json.dumps(s["variants"]))
                print(f"turn {turn + 1}/{args.repeat} done, load {os.getloadavg()[0]:.1f}",
                      flush=True)
    finally:
        for p, _ in clusters.values():
            p.stdin.close()  # type: ignore[union-attr]
            p.wait(timeout=60)
    print(f"median of {args.repeat}, trees in turn; wall s (engine / end to end)")
    for (n, c, name), rows in seen.items():
        eng = statistics.median(r[0] for r in rows)
        e2e = statistics.median(r[1] for r in rows)
        print(f"  {n:5d} seeds  {c:5s}  {name:6s}  {eng:7.2f} / {e2e:7.2f}   "
              f"(all: {', '.join(f'{r[0]:.1f}' for r in rows)})")
    for n, ags in aggregates.items():
        print(f"  {n} seeds: {len(ags)} batches, aggregates identical: {len(set(ags)) == 1}")


if __name__ == "__main__":
    main()
