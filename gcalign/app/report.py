"""Rich tables built by pure functions from plain summaries (the same dicts the JSON holds)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from rich.table import Table
from rich.text import Text


def fmt(x, digits: int = 4) -> str:
    """A number or a vector of numbers in a compact, aligned form."""
    if x is None:
        return "—"
    if isinstance(x, (list, tuple)):
        return "  ".join(fmt(v, digits) for v in x)
    if isinstance(x, float):
        if x != 0 and (abs(x) < 10 ** -(digits - 1) or abs(x) >= 1e6):
            return f"{x:.{digits - 1}e}"
        return f"{x:.{digits}f}"
    return str(x)


def kv_table(title: str, rows: Iterable[Sequence], headers: Sequence[str] = ("", "")) -> Table:
    table = Table(title=title, title_justify="left", header_style="bold")
    for i, h in enumerate(headers):
        table.add_column(h, justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*(Text(c if isinstance(c, str) else fmt(c)) for c in row))
    return table


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


def summary_table(kind: str, summary: dict) -> Table:
    """The table a command printed, rebuilt from its summary (for `gcalign show`)."""
    builders = {
        "simulate": simulate_table,
        "navigate": navigate_table,
        "align": align_table,
        "batch": batch_table,
    }
    builders["northfind"] = northfind_table
    if kind not in builders:
        return kv_table(f"gcalign {kind}", ((k, str(v)) for k, v in summary.items()))
    return builders[kind](summary)


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


def batch_table(s: dict) -> Table:
    """Variants compared: for each metric (and vector component) a section with one row per
    variant; columns are the statistics over seeds (mean, std, RMS, median, 5 and 95 %
    percentiles), three significant digits (``--json`` has them all)."""
    from rich import box

    def _plain(x) -> str:  # an override value as the user wrote it (150, 0.5, full-cycle)
        return x if isinstance(x, str) else f"{x:g}" if isinstance(x, float) else str(x)

    variants = s["variants"]
    keys = list(s.get("grid") or {})
    tails = [k.rsplit(".", 1)[-1] for k in keys]
    short = {k: (t if tails.count(t) == 1 else k) for k, t in zip(keys, tails, strict=True)}
    title = (
        f"gcalign batch: {s['sweep']} — {s['command']}, {len(variants)} variant(s) × "
        f"{s['seeds']} seed(s) {s['seed_start']}…{s['seed_start'] + s['seeds'] - 1}"
    )
    table = Table(
        title=title,
        title_justify="left",
        header_style="bold",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        padding=(0, 0, 0, 1),
    )
    for name in ("variant", "n", "mean", "std", "RMS", "median", "5 %", "95 %"):
        table.add_column(
            name,
            justify="left" if name == "variant" else "right",
            overflow="fold" if name == "variant" else "ellipsis",
        )
    for m in s["metrics"]:
        per = [(v, v["stats"].get(m)) for v in variants]
        comps = next((st["components"] for _, st in per if st and st.get("components")), None)
        units = next((st.get("units") for _, st in per if st and st.get("units")), "")
        shown = (comps or [None])[:6]  # a long vector (e.g. one error per azimuth): the start
        for ci, comp in enumerate(shown):
            label = m + (f" {comp}" if comp is not None else "") + (f" ({units})" if units else "")
            if ci == len(shown) - 1 and comps and len(comps) > len(shown):
                label += f"  (+{len(comps) - len(shown)} more components in --json / the file)"
            table.add_row(Text(label, style="bold"), *[""] * 7)
            for j, (v, st) in enumerate(per):
                name = (
                    "\n".join(f"{short.get(k, k)}={_plain(x)}" for k, x in v["overrides"].items())
                    or "base"
                )
                if v["failed"]:
                    name += f"\n[{v['failed']} failed]"
                cells = []
                for stat in ("mean", "std", "rms", "median", "p05", "p95"):
                    x = None if st is None else st.get(stat)
                    if isinstance(x, list):
                        x = x[ci] if ci < len(x) else None
                    cells.append("—" if x is None else f"{x:.3g}")
                table.add_row(
                    Text(name),
                    str(0 if st is None else st["n"]),
                    *cells,
                    end_section=j == len(per) - 1,
                )
    done = f"{s['runs']} runs" if s["complete"] else f"{s['finished']} of {s['runs']} runs finished"
    notes = [f"{done}: {s['ok']} ok, {s['failed']} failed"]
    for f in s.get("failures", [])[:3]:
        notes.append(f"failed: variant {f['variant']} seed {f['seed']}: {f['error']}")
    if s.get("wall_s") is not None:
        notes.append(f"{s.get('executor') or ''}; wall {s['wall_s']:.2f} s".lstrip("; "))
    notes.append(f"output {s.get('output') or '—'}")
    table.caption = "\n".join(notes)
    table.caption_justify = "left"
    return table
