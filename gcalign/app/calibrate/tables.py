"""The `gcalign calibrate` tables: one run per state (injected, estimate, error, σ), or the
six runs of ``--compare`` (the seed's Table 3 analogue). Display units are the seed's
(″, ′, m/s, m, °/h, µg, ppm); the JSON holds SI."""

from __future__ import annotations

import math
from pathlib import Path

from rich import box
from rich.table import Column, Table
from rich.text import Text

from gcalign.app.report import DASH, UNIT_TEXT, number, numbers, run_line, stacked, titled, vector
from gcalign.units import angle_text

GROUP_ENDS = ("phiU", "dvU", "dh", "ebz", "dbz", "dKgz", "dKaz")
SHORT = {"velocity": "v", "position": "p", "both": "v+p"}
#: Decimals per display unit: one resolution for every number of a state group (0.01″,
#: 0.001′, 0.1 mm/s, 1 cm, 1e-4 °/h, 0.1 µg, 0.1 ppm), so columns compare at a glance.
DECIMALS = {"arcsec": 2, "arcmin": 3, "m/s": 4, "m": 2, "deg/h": 4, "ug": 1, "ppm": 1}


def _g(x, k: float, unit: str) -> str:
    """An SI value `x` in its display unit (`k` the factor), at that unit's resolution."""
    y = None if x is None else x * k
    if y is None or (isinstance(y, float) and not math.isfinite(y)):
        return DASH
    return number(y, DECIMALS.get(unit, 3))


def _display(s: dict):
    return list(s["units"]), s["display_scale"], s["display_units"]


def calibrate_table(s: dict) -> Table:
    return compare_table(s) if s.get("compare") else run_table(s)


def _title(s: dict, what: str) -> str:
    loop = "closed loop" if s["feedback"] else "feed-forward"
    return (f"gcalign calibrate: {s['scenario']} — {what}, navigation "
            f"{s['navigation_rate_hz']:g} Hz, filter {s['filter_rate_hz']:g} Hz, {loop}")


def run_table(s: dict) -> Table:
    names, scale, units = _display(s)
    aid = {"zero-velocity": "zero-velocity updates",
           "file": f"{s['measure']} from files"}.get(s["aiding"], f"DGNSS {s['measure']}")
    table = titled(_title(s, f"{aid} over {s['duration_s']:.0f} s"), ("state", "unit"),
                   ("injected", "estimate", "error", "σ final", "σ0", "error/σ"))
    for name in names:
        st, k, u = s["states"][name], scale[name], units[name]
        err = st["error"]
        table.add_row(Text(name), UNIT_TEXT.get(u, u), *(_g(st[c], k, u) for c in (
            "injected", "estimate", "error", "sigma", "sigma0")),
                      DASH if err is None else f"{err / st['sigma']:+.2f}".replace("-0.00",
                                                                                  "+0.00"),
                      end_section=name in GROUP_ENDS)
    notes = []
    nees = s.get("nees")
    if nees is not None:
        lo, hi = nees["band_95"]
        notes.append(f"NEES final {nees['final']:.1f}, mean {nees['mean']:.1f} (χ²₂₁ 95 % band "
                     f"{lo:.1f}…{hi:.1f} for a truth drawn from P0; {100 * nees['inside_95']:.0f}"
                     " % of epochs inside)")
    nis, inn = s["nis"], s["innovation"]
    notes.append(f"NIS mean {nis['mean']:.2f} (χ²_{nis['dof']} mean {nis['dof']}); standardized "
                 f"innovations {', '.join(inn['names'])}: mean "
                 f"{'  '.join(number(x, 3) for x in inn['standardized_mean'])}, std "
                 f"{'  '.join(number(x, 3) for x in inn['standardized_std'])}")
    att = s["attitude_deg"]
    notes.append(f"INS attitude at the end (pitch, roll, yaw) {att[0]:.4f}°, {att[1]:.4f}°, "
                 f"{att[2]:.4f}°" + (f"; coarse {vector(s['coarse_attitude_deg'], most=4)}°"
                                     if s.get("coarse_attitude_deg") else ""))
    notes += aided_notes(s)
    for key, f in (s.get("aiding_files") or {}).items():
        lever = f["lever_arm_m"]
        notes.append(f"{key} from {f['path'].rsplit('/', 1)[-1]} ({f['format']}), measured at "
                     + ("the IMU" if not any(lever) else
                        f"lever arm ({', '.join(f'{x:g}' for x in lever)}) m, body RFU"))
    sm = s.get("smoothed_initial")
    if sm:
        k = scale["phiU"]
        phi = ", ".join(f"{sm[n]['estimate'] * scale[n]:.3g} ± {sm[n]['sigma'] * scale[n]:.3g}"
                        f"{UNIT_TEXT.get(units[n], units[n])}" for n in ("phiE", "phiN", "phiU"))
        notes.append(f"RTS smoother: φ at the start (E, N, U) {phi}; φU σ "
                     f"{sm['phiU']['filtered_sigma'] * k:.3g}′ filtered → "
                     f"{sm['phiU']['sigma'] * k:.3g}′ smoothed" + (
                         " (the sensor errors, constants without process noise, gain nothing: "
                         "their smoothed σ is the final filtered σ)"
                         if s.get("processes") is None else ""))
    e = s.get("final_error") if s.get("error_source") == "reference" else None
    if e:
        a = [angle_text(math.radians(x)) for x in e["attitude_deg"]]
        notes.append(f"against the reference at {e['t_s']:.2f} s: attitude (pitch, roll, yaw) "
                     f"{', '.join(a)}; velocity {'  '.join(numbers(e['velocity_mps'], most=3))}"
                     f" m/s; position {'  '.join(numbers(e['position_m'], most=3))} m ENU")
    notes.append("navigation states at the end: estimate = estimated error of the INS before "
                 "the last correction; error = what the correction leaves; injected at t = 0")
    notes.append(f"truth {s['truth_source'] or 'unknown (recorded data)'}; "
                 + run_line(s, "compute (the filter)"))
    table.caption = "\n".join(notes)
    return table




