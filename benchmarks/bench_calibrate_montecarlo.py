"""CPU per run of the seed 002 NEES Monte Carlo inside ``gcalign batch``, and the wall time
of a whole batch; optionally against another checkout, interleaved.

The sweep: the built-in designed take-off (``configs/seed002_designed.yaml``: 590 s, IMU
100 Hz, navigation 25 Hz, filter 1 Hz, velocity matching) with the truth drawn from P0 at
p0_scale 1 (``calibrate.truth: draw``: the consistency checks' Monte Carlo), metrics NEES
and the normalised errors (the defaults).

* one run as a pool worker executes it (``run_task``: the scenario, the sensor errors on
  the shared noise-free simulation, the filter, the NEES, the summary, the metrics), CPU
  (user + system) per run over consecutive seeds after a warm-up;
* the same seeds as a batch worker runs them, in chunks of 16 (``run_chunk``: the seeds of
  the variant in lockstep where the tree has it), CPU per run, each chunk's metrics checked
  equal to those of the same seeds run one by one;
* ``--batch N``: ``gcalign batch`` of N seeds with ``--workers 2`` (process start, pool,
  warm-up, journal and results file included), wall and CPU of the whole command, medians
  of ``--repeats``; with ``--before`` the two trees in turn, and their results files
  compared dataset by dataset (``benchmarks/same_results.py``: the aggregate identical).

``--before DIR`` runs the same seeds in a second process on the checkout DIR (e.g. ``git
archive`` of main), seed by seed in turn with this one, so that both see the same load.

Run: ``python benchmarks/bench_calibrate_montecarlo.py [--seeds 32] [--before DIR]
[--batch 200 --repeats 5]``
"""

from __future__ import annotations

import argparse
import json
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import resource  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from _child import Child  # noqa: E402

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
CHUNK = 16  #: runs a worker takes at a time (gcalign.app.batch.engine.CHUNK_MAX)
HERE = Path(__file__).resolve()
ROOT = HERE.parents[1]


def sweep_text(seeds: int, tree: Path) -> str:
    return (f"name: nees-mc\nbase: {(tree / 'configs' / 'seed002_designed.yaml').resolve()}\n"
            f"command: calibrate\nseeds: {seeds}\n"
            "cases: {draw: {calibrate.truth: draw, calibrate.p0_scale: 1}}\n")


def usage() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


class Runs:
    """The sweep's tasks in this process."""

    def __init__(self, seeds: int):
        import gcalign
        from gcalign.app.batch import runs as B
        from gcalign.app.batch.engine import _tasks
        from gcalign.app.batch.sweep import load_sweep

        self.B = B
        tree = Path(gcalign.__file__).resolve().parents[1]  # the checkout this process runs
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "mc.yaml"
            path.write_text(sweep_text(seeds + 1, tree), encoding="utf-8")
            sweep = load_sweep(path)
        self.tasks = _tasks(sweep, sweep.run_keys())
        B.warm_up("calibrate")  # what a worker's initializer does
        rec = B.run_task(self.tasks[0])  # warm-up: JIT cache, imports, the simulation
        assert rec["status"] == "ok", rec
        B.run_chunk(self.tasks[:2])  # and the chunk's kernels, if another

    def run(self, k: int) -> dict:
        c0 = usage()
        rec = self.B.run_task(self.tasks[k])
        assert rec["status"] == "ok", rec
        return {"run": (usage() - c0) * 1e3, "metrics": rec["metrics"]}

    def chunk(self, k: int) -> dict:
        c0 = usage()
        recs = self.B.run_chunk(self.tasks[k:k + CHUNK])
        assert all(r["status"] == "ok" for r in recs), recs
        return {"per_run": (usage() - c0) * 1e3 / len(recs),
                "metrics": [r["metrics"] for r in recs]}


def serve(seeds: int) -> None:
    """Child mode: read "run K" or "chunk K" on stdin, answer one JSON line each."""
    runs = Runs(seeds)
    print("ready", flush=True)
    for line in sys.stdin:
        what, k = line.split()
        print(json.dumps({"run": runs.run, "chunk": runs.chunk}[what](int(k))), flush=True)


