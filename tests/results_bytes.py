"""Results files damaged byte by byte, read back by show, export and plot.

:mod:`damage_cases` damages datasets as HDF5 sees them (values, shapes, types); this is the
damage a disk or a transfer does underneath: 16 bytes inverted inside the first compressed
chunk of three compressed datasets (a block that no longer decompresses), and at
:data:`RANDOM_OFFSETS` seeded offsets anywhere in the file (object headers, B-trees, heaps,
raw data). One small real file of every kind (:func:`damage_cases.make_files`).

Outcomes of each read-back: ``ok`` (exit 0: the damage fell where nothing is read, or in
uncompressed numbers, which HDF5 stores without a checksum), ``refused`` (exit 2, one line
naming the file), and the broken ones: an internal error, a traceback, anything else.
``python tests/results_bytes.py [OFFSETS]`` prints the counts (docs/robustness.md).
"""

from __future__ import annotations

import random
import sys
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import damage_cases as D  # noqa: E402

RANDOM_OFFSETS = 5  #: seeded random offsets per file, beside the three compressed chunks
SEED = 1
COMMANDS = ("show", "export", "plot")


@dataclass(frozen=True)
class Case:
    kind: str
    offset: int
    where: str  # "chunk of /x/y" or "random"

    @property
    def id(self) -> str:
        return f"{self.kind}@{self.offset}"


def offsets(path: Path, kind: str, random_offsets: int | None = None) -> list[Case]:
    import h5py

    chunks: list[tuple[str, int]] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.compression and obj.id.get_num_chunks():
            info = obj.id.get_chunk_info(0)
            chunks.append((obj.name, info.byte_offset + info.size // 2))

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    rng = random.Random(f"{SEED}-{kind}")
    size = path.stat().st_size
    return ([Case(kind, off, f"chunk of {name}") for name, off in chunks[:3]]
            + [Case(kind, rng.randrange(0, size - 16), "random")
               for _ in range(RANDOM_OFFSETS if random_offsets is None else random_offsets)])


def damaged(src: Path, case: Case, dst: Path) -> Path:
    b = bytearray(src.read_bytes())
    b[case.offset:case.offset + 16] = bytes(x ^ 0xFF for x in b[case.offset:case.offset + 16])
    dst.write_bytes(bytes(b))
    return dst


def read_back(path: Path, command: str, folder: Path) -> tuple[str, str]:
    """``(outcome, last stderr line)`` of one read-back (module docstring)."""
    argv = {"show": ["show", path],
            "export": ["export", path, "--format", "csv", "-o", folder / "x.csv"],
            "plot": ["plot", path, "-o", folder / "figs"]}[command]
    res = D._cli(argv)
    lines = res.stderr.strip().splitlines()
    last = lines[-1] if lines else repr(res.exception)
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        return "traceback", repr(res.exception)[:200]
    if res.exit_code == 0:
        return "ok", ""
    if "internal error" in res.stderr:
        return "internal", last
    if res.exit_code == 2 and len(lines) == 1 and str(path) in lines[0]:
        return "refused", last
    return "other", last


def count(folder: Path, files: dict[str, Path], random_offsets: int | None = None
          ) -> tuple[Counter, list]:
    tally: Counter = Counter()
    broken = []
    for kind, src in files.items():
        for case in offsets(src, kind, random_offsets):
            dst = damaged(src, case, folder / f"d-{case.id}.h5")
            for command in COMMANDS:
                cls, line = read_back(dst, command, folder)
                tally[cls] += 1
                tally[(kind, cls)] += 1
                if cls not in ("ok", "refused"):
                    broken.append((case.id, case.where, command, cls, line))
            dst.unlink()
    return tally, broken


if __name__ == "__main__":
    import tempfile

    n_random = int(sys.argv[1]) if len(sys.argv) > 1 else RANDOM_OFFSETS
    with tempfile.TemporaryDirectory() as d:
        files = D.make_files(Path(d))
        tally, broken = count(Path(d), files, n_random)
    classes = ("ok", "refused", "internal", "traceback", "other")
    n = sum(tally[c] for c in classes)
    print(f"{len(files)} kinds, {n // len(COMMANDS)} damaged files (up to 3 compressed chunks "
          f"and {n_random} offsets each) × {len(COMMANDS)} read-backs: {n}")
    print("| kind | read-backs | " + " | ".join(classes) + " |")
    print("| --- | ---: | " + " | ".join("---:" for _ in classes) + " |")
    for kind in files:
        m = sum(tally[(kind, c)] for c in classes)
        print(f"| {kind} | {m} | " + " | ".join(str(tally[(kind, c)]) for c in classes) + " |")
    print(f"| all | {n} | " + " | ".join(str(tally[c]) for c in classes) + " |")
    print(f"broken: {len(broken)}")
    for b in broken:
        print("  ", *b)
