"""The `gcalign realtime` table: the seed's Table 1 beside ours, from the summary alone."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

REFERENCE_TEXT = {
    "seed": "the INS's own output T after the pulse (the seed's semi-physical reference)",
    "truth": "the true attitude at the pulse time",
}


def _a(x, digits: int = 3) -> str:
    return "—" if x is None else f"{x:.{digits}f}"


def _before(c: dict) -> str:
    if c["motion"] == "accel":
        return f"{_a(c['before_slope_arcsec_per_s'], 1)}″/s"
    return f"{_a(c['before_max_arcsec'], 1)}″"


def _theory(c: dict) -> str:
    if c["motion"] == "accel":
        return f"{_a(c['before_theory_arcsec_per_s'], 1)}″/s"
    v = c.get("before_theory_arcsec")
    return "—" if v is None else f"{v:.1f}″"


def _tdelay(c: dict, T_ms: float) -> str:
    lo, hi = c["dt_us"]["min"], c["dt_us"]["max"]
    if lo is None:
        return "—"
    if hi - lo < 1e-3:
        return f"{T_ms + lo * 1e-3:.3f}"
    return f"{T_ms + lo * 1e-3:.1f}–{T_ms + hi * 1e-3:.1f}"


def realtime_table(s: dict) -> Table:
    """Per case: T + Δt, the error before prediction (seed's, ours, closed form), the seed's
    "after", and ours per predictor (max and rms, ″) on the run's reference; the last
    column is against the truth."""
    after = [p for p in s["predictors"] if p != "none"] or list(s["predictors"])
    T = s["filter_delay_ms"]
    setting = ("the seed's semi-physical setting: T fixed at 4 ms (n = 4), pulses on the "
               "solution instants (Δt = 0)" if s["semi_physical"] else
               f"T = {T:.4f} ms")
    table = Table(
        title=f"gcalign realtime: {s['scenario']} — {setting}; the designed chain's own "
        f"delay {s['chain_delay_ms']:.4f} ms (FIR {s['fir_delay_ms']:.3f} ms + notch "
        f"{s['notch_delay_us']:.2f} µs)",
        title_justify="left", header_style="bold")
    table.add_column("case", justify="left", no_wrap=True)
    table.add_column("T+Δt ms", justify="right")
    table.add_column("before: seed", justify="right")
    table.add_column("ours", justify="right")
    table.add_column("closed form", justify="right")
    table.add_column("after: seed", justify="right")
    for p in after:
        table.add_column(f"{p} max (rms)", justify="right")
    table.add_column("truth: max", justify="right")
    for c in s["cases"]:
        cells = [Text(c["name"]), _tdelay(c, T), c["seed_before"] or "—", _before(c),
                 _theory(c), c["seed_after"] or "—"]
        for p in after:
            cells.append(f"{_a(c['after_max_arcsec'][p])} ({_a(c['after_rms_arcsec'][p])})")
        cells.append(" / ".join(_a(c["truth"]["after_max_arcsec"][p], 2) for p in after))
        table.add_row(*cells)
    m = s["model"]
    truth = " / ".join(after)
    lags = [f"{c['name']} {c['lag_ms']:.3f} ms" for c in s["cases"] if c.get("lag_ms")]
    table.caption = (
        f"″ of the turned Euler angle against {REFERENCE_TEXT[s['reference']]}"
        + (f" (truth: {truth} against the true attitude at the pulse time)"
           if s["reference"] != "truth" else "") + f", after "
        f"{s['settle_s']:g} s, ±{s['corner_ms']:g} ms around the ramp corners excluded; "
        f"ramps: before = slope. Gyros (ours, the seed gives none): counts "
        f"{m['quantum_arcsec']:g}″, ARW {m['arw_dprh']:g} °/√h, dither "
        f"{m['dither_arcsec']:g}″ @ {m['dither_hz']:g} Hz; tracker Qc {m['qc_rad2ps5']:g} "
        f"rad²/s⁵, R = ({m['r_std_arcsec']:g}″)². "
        + (f"INS lag behind the table at uniform rate (seed Fig. 4: 4.4 ms): "
           f"{'; '.join(lags)}. " if lags else "")
        + f"seed {s['seed']}; compute {s['compute_s']:.2f} s; output {s.get('output') or '—'}")
    return table
