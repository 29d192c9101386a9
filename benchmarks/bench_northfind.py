"""Benchmark of gcalign.northfind: a 72-azimuth sweep, all four methods.

Scenario: 24 positions, 60 s dwell at 100 Hz (6000 samples per position), 10° tilt,
gyro ARW 0.005°/√h, accelerometer VRW 20 µg/√Hz, 5″ indexing error, 7 repeats per
azimuth (the seed's 7 groups). Two simulation paths:

* ``averaged`` (default of ``run_northfind``): dwell means drawn as N(0, σ²/N) — the
  exact law of the mean of N white samples;
* ``samples``: every one of the 72·7·24·3·6000 = 218 M samples drawn (numba kernel).

Timings are taken after a warm-up call (numba JIT / cache load) and are the best of a few
repeats. The target (design: sweeps of 72 azimuths × 7 repeats must be fast) is 2 s warm.

Run: ``python benchmarks/bench_northfind.py``
"""

from __future__ import annotations

import os
import time

import numpy as np

from gcalign.northfind import METHODS, NorthfindSetup, run_northfind
from gcalign.units import ARCSEC, DEG, DPSH, UGPSHZ

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TARGET_S = 2.0


def _setup(repeats: int) -> NorthfindSetup:
    return NorthfindSetup(
        azimuths=np.arange(0.0, 360.0, 90.0 if SMOKE else 5.0) * DEG,
        lat=40.0 * DEG,
        positions=24,
        dwell_s=60.0,
        rate_hz=100.0,
        tilt=10.0 * DEG,
        tilt_direction=30.0 * DEG,
        repeats=repeats,
        gyro_arw=0.005 * DPSH,
        accel_vrw=20.0 * UGPSHZ,
        index_error=5.0 * ARCSEC,
    )


def _time(setup: NorthfindSetup, samples: bool, n_best: int) -> tuple[float, object]:
    run_northfind(setup, np.random.default_rng(0), samples=samples)  # warm-up
    best, res = np.inf, None
    for k in range(n_best):
        t0 = time.perf_counter()
        res = run_northfind(setup, np.random.default_rng(k + 1), methods=METHODS, samples=samples)
        best = min(best, time.perf_counter() - t0)
    return best, res


def main() -> None:
    print("gcalign.northfind benchmark: 72 azimuths, 24 positions, 60 s at 100 Hz, 4 methods")
    print(
        f"{'path':<10}{'repeats':>8}{'runs':>7}{'samples/run':>13}{'time [s]':>11}"
        f"{'runs/s':>11}{'Msamples/s':>12}{'time/target':>13}"
    )
    for samples in (False, True):
        for repeats in (1, 7):
            setup = _setup(repeats)
            best, res = _time(setup, samples, n_best=1 if SMOKE else 3 if samples else 10)
            runs = setup.azimuths.size * repeats
            per_run = 3 * setup.positions * setup.n_samples  # gyro + 2 accelerometers
            path = "samples" if samples else "averaged"
            print(
                f"{path:<10}{repeats:>8}{runs:>7}{per_run:>13}{best:>11.4f}{runs / best:>11.0f}"
                f"{runs * per_run / best / 1e6:>12.1f}{best / TARGET_S:>13.4f}"
            )
    print("(Msamples/s of the averaged path: equivalent samples, drawn as one mean per dwell)")
    std = np.degrees(res.error_std()).mean(-1) * 3600.0
    pred = np.degrees(res.azimuth_std_pred).mean(-1) * 3600.0
    print("\nsanity (samples path, 7 repeats): azimuth error std per method, mean over azimuths")
    for m, s, p in zip(res.methods, std, pred, strict=True):
        print(f"  {m:<11} std {s:8.1f}″   predicted {p:8.1f}″")


if __name__ == "__main__":
    main()
