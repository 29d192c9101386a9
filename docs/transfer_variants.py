"""The variants table of docs/results_transfer.md: PSINS's FOG/MEMS demo file, 100 s, the
demo's settings and one change each. ``python docs/transfer_variants.py`` (about 10 s)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.io

from gcalign.transfer import MasterSeries, TransferSettings, transfer_align
from gcalign.units import ARCMIN, DPH, UG

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "transfer_align_fog_mems.mat"

VARIANTS = {
    "demo (attitude + velocity, flexure, bias feedback)": {},
    "velocity matching only": {"matching": "velocity"},
    "attitude matching only": {"matching": "attitude"},
    "no bias feedback": {"bias_feedback": False},
    "constant gravity g0": {"gravity": "constant"},
    "no flexure (15 states)": {"flexure": False,
                               "p0_sigma": TransferSettings().p0_sigma[:15]},
    "attitude feedback too": {"attitude_feedback": True},
}


def inputs():
    d = scipy.io.loadmat(DATA)
    m, f = np.asarray(d["mimu"], float), np.asarray(d["fogavp"], float)
    return m[:, 0:3], m[:, 3:6], m[:, 6], MasterSeries(f[:, 9], f[:, 0:3], f[:, 3:6], f[:, 6:9])


def row(label: str, r) -> str:
    x, s = r.x[-1], r.sigma[-1]

    def fmt(v, unit, nd):
        return ", ".join(f"{a / unit:.{nd}f}" for a in v)

    return (f"| {label} | {fmt(x[12:15], ARCMIN, 2)} | {fmt(s[12:15], ARCMIN, 2)} | "
            f"{fmt(x[6:9], DPH, 2)} | {fmt(s[6:9], DPH, 2)} | {fmt(x[9:12], UG, 0)} | "
            f"{fmt(s[9:12], UG, 0)} | {r.nis.mean():.2f} |")


if __name__ == "__main__":
    args = inputs()
    print("| variant | μ x, y, z | σ(μ) | ε x, y, z | σ(ε) | ∇ x, y, z | σ(∇) | NIS mean |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for label, kw in VARIANTS.items():
        print(row(label, transfer_align(*args, TransferSettings(**kw))))
