"""Results files damaged byte by byte, read back by show, export and plot.

:mod:`damage_cases` damages datasets as HDF5 sees them (values, shapes, types); this is the
damage a disk or a transfer does underneath: 16 bytes inverted inside the first compressed
chunk of three compressed datasets (a block that no longer decompresses), and at
:data:`RANDOM_OFFSETS` seeded offsets anywhere in the file (object headers, B-trees, heaps,
raw data). One small real file of every kind (:func:`damage_cases.make_files`).

Outcomes of each read-back: ``ok`` (exit 0: the damage fell where nothing is read, or in
uncompressed numbers, which HDF5 stores without a checksum), ``refused`` (exit 2, one line
naming the file), and the broken ones: an internal error, a traceback, anything else.
``python tests/results_bytes.py [OFFSETS] [--children]`` prints the counts
(docs/robustness.md); ``--children`` reads back in child processes with a time limit, so
that a version that hangs inside HDF5 is counted too (``hang``).
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


#: seconds a read-back may take in a child process (``--children``): longer is a hang
HANG_S = 60.0


def _child(argv: list) -> tuple[int, str, BaseException | None]:
    """The command line in a child process with :data:`HANG_S` (a version that hangs in
    HDF5 cannot be interrupted in-process): ``(exit code, stderr, None)``, -1 for a hang."""
    import subprocess

    code = ("import sys; from gcalign.cli import main; sys.argv = ['gcalign'] + sys.argv[1:]; "
            "main()")
    try:
        res = subprocess.run([sys.executable, "-c", code, *map(str, argv)],
                             capture_output=True, text=True, timeout=HANG_S)
    except subprocess.TimeoutExpired:
        return -1, "", None
    return res.returncode, res.stderr, None


CHILDREN = False  #: read back in child processes (``python tests/results_bytes.py --children``)


def read_back(path: Path, command: str, folder: Path) -> tuple[str, str]:
    """``(outcome, last stderr line)`` of one read-back (module docstring); ``hang`` when a
    child process (:data:`CHILDREN`) did not finish within :data:`HANG_S`."""
    argv = {"show": ["show", path],
            "export": ["export", path, "--format", "csv", "-o", folder / "x.csv"],
            "plot": ["plot", path, "-o", folder / "figs"]}[command]
    if CHILDREN:
        code, stderr, _ = _child(argv)
        if code == -1:
            return "hang", f"no answer within {HANG_S:g} s"
        lines = stderr.strip().splitlines()
        last = lines[-1] if lines else ""
        if code == 0:
            return "ok", ""
        if "Traceback" in stderr or code < 0:
            return "traceback", last
        if "internal error" in stderr:
            return "internal", last
        if code == 2 and len(lines) == 1 and str(path) in lines[0]:
            return "refused", last
        return "other", last
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
                if cls not in ("ok", "refused"):  # internal, traceback, hang, other
                    broken.append((case.id, case.where, command, cls, line))
            dst.unlink()
    return tally, broken


if __name__ == "__main__":
    import tempfile

    args = [a for a in sys.argv[1:] if a != "--children"]
    CHILDREN = "--children" in sys.argv
    n_random = int(args[0]) if args else RANDOM_OFFSETS
    with tempfile.TemporaryDirectory() as d:
        files = D.make_files(Path(d))
        tally, broken = count(Path(d), files, n_random)
    classes = ("ok", "refused", "internal", "traceback", "hang", "other")
    n = sum(tally[c] for c in classes)
    print(f"{len(files)} kinds, {n // len(COMMANDS)} damaged files (up to 3 compressed chunks "
          f"and {n_random} offsets each) × {len(COMMANDS)} read-backs: {n}")
    from reader_damage import print_counts

    print_counts(tally, broken, "kind", "read-backs", list(files), classes)
