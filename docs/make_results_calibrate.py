"""Regenerate the tables of docs/results_calibrate.md (seed 002) from the scenarios the
commands run: configs/seed002_designed.yaml (the 590 s designed take-off; the conventional
take-off is its first 6 segments) and configs/lasergyro_calibrate.yaml (real data).

Run from the repository root:  python docs/make_results_calibrate.py [--runs 100]
It prints every table as Markdown (about 4 minutes, most of it the Monte Carlo);
docs/results_calibrate.md quotes them with the text. Figures: ``gcalign calibrate
--compare -o runs/cmp.h5 && gcalign plot runs/cmp.h5`` (and ``gcalign observability``),
copied to docs/figures/calibrate_*.png.
"""

from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402
from scipy.stats import chi2  # noqa: E402

from gcalign.app.calibrate.run import (  # noqa: E402
    compare_runs,
    recorded_case,
    run_filter,
    simulated_case,
)
from gcalign.calibrate import Settings, calibrate, covariance_run, observability_table  # noqa: E402
from gcalign.estimation import ins_error as ie  # noqa: E402
from gcalign.io.scenario import load_scenario, parse_scenario  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DESIGNED = ROOT / "configs" / "seed002_designed.yaml"
NAMES = ie.STATE_NAMES
# the seed's P0 list (before ×10) in display units: results are quoted in multiples of it
LISTED = np.array([20, 20, 30, 0.2, 0.2, 0.2, 1, 1, 1] + [0.01] * 3 + [50] * 3 + [100] * 6,
                  dtype=float)


def scenario(noise: bool = True, **calibrate):
    """The designed scenario with `calibrate` keys changed (and without sensor noise)."""
    data = yaml.safe_load(DESIGNED.read_text(encoding="utf-8"))
    data["calibrate"] |= calibrate
    if not noise:
        data["imu"]["gyro"]["arw_dprh"] = data["imu"]["accel"]["vrw_ugrhz"] = 0
    return parse_scenario(data, "designed")


def listed_units(sigma: np.ndarray, pos) -> np.ndarray:
    """σ in multiples of the seed's listed value (P0 starts at 10)."""
    return sigma * ie.display_scale(float(pos[0]), float(pos[2])) / LISTED


def fmt(v: float) -> str:
    if v == 0:
        return "0"
    return f"{v:.0e}".replace("e-0", "e-").replace("e+0", "e")


def table1(data, scaling: str) -> list[str]:
    tab = observability_table(data.truth, data.segments, "velocity", scaling, covariance=False)
    out = ["| # | segment | " + " | ".join(NAMES) + " | rank | margin | TOM | rank cum. |",
           "|---" * (len(NAMES) + 6) + "|"]
    for i, seg in enumerate(tab.segments):
        cells = " | ".join(fmt(v) for v in tab.eta[i])
        out.append(f"| {i + 1} | {seg} | {cells} | {tab.rank[i]} | ×{tab.margin[i]:.2g} | "
                   f"{tab.tom_rank[i]} | {tab.rank_cum[i]} |")
    cells = " | ".join(fmt(v) for v in tab.eta_cum[-1])
    out.append(f"| | whole run | {cells} | {tab.rank_cum[-1]} | ×{tab.margin_cum[-1]:.2g} | "
               f"{tab.tom_rank_cum[-1]} | |")
    res = tab.null_residual
    out.append("")
    out.append(f"eq. 12 residual ‖F N‖/‖F‖ per segment: {res.min():.0e} … {res.max():.0e}; "
               f"condition (≤ 1e-9) holds in segments "
               f"{[int(i) + 1 for i in np.flatnonzero(tab.condition)]};"
               f" SOM ≠ TOM rank in {int(np.sum(tab.rank != tab.tom_rank))} of "
               f"{len(tab.rank)} segments")
    return out


def covariance_degree_table(data) -> list[str]:
    tab = observability_table(data.truth, data.segments, "velocity", "none")
    cols = list(NAMES[9:]) + ["phiU"]
    out = ["| # | after | " + " | ".join(cols) + " |", "|---" * (len(cols) + 2) + "|"]
    assert tab.cov_degree is not None
    for i, seg in enumerate(tab.segments):
        vals = list(tab.cov_degree[i, 9:]) + [tab.cov_degree[i, 2]]
        out.append(f"| {i + 1} | {seg} | " + " | ".join(f"{v:.1f}" for v in vals) + " |")
    return out


