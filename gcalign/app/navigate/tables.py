"""The `gcalign navigate` table: final and largest errors (or the final state)."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from gcalign.app.report import fmt


def navigate_table(s: dict) -> Table:
    table = Table(
        title=f"gcalign navigate: {s['scenario']} ({s['samples']} samples, "
        f"{s['duration_s']:.1f} s)",
        title_justify="left",
        header_style="bold",
    )
    table.add_column("quantity")
    table.add_column("final", justify="right")
    table.add_column("max |error|", justify="right")
    fe, me = s.get("final_error"), s.get("max_error") or {}
    if fe is None:
        st = s["final_state"]
        rows = [
            ("attitude (pitch, roll, yaw) (deg)", fmt(st["attitude_deg"]), "no truth"),
            ("velocity ENU (m/s)", fmt(st["velocity_mps"]), "no truth"),
            ("lat, lon (deg), h (m)", fmt(st["position_deg_m"], 6), "no truth"),
        ]
    else:
        rows = [
            (
                "attitude error (pitch, roll, yaw) (deg)",
                fmt(fe["attitude_deg"]),
                fmt(me["attitude_deg"]),
            ),
            ("velocity error ENU (m/s)", fmt(fe["velocity_mps"]), fmt(me["velocity_mps"])),
            ("position error ENU (m)", fmt(fe["position_m"]), fmt(me["position_m"])),
        ]
    for row in rows:
        table.add_row(*map(Text, row))
    table.caption = f"compute {s['compute_s'] * 1e3:.1f} ms; output {s.get('output') or '—'}"
    if fe is None:
        table.caption = (
            "recorded data: free navigation from the file header's nominal state, "
            "unaided (the vertical channel diverges); " + table.caption
        )
    return table
