"""Rich tables built by pure functions from plain summaries (the same dicts the JSON holds),
and the formatting every command's table shares.

Rules the helpers keep (a table is read down its columns):

* one format per column or group of rows: fixed decimals chosen from the largest value
  (:func:`numbers`), scientific only when the whole group needs it; values below the last
  shown decimal print as 0 (never ``-1.529e-13``, never ``-0.000``);
* attitude errors in the unit that reads best for their size (:func:`angle_unit`: deg from
  1°, arc-minutes from 1′, else arc-seconds) with a fixed resolution per unit;
* the caption ends with what ``compute`` measured beside the wall time (:func:`run_line`)
  and the run's warnings (:func:`gcalign.app.readback.summary_table` adds them to every
  command's table).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

from rich.console import Group, RenderableType
from rich.table import Column, Table
from rich.text import Text

from gcalign import units

DASH = "—"


UNIT_TEXT = {"arcsec": "″", "arcmin": "′", "deg/h": "°/h", "ug": "µg", "ppm": "ppm",
             "m/s": "m/s", "m": "m"}
"""Printed symbols of the display units (:data:`gcalign.estimation.ins_error.DISPLAY_UNITS`)."""


def _finite(values) -> list[float]:
    return [abs(float(v)) for v in values
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)]


def decimals(values: Iterable, sig: int = 4, most: int = 6,
             tiny_as_zero: bool = False) -> int | None:
    """Decimals that give the largest |value| `sig` significant digits (0 … `most`), or
    None when the group needs scientific notation: values ≥ 1e6, or all below the last
    decimal allowed -- unless `tiny_as_zero` (a physical resolution: they print as 0 at
    `most` decimals)."""
    top = max(_finite(values), default=0.0)
    if top == 0.0:
        return min(sig - 1, most)
    if top >= 1e6:
        return None
    if top < 10.0 ** -most:
        return most if tiny_as_zero else None
    return max(0, min(most, sig - 1 - math.floor(math.log10(top))))


def number(x, d: int | None, sig: int = 4) -> str:
    """`x` with `d` decimals (None: scientific, `sig` digits); None prints as a dash."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return DASH if x is None else str(x)
    if d is None:
        return f"{float(x):.{sig - 1}e}"
    text = f"{float(x):.{d}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def numbers(values: Sequence, sig: int = 4, most: int = 6,
            tiny_as_zero: bool = False) -> list[str]:
    """Every value of a group (a column, a vector) in one format: :func:`decimals`."""
    d = decimals(values, sig, most, tiny_as_zero)
    return [number(v, d, sig) for v in values]


def vector(values: Sequence[float | None] | None, **kw: Any) -> str:
    """A vector in one cell, its components in one format (:func:`numbers`, `kw` its
    options)."""
    return DASH if values is None else "  ".join(numbers(list(values), **kw))


#: Angle units: factor from degrees and the decimals shown (resolution 0.36″, 0.06″, 0.01″).
ANGLE_UNITS = {"deg": (1.0, 4), "′": (60.0, 3), "″": (3600.0, 2)}
#: Their names in headers and labels (those of :data:`gcalign.units.ANGLE_UNITS`).
UNIT_NAME = {"deg": "deg", "′": "arcmin", "″": "arcsec"}
_SYMBOL = {name: symbol for symbol, name in UNIT_NAME.items()}


def angle_unit(values_deg: Iterable) -> str:
    """The table's symbol of the unit the largest |value| (deg) reads best in: the rule of
    :func:`gcalign.units.angle_unit` (deg from 1°, arc-minutes from 1′, else arc-seconds)."""
    return _SYMBOL[units.angle_unit(max(_finite(values_deg), default=0.0) * units.DEG)]


def angles(values_deg: Sequence, unit: str) -> list[str]:
    """Angles (given in degrees) in `unit`, at that unit's fixed resolution."""
    factor, d = ANGLE_UNITS[unit]
    return [number(None if v is None else float(v) * factor, d) for v in values_deg]


