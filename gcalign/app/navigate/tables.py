"""The `gcalign navigate` table: final and largest errors against truth or a reference
solution (labelled so), or (recorded data without one) the final state and its drift from
the start. One row per quantity and instant, one
column per component; each quantity's final and largest values share a unit and format."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from gcalign.app.report import UNIT_NAME, angle_unit, angles, flat, numbers, run_line, span, titled

#: Velocity and position at 1 µm/s and 1 µm at most: below that is round-off.
METRIC = {"sig": 4, "most": 6, "tiny_as_zero": True}


def _pair(table: Table, label: str, final, peak, kind: str) -> None:
    """Two rows, final and max |·|, in one unit ('angle') or one format ('metric')."""
    both = flat([final, peak])
    if kind == "angle":
        unit = angle_unit(both)
        label = f"{label} ({UNIT_NAME[unit]})"
        cells = angles(both, unit)
    else:
        cells = numbers(both, **METRIC)  # type: ignore[arg-type]
    n = len(final)
    rows = [("final", cells[:n]), ("max |·|", cells[n:])] if peak is not None else [
        ("final", cells)]
    for i, (when, values) in enumerate(rows):
        values = values + [""] * (3 - len(values))
        table.add_row(Text(label if i == 0 else ""), when, *values,
                      end_section=i == len(rows) - 1)


def navigate_table(s: dict) -> Table:
    tau = f" (τ {s['vertical_tau_s']:g} s)" if s.get("vertical_tau_s") else ""
    table = titled(f"gcalign navigate: {s['scenario']} — {span(s['duration_s'])} "
                   f"({s['samples']} samples) from {s['start_s']:g} s, vertical channel "
                   f"{s['vertical']}{tau}", ("", ""), ("pitch · E", "roll · N", "yaw · U"))
    fe, me = s.get("final_error"), s.get("max_error") or {}
    st = s["final_state"]
    if fe is None:
        table.add_row(Text("attitude (deg)"), "final", *angles(st["attitude_deg"], "deg"))
        table.add_row(Text("velocity ENU (m/s)"), "final", *numbers(st["velocity_mps"],
                                                                     **METRIC))  # type: ignore[arg-type]
        lat, lon, h = st["position_deg_m"]
        table.add_row(Text("lat, lon (deg); h (m)"), "final", f"{lat:.7f}", f"{lon:.7f}",
                      f"{h:.2f}", end_section=True)
        disp = s["displacement_m"]
        cells = numbers([*disp, s["max_horizontal_displacement_m"]], **METRIC)  # type: ignore[arg-type]
        table.add_row(Text("displacement from the start (m)"), "final", *cells[:3])
        table.add_row(Text("horizontal displacement (m)"), "max", cells[3], "", "")
    else:
        _pair(table, "attitude error", fe["attitude_deg"], me.get("attitude_deg"), "angle")
        _pair(table, "misalignment φ ENU", fe["misalignment_deg"], me.get("misalignment_deg"),
              "angle")
        _pair(table, "velocity error ENU (m/s)", fe["velocity_mps"], me.get("velocity_mps"),
              "metric")
        _pair(table, "position error ENU (m)", fe["position_m"], me.get("position_m"),
              "metric")
        horiz = float(sum(x * x for x in fe["position_m"][:2]) ** 0.5)
        _pair(table, "horizontal position error (m)", [horiz],
              [s["max_horizontal_error_m"]], "metric")
    notes = [f"start: {s['init']}; earth {s['earth']}"
             + ("; IMU on a mechanism: body attitude through the mechanism angles"
                if s.get("mechanism") else "")]
    if fe is None:
        notes.append("recorded data, no truth: the displacement from the start is the drift "
                     "if the vehicle stood still")
    else:
        if s.get("error_source") == "reference":
            notes.append(f"errors: estimate − reference ({s['reference']['path']}, interpolated "
                         "to every sample, attitude on the rotation group; it is not truth: "
                         "its own errors are in these numbers; φ: C_nb,est C_nb,ref^T = "
                         "exp(−[φ×]))")
        else:
            notes.append("errors: estimate − truth at every sample (attitude as Euler angles, "
                         "roll and yaw wrapped; φ: C_nb,est C_nb,true^T = exp(−[φ×]))")
    notes.append(f"series stored at {s['output_rate_hz']:g} Hz; "
                 + run_line(s, "compute (the strapdown kernel)"))
    table.caption = "\n".join(notes)
    return table
