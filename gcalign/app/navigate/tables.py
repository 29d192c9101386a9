"""The `gcalign navigate` table: final and largest errors, or the final state and its drift."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from gcalign.app.report import fmt


def navigate_table(s: dict) -> Table:
    hours = s["duration_s"] / 3600.0
    span = f"{s['duration_s']:.1f} s" if hours < 1 else f"{hours:.3g} h"
    table = Table(
        title=f"gcalign navigate: {s['scenario']} — {s['samples']} samples ({span}) from "
        f"{s['start_s']:g} s, vertical channel {s['vertical']}"
        + (f" (τ {s['vertical_tau_s']:g} s)" if s.get("vertical_tau_s") else ""),
        title_justify="left",
        header_style="bold",
    )
    table.add_column("quantity")
    table.add_column("final", justify="right")
    table.add_column("max |·|", justify="right")
    fe, me = s.get("final_error"), s.get("max_error") or {}
    st = s["final_state"]
    if fe is None:
        rows = [
            ("attitude (pitch, roll, yaw) (deg)", fmt(st["attitude_deg"]), ""),
            ("velocity ENU (m/s)", fmt(st["velocity_mps"]), ""),
            ("lat, lon (deg), h (m)", fmt(st["position_deg_m"], 6), ""),
            ("displacement from the start ENU (m)", fmt(s["displacement_m"], 2),
             fmt(s["max_horizontal_displacement_m"], 2) + " horiz."),
        ]
    else:
        rows = [
            ("attitude error (pitch, roll, yaw) (deg)", fmt(fe["attitude_deg"]),
             fmt(me["attitude_deg"])),
            ("misalignment φ ENU (deg)", fmt(fe["misalignment_deg"]),
             fmt(me["misalignment_deg"])),
            ("velocity error ENU (m/s)", fmt(fe["velocity_mps"]), fmt(me["velocity_mps"])),
            ("position error ENU (m)", fmt(fe["position_m"]), fmt(me["position_m"])),
            ("horizontal position error (m)",
             fmt(float(sum(x * x for x in fe["position_m"][:2]) ** 0.5), 3),
             fmt(s["max_horizontal_error_m"], 3)),
        ]
    for row in rows:
        table.add_row(*map(Text, row))
    notes = [f"start: {s['init']}; earth {s['earth']}"
             + ("; IMU on a mechanism: body attitude through the mechanism angles"
                if s.get("mechanism") else "")]
    if fe is None:
        notes.append("recorded data, no truth: the displacement from the start is the drift "
                     "if the vehicle stood still")
    notes.append(f"stored at {s['output_rate_hz']:g} Hz; compute {s['compute_s']:.2f} s; "
                 f"output {s.get('output') or '—'}")
    table.caption = "\n".join(notes)
    table.caption_justify = "left"
    return table