def final_sigma_table(data) -> list[str]:
    conv = data.between(0.0, data.segments[5].end)
    rows = []
    for label, d in (("conventional (first 6 stages, 238 s)", conv),
                     ("designed (21 stages, 590 s)", data)):
        for m in ie.MEASUREMENTS:
            s = listed_units(covariance_run(d.truth, Settings(measure=m)).sigma[-1],
                             d.start.pos)
            rows.append((label, m, s))
    cols = list(NAMES[9:])
    out = ["| trajectory | measure | " + " | ".join(cols) + " |", "|---" * (len(cols) + 2) + "|"]
    for label, m, s in rows:
        out.append(f"| {label} | {m} | " + " | ".join(f"{v:.2f}" for v in s[9:]) + " |")
    return out


def crossover_table(data) -> list[str]:
    v = covariance_run(data.truth, Settings(measure="velocity")).sigma[-1, 9:]
    out = ["| σ_p (m) | sensor errors where position beats velocity (of 12) |", "|---|---|"]
    for sp in (1.0, 3.0, 10.0, 30.0):
        p = covariance_run(data.truth, Settings(measure="position", sigma_p=sp)).sigma[-1, 9:]
        out.append(f"| {sp:g} | {int(np.sum(p < v))} |")
    return out


def table3() -> list[str]:
    """One run of ``gcalign calibrate --compare`` (the scenario's injected errors, seed 1)."""
    sc = scenario()
    case = simulated_case(sc)
    runs = compare_runs(case, 6)
    pos = case.data.start.pos
    k = ie.display_scale(float(pos[0]), float(pos[2]))
    units = dict(zip(NAMES, ie.DISPLAY_UNITS, strict=True))
    heads = [f"{'des.' if r.label == 'designed' else 'conv.'} {r.result.settings.measure}"
             for r in runs]
    out = ["| state | unit | injected | " + " | ".join(heads) + " |",
           "|---" * (len(heads) + 3) + "|"]
    for i in [2, *range(9, 21)]:
        cells = []
        for r in runs:
            e = (r.result.estimate[-1, i] - r.result.truth[-1, i]) * k[i]
            cells.append(f"{e:.2g} ({r.result.sigma[-1, i] * k[i]:.2g})")
        out.append(f"| {NAMES[i]} | {units[NAMES[i]]} | {case.data.x_true[i] * k[i]:.3g} | "
                   + " | ".join(cells) + " |")
    nees = ", ".join(f"{h} {r.result.nees[-1]:.1f}" for h, r in zip(heads, runs, strict=True))
    out += ["", f"final NEES: {nees}"]
    return out


def noise_free() -> list[str]:
    data = simulated_case(scenario(noise=False, gnss_noise=False)).data
    out = ["| measure | max \\|error\\|/σ | sensor errors with σ(0)/σ(end) ≥ 2: remaining "
           "error / injected |", "|---|---|---|"]
    for m in ie.MEASUREMENTS:
        r = calibrate(data, Settings(measure=m, gnss_noise=False))
        obs = r.sigma[0, 9:] / r.sigma[-1, 9:] >= 2
        rel = np.abs(r.error[-1, 9:] / r.truth[-1, 9:])
        cells = ", ".join(f"{n} {v:.2f}" for n, v, o in zip(NAMES[9:], rel, obs, strict=True)
                          if o)
        out.append(f"| {m} | {np.abs(r.error / r.sigma).max():.2f} | {cells} |")
    return out


PER_STATE: dict[tuple[int, str], np.ndarray] = {}  # (first seed, measure) -> (runs, K+1, 21)
DRAWS: dict[int, np.ndarray] = {}  # first seed -> (runs, 21) the draws in units of σ(0)