def flat(groups: Iterable[Sequence | None]) -> list:
    """The values of several vectors (None skipped), to choose one unit or format for all."""
    return [v for g in groups if g is not None for v in g]


def duration(seconds: float | None) -> str:
    """A duration that reads at a glance: ms below 1 s, s below 2 min, then min and h."""
    if seconds is None:
        return DASH
    if seconds < 1.0:
        return f"{seconds * 1e3:.1f} ms"
    if seconds < 120.0:
        return f"{seconds:.2f} s"
    if seconds < 7200.0:
        return f"{seconds / 60.0:.1f} min"
    return f"{seconds / 3600.0:.2f} h"


def span(seconds: float) -> str:
    """A data duration: seconds up to an hour, then hours."""
    return f"{seconds:g} s" if seconds < 3600.0 else f"{seconds / 3600.0:.4g} h"


def run_line(s: dict, compute: str | None = "compute") -> str:
    """The caption's last line: the random seed, what ``compute_s`` measured (`compute`
    names it) beside the wall time of the whole command, and the output file."""
    parts = []
    if "seed" in s:
        parts.append("recorded data" if s["seed"] is None else f"random seed {s['seed']}")
    if compute and s.get("compute_s") is not None:
        timing = f"{compute} {duration(s['compute_s'])}"
        if s.get("wall_s") is not None:
            timing += f" of {duration(s['wall_s'])} wall"
        parts.append(timing)
    elif s.get("wall_s") is not None:
        parts.append(f"wall {duration(s['wall_s'])}")
    parts.append(f"output {s.get('output') or DASH}")
    return "; ".join(parts)


def titled(title: str | None, labels: Sequence[str | Column] = (),
           values: Sequence[str] = (), **options: Any) -> Table:
    """A command's table: the title and the caption on the left, bold headers, the `labels`
    columns (left-justified; a :class:`~rich.table.Column` for one with options of its own),
    then the `values` columns, right-justified (numbers are read down them); `options`
    those of :class:`~rich.table.Table`."""
    table = Table(*labels, title=title, title_justify="left", caption_justify="left",
                  header_style="bold", **options)
    for name in values:
        table.add_column(name, justify="right")
    return table


def stacked(title: str, tables: Iterable[RenderableType], notes: str,
            padding: tuple[int, int] = (0, 0)) -> Table:
    """Tables one above the other (`padding`: lines and columns around each) under one
    title, with `notes` under them all."""
    outer = Table.grid(padding=padding)
    outer.title, outer.title_justify = title, "left"
    outer.caption, outer.caption_justify = notes, "left"
    for table in tables:
        outer.add_row(table)
    return outer


def kv_table(title: str, rows: Iterable[Sequence[str]], headers: Sequence[str] = ("", ""),
             justify: Sequence[str] | None = None) -> Table:
    """Rows of text (never read as markup) under `headers`: the first column on the left,
    the others on the right unless `justify` says otherwise."""
    table = titled(title)
    for i, h in enumerate(headers):
        j = justify[i] if justify else ("left" if i == 0 else "right")
        table.add_column(h, justify=j)  # type: ignore[arg-type]
    for row in rows:
        table.add_row(*map(Text, row))
    return table


def with_warnings(table: RenderableType, warnings: Sequence[str]) -> RenderableType:
    """The run's warnings under the caption, one line each (under the whole output when a
    command prints more than one table)."""
    if not warnings:
        return table
    if not isinstance(table, Table):
        return Group(table, Text("\n".join(f"warning: {w}" for w in warnings),
                                 style="yellow"))
    caption = table.caption
    text = Text() if caption is None else (
        caption.copy() if isinstance(caption, Text) else Text.from_markup(str(caption)))
    for w in warnings:
        text.append(("\n" if text.plain else "") + f"warning: {w}", style="yellow")
    table.caption = text
    table.caption_justify = "left"
    return table
