"""The `gcalign northfind` table: one determination, repeats (seed Table 1) or a sweep.

Azimuths in degrees (4 decimals, 0.36″); errors, spreads and predictions in arc-minutes
(3 decimals), the unit the seed and north-finder data sheets use."""

from __future__ import annotations

from rich.table import Column, Table
from rich.text import Text

from gcalign.app.report import DASH, angles, run_line, titled


def _rms(values) -> float | None:
    v = [x for x in values if x is not None]
    return (sum(x * x for x in v) / len(v)) ** 0.5 if v else None


def northfind_table(s: dict) -> Table:
    """North-finding per method: a single determination, the seed's Table 1 (repeats of one
    azimuth: estimates, mean, std, bias) or a sweep (max and RMS error per method)."""
    r, m = s["shape"]
    order, ms = s["method_order"], s["methods"]
    ref = "from the reference axis" if s["tilt_reference"] == "table" else "true azimuth"
    title = (f"gcalign northfind: {s['scenario']} — {s['positions']} positions × "
             f"{s['dwell_s']:g} s, lat {s['latitude_deg']:g}°, tilt {s['tilt_deg']:.4g}° "
             f"toward {s['tilt_direction_deg']:.4g}° ({ref})")
    tilt = s["tilt_est_deg"]
    tail = run_line(s, "compute")

    def columns(label: str, *values: str) -> Table:
        return titled(title, [Column(label, no_wrap=True)], values)  # the labels whole

    if m == 1 and r == 1:
        table = columns("method", "azimuth (deg)", "error (′)", "pred. σ (′)", "tilt est (deg)")
        for name in order:
            d = ms[name]
            table.add_row(
                Text(name),
                *angles([d["estimates_deg"][0]], "deg"),
                *angles([d["errors_deg"][0], d["std_pred_deg"][0]], "′"),
                DASH if name == "none" else angles([tilt[0]], "deg")[0],
            )
        table.caption = (
            f"true azimuth {s['azimuth_true_deg'][0]:.4f}°; estimated tilt "
            f"{tilt[0]:.4f}° toward {s['tilt_direction_est_deg'][0]:.3f}° (true "
            f"{s['tilt_deg']:.4g}° toward {s['tilt_direction_true_deg'][0]:.4g}°, "
            f"from north)\n{tail}"
        )
    elif m == 1:
        table = columns("", *(f"{n} (deg)" for n in order), "tilt est (deg)")
        shown = range(r) if r <= 25 else [*range(10), None, *range(r - 5, r)]
        for i in shown:
            if i is None:
                table.add_row(Text("…"), *["…"] * (len(order) + 1))
                continue
            table.add_row(
                Text(f"group {i + 1}"),
                *angles([ms[n]["estimates_deg"][i] for n in order], "deg"),
                angles([tilt[i]], "deg")[0],
                end_section=i == r - 1,
            )
        table.add_row(Text("mean (deg)"),
                      *angles([ms[n]["mean_deg"][0] for n in order], "deg"), "")
        for label, key in (("std (′)", "std_deg"), ("bias (′)", "bias_deg"),
                           ("pred. σ (′)", "std_pred_deg")):
            table.add_row(Text(label), *angles([ms[n][key][0] for n in order], "′"), "")
        table.add_row(Text("max |error| (′)"),
                      *angles([ms[n]["max_abs_error_deg"] for n in order], "′"), "")
        table.caption = (
            f"true azimuth {s['azimuth_true_deg'][0]:.4f}°; {r} independent "
            f"determinations; std: sample standard deviation (ddof 1); bias: mean − "
            f"truth\n{tail}"
        )
    else:
        cols = ["method", "max |error| (′)", "RMS error (′)", "mean error (′)",
                "closed form max (′)", "pred. σ (′)"]
        if r > 1:
            cols.append("std over repeats (′)")
        table = columns(*cols)
        for name in order:
            d = ms[name]
            bias = [b for b in d["bias_deg"] if b is not None]
            values = [d["max_abs_error_deg"], d["rms_error_deg"],
                      sum(bias) / len(bias) if bias else None, d["max_abs_error_pred_deg"],
                      _rms(d["std_pred_deg"])]
            if r > 1:
                values.append(_rms(d["std_deg"]))
            table.add_row(Text(name), *angles(values, "′"))
        sweep = s.get("sweep")
        az = (
            f"sweep {sweep['start_deg']:g}…{sweep['stop_deg']:g}° step {sweep['step_deg']:g}°"
            if sweep
            else "azimuths"
        )
        table.caption = (
            f"{az}: {m} true azimuths × {r} repeat(s); closed form: noise-free "
            f"tilt error; predicted σ and std: RMS over the sweep; estimated tilt "
            f"{min(tilt):.4f}…{max(tilt):.4f}°\n{tail}"
        )
    return table
