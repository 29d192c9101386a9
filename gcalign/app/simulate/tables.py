"""The `gcalign simulate` table: what was simulated and where the motion ended."""

from __future__ import annotations

from rich.table import Table

from gcalign.app.report import DASH, angles, kv_table, run_line, span, vector


def simulate_table(s: dict) -> Table:
    metric = {"sig": 4, "most": 6, "tiny_as_zero": True}
    att0, att1 = s["initial_attitude_deg"], s["final_attitude_deg"]
    rows = [
        ("samples", f"{s['samples']} at {s['rate_hz']:g} Hz ({span(s['duration_s'])})"),
        ("stored at", f"{s['output_rate_hz']:g} Hz"
         + ("; IMU on a mechanism (sensor frame)" if s.get("mechanism") else "")),
        ("initial attitude (pitch, roll, yaw) (deg)",
         DASH if att0 is None else "  ".join(angles(att0, "deg"))),
        ("final attitude (pitch, roll, yaw) (deg)",
         DASH if att1 is None else "  ".join(angles(att1, "deg"))),
        ("final velocity ENU (m/s)", vector(s["final_velocity_mps"], **metric)),
        ("distance travelled (m)", vector(None if s["distance_m"] is None else
                                          [s["distance_m"]], **metric)),
        ("height range (m)", vector(s.get("height_range_m"), **metric)),
        ("final displacement ENU (m)", vector(s.get("final_displacement_m"), **metric)),
    ]
    table = kv_table(f"gcalign simulate: {s['scenario']} (earth {s.get('earth', 'wgs84')})",
                     rows, ("", "value"))
    table.caption = run_line(s, "compute (simulation and writing)")
    return table
