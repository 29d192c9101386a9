"""The transfer filter's consistency on the simulated case, per state (docs/results_transfer.md).

30 seeded runs (seeds 1000–1029) of :func:`gcalign.transfer.simulate.transfer_case`, 20 s
(12 m/s at heading 30°, roll ±20° at 10 °/s; μ, ε, ∇ drawn from P0 1°, 500 °/h, 1000 µg;
master noise 1′ and 0.02 m/s at 10 Hz, R set to it; 15 states). For every matching, with
attitude feedback on and off, and two starts:

* wide: P0(φ) = 10°, the slave started from the master's attitude (the demo's start: its
  true φ0 is the mounting μ turned into n, about 1°, well inside 10°);
* tight: P0(φ) = 0.1°, the slave started from its own attitude with φ0 drawn from 0.1°.

Prints, per state, the mean over the runs of (e/σ)² at the last epoch (e = x̂ − x), the
mean NEES of the 15 states and the mean NIS; each in the two-sided 95 % band of a mean of
30 χ²₁ (0.56–1.57), 30 χ²₁₅, and the epochs' χ²_m. ``python docs/transfer_monte_carlo.py``
(about 30 s of CPU); ``--runs``, ``--duration``, ``--seed0`` change the set.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
from scipy.stats import chi2

from gcalign.estimation.kalman import nees
from gcalign.transfer import transfer_align
from gcalign.transfer.filter import MATCHINGS, NAMES_15
from gcalign.transfer.simulate import estimation_error, transfer_case
from gcalign.units import DEG

STARTS = {"wide": 10 * DEG, "tight": 0.1 * DEG}


def run(matching: str, feedback: bool, start: str, seed: int, duration: float):
    """One run: the case, the result, the error (K, 15)."""
    c = transfer_case(np.random.default_rng(seed), duration=duration,
                      phi0_sigma=STARTS[start])
    s = replace(c.settings, matching=matching, attitude_feedback=feedback)
    r = transfer_align(c.dtheta, c.dv, c.t, c.master, s,
                       att0=None if start == "wide" else c.att0)
    return c, r, estimation_error(r, c)


def monte_carlo(matching: str, feedback: bool, start: str, runs: int = 30,
                duration: float = 20.0, seed0: int = 1000) -> dict[str, np.ndarray]:
    """Per run: z2 (runs, 15) (e/σ)² at the last epoch; nees (runs,); nis (runs,) the
    run's mean NIS; m its dof."""
    z2, ne, nis = [], [], []
    m = 0
    for i in range(runs):
        _c, r, e = run(matching, feedback, start, seed0 + i, duration)
        z2.append((e[-1] / r.sigma[-1]) ** 2)
        ne.append(nees(e[-1], r.P[-1]))
        nis.append(r.nis.mean())
        m = r.m
        k = len(r.nis)
    return {"z2": np.array(z2), "nees": np.array(ne), "nis": np.array(nis), "m": m, "k": k}


def band(dof: int, runs: int, p: float = 0.95) -> tuple[float, float]:
    """Two-sided p band of the mean of `runs` χ²_dof."""
    a = (1 - p) / 2
    lo, hi = chi2.ppf([a, 1 - a], dof * runs) / runs
    return float(lo), float(hi)


def table(runs: int, duration: float, seed0: int) -> str:
    cols = [(m, fb, st) for st in STARTS for m in MATCHINGS for fb in (True, False)]
    res = {col: monte_carlo(*col, runs=runs, duration=duration, seed0=seed0) for col in cols}
    lo1, hi1 = band(1, runs)
    lo15, hi15 = band(15, runs)

    def cell(v: float, lo: float, hi: float) -> str:
        return f"{v:.2f}" if lo <= v <= hi else f"**{v:.2f}**"

    head = ["state"] + [f"{st} {m.replace('attitude', 'att').replace('velocity', 'vel')}"
                        f" fb {'on' if fb else 'off'}" for m, fb, st in cols]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for i, name in enumerate(NAMES_15):
        lines.append("| " + " | ".join([name] + [cell(res[c]["z2"][:, i].mean(), lo1, hi1)
                                                 for c in cols]) + " |")
    lines.append("| " + " | ".join(["NEES (15)"] + [cell(res[c]["nees"].mean(), lo15, hi15)
                                                    for c in cols]) + " |")
    nis_cells = []
    for c in cols:
        lo, hi = band(res[c]["m"], runs * res[c]["k"])
        nis_cells.append(cell(res[c]["nis"].mean(), lo, hi) + f" ({res[c]['m']})")
    lines.append("| " + " | ".join(["NIS (dof)"] + nis_cells) + " |")
    lines.append("")
    lines.append(f"{runs} runs, seeds {seed0}–{seed0 + runs - 1}, {duration:g} s; bold: "
                 f"outside the 95 % band (one state {lo1:.2f}–{hi1:.2f}, NEES "
                 f"{lo15:.2f}–{hi15:.2f}).")
    return "\n".join(lines)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--duration", type=float, default=20.0)
    ap.add_argument("--seed0", type=int, default=1000)
    a = ap.parse_args()
    print(table(a.runs, a.duration, a.seed0))
