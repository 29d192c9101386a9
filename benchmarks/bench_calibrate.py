"""Benchmark of in-flight calibration (seed 002, spec must-show 6) on the built-in scenario
(``configs/seed002_designed.yaml``: the 590 s designed take-off, IMU 100 Hz, navigation
25 Hz, filter 1 Hz).

Rows (after a warm-up call: numba cache load and first-call costs excluded):

* ``calibrate``: one 590 s calibration (velocity matching, NEES against the truth) on the
  scenario's data; median of 5. Target ≤ 0.5 s.
* ``calibrate + smoother``: the same with the RTS smoother.
* ``observability table``: 21 segments, 590 one-second pieces, SOM, TOM, null-space
  condition and covariance degree; median of 5. Target ≤ 0.5 s.
* ``gcalign batch``: 100 calibrations with the truth drawn from P0 (``calibrate.truth:
  draw``, seeds 1–100), 2 local workers, through the batch engine as ``gcalign batch``
  runs it (pool start, warm-up, the noise-free simulation once per worker, journal and
  results file included); one timing. Target ≤ 60 s.
* the simulation of the flight (truth and ideal increments at 100 Hz), for scale.

The small-matrix linear algebra runs faster on one BLAS thread than on two, and much slower
when several multi-threaded processes share the two cores: this script sets
``OPENBLAS_NUM_THREADS=1`` before NumPy is imported (batch workers inherit it).

Run: ``python benchmarks/bench_calibrate.py``
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import copy  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
ROOT = Path(__file__).resolve().parents[1]
DESIGNED = ROOT / "configs" / "seed002_designed.yaml"


def _median(fn, repeats: int = 5) -> float:
    fn()
    times = []
    for _ in range(1 if SMOKE else repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main() -> None:
    from gcalign.app.batch import run_batch, sweep_from_mapping
    from gcalign.app.calibrate.run import simulated_case
    from gcalign.app.data import noise_free
    from gcalign.app.observability.run import flight_truth
    from gcalign.calibrate import calibrate, observability_table
    from gcalign.io.scenario import load_scenario

    sc, _ = load_scenario(DESIGNED)
    sim = _median(lambda: noise_free(sc), 3)
    case = simulated_case(sc)
    s = case.settings
    traj, spans = flight_truth(sc)

    def one(settings):
        return calibrate(case.data, settings, np.random.default_rng(2))

    rows = [
        ("calibrate 590 s", _median(lambda: one(s)), 0.5),
        ("calibrate 590 s + smoother", _median(lambda: one(replace(s, smoother=True))), None),
        ("observability table 590 s",
         _median(lambda: observability_table(traj, spans, settings=s)), 0.5),
        ("(simulation of the flight, 100 Hz)", sim, None),
    ]
    base = yaml.safe_load(DESIGNED.read_text(encoding="utf-8"))
    base["calibrate"] |= {"truth": "draw", "p0_scale": 1}
    sweep = sweep_from_mapping({"name": "mc", "base": copy.deepcopy(base),
                                "command": "calibrate", "seeds": 4 if SMOKE else 100}, "bench")
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        res = run_batch(sweep, Path(tmp) / "mc.h5", workers=2)
        rows.append((f"gcalign batch: {sweep.seeds} runs, 2 workers",
                     time.perf_counter() - start, 60.0))
    stats = res.summary["variants"][0]["stats"]["nees.final"]
    print(f"{'row':38s} {'time s':>8s} {'target s':>9s} {'margin':>7s}")
    for name, t, target in rows:
        margin = f"{target / t:7.1f}" if target else "      -"
        tgt = f"{target:9.1f}" if target else "        -"
        print(f"{name:38s} {t:8.3f} {tgt} {margin}")
    print(f"(Monte Carlo: {res.summary['failed']} failed; final NEES mean {stats['mean']:.2f}, "
          "χ²₂₁ mean 21)")


if __name__ == "__main__":
    main()
