"""The `gcalign modulate` table: per scheme the horizontal position error at the report hours
and its maximum, the linear model beside it, the attitude-error maxima and the invariants."""

from __future__ import annotations

from rich import box
from rich.console import Group, RenderableType
from rich.table import Column, Table
from rich.text import Text

from gcalign.app.report import DASH, titled


def metres(x: float | None) -> str:
    if x is None:
        return DASH
    return f"{x:,.1f}" if abs(x) < 10 else f"{x:,.0f}"


def _diag(C) -> str:
    d = [C[i][i] for i in range(3)]
    off = max(abs(C[i][j]) for i in range(3) for j in range(3) if i != j)
    text = " ".join(f"{x:.2g}" if abs(x) > 1e-9 else "0" for x in d)
    return text + ("*" if off > 1e-9 else "")


def _triple(v, fmt: str) -> str:
    """Three numbers, "0" for exact zeros; one "0" when all are (the cancelled terms)."""
    if v is None:
        return DASH
    if all(x == 0 for x in v):
        return "0"
    return " ".join("0" if x == 0 else fmt.format(x) for x in v)


def _errors_line(e: dict) -> str:
    parts = []
    for key, label, unit in (("gyro_bias_dph", "ε", "°/h"), ("accel_bias_ug", "∇", "µg"),
                             ("gyro_scale_ppm", "δk_g", "ppm"), ("gyro_asym_ppm", "δk_g,asym",
                                                                 "ppm"),
                             ("accel_scale_ppm", "δk_a", "ppm"), ("accel_asym_ppm", "δk_a,asym",
                                                                  "ppm"),
                             ("arw_dprh", "ARW", "°/√h"), ("vrw_ugrhz", "VRW", "µg/√Hz")):
        v = e.get(key)
        if v and any(x != 0 for x in v):
            parts.append(f"{label} {', '.join(f'{x:g}' for x in v)} {unit}")
    for key, label in (("gyro_misalignment_arcsec", "gyro misalignment"),
                       ("accel_misalignment_arcsec", "accel misalignment")):
        if any(x != 0 for row in e.get(key) or [] for x in row):
            parts.append(f"{label} (″) {e[key]}")
    if e.get("lever_arm_cm"):
        parts.append(f"lever arm {', '.join(f'{x:g}' for x in e['lever_arm_cm'])} cm")
    return "sensor errors (sensor frame): " + ("; ".join(parts) or "none")


def _net_peak_mean(r: dict, term: str) -> str:
    """A rate term's net over the cycle / peak in it / cycle mean (the standing offset);
    one "0" when all three are."""
    parts = [_triple(r.get(f"{term}_{part}_arcsec"), "{:.2g}") for part in ("net", "peak",
                                                                            "offset")]
    return "0" if all(x == "0" for x in parts) else " / ".join(parts)


def _ratios(r: dict) -> list[str]:
    """The ratios to the unrotated run: last hour, whole-run maxima, RMS."""
    q = r.get("ratio_to_fixed")
    if not q:
        return [DASH] * 3
    return [DASH if q[k] is None else f"{q[k]:.3g}" for k in ("last_hour", "max", "rms")]


def _schemes(title: str, width: int, *columns: str) -> Table:
    """A table of one row per scheme: its name (`width` wide), then `columns` of numbers."""
    return titled(title, [Column("scheme", no_wrap=True, min_width=width)], columns,
                  box=box.SIMPLE_HEAD)


def _terms_table(rows: list[list[str]]) -> Table:
    """The invariant terms per scheme; each column at least as wide as its numbers (the
    headers wrap instead)."""
    t = titled("invariants over one cycle, for these errors", box=box.SIMPLE_HEAD)
    heads = ("scheme", "peak ∫C dt (s)", "ε excursion (″)", "δk term (″)", "M term (″)")
    for k, col in enumerate(heads):
        t.add_column(col, justify="left" if k == 0 else "right",
                     min_width=max(len(r[k]) for r in rows))
    for r in rows:
        t.add_row(*map(Text, r))
    return t


