"""Rich tables built by pure functions from plain summaries (the same dicts the JSON holds)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from rich.table import Table
from rich.text import Text


def fmt(x, digits: int = 4) -> str:
    """A number or a vector of numbers in a compact, aligned form."""
    if x is None:
        return "—"
    if isinstance(x, (list, tuple)):
        return "  ".join(fmt(v, digits) for v in x)
    if isinstance(x, float):
        if x != 0 and (abs(x) < 10 ** -(digits - 1) or abs(x) >= 1e6):
            return f"{x:.{digits - 1}e}"
        return f"{x:.{digits}f}"
    return str(x)


def kv_table(title: str, rows: Iterable[Sequence], headers: Sequence[str] = ("", "")) -> Table:
    table = Table(title=title, title_justify="left", header_style="bold")
    for i, h in enumerate(headers):
        table.add_column(h, justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*(Text(c if isinstance(c, str) else fmt(c)) for c in row))
    return table


def simulate_table(s: dict) -> Table:
    rows = [
        ("scenario", s["scenario"]),
        ("seed", str(s["seed"])),
        ("samples", str(s["samples"])),
        ("rate (Hz)", fmt(s["rate_hz"], 2)),
        ("duration (s)", fmt(s["duration_s"], 2)),
        ("initial attitude (pitch, roll, yaw) (deg)", fmt(s["initial_attitude_deg"])),
        ("final attitude (pitch, roll, yaw) (deg)", fmt(s["final_attitude_deg"])),
        ("final velocity ENU (m/s)", fmt(s["final_velocity_mps"])),
        ("distance travelled (m)", fmt(s["distance_m"], 2)),
        ("compute (s)", fmt(s["compute_s"], 3)),
        ("output", s.get("output") or "—"),
    ]
    return kv_table("gcalign simulate", rows, ("", "value"))


def navigate_table(s: dict) -> Table:
    table = Table(title=f"gcalign navigate: {s['scenario']} ({s['samples']} samples, "
                  f"{s['duration_s']:.1f} s)", title_justify="left", header_style="bold")
    table.add_column("quantity")
    table.add_column("final", justify="right")
    table.add_column("max |error|", justify="right")
    fe, me = s.get("final_error"), s.get("max_error")
    if fe is None:
        st = s["final_state"]
        rows = [
            ("attitude (pitch, roll, yaw) (deg)", fmt(st["attitude_deg"]), "no truth"),
            ("velocity ENU (m/s)", fmt(st["velocity_mps"]), "no truth"),
            ("lat, lon (deg), h (m)", fmt(st["position_deg_m"], 6), "no truth"),
        ]
    else:
        rows = [
            ("attitude error (pitch, roll, yaw) (deg)", fmt(fe["attitude_deg"]),
             fmt(me["attitude_deg"])),
            ("velocity error ENU (m/s)", fmt(fe["velocity_mps"]), fmt(me["velocity_mps"])),
            ("position error ENU (m)", fmt(fe["position_m"]), fmt(me["position_m"])),
        ]
    for row in rows:
        table.add_row(*map(Text, row))
    table.caption = f"compute {s['compute_s'] * 1e3:.1f} ms; output {s.get('output') or '—'}"
    return table


def align_table(s: dict) -> Table:
    """Truth, estimate and error at T2 and T3, the error after each pass, timing."""
    table = Table(
        title=f"gcalign align: {s['scenario']} — {s['mode']}, compensation {s['compensation']}, "
              f"poles {s['azimuth_poles']}",
        title_justify="left", header_style="bold")
    for name in ("", "t (s)", "pitch (deg)", "roll (deg)", "yaw (deg)"):
        table.add_column(name, justify="left" if not name else "right")
    for when in ("t2", "t3"):
        for what, name in (("truth", "truth"), ("attitude", "estimate"), ("error", "error")):
            vals = s.get(f"{what}_{when}_deg")
            cells = ["—"] * 3 if vals is None else [fmt(v, 4 if what != "error" else 5) for v in vals]
            table.add_row(Text(f"{name} at T{when[1]}"), fmt(s[f"{when}_s"], 2), *cells,
                          end_section=what == "error")
    for p in s["passes"]:
        has_error = p["error_deg"] is not None
        vals = p["error_deg"] if has_error else p["attitude_deg"]
        table.add_row(Text(f"pass {p['index'] + 1} {p['direction'][0].upper()} {p['kind']} "
                           f"s{p['stage'] + 1} {'error' if has_error else 'attitude'}"),
                      fmt(p["t_end_s"], 1), *[fmt(v, 5) for v in vals])
    table.caption = (f"data used {s['data_used_s']:.1f} s, equivalent length "
                     f"{s['equivalent_s']:.1f} s; compute {s['compute_s'] * 1e3:.1f} ms; "
                     f"output {s.get('output') or '—'}")
    return table


def summary_table(kind: str, summary: dict) -> Table:
    """The table a command printed, rebuilt from its summary (for `gcalign show`)."""
    builders = {"simulate": simulate_table, "navigate": navigate_table, "align": align_table}
    if kind not in builders:
        return kv_table(f"gcalign {kind}", ((k, str(v)) for k, v in summary.items()))
    return builders[kind](summary)
