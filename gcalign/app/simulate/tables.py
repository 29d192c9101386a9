"""The `gcalign simulate` table."""

from __future__ import annotations

from rich.table import Table

from gcalign.app.report import fmt, kv_table


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
