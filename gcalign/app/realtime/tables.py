"""The `gcalign realtime` table: the seed's Table 1 beside ours, from the summary alone."""

from __future__ import annotations

from rich.table import Column, Table
from rich.text import Text

from gcalign.app.report import DASH, run_line, stacked, titled

REFERENCE_TEXT = {
    "seed": "the INS's own output T after the pulse (the seed's semi-physical reference)",
    "truth": "the true attitude at the pulse time",
}


def _a(x, digits: int = 3) -> str:
    return DASH if x is None else f"{x:.{digits}f}"


def _before(c: dict) -> str:
    if c["motion"] == "accel":
        return f"{_a(c['before_slope_arcsec_per_s'], 1)}″/s"
    return f"{_a(c['before_max_arcsec'], 1)}″"


def _theory(c: dict) -> str:
    if c["motion"] == "accel":
        return f"{_a(c['before_theory_arcsec_per_s'], 1)}″/s"
    v = c.get("before_theory_arcsec")
    return DASH if v is None else f"{v:.1f}″"


def _tdelay(c: dict, T_ms: float) -> str:
    lo, hi = c["dt_us"]["min"], c["dt_us"]["max"]
    if lo is None:
        return DASH
    if hi - lo < 1e-3:
        return f"{T_ms + lo * 1e-3:.3f}"
    return f"{T_ms + lo * 1e-3:.1f}–{T_ms + hi * 1e-3:.1f}"


def _cases(title: str, *columns: str) -> Table:
    """A table of one row per case: its name, then `columns` of numbers."""
    return titled(title, [Column("case", no_wrap=True)], columns)


def realtime_table(s: dict) -> Table:
    """Two tables, one above the other (each fits 80 columns): per case T + Δt and the
    error before prediction (the seed's, ours, the closed form); then the seed's "after"
    and ours per predictor (max and rms, ″) on the run's reference, and the max against
    the truth."""
    after = [p for p in s["predictors"] if p != "none"] or list(s["predictors"])
    T = s["filter_delay_ms"]
    setting = ("the seed's semi-physical setting: T fixed at 4 ms (n = 4), pulses on the "
               "solution instants (Δt = 0)" if s["semi_physical"] else
               f"T = {T:.4f} ms")
    before = _cases("before prediction: the attitude latched at the pulse",
                    "T+Δt (ms)", "seed", "ours", "closed form")
    later = _cases("after prediction to the pulse time: max (rms), ″", "seed", *after,
                   f"truth: max ({' / '.join(after)})")

    for c in s["cases"]:
        before.add_row(Text(c["name"]), _tdelay(c, T), c["seed_before"] or DASH, _before(c),
                       _theory(c))
        cells = [Text(c["name"]), c["seed_after"] or DASH]
        for p in after:
            cells.append(f"{_a(c['after_max_arcsec'][p])} ({_a(c['after_rms_arcsec'][p])})")
        cells.append(" / ".join(_a(c["truth"]["after_max_arcsec"][p], 2) for p in after))
        later.add_row(*cells)
        cm = c.get("corner_max_arcsec")
        if cm:  # the ramp's corners, where the seed's bound does not hold: max only
            later.add_row(Text(f"  corners ±{s['corner_ms']:g} ms", style="dim"), "",
                          *(_a(cm[p]) for p in after), "")
    title = (f"gcalign realtime: {s['scenario']} — {setting}; the designed chain's own delay "
             f"{s['chain_delay_ms']:.4f} ms (FIR {s['fir_delay_ms']:.3f} ms + notch "
             f"{s['notch_delay_us']:.2f} µs)")
    m = s["model"]
    truth = " / ".join(after)
    lags = [f"{c['name']} {c['lag_ms']:.3f} ms" for c in s["cases"] if c.get("lag_ms")]
    notes = (
        f"″ of the turned Euler angle against {REFERENCE_TEXT[s['reference']]}"
        + (f" (truth: {truth} against the true attitude at the pulse time)"
           if s["reference"] != "truth" else "") + f", after "
        f"{s['settle_s']:g} s, ±{s['corner_ms']:g} ms around the ramp corners excluded (their "
        f"max on the rows 'corners', on the run's reference); "
        f"ramps: before = slope. Gyros (ours, the seed gives none): counts "
        f"{m['quantum_arcsec']:g}″, ARW {m['arw_dprh']:g} °/√h, dither "
        f"{m['dither_arcsec']:g}″ @ {m['dither_hz']:g} Hz; tracker Qc {m['qc_rad2ps5']:g} "
        f"rad²/s⁵, R = ({m['r_std_arcsec']:g}″)². "
        + (f"INS lag behind the table at uniform rate (seed Fig. 4: 4.4 ms): "
           f"{'; '.join(lags)}. " if lags else "")
        + "\n" + run_line(s, f"compute ({len(s['cases'])} cases)"))
    return stacked(title, (before, later), notes, padding=(1, 0))