def monte_carlo(runs: int, first: int = 1) -> list[str]:
    """Truth from P0 at p0_scale 1 (calibrate.truth: draw), sensor noise and DGNSS noise,
    seeds first … first + runs − 1, the three measurements on the same data. Keeps every
    run's (error/σ)² per state for :func:`per_state_nees`."""
    sc = scenario(truth="draw", p0_scale=1)
    out = ["| seeds | measure | ANEES min…max (χ²₂₁ 95 % band) | epochs inside | mean NIS/m | "
           "whitened innovation mean, variance |", "|---|---|---|---|---|---|"]
    store: dict[str, tuple[list, list, list]] = {m: ([], [], []) for m in ie.MEASUREMENTS}
    draws = []
    for seed in range(first, first + runs):
        case = simulated_case(sc, seed, cache_key="mc")
        assert case.data.x_true is not None
        draws.append(case.data.x_true / np.sqrt(np.diag(case.settings.covariances(
            case.data.start.pos, case.data.earth)[0])))
        for m in ie.MEASUREMENTS:
            r = run_filter(case, m).result
            assert r.truth is not None
            PER_STATE.setdefault((first, m), []).append(  # type: ignore[arg-type]
                ((r.estimate - r.truth) / r.sigma) ** 2)
            for lst, v in zip(store[m], (r.nees, r.nis, r.standardized), strict=True):
                lst.append(v)
    DRAWS[first] = np.array(draws)
    for m, (nees, nis, white) in store.items():
        a = np.mean(nees, 0)
        lo, hi = chi2.ppf([0.025, 0.975], 21 * runs) / runs
        w = np.concatenate(white)
        out.append(f"| {first}…{first + runs - 1} | {m} | {a.min():.2f}…{a.max():.2f} "
                   f"({lo:.2f}…{hi:.2f}) | "
                   f"{np.mean((a > lo) & (a < hi)):.0%} | {np.mean(nis) / w.shape[1]:.3f} | "
                   f"{np.abs(w.mean(0)).max():.3f}, {w.var(0).min():.3f}…{w.var(0).max():.3f} |")
    return out


STATIC_END_S = 60.0  # the designed flight's static stage


def per_state_nees(runs: int, states: tuple[str, ...] = ("dvU", "dh", "dbz", "dKaz", "phiU",
                                                          "dvE", "ebx")) -> list[str]:
    """Mean (error/σ)² over the runs of each seed set, per state: at t = 0 (the draws
    themselves), at the end of the static stage, its range over the flight and at the end,
    against the χ²_N/N band of N runs; "out" where an epoch leaves the band. Needs
    :func:`monte_carlo` first. The overall ANEES averages 21 states and can hide one."""
    lo, hi = chi2.ppf([0.025, 0.975], runs) / runs
    out = [f"| seeds | measure | state | t = 0 (draws) | after {STATIC_END_S:g} s static | "
           f"flight min…max | end | epochs outside {lo:.2f}…{hi:.2f} |", "|---" * 8 + "|"]
    t = np.arange(next(iter(PER_STATE.values()))[0].shape[0], dtype=float)  # 1 Hz epochs
    k60 = int(np.argmin(np.abs(t - STATIC_END_S)))
    for (first, m), acc in PER_STATE.items():
        a = np.mean(acc, 0)
        z0 = np.mean(DRAWS[first] ** 2, 0)
        for n in states:
            i = ie.IDX[n]
            outside = np.mean((a[:, i] < lo) | (a[:, i] > hi))
            out.append(f"| {first}…{first + runs - 1} | {m} | {n} | {z0[i]:.2f} | "
                       f"{a[k60, i]:.2f} | {a[k60:, i].min():.2f}…{a[k60:, i].max():.2f} | "
                       f"{a[-1, i]:.2f} | {outside:.0%} |")
    every = np.concatenate([np.asarray(v) for (f, m), v in PER_STATE.items()
                            if m == "velocity"])
    a = every.mean(0)
    lo3, hi3 = chi2.ppf([0.025, 0.975], len(every)) / len(every)
    bad = [n for n in NAMES if np.mean((a[:, ie.IDX[n]] < lo3) | (a[:, ie.IDX[n]] > hi3)) > 0.5]
    out += ["", f"velocity, all {len(every)} runs together (band {lo3:.2f}…{hi3:.2f}): dvU "
            f"{a[k60:, ie.IDX['dvU']].min():.2f}…{a[k60:, ie.IDX['dvU']].max():.2f}, dh "
            f"{a[k60:, ie.IDX['dh']].min():.2f}…{a[k60:, ie.IDX['dh']].max():.2f} over the "
            f"flight; states outside the band at most epochs: {', '.join(bad) or 'none'}"]
    return out


