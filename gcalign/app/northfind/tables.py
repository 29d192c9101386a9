"""The `gcalign northfind` table: one determination, repeats (seed Table 1) or a sweep."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text

from gcalign.app.report import fmt


def _rms(values) -> float | None:
    v = [x for x in values if x is not None]
    return (sum(x * x for x in v) / len(v)) ** 0.5 if v else None


def _arcmin(x):
    return None if x is None else x * 60.0


def northfind_table(s: dict) -> Table:
    """North-finding per method: a single determination, the seed's Table 1 (repeats of one
    azimuth: estimates, mean, std, bias) or a sweep (max and RMS error per method)."""
    r, m = s["shape"]
    order, ms = s["method_order"], s["methods"]
    ref = "from the reference axis" if s["tilt_reference"] == "table" else "true azimuth"
    table = Table(
        title=f"gcalign northfind: {s['scenario']} — {s['positions']} positions × "
        f"{s['dwell_s']:g} s, lat {s['latitude_deg']:g}°, tilt {s['tilt_deg']:.4g}° toward "
        f"{s['tilt_direction_deg']:.4g}° ({ref})",
        title_justify="left",
        header_style="bold",
    )
    tilt = s["tilt_est_deg"]
    tail = (
        f"seed {s['seed']}; compute {s['compute_s'] * 1e3:.1f} ms; output {s.get('output') or '—'}"
    )
    if m == 1 and r == 1:
        for name in (
            "method",
            "azimuth (deg)",
            "error (deg)",
            "error (′)",
            "pred. σ (′)",
            "tilt est (deg)",
        ):
            table.add_column(
                name, justify="left" if name == "method" else "right", no_wrap=name == "method"
            )
        for name in order:
            d = ms[name]
            table.add_row(
                Text(name),
                fmt(d["estimates_deg"][0], 5),
                fmt(d["errors_deg"][0], 5),
                fmt(_arcmin(d["errors_deg"][0]), 3),
                fmt(_arcmin(d["std_pred_deg"][0]), 3),
                "—" if name == "none" else fmt(tilt[0], 4),
            )
        table.caption = (
            f"true azimuth {s['azimuth_true_deg'][0]:.4f}°; estimated tilt "
            f"{tilt[0]:.4f}° toward {s['tilt_direction_est_deg'][0]:.3f}° (true "
            f"{s['tilt_deg']:.4g}° toward {s['tilt_direction_true_deg'][0]:.4g}°, "
            f"from north); {tail}"
        )
    elif m == 1:
        table.add_column("group", justify="left")
        for name in order:
            table.add_column(f"{name} (deg)", justify="right")
        table.add_column("tilt est (deg)", justify="right")
        shown = range(r) if r <= 25 else [*range(10), None, *range(r - 5, r)]
        for i in shown:
            if i is None:
                table.add_row(Text("…"), *["…"] * (len(order) + 1))
                continue
            table.add_row(
                Text(str(i + 1)),
                *[fmt(ms[n]["estimates_deg"][i], 5) for n in order],
                fmt(tilt[i], 4),
                end_section=i == r - 1,
            )
        stats = (
            ("mean (deg)", "mean_deg", 1.0, 5),
            ("std (′)", "std_deg", 60.0, 4),
            ("bias (′)", "bias_deg", 60.0, 4),
            ("pred. σ (′)", "std_pred_deg", 60.0, 4),
        )
        for label, key, scale, digits in stats:
            cells = []
            for n in order:
                v = ms[n][key][0]
                cells.append(fmt(None if v is None else v * scale, digits))
            table.add_row(Text(label), *cells, "")
        table.add_row(
            Text("max |err| (′)"), *[fmt(ms[n]["max_abs_error_deg"] * 60.0, 4) for n in order], ""
        )
        table.caption = (
            f"true azimuth {s['azimuth_true_deg'][0]:.4f}°; {r} independent "
            f"determinations; std: sample standard deviation (ddof 1); bias: mean − "
            f"truth; {tail}"
        )
    else:
        cols = [
            "method",
            "max |error| (deg)",
            "RMS error (deg)",
            "mean error (deg)",
            "closed form max (deg)",
            "pred. σ (′)",
        ]
        if r > 1:
            cols.append("std over repeats (′)")
        for name in cols:
            table.add_column(
                name, justify="left" if name == "method" else "right", no_wrap=name == "method"
            )
        for name in order:
            d = ms[name]
            bias = [b for b in d["bias_deg"] if b is not None]
            row = [
                fmt(d["max_abs_error_deg"], 4),
                fmt(d["rms_error_deg"], 4),
                fmt(sum(bias) / len(bias) if bias else None, 4),
                fmt(d["max_abs_error_pred_deg"], 4),
                fmt(_arcmin(_rms(d["std_pred_deg"])), 3),
            ]
            if r > 1:
                row.append(fmt(_arcmin(_rms(d["std_deg"])), 3))
            table.add_row(Text(name), *row)
        sweep = s.get("sweep")
        az = (
            f"sweep {sweep['start_deg']:g}…{sweep['stop_deg']:g}° step {sweep['step_deg']:g}°"
            if sweep
            else "azimuths"
        )
        table.caption = (
            f"{az}: {m} true azimuths × {r} repeat(s); closed form: noise-free "
            f"tilt error; predicted σ and std: RMS over the sweep; estimated tilt "
            f"{min(tilt):.4f}…{max(tilt):.4f}°; {tail}"
        )
    return table
