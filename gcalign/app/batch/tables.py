"""The `gcalign batch` table: statistics over seeds of each metric, per variant."""

from __future__ import annotations

from rich.table import Table
from rich.text import Text


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