def vertical_sweep(runs: int) -> list[str]:
    """What moves the vertical states' per-state NEES (velocity matching, seeds 1 … runs):
    the filter's process noise, the DGNSS noise (simulation and filter together), the
    filter's P0 of δvU and δh against the draw's; the simulation's sensor noise."""
    from dataclasses import replace

    def scaled_p0(k: float):
        def f(s: Settings) -> Settings:
            assert s.p0_sigma is not None
            p = np.array(s.p0_sigma)
            p[[ie.IDX["dvU"], ie.IDX["dh"]]] *= k
            return replace(s, p0_sigma=tuple(p))
        return f

    variants = [
        ("as simulated", {}, lambda s: s),
        ("filter Q × 0.01", {}, lambda s: replace(s, arw=s.arw * 0.01, vrw=s.vrw * 0.01)),
        ("filter Q × 10", {}, lambda s: replace(s, arw=s.arw * 10, vrw=s.vrw * 10)),
        ("no sensor noise in the simulation", {"noise": False}, lambda s: s),
        ("no DGNSS noise (simulation and filter)", {"gnss_noise": False}, lambda s: s),
        ("filter P0 of δvU, δh × 0.5", {}, scaled_p0(0.5)),
        ("filter P0 of δvU, δh × 2", {}, scaled_p0(2.0)),
    ]
    out = ["| variant | δvU: static end / flight mean / end | δh: static end / flight mean / end "
           "| δvE end |", "|---|---|---|---|"]
    for label, kw, change in variants:
        noise = kw.pop("noise", True)
        sc = scenario(noise=noise, truth="draw", p0_scale=1, **kw)
        acc = []
        for seed in range(1, runs + 1):
            case = simulated_case(sc, seed, cache_key=f"sweep-{noise}")
            s = change(replace(case.settings, measure="velocity"))
            r = calibrate(case.data, s, np.random.default_rng([seed, 3]))
            assert r.truth is not None
            acc.append(((r.estimate - r.truth) / r.sigma) ** 2)
        a = np.mean(acc, 0)
        k60 = int(np.argmin(np.abs(r.t - STATIC_END_S)))
        cells = [" / ".join(f"{v:.2f}" for v in (a[k60, i], a[k60:, i].mean(), a[-1, i]))
                 for i in (ie.IDX["dvU"], ie.IDX["dh"])]
        out.append(f"| {label} | {cells[0]} | {cells[1]} | {a[-1, ie.IDX['dvE']]:.2f} |")
    lo, hi = chi2.ppf([0.025, 0.975], runs) / runs
    out += ["", f"{runs} runs: band {lo:.2f}…{hi:.2f}"]
    return out


def smoother() -> list[str]:
    case = simulated_case(scenario(smoother=True))
    r = run_filter(case).result
    s = r.smoothed
    assert s is not None
    k = ie.display_scale(float(case.data.start.pos[0]), 0.0)
    out = ["| state | unit | σ at t = 0 filtered (P0) | smoothed | smoothed error at t = 0 | "
           "σ at the end |", "|---|---|---|---|---|---|"]
    for i in (0, 1, 2, 3, 4):
        out.append(f"| {NAMES[i]} | {ie.DISPLAY_UNITS[i]} | {r.sigma[0, i] * k[i]:.3g} | "
                   f"{s.sigma[0, i] * k[i]:.3g} | "
                   f"{(s.estimate[0, i] - r.truth[0, i]) * k[i]:.3g} | "
                   f"{r.sigma[-1, i] * k[i]:.3g} |")
    gain = np.max(np.abs(s.sigma[:, 9:] / r.sigma[-1, 9:] - 1))
    out += ["", f"sensor errors: smoothed σ at every epoch = final filtered σ to {gain:.0e}"]
    return out