def modulate_table(s: dict) -> Group:
    """Two tables: the horizontal position error per scheme and hour (navigation, its
    maximum over every sample, the linear model at the last hour), then the attitude-error
    maxima and the invariants; notes below."""
    lat, lon, _ = s["site_deg_m"]
    hours = s["report_hours"]
    key = f"{hours[-1]:g}h" if hours else None
    head = Text(f"gcalign modulate: {s['scenario']} — {s['hours']:g} h at {s['rate_hz']:g} Hz, "
                f"{s['motion']} base at {lat:g}°, {lon:g}°, earth {s['earth']}, seed "
                f"{s['seed']}", style="bold")
    width = max((len(n) for n in s["compare"]), default=6)  # names whole, never "four-posit…"
    pos = _schemes("horizontal position error (m)", width, *(f"{h:g} h" for h in hours), "max")
    # the linear model and the ratios to the unrotated run in a table of their own: with
    # them the 72 h table is 92 columns wide, and rich cut its numbers at 80 ("2,0…")
    ratios = any(s["schemes"][n].get("ratio_to_fixed") for n in s["compare"])
    last = f"{hours[-1]:g} h" if hours else "end"
    cmp = _schemes("against the linear model and the unrotated run", width,
                   f"lin. {hours[-1]:g} h" if hours else "linear",
                   *((f"fixed ÷ at {last}", "fixed ÷ max", "fixed ÷ RMS") if ratios else ()))
    inv = _schemes("attitude error and invariants", width)
    for col, just in (("ref", "left"), ("T (min)", "right"), ("diag C̄", "right"),
                      ("φ max (″)", "right"), ("Schuler", "center")):
        inv.add_column(col, justify=just)  # type: ignore[arg-type]
    term_rows: list[list[str]] = []
    residuals: list[str] = []
    for name in s["compare"]:
        r = s["schemes"][name]
        lin = r.get("linear")
        lin_v = None if lin is None else (lin["horizontal_error_m"].get(key) if key else
                                          lin["final_horizontal_error_m"])
        pos.add_row(*map(Text, [name] + [metres(r["horizontal_error_m"].get(f"{h:g}h"))
                                         for h in hours]
                         + [metres(r["max_horizontal_error_m"])]))
        cmp.add_row(*map(Text, [name, metres(lin_v)] + (_ratios(r) if ratios else [])))
        inv.add_row(*map(Text, [
            name, {"navigation": "nav"}.get(r["reference"], r["reference"])
            if r["mechanism"] else DASH,
            DASH if r["cycle_s"] is None else f"{r['cycle_s'] / 60:.1f}", _diag(r["cycle_mean"]),
            " ".join(f"{x:.0f}" if x >= 10 else f"{x:.2g}"
                     for x in r["max_misalignment_arcsec"]),
            "warn" if r["schuler_warnings"] else "–"]))
        if r["mechanism"]:
            term_rows.append([
                name, _triple(r.get("peak_integral_C_s"), "{:.0f}"),
                _triple(r["gyro_bias_excursion_arcsec"], "{:.2g}"),
                _net_peak_mean(r, "scale_factor"), _net_peak_mean(r, "misalignment")])
            res = r["residual_gyro_bias_dph"]
            if any(abs(x) > 1e-12 for x in res):
                residuals.append(
                    f"{name}: residual drift C̄ε = ({', '.join(f'{x:.3g}' for x in res)}) °/h, "
                    f"C̄∇ = ({', '.join(f'{x:.3g}' for x in r['residual_accel_bias_ug'])}) µg")
    notes = [
        "navigation against truth at each hour (the last: the run's end); max: over every "
        "sample; lin.: the linear error model (static base) for the same errors; fixed ÷: the "
        "unrotated run's error over this scheme's: at the last hour (one instant of an "
        "oscillating curve), of the whole-run maxima, of the RMS over the stored rows; "
        "φ max: largest misalignment, E N U; "
        "T: cycle; diag C̄: mean of C_s^r over the cycle (* off-diagonal terms too); "
        "invariants, open loop: peak of |∫C e_j dt| per sensor axis, attitude excursion "
        "from the gyro bias, scale-factor δk and gyro misalignment M × rate terms (net over "
        "the cycle / peak in it / cycle mean: the standing attitude offset the navigation "
        "sees as an initial attitude error, which a net 0 does not cancel), E N U",
        _errors_line(s["errors"]), *residuals,
        f"output {s.get('output') or DASH}; {s['wall_s']:.1f} s",
    ]
    tables: list[RenderableType] = [head, pos, cmp, inv]
    if term_rows:
        tables.append(_terms_table(term_rows))
    return Group(*tables, Text("\n".join(notes), style="dim"))
