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
* ``filter epoch``: one predict + Joseph update of the 21-state filter (m = 2 and 3
  measurements; a covariance and transition of the filter's sizes), CPU per epoch, medians
  of 7 interleaved rounds: ``gcalign.estimation.kalman`` against the same equations as
  plain NumPy expressions (the form it had before its numba kernels) and, if installed,
  filterpy's ``KalmanFilter`` (which also updates in Joseph form). Target: ≤ filterpy's.
  ``--epoch-only`` prints this row alone.

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


def _numpy_epoch(x, P, Phi, Qd, z, H, R):
    """predict + Joseph update as plain NumPy expressions (I − KH formed)."""
    M = Phi @ P @ Phi.T + Qd
    x, P = Phi @ x, 0.5 * (M + M.T)
    y = z - H @ x
    PHt = P @ H.T
    S = H @ PHt + R
    Li = np.linalg.inv(np.linalg.cholesky(0.5 * (S + S.T)))
    K = PHt @ (Li.T @ Li)
    I_KH = np.eye(len(x)) - K @ H
    P = I_KH @ P @ I_KH.T + K @ R @ K.T
    w = Li @ y
    return x + K @ y, 0.5 * (P + P.T), float(w @ w)


def filter_epoch(m: int) -> dict[str, float]:
    """CPU µs of one predict + update (21 states, m measurements) by each contender."""
    from gcalign.estimation.kalman import predict, update

    rng = np.random.default_rng(m)
    n = 21
    A = rng.normal(size=(n, n))
    P = A @ A.T + n * np.eye(n)
    Phi = np.eye(n) + 0.01 * rng.normal(size=(n, n))
    Qd = np.diag(rng.uniform(0.1, 1.0, n))
    x, z = rng.normal(size=n), rng.normal(size=m)
    H, R = rng.normal(size=(m, n)), np.diag(rng.uniform(0.1, 1.0, m))

    def ours():
        xp, Pp = predict(x, P, Phi, Qd)
        update(xp, Pp, z, H, R)

    runs = {"gcalign": ours, "NumPy, same form": lambda: _numpy_epoch(x, P, Phi, Qd, z, H, R)}
    try:
        from filterpy.kalman import KalmanFilter
    except ImportError:
        pass
    else:
        kf = KalmanFilter(dim_x=n, dim_z=m)
        kf.F, kf.Q, kf.H, kf.R = Phi, Qd, H, R

        def filterpy():
            kf.x, kf.P = x.copy(), P.copy()
            kf.predict()
            kf.update(z)

        runs["filterpy"] = filterpy
    reps = 20 if SMOKE else 2000
    times: dict[str, list[float]] = {k: [] for k in runs}
    for f in runs.values():
        f()
    for _ in range(1 if SMOKE else 7):
        for name, f in runs.items():
            start = time.process_time()
            for _ in range(reps):
                f()
            times[name].append((time.process_time() - start) / reps * 1e6)
    return {k: float(np.median(v)) for k, v in times.items()}


def print_epochs() -> None:
    for m in (2, 3):
        t = filter_epoch(m)
        best = t.get("filterpy")
        print(f"filter epoch, 21 states, m = {m} (CPU µs, load {os.getloadavg()[0]:.1f}): "
              + ", ".join(f"{k} {v:.1f}" for k, v in t.items())
              + ("" if best is None else
                 f"; gcalign ≤ filterpy: {'OK' if t['gcalign'] <= best else 'MISSED'}"))


def main() -> None:
    import sys

    if "--epoch-only" in sys.argv[1:]:
        print_epochs()
        return
    from gcalign.app.batch.engine import run_batch
    from gcalign.app.batch.sweep import sweep_from_mapping
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
    print_epochs()


if __name__ == "__main__":
    main()
