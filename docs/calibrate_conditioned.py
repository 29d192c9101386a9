"""Seed 002's per-state NEES of the vertical channel conditioned on the truth draws
(docs/results_calibrate.md, "Per state"). ``python docs/calibrate_conditioned.py``
(about a minute of CPU).

The designed flight, velocity matching, truth drawn from P0 at p0_scale 1 (the Monte Carlo
of ``make_results_calibrate.py``): δvU's and δh's end errors are a fixed linear mix of the
21 initial draws (measured by central differences of ±1σ on the noise-free flight) plus
what the sensor and DGNSS noise add (measured by 30 runs without draws). The filter's σ² is
compared with their sum; each seed set's mean (e/σ)² is predicted from its draws alone.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.stats import chi2

sys.path.insert(0, str(Path(__file__).resolve().parent))

from make_results_calibrate import scenario  # noqa: E402

from gcalign.app.calibrate.run import config_of, run_filter, simulated_case  # noqa: E402
from gcalign.app.data import cached_noise_free  # noqa: E402
from gcalign.calibrate import draw_truth, flight_from_ideal, motion_spans  # noqa: E402
from gcalign.estimation import ins_error as ie  # noqa: E402

STATES = ("dvU", "dh")


def main() -> None:
    sc = scenario(noise=False, truth="draw", p0_scale=1, gnss_noise=False)
    base = simulated_case(sc, 1, cache_key="lin")
    raw = cached_noise_free(sc, "lin")
    earth, site = sc.earth_model, raw.site
    P0 = base.settings.covariances(site, earth)[0]
    s0 = np.sqrt(np.diag(P0))
    n = config_of(sc).subsamples(sc.imu.rate_hz)
    spans = motion_spans(sc.motion.to_motion(), float(raw.truth.t[-1]))
    rows = [ie.IDX[k] for k in STATES]

    def end(x):
        data = flight_from_ideal(raw.truth, raw.imu, x, sc.imu.errors(),
                                 np.random.default_rng(0), spans, n, earth)
        r = run_filter(replace(base, data=data), "velocity").result
        return r.error[-1, rows], r.sigma[-1, rows]

    A = np.zeros((len(rows), 21))
    for i in range(21):
        x = np.zeros(21)
        x[i] = s0[i]
        ep, sig = end(x)
        A[:, i] = (ep - end(-x)[0]) / 2
    noisy = scenario(truth="draw", p0_scale=1)
    noise = []
    for seed in range(1, 31):  # the Monte Carlo's noise, no draws
        case = simulated_case(noisy, seed, cache_key="mc")
        data = flight_from_ideal(raw.truth, raw.imu, np.zeros(21), noisy.imu.errors(),
                                 np.random.default_rng(seed), spans, n, earth)
        r = run_filter(replace(case, data=data), "velocity").result
        noise.append(r.error[-1, rows])
    noise = np.array(noise)
    q = np.mean(noise ** 2, axis=0) / sig ** 2
    a2 = np.sum(A ** 2, axis=1) / sig ** 2
    print("state | σ end | draws' part |a|²/σ² | noise part | sum | largest weights (of σ)")
    for k, name in enumerate(STATES):
        big = np.argsort(-np.abs(A[k]))[:5]
        w = ", ".join(f"{ie.STATE_NAMES[j]} {A[k, j] / sig[k]:+.2f}" for j in big)
        print(f"{name} | {sig[k]:.4g} | {a2[k]:.3f} | {q[k]:.3f} | {a2[k] + q[k]:.3f} | {w}")
    z = np.array([draw_truth(P0, np.random.default_rng([s, 2])) / s0 for s in range(1, 2001)])
    for k, name in enumerate(STATES):
        v = (z @ (A[k] / sig[k])) ** 2 + q[k]
        sets = ", ".join(f"{lo}…{lo + 99}: {v[lo - 1:lo + 99].mean():.2f}" for lo in (1, 101, 201))
        b50 = np.array([v[i:i + 50].mean() for i in range(0, 2000, 50)])
        p = chi2.cdf(0.69 * 50 / (a2[k] + q[k]), 50)
        print(f"{name}: implied by the draws (+ noise part), seeds {sets}; 40 disjoint 50-seed "
              f"sets of seeds 1…2000: {np.sum(b50 <= 0.69)} at or below 0.69 (lowest "
              f"{b50.min():.2f}); a χ²₅₀ of the filter's scale puts {100 * p:.1f} % there")


if __name__ == "__main__":
    main()
