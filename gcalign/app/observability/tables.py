"""The `gcalign observability` table: log10 η per segment and state (seed Table 1), in two
blocks that fit 80 columns (navigation errors with the ranks; position and sensor errors)."""

from __future__ import annotations

import math

from rich import box
from rich.table import Table
from rich.text import Text

from gcalign.app.report import DASH, stacked, titled

CELL = 4  # a state column: "-12"; headers are at most 4 characters, columns 1 space apart


def _exp(eta: float) -> str:
    """η as its rounded decimal exponent (η = 0 is '·': not observable there)."""
    return "·" if eta <= 0 else f"{round(math.log10(eta)):d}"


def margin(m: float | None) -> str:
    """A rank's margin from the cut-off as ×factor ('—': nothing near it)."""
    if m is None:
        return DASH
    return f"×{m:.2g}" if m < 100 else f"×{m:.0e}".replace("e+0", "e")


def _block(title: str | None) -> Table:
    t = titled(title, box=box.SIMPLE_HEAD, pad_edge=False, padding=(0, 0), show_edge=False,
               collapse_padding=True)
    t.add_column("#", justify="right", min_width=2)
    return t


def observability_table(s: dict) -> Table:
    names = s["states"]
    nav, rest = names[:6], names[6:]
    rows = [(seg, cum) for seg, cum in zip(s["segments"], s["cumulative"], strict=True)]
    a = _block(None)
    for h, w in (("segment", 16), ("t (s)", 7), ("rank", 4), ("TOM", 3), ("cum.", 4)):
        a.add_column(h, justify="left" if h == "segment" else "right", min_width=w,
                     no_wrap=True)
    b = _block(None)
    for n in nav:
        a.add_column(n, justify="right", min_width=CELL)
    for n in rest:
        b.add_column(n, justify="right", min_width=CELL)
    for i, (seg, cum) in enumerate(rows):
        a.add_row(str(i + 1), Text(seg["name"]), f"{seg['t0_s']:.0f}–{seg['t1_s']:.0f}",
                  str(seg["rank"]), str(seg["tom_rank"]), str(cum["rank"]),
                  *(_exp(seg["degree"][n]) for n in nav))
        b.add_row(str(i + 1), *(_exp(seg["degree"][n]) for n in rest))
    last = s["cumulative"][-1]
    a.add_row("", Text("whole run", style="bold"), f"{last['t0_s']:.0f}–{last['t1_s']:.0f}",
              str(last["rank"]), str(last["tom_rank"]), str(last["rank"]),
              *(_exp(last["degree"][n]) for n in nav))
    b.add_row("all", *(_exp(last["degree"][n]) for n in rest))
    margins = " ".join(f"{i + 1}:{margin(seg.get('rank_margin'))}"  # a pair never split
                        for i, (seg, _) in enumerate(rows))
    return stacked(
        f"gcalign observability: {s['scenario']} — {s['measure']} matching, scaling "
        f"{s['scaling']}, {len(rows)} segments in {s['piece_s']:g} s pieces", (a, b),
        "cells: log10 of the degree η = σ_(k)/σ_0 (seed eq. 17; σ_0 the measured states' "
        "largest singular value), rounded: −3 ≈ 1e-3; · = 0 (unobservable, or below the rank "
        f"tolerance {s['rank_rtol']:g}·σ_max). rank, TOM: the segment's SOM and TOM ranks; "
        "cum.: the SOM rank from the start; 'whole run'/'all': the cumulative degree at the "
        f"end.\nrank margin per segment (how far its rank is from the cut-off: the smaller "
        f"of σ_rank/cut and cut/σ_rank+1; a margin of a few moves with small changes of F "
        f"or of the units): {margins}; whole run {margin(last.get('rank_margin'))}.\n"
        "The values, eq. 12's null-space residual and the covariance degree σ(0)/σ(t) are in "
        f"--json and the results file. Compute {s['compute_s']:.2f} s; output "
        f"{s.get('output') or DASH}")
