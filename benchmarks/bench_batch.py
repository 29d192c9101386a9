"""Benchmark of `gcalign batch`: 100 seeds of the seed 000 §5.3 full-cycle case.

The built-in scenario (``gcalign/scenarios/seed000_moving_full_cycle.yaml``: 400 s of
moving-base data at 100 Hz, 5 passes over [10, 300] s) is run for seeds 1..100, once with
one worker process and once with two, end to end (``gcalign batch`` as a subprocess:
interpreter start, pool start, JIT cache load in each worker, journal, HDF5). Targets on
this 2-core machine: two workers ≥ 1.7× faster than one, and ≤ 15 s wall time with two.
It also checks that the workers load the numba kernels from the on-disk cache instead of
compiling them again (cache misses must be 0), that both runs give the same aggregate, and
how fast a Dask scheduler that refuses or never answers is given up (README: ≤ 15 s).

Run: ``python benchmarks/bench_batch.py [--seeds 100]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TARGET_RATIO = 1.7
TARGET_WALL_S = 15.0
FAIL_FAST_S = 15.0  #: README: a scheduler that does not answer fails within this


def sweep_file(folder: Path, seeds: int) -> Path:
    base = resources.files("gcalign.scenarios").joinpath("seed000_moving_full_cycle.yaml")
    path = folder / "bench.yaml"
    path.write_text(f"name: bench\nbase: {Path(str(base)).resolve()}\nseeds: {seeds}\n"
                    "metrics: [error_t3_deg, error_t2_deg]\n", encoding="utf-8")
    return path


def per_run_s(out: Path) -> float:
    """Mean wall time of one run inside its worker (s): shows CPU contention."""
    import h5py
    import numpy as np

    with h5py.File(out, "r") as f:
        return float(np.nanmean(f["batch/runs/wall_s"][()]))


def run(sweep: Path, workers: int, out: Path) -> tuple[float, dict]:
    cmd = [sys.executable, "-c", "from gcalign.cli import main; main()", "batch", str(sweep),
           "--workers",
           str(workers), "-o", str(out), "--json"]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(f"gcalign batch failed ({proc.returncode}):\n{proc.stderr}")
    return wall, json.loads(proc.stdout)


def worker_cache_stats() -> list[dict]:
    """Numba cache hits/misses in fresh pool workers after their warm-up."""
    from gcalign.app.batch.backends import local_workers
    from gcalign.app.batch.runs import kernel_cache_stats

    backend = local_workers(2, "align")
    try:
        return [backend.executor.submit(kernel_cache_stats).result() for _ in range(2)]
    finally:
        backend.close()


def scheduler_fail_fast(sweep: Path, folder: Path) -> dict[str, float]:
    """Wall time (s) until `gcalign batch --scheduler` gives up on a scheduler that refuses
    the connection, and on one that accepts it and never answers (README: within 15 s)."""
    import socket
    import threading

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        refused = s.getsockname()[1]
    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(8)
    held: list[socket.socket] = []

    def accept() -> None:
        try:
            while True:
                held.append(silent.accept()[0])
        except OSError:
            pass

    threading.Thread(target=accept, daemon=True).start()
    out = {}
    try:
        for what, port in (("refused", refused), ("silent", silent.getsockname()[1])):
            cmd = [sys.executable, "-m", "gcalign", "batch", str(sweep), "-o",
                   str(folder / f"{what}.h5"), "--scheduler", f"tcp://127.0.0.1:{port}"]
            t0 = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
            out[what] = time.perf_counter() - t0
            if proc.returncode != 1:
                sys.exit(f"gcalign batch on a {what} scheduler: exit {proc.returncode}, not 1")
    finally:
        silent.close()
        for c in held:
            c.close()
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4 if SMOKE else 100)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sweep = sweep_file(tmp, args.seeds)
        # Populate the on-disk JIT cache first (a no-op when it is already there).
        subprocess.run([sys.executable, "-c",
                        "from gcalign.app.batch.runs import warm_up; warm_up()"], check=True)
        t1, s1 = run(sweep, 1, tmp / "w1.h5")
        t2, s2 = run(sweep, 2, tmp / "w2.h5")
        r1, r2 = per_run_s(tmp / "w1.h5"), per_run_s(tmp / "w2.h5")
        stats = worker_cache_stats()
        fail = scheduler_fail_fast(sweep, tmp)
    ratio = t1 / t2
    engine_ratio = s1["wall_s"] / s2["wall_s"]
    print(f"gcalign batch, {args.seeds} seeds of seed000-moving-full-cycle "
          f"(end to end, incl. interpreter start):")
    print(f"  1 worker : {t1:6.2f} s   (engine {s1['wall_s']:.2f} s; one run {r1 * 1e3:.0f} ms "
          "in its worker)")
    ok = "OK" if t2 <= TARGET_WALL_S else "MISSED"
    print(f"  2 workers: {t2:6.2f} s   (engine {s2['wall_s']:.2f} s; one run {r2 * 1e3:.0f} ms "
          f"in its worker)   target ≤ {TARGET_WALL_S} s  {ok}")
    for what, r in (("engine (pool start, runs, journal, file)", engine_ratio),
                    ("end to end (+ interpreter start, imports)", ratio)):
        print(f"  speed-up, {what}: {r:5.2f}×   target ≥ {TARGET_RATIO}×  "
              f"{'OK' if r >= TARGET_RATIO else 'MISSED'}")
    print(f"  aggregates identical for 1 and 2 workers: {s1['variants'] == s2['variants']}")
    misses = sum(s["cache_misses"] for s in stats)
    print(f"  numba cache in pool workers: hits {[s['cache_hits'] for s in stats]}, "
          f"misses {misses} ({'reused' if misses == 0 else 'RECOMPILED'})")
    for what, t in fail.items():
        print(f"  a {what} Dask scheduler: exit 1 after {t:5.2f} s   target ≤ {FAIL_FAST_S:g} s  "
              f"{'OK' if t <= FAIL_FAST_S else 'MISSED'}")
    yaw = s2["variants"][0]["stats"]["error_t3_deg"]
    print(f"  heading error at T3 over {yaw['n']} seeds: mean {yaw['mean'][2]:.4f}°, "
          f"std {yaw['std'][2]:.4f}°, RMS {yaw['rms'][2]:.4f}°")


if __name__ == "__main__":
    main()