def lasergyro() -> list[str]:
    from gcalign.app.align.run import run_alignment
    from gcalign.app.data import scenario_data

    out = ["| window start (s) | KF ZUPT yaw (°) | gyrocompass yaw (°) | KF pitch, roll (°) | "
           "gyrocompass pitch, roll (°) | KF σ yaw (′) |", "|---|---|---|---|---|---|"]
    for start_s in (0.0, 600.0, 1200.0):
        sc, _ = load_scenario(ROOT / "configs/lasergyro_calibrate.yaml")
        assert sc.calibrate is not None
        sc.calibrate.start_s = start_s
        r = run_filter(recorded_case(sc)).result
        ga, _ = load_scenario(ROOT / "configs/lasergyro_align.yaml")
        assert ga.align is not None
        ga.align.start_s = start_s
        g = np.degrees(run_alignment(ga, scenario_data(ga)).att_t2)
        k = np.degrees(r.att[-1])
        out.append(f"| {start_s:g} | {k[2]:.3f} | {g[2]:.3f} | {k[0]:.3f}, {k[1]:.3f} | "
                   f"{g[0]:.3f}, {g[1]:.3f} | {np.degrees(r.sigma[-1, 2]) * 60:.1f} |")
    return out


def f_check() -> list[str]:
    """F against the nonlinear mechanisation on the designed flight (the windows of
    tests/test_ins_error.py)."""
    sys.path.insert(0, str(ROOT / "tests"))
    from calibrate_cases import TS, motion, site
    from test_ins_error import WINDOWS, _relative_errors

    from gcalign.sim.imu import ideal_imu

    flight = ideal_imu(motion(), site(), TS, substeps=4)
    out = ["| second | accumulated Φ: response | change (worst state but δL) | δL change | "
           "Van Loan on mean F: response | change |", "|---|---|---|---|---|---|"]
    for name, t in WINDOWS.items():
        incr, lit, _ = _relative_errors(flight, t, "accumulated")
        incr_v, lit_v, _ = _relative_errors(flight, t, "van_loan")
        others = np.delete(incr, ie.IDX["dL"])
        j = int(np.argmax(others))
        worst = [n for n in NAMES if n != "dL"][j]
        out.append(f"| {name} ({t:g} s) | {lit.max():.1e} | {others.max():.1e} ({worst}) | "
                   f"{incr[ie.IDX['dL']]:.1e} | {lit_v.max():.1e} | {incr_v.max():.1e} |")
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--only", choices=["nees"], help="only the Monte Carlo, the per-state "
                    "NEES and the vertical sweep")
    args = ap.parse_args()
    if args.only == "nees":
        mc = (monte_carlo(args.runs) + monte_carlo(args.runs, 1 + args.runs)[2:]
              + monte_carlo(args.runs, 1 + 2 * args.runs)[2:])
        for title, lines in ((f"Monte Carlo, {args.runs} runs per seed set", mc),
                             ("Per-state NEES", per_state_nees(args.runs)),
                             ("Vertical channel sweep", vertical_sweep(min(40, args.runs)))):
            print(f"### {title}\n\n" + "\n".join(lines) + "\n")
        return
    data = simulated_case(scenario()).data
    sections = [
        ("Table 1 analogue, scaled by the initial σ (the default, --scaling p0)",
         table1(data, "p0")),
        ("Table 1 analogue, designed flight, velocity matching, unscaled (the paper's η, "
         "--scaling none)", table1(data, "none")),
        ("Covariance degree σ(0)/σ(t), velocity (PSINS kfstat)", covariance_degree_table(data)),
        ("Final σ in multiples of the listed value (P0 = 10)", final_sigma_table(data)),
        ("Position vs velocity as the position noise grows (designed)", crossover_table(data)),
        ("Table 3 analogue: gcalign calibrate --compare (seed 1)", table3()),
        ("Noise-free DGNSS and sensors, designed flight", noise_free()),
        ("RTS smoother, designed flight, velocity", smoother()),
        ("F against the nonlinear mechanisation", f_check()),
        (f"Monte Carlo, designed flight, {args.runs} runs per seed set",
         monte_carlo(args.runs) + monte_carlo(args.runs, 1 + args.runs)[2:]
         + monte_carlo(args.runs, 1 + 2 * args.runs)[2:]),
        ("Per-state NEES (the Monte Carlo above)", per_state_nees(args.runs)),
        ("Vertical channel sweep (velocity, 40 runs)", vertical_sweep(40)),
        ("lasergyro.imu: zero-velocity KF vs gyrocompass", lasergyro()),
    ]
    for title, lines in sections:
        print(f"### {title}\n")
        print("\n".join(lines))
        print()


if __name__ == "__main__":
    main()