def batch(tree: Path, seeds: int, out: Path) -> dict:
    """``gcalign batch`` of the sweep on the checkout `tree`, 2 workers: wall, CPU (s)."""
    sweep = out.with_suffix(".yaml")
    sweep.write_text(sweep_text(seeds, tree), encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(tree))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "gcalign", "batch", str(sweep), "--workers", "2",
                    "-o", str(out), "--json"], check=True, env=env, cwd=tree,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return {"wall": wall, "cpu": r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=2 if SMOKE else 32)
    ap.add_argument("--before", type=Path, help="another checkout, run interleaved")
    ap.add_argument("--batch", type=int, default=0, help="seeds of the gcalign batch timing")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.serve:
        serve(args.seeds)
        return
    trees = {"after": ROOT}
    if args.before is not None:
        trees = {"before": args.before.resolve(), **trees}
    load0 = os.getloadavg()[0]
    sides = {name: Child(HERE, tree, args.seeds) for name, tree in trees.items()}
    res: dict[str, list[dict]] = {k: [] for k in sides}
    for k in range(1, args.seeds + 1):
        for name, child in sides.items():
            res[name].append(child.ask("run", k))
    chunks: dict[str, list[dict]] = {k: [] for k in sides}
    for k in range(1, args.seeds + 1 - CHUNK + 1 if args.seeds >= CHUNK else 2, CHUNK):
        for name, child in sides.items():
            chunks[name].append(child.ask("chunk", k) | {"first": k})
    for child in sides.values():
        child.close()
    chunk_same = all(m == res[name][c["first"] + i - 1]["metrics"]
                     for name, cs in chunks.items() for c in cs
                     for i, m in enumerate(c["metrics"]))
    print(f"seed 002 NEES Monte Carlo run inside gcalign batch, {args.seeds} seeds, CPU per "
          f"run (medians; load {load0:.1f} → {os.getloadavg()[0]:.1f}, {os.cpu_count()} CPUs, "
          f"python {sys.version.split()[0]}):")
    for name in res:
        run = statistics.median(r["run"] for r in res[name])
        per = statistics.median(c["per_run"] for c in chunks[name])
        print(f"  {name:<6}  one run {run:6.1f} ms   in chunks of {CHUNK} (as a batch worker "
              f"runs them) {per:6.1f} ms a run (median of {len(chunks[name])} chunks)")
    print(f"  each chunk's metrics those of the same seeds run alone: "
          f"{'yes' if chunk_same else 'NO'}"
          + ("" if "before" not in res else "; the same seeds' metrics before and after: "
             + ("yes" if all(a["metrics"] == b["metrics"] for a, b in
                             zip(res["before"], res["after"], strict=True)) else "NO")))
    if args.batch:
        tmp = Path(tempfile.mkdtemp())
        times: dict[str, list[dict]] = {k: [] for k in trees}
        for rep in range(args.repeats):
            for name, tree in trees.items():
                (tmp / name).mkdir(exist_ok=True)
                times[name].append(batch(tree, args.batch, tmp / name / "mc.h5"))
                print(f"  batch {rep + 1} {name}: {times[name][-1]['wall']:.1f} s wall, "
                      f"{times[name][-1]['cpu']:.1f} s CPU (load {os.getloadavg()[0]:.1f})",
                      flush=True)
        for name in trees:
            print(f"  {name:<6}  gcalign batch, {args.batch} seeds, --workers 2: "
                  f"{statistics.median(t['wall'] for t in times[name]):6.1f} s wall, "
                  f"{statistics.median(t['cpu'] for t in times[name]):6.1f} s CPU "
                  f"(medians of {args.repeats})")
        if "before" in trees:
            same = subprocess.run([sys.executable, str(HERE.parent / "same_results.py"),
                                   str(tmp / "before"), str(tmp / "after")],
                                  capture_output=True, text=True)
            print("  results files, before against after: " + same.stdout.strip()
                  .splitlines()[-1])
        shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
