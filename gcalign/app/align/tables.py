"""The `gcalign align` table: truth and estimate at T2 and T3, the error there and its
spread over the last pass, the error (or, without truth, the attitude) at the end of every
pass. Attitudes in degrees; errors in deg, ′ or ″ as their size needs."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from gcalign.app.report import DASH, UNIT_NAME, angle_unit, angles, flat, number, run_line, titled


def _pass_label(p: dict) -> str:
    return f"{p['pass']}: {p['direction']}, {p['kind']}, stage {p['stage']}"


def _numbered(p: dict) -> dict:
    """A pass of the summary numbered from 1 (files written before that have 'index' and a
    stage from 0)."""
    if "pass" in p:
        return p
    return {**p, "pass": p["index"] + 1, "stage": p["stage"] + 1}


def align_table(s: dict) -> Table:
    """See the module docstring; every number of a section in one unit and format."""
    if s.get("mode") == "transfer":
        from gcalign.app.align.transfer import table as transfer_table
        return transfer_table(s)
    passes = [_numbered(p) for p in s["passes"]]
    n_fwd = sum(p["direction"] == "forward" for p in passes)
    plan = (f"{len(passes)} passes ({n_fwd} forward + {len(passes) - n_fwd} reverse)"
            if len(passes) > 1 else "1 pass")
    comp = ("real time (no compensation)" if s["compensation"] == "real time"
            else f"compensation {s['compensation']} T2 → T3")
    table = titled(f"gcalign align: {s['scenario']} — {s['mode']}, {plan}, {comp}, azimuth "
                   f"poles {s['azimuth_poles']}", ("",), ("t (s)", "pitch", "roll", "yaw"))
    has_truth = s.get("truth_t3_deg") is not None
    against = s.get("error_source") or "truth"  # or "reference" (recorded data)

    def row(label, t, values, unit, end=False):
        t_text = t if isinstance(t, str) else number(t, 2)
        cells = [DASH] * 3 if values is None else angles(values, unit)
        table.add_row(Text(label), t_text, *cells, end_section=end)

    for when in ("t2", "t3"):
        t = s[f"{when}_s"]
        if has_truth:
            row(f"{against} at T{when[1]} (deg)", t, s[f"truth_{when}_deg"], "deg")
        row(f"estimate at T{when[1]} (deg)", t, s[f"attitude_{when}_deg"], "deg",
            end=when == "t3")

    last = s.get("last_pass_error")
    if has_truth:
        stats = [] if last is None else [last["mean_deg"], last["std_deg"], last["max_deg"]]
        unit = angle_unit(flat([s["error_t2_deg"], s["error_t3_deg"], *stats]))
        u = UNIT_NAME[unit]
        row(f"error at T2 ({u})", s["t2_s"], s["error_t2_deg"], unit)
        row(f"error at T3 ({u})", s["t3_s"], s["error_t3_deg"], unit, end=last is None)
        if last is not None:
            a, b = last["window_s"]
            table.add_row(Text(f"last pass, 2nd half ({u})", style="bold"),
                          f"{a:.0f}–{b:.0f}", "", "", "")
            row("  mean", "", last["mean_deg"], unit)
            row("  std", "", last["std_deg"], unit)
            row("  max |error|", "", last["max_deg"], unit, end=True)
        ends = [p["error_deg"] for p in passes]
        unit = angle_unit(flat(ends))
        table.add_row(Text(f"error at the end of pass ({UNIT_NAME[unit]})", style="bold"),
                      "", "", "", "")
        for p in passes:
            row(_pass_label(p), p["t_end_s"], p["error_deg"], unit)
    else:
        table.add_row(Text("attitude at the end of pass (deg)", style="bold"), "", "", "", "")
        for p in passes:
            row(_pass_label(p), p["t_end_s"], p["attitude_deg"], "deg")

    notes = [
        f"window T1–T2 = {s['t1_s']:g}–{s['t2_s']:g} s ({s['t2_s'] - s['t1_s']:g} s, each "
        f"pass over it; the coarse alignment before T1); data used {s['data_used_s']:.1f} s, "
        f"equivalent length {s['equivalent_s']:.1f} s (passes laid end to end)"
        + ("" if s.get("t3_source") != "measured" else
           f"; T3 measured: T2 + the passes' compute time = {s['t3_s']:.2f} s"),
    ]
    notes.append("pass: direction, loop (compass: the gyrocompass loops; attitude: "
                 "attitude-only strapdown), stage of the loop parameters (align.stages); t: "
                 "alignment time (a reverse pass ends at T1)")
    if has_truth:
        notes.append(f"error: estimate − {against} as Euler angles (yaw wrapped)"
                     + ("" if last is None else
                        f"; last pass, 2nd half: its {last['rows']} stored rows, std ddof 0"))
    else:
        notes.append("recorded data: no truth, so no errors; the estimate only")
    notes.append(run_line(s, "compute (the passes)"))
    table.caption = "\n".join(notes)
    return table
