"""The `gcalign allan` table: each fitted term per axis with its 1σ interval and τ range,
under the scenario key it feeds, and σ at 1, 10 and 100 s."""

from __future__ import annotations

import math

from rich.table import Table

from gcalign.app.report import DASH, numbers, run_line, span, titled

AXES = ("x", "y", "z")
LABEL = {"quantum_arcsec": "quantization: quantum (″)", "arw_dprh": "ARW (°/√h)",
         "bias_instability_dph": "bias instability (°/h)",
         "bias_rw_dphrh": "rate random walk ((°/h)/√h)",
         "quantum_ugs": "quantization: quantum (µg·s)", "vrw_ugrhz": "VRW (µg/√Hz)",
         "bias_instability_ug": "bias instability (µg)",
         "bias_rw_ughrh": "accel. random walk (µg/√h)"}


def _ok(x) -> bool:
    return x is not None and isinstance(x, (int, float)) and math.isfinite(x)


def _tau(a, b) -> str:
    return DASH if not (_ok(a) and _ok(b)) else f"{a:.3g}–{b:.3g} s"


def _cells(term: dict) -> list[str]:
    """Per axis: value [lo, hi] (τ range), or ≤ bound when not resolved."""
    vals = [v for v in term["value"] + [x for p in term["interval"] for x in p] +
            term["bound"] if _ok(v)]
    shown = numbers(vals, sig=3, most=6) if vals else []
    fmt = dict(zip(map(float, vals), shown, strict=True)) if vals else {}

    def f(x) -> str:
        return fmt.get(float(x), f"{x:.3g}")

    out = []
    for i in range(3):
        v = term["value"][i]
        if _ok(v):
            lo, hi = term["interval"][i]
            a, b = term["tau_range_s"][i]
            out.append(f"{f(v)} [{f(lo)}, {f(hi)}]\n{_tau(a, b)}")
        elif _ok(term["bound"][i]):
            out.append(f"≤ {f(term['bound'][i])}\nnot resolved")
        else:
            out.append(DASH)
    return out


def allan_table(s: dict) -> Table:
    table = titled(f"gcalign allan: {s['scenario']} ({s['samples']} samples at "
                   f"{s['rate_hz']:g} Hz, {span(s['duration_s'])} from {s['start_s']:g} s)",
                   ("term (scenario key)",),
                   [f"{a}: value [1σ interval]\nτ range" for a in AXES], show_lines=True)
    for triad in ("gyro", "accel"):
        for key, term in s[triad].items():
            table.add_row(f"{triad}.{key}\n{LABEL.get(key, key)}", *_cells(term))
    at = s["adev_at"]
    for triad, unit in (("gyro", "°/h"), ("accel", "µg")):
        rows = at[f"{triad}_{'dph' if triad == 'gyro' else 'ug'}"]
        for tau, row in zip(at["tau_s"], rows, strict=True):
            table.add_row(f"{triad} σ(τ = {tau:g} s) ({unit})",
                          *numbers(row, sig=4, most=6))
    mean = "  ".join(numbers(s["mean_rate_dph"], sig=4))
    force = "  ".join(f"{x:.1f}" for x in s["mean_force_ug"])
    mis = "; ".join(f"{t} " + " ".join(DASH if v is None else f"{v:.3g}"
                                        for v in s["misfit"][t]) for t in ("gyro", "accel"))
    table.caption = (f"model misfit (RMS in 1σ, x y z): {mis}\n"
                     f"mean rate (°/h): {mean}; mean specific force (µg): {force}; "
                     f"1-s specific force spread {s['at_rest']['force_spread_mg']:.3g} mg\n"
                     "intervals 1σ from the number of clusters (IEEE Std 952 C.3); bias "
                     "instability = flat σ / 0.664; quantum q = √12·Q\n"
                     + run_line(s, "compute (Allan deviation and fits)"))
    return table
