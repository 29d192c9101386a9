"""The `gcalign align` table: truth, estimate and error at T2 and T3, the passes."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from gcalign.app.report import fmt


def align_table(s: dict) -> Table:
    """Truth, estimate and error at T2 and T3, the error after each pass, timing."""
    table = Table(
        title=f"gcalign align: {s['scenario']} — {s['mode']}, compensation {s['compensation']}, "
        f"poles {s['azimuth_poles']}",
        title_justify="left",
        header_style="bold",
    )
    for name in ("", "t (s)", "pitch (deg)", "roll (deg)", "yaw (deg)"):
        table.add_column(name, justify="left" if not name else "right")
    for when in ("t2", "t3"):
        for what, name in (("truth", "truth"), ("attitude", "estimate"), ("error", "error")):
            vals = s.get(f"{what}_{when}_deg")
            digits = 5 if what == "error" else 4
            cells = ["—"] * 3 if vals is None else [fmt(v, digits) for v in vals]
            table.add_row(
                Text(f"{name} at T{when[1]}"),
                fmt(s[f"{when}_s"], 2),
                *cells,
                end_section=what == "error",
            )
    for p in s["passes"]:
        has_error = p["error_deg"] is not None
        vals = p["error_deg"] if has_error else p["attitude_deg"]
        table.add_row(
            Text(
                f"pass {p['index'] + 1} {p['direction'][0].upper()} {p['kind']} "
                f"s{p['stage'] + 1} {'error' if has_error else 'attitude'}"
            ),
            fmt(p["t_end_s"], 1),
            *[fmt(v, 5) for v in vals],
        )
    table.caption = (
        f"data used {s['data_used_s']:.1f} s, equivalent length "
        f"{s['equivalent_s']:.1f} s; compute {s['compute_s'] * 1e3:.1f} ms; "
        f"output {s.get('output') or '—'}"
    )
    return table
