"""Regenerate docs/results.md: the seeds' numbers beside ours.

Run from the repository root:  python docs/make_results.py [--workers 2] [--resume] [--all]

The document is the section files below, in this order; a missing file is skipped. The
seed-000 section is written first from its sweeps (configs/sweeps/, run by the batch engine
with a local pool into runs/); with --all the real-time and modulation sections are
rewritten by their generators too (docs/results_realtime.py, docs/results_modulate.py:
several minutes more, the 72 h runs); the others are kept as written (the calibration
tables come from docs/make_results_calibrate.py). Adding a capability's results is one line
in SECTIONS (and, if generated, one in GENERATORS or SLOW_GENERATORS).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent

SECTIONS = (
    "results_intro.md",
    "results_seed000.md",
    "results_northfind.md",
    "results_calibrate.md",
    "results_realtime.md",
    "results_modulate.md",
    "results_transfer.md",
    "results_recorded.md",
)


def _seed000(args) -> str:
    import seed000_results

    return seed000_results.section(args.workers, ROOT / "runs", args.resume)


def _realtime(args) -> str:
    import results_realtime

    return results_realtime.section(figure_dir=DOCS / "figures")


def _modulate(args) -> str:
    import results_modulate

    return results_modulate.section()


GENERATORS = {"results_seed000.md": _seed000}
SLOW_GENERATORS = {"results_realtime.md": _realtime, "results_modulate.md": _modulate}


def assemble() -> Path:
    """docs/results.md from the section files that exist, in SECTIONS order."""
    parts = [(DOCS / name).read_text().rstrip() for name in SECTIONS if (DOCS / name).is_file()]
    out = DOCS / "results.md"
    out.write_text("\n\n".join(parts) + "\n")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2, help="local worker processes")
    ap.add_argument("--resume", action="store_true",
                    help="reuse finished runs of earlier batches in runs/ (same scenarios)")
    ap.add_argument("--all", action="store_true",
                    help="also rewrite the real-time and modulation sections")
    ap.add_argument("--assemble-only", action="store_true",
                    help="only join the section files (no runs)")
    args = ap.parse_args()
    sys.path.insert(0, str(DOCS))
    if not args.assemble_only:
        generators = GENERATORS | (SLOW_GENERATORS if args.all else {})
        for name, generate in generators.items():
            t0 = time.perf_counter()
            (DOCS / name).write_text(generate(args).rstrip() + "\n")
            print(f"wrote {DOCS / name} ({time.perf_counter() - t0:.0f} s)")
    print(f"wrote {assemble()}")


if __name__ == "__main__":
    main()
