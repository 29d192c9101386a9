"""The `gcalign batch` table: statistics over seeds of each metric, per variant.

One small table per metric (and vector component), its name and unit in the title line
(never wrapped into a cell); all statistics of a metric in one unit and format (angles in
deg, ′ or ″ as their size needs); variant names broken only between overrides."""

from __future__ import annotations

import re

from rich import box
from rich.table import Column, Table
from rich.text import Text

from gcalign.app.report import DASH, UNIT_NAME, angle_unit, angles, numbers, stacked, titled

STATS = (("mean", "mean"), ("std", "std"), ("RMS", "rms"), ("median", "median"),
         ("5 %", "p05"), ("95 %", "p95"))
#: Columns a variant name may take before it wraps (between its overrides).
NAME_WIDTH = 28


def written(x) -> str:
    """An override value as the user wrote it (150, 0.5, full-cycle)."""
    return x if isinstance(x, str) else f"{x:g}" if isinstance(x, float) else str(x)


def short_keys(keys: list[str]) -> dict[str, str]:
    """The last part of each dotted key where it is unique (``t_z_s``), else the key."""
    tails = [k.rsplit(".", 1)[-1] for k in keys]
    return {k: (t if tails.count(t) == 1 else k) for k, t in zip(keys, tails, strict=True)}


def _file_label(name: str) -> str:
    """A scenario file as a variant label: its name without ``.yaml``, broken after ``_``,
    ``-`` or ``.`` into lines of at most NAME_WIDTH (never inside a word)."""
    stem = re.sub(r"\.ya?ml$", "", name)
    lines = [""]
    for part in re.findall(r"[^_.\-/]*[_.\-/]?", stem):
        if lines[-1] and len(lines[-1]) + len(part) > NAME_WIDTH:
            lines.append("")
        lines[-1] += part
    return "\n".join(line for line in lines if line)


def _names(s: dict) -> list[str]:
    """Each variant's overrides, one per line (a batch of files: the file name alone)."""
    short = short_keys(list(s.get("grid") or {}))
    out = []
    for v in s["variants"]:
        lines = [_file_label(written(x)) if k == "scenario" else f"{short.get(k, k)}={written(x)}"
                 for k, x in v["overrides"].items()]
        name = "\n".join(lines) or "base"
        if v["failed"]:
            name += f"\n[{v['failed']} failed]"
        out.append(name)
    return out


def _cells(values: list, units: str) -> tuple[list[str], str]:
    """The statistics of one metric section in one format, and the unit to show."""
    if units == "deg":
        unit = angle_unit(values)
        return angles(values, unit), UNIT_NAME[unit]
    return numbers(values, sig=4), units


def batch_table(s: dict) -> Table:
    """Variants compared: for each metric (and vector component) a table with one row per
    variant; columns are the statistics over seeds (mean, std, RMS, median, 5 and 95 %
    percentiles); ``--json`` has every digit."""
    variants = s["variants"]
    names = _names(s)
    width = min(NAME_WIDTH, max((len(line) for n in names for line in n.split("\n")),
                                default=7))
    title = (f"gcalign batch: {s['sweep']} — {s['command']}, {len(variants)} variant(s) "
             f"× {s['seeds']} seed(s) {s['seed_start']}…{s['seed_start'] + s['seeds'] - 1}")
    tables = []
    ns = {st["n"] for v in variants for st in v["stats"].values() if st}
    for m in s["metrics"]:
        per = [(v, v["stats"].get(m)) for v in variants]
        comps = next((st["components"] for _, st in per if st and st.get("components")), None)
        units = next((st.get("units") for _, st in per if st and st.get("units")), "")
        shown = (comps or [None])[:6]  # a long vector (e.g. one error per azimuth): the start
        for ci, comp in enumerate(shown):
            values = []
            for _, st in per:
                for _, key in STATS:
                    x = None if st is None else st.get(key)
                    if isinstance(x, list):
                        x = x[ci] if ci < len(x) else None
                    values.append(x)
            cells, unit = _cells(values, units)
            label = m + (f" {comp}" if comp is not None else "") + (f" ({unit})" if unit else "")
            if ci == len(shown) - 1 and comps and len(comps) > len(shown):
                label += f"; +{len(comps) - len(shown)} more components in --json and the file"
            table = titled(label, [Column("variant", min_width=width, overflow="fold")],
                           title_style="bold", box=box.SIMPLE_HEAD, pad_edge=False,
                           padding=(0, 0, 0, 1))
            for head, _ in STATS:
                table.add_column(head, justify="right", no_wrap=True)
            for j, name in enumerate(names):
                table.add_row(Text(name), *cells[j * len(STATS):(j + 1) * len(STATS)])
            tables.append(table)
    done = f"{s['runs']} runs" if s["complete"] else f"{s['finished']} of {s['runs']} runs finished"
    per_variant = f"; {ns.pop()} seed(s) per statistic" if len(ns) == 1 else ""
    notes = [f"{done}: {s['ok']} ok, {s['failed']} failed{per_variant}"]
    for f in s.get("failures", [])[:3]:
        notes.append(f"failed: variant {f['variant']} seed {f['seed']}: {f['error']}")
    if s.get("wall_s") is not None:
        notes.append(f"{s.get('executor') or ''}; wall {s['wall_s']:.2f} s".lstrip("; "))
    notes.append(f"output {s.get('output') or DASH}")
    return stacked(title, tables, "\n".join(notes))
