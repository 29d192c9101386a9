"""Benchmark of gcalign.realtime: the seed's full Table 1 (must-show 6).

Twelve cases of 12 s each at 5 kHz (60 000 gyro samples, 12 000 attitude solutions and
pulses per case), default noise model, three predictors (none, taylor, kalman-ls), both
error metrics, summarised into table rows — end to end as `table1` + `summarise` run it.
Timings are taken after a warm-up call (numba cache load) and are the median of 7 runs.
Target: ≤ 5 s warm.

Run: ``python benchmarks/bench_realtime.py``
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from gcalign.realtime import TABLE1, Settings, summarise, table1

TARGET_S = 5.0
RUNS = 7


def _once(settings: Settings, seed: int) -> float:
    t0 = time.perf_counter()
    rows = [summarise(r) for r in table1(settings, np.random.default_rng(seed))]
    dt = time.perf_counter() - t0
    assert len(rows) == len(TABLE1)
    return dt


def main() -> None:
    s = Settings()
    _once(s, 0)  # warm-up: numba cache, scipy imports
    times = [_once(s, k + 1) for k in range(RUNS)]
    med = statistics.median(times)
    samples = len(TABLE1) * s.duration_s * s.filter.fs_hz
    print("gcalign.realtime benchmark: seed 003 Table 1, 12 cases × 12 s at 5 kHz, "
          "3 predictors")
    print(f"{'runs':>5}{'median [s]':>12}{'min [s]':>10}{'max [s]':>10}{'per case [ms]':>15}"
          f"{'Msamples/s':>12}{'time/target':>13}")
    print(f"{RUNS:>5}{med:>12.3f}{min(times):>10.3f}{max(times):>10.3f}"
          f"{1e3 * med / len(TABLE1):>15.1f}{samples / med / 1e6:>12.2f}{med / TARGET_S:>13.2f}")


if __name__ == "__main__":
    main()