def _outage_text(o: dict) -> str:
    return f"{o['start_data_s']:.2f}–{o['end_data_s']:.2f} s ({o['length_s']:.1f} s)"


def _errors_line(label: str, e: dict | None) -> str | None:
    """One line of a solution's errors: horizontal and vertical position, velocity and
    heading RMS / max."""
    if e is None:
        return None
    pos_rms, pos_max = e["position_rms_m"], e["position_max_m"]
    v_rms = math.sqrt(sum(x * x for x in e["velocity_rms_mps"]))
    yaw = angle_text(math.radians(e["attitude_rms_deg"][2]))
    return (f"  {label}: horizontal {e['horizontal_rms_m']:.3f} / {e['horizontal_max_m']:.3f} m,"
            f" up {pos_rms[2]:.3f} / {pos_max[2]:.3f} m, velocity {v_rms:.3f} m/s, yaw {yaw}"
            f" (RMS / max, {e['samples']} samples)")


def aided_notes(s: dict) -> list[str]:
    """What a run on aiding files adds: the fixes and their σ, the outages, where the start
    came from, and the solution's errors inside and outside the outages."""
    notes = []
    start = s.get("start")
    if start:
        att = start.get("attitude_deg")
        notes.append(f"start at {start['t_data_s']:.3f} s (the recording's time): "
                     f"{start['source']}" + ("" if att is None else
                                             f"; attitude {vector(att, most=4)}°"))
    fx = s.get("fixes")
    if fx:
        sig = ("σ per fix " + "–".join(f"{x:.3g}" for x in fx["sigma_enu_range_m"]) + " m"
               if fx["sigma_enu_range_m"] else fx["sigma"])
        outs = fx["outages"]
        notes.append(f"fixes: {fx['epochs']} of {Path(fx['path']).name} "
                     f"({fx['first_s']:.2f}–{fx['last_s']:.2f} s, every "
                     f"{fx['median_interval_s']:.3g} s), {sig}; {s['components']}; "
                     f"{len(outs)} outage{'s' if len(outs) != 1 else ''} longer than "
                     f"{fx['max_gap_s']:.3g} s" + (": " + ", ".join(
                         _outage_text(o) for o in outs[:6]) + (" …" if len(outs) > 6 else "")
                         if outs else ""))
    e = s.get("solution_errors")
    if e:
        lines = [_errors_line("outside the outages", e["outside_outages"]),
                 _errors_line("in the outages", e["in_outages"])]
        sm = (s.get("epoch_errors") or {}).get("smoothed")
        if sm:
            lines.append(_errors_line("in the outages, smoothed (filter epochs)",
                                      sm["in_outages"]))
            fw = s["epoch_errors"]["forward"]["in_outages"]
            lines.append(_errors_line("in the outages, forward (filter epochs)", fw))
        shown = [x for x in lines if x is not None]
        if shown:
            notes.append(f"solution against the {e['against']} at every navigation sample:")
            notes += shown
    return notes


def _tag(run: dict) -> str:
    return f"{'des.' if run['label'] == 'designed' else 'conv.'} {SHORT[run['measure']]}"


def compare_table(s: dict) -> Table:
    """Final error and final σ of the heading and the sensor errors for each trajectory and
    measurement, in two blocks that fit 80 columns."""
    names, scale, units = _display(s)
    runs = s["runs"]
    shown = names[2:3] + names[9:]  # φU and the twelve sensor errors
    blocks = []
    for what in ("error", "sigma"):
        t = titled("estimate − truth at the end" if what == "error" else "final σ",
                   [Column("state", min_width=5), Column("unit", min_width=4)],
                   box=box.SIMPLE_HEAD, pad_edge=False, padding=(0, 0), collapse_padding=True)
        t.add_column("injected", justify="right", min_width=8)
        for r in runs:
            t.add_column(_tag(r), justify="right", min_width=8, no_wrap=True)
        for name in shown:
            k, u = scale[name], units[name]
            cells = [_g(r["states"][name][what], k, u) for r in runs]
            t.add_row(Text(name), UNIT_TEXT.get(u, u),
                      _g(runs[0]["states"][name]["injected"], k, u), *cells,
                      end_section=name in GROUP_ENDS)
        blocks.append(t)
    title = _title(s, "designed vs conventional take-off (seed Table 3)")
    durations = {r["label"]: (r["duration_s"], len(r["segments"])) for r in runs}
    notes = [f"{lab}: {n} segments, {d:.0f} s of filter steps" for lab, (d, n)
             in durations.items()]
    nees = [f"{_tag(r)} {r['nees']['final']:.1f}" for r in runs if r.get("nees")]
    if nees:
        notes.append("NEES final (χ²₂₁): " + ", ".join(nees))
    notes.append("v: velocity, p: position, v+p: both; φU: the INS heading error the "
                 "correction leaves; the same data and DGNSS noise in every column")
    notes.append(run_line(s, "compute (the six filter runs)"))
    return stacked(title, blocks, "\n".join(notes))
