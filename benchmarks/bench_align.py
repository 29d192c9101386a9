"""Gyrocompass throughput and the seed 000 §5.3 alignment timings.

Run: python benchmarks/bench_align.py   (medians of 5-7 runs; the numba cache warmed first)
Targets (one core): ≥ 5 M gyrocompass steps/s; the §5.3 full-cycle computation (290 s at
100 Hz, 5 passes) ≤ 50 ms; `gcalign align` end to end ≤ 3 s with a warm JIT cache.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from gcalign.align import kernel as K
from gcalign.align.cycles import loop_gains
from gcalign.align.stages import Stage
from gcalign.app.align.run import run_alignment
from gcalign.app.data import scenario_data
from gcalign.cli.common import load_with_overrides
from gcalign.nav.earth import WGS84

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes


def median_time(fn, repeat=1 if SMOKE else 7):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    rows = []
    lat = np.radians(45.7796)
    n = 20_000 if SMOKE else 2_000_000
    rng = np.random.default_rng(0)
    dtheta = 1e-6 * rng.standard_normal((n, 3))
    dv = np.tile([0.0, 0.0, 0.0978], (n, 1)) + 1e-5 * rng.standard_normal((n, 3))
    vref = np.zeros((n + 1, 3))
    gains = loop_gains(Stage(20, 100, 0.707), lat, 0.0, "double-oscillator")
    q_out = np.empty((n + 1, 4))
    E = WGS84.params()

    def steps():
        s = K.new_state(np.array([1.0, 0, 0, 0]), np.zeros(3), np.array([lat, 0, 0]))
        K.gyrocompass_block(s, dtheta, dv, vref, False, 0.01, 1.0, E, gains, K.COMPASS,
                             q_out)

    steps()
    t = median_time(steps)
    rate = n / t / 1e6
    rows.append(("gyrocompass steps (M/s, one core)", f"{rate:.1f}", "≥ 5", f"{rate / 5:.2f}×"))

    sc = load_with_overrides("align", None).scenario
    data = scenario_data(sc)
    run_alignment(sc, data)  # warm
    repeat = 1 if SMOKE else 7
    comp = statistics.median(run_alignment(sc, data).compute_s for _ in range(repeat)) * 1e3
    rows.append(
        ("§5.3 full-cycle, 5 passes × 290 s (ms)", f"{comp:.1f}", "≤ 50", f"{50 / comp:.1f}× under")
    )

    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "gcalign", "align", "-o", f"{tmp}/a.h5"]
        subprocess.run(cmd, check=True, capture_output=True)  # warm the cache
        wall = median_time(lambda: subprocess.run(cmd, check=True, capture_output=True),
                           1 if SMOKE else 5)
    rows.append(
        ("gcalign align end to end, warm cache (s)", f"{wall:.2f}", "≤ 3", f"{3 / wall:.1f}× under")
    )

    width = max(len(r[0]) for r in rows)
    print(f"{'measure':<{width}}  {'value':>8}  {'target':>7}  ratio")
    for name, value, target, ratio in rows:
        print(f"{name:<{width}}  {value:>8}  {target:>7}  {ratio}")


if __name__ == "__main__":
    main()
