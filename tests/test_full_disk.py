"""A full disk under every writer: each command of the registry, a transfer alignment, every
export format and plot, stopped by ``ulimit -f`` at several sizes of what it writes.

The contract (docs/robustness.md): exit 1, one line ``error: cannot write NAME: File too
large``, nothing under the output name and no temporary file (a batch keeps its journal, for
``--resume``), never a crash. HDF5 meets
the refused write wherever the file is at that moment (raw data, metadata, a global heap of
strings that it reads back), so the sizes are fractions of each writer's own file: before
its first byte, a third, two thirds, and its last byte.

The limit is the soft RLIMIT_FSIZE of this test process, set for the one command and
restored (Python ignores SIGXFSZ: a refused write is EFBIG), so every writer of the
registry runs in a second instead of a new interpreter each. A writer added to the registry
is covered by :data:`WRITERS` or fails :func:`test_every_registered_command_has_a_full_disk_case`.
"""

from __future__ import annotations

import resource
import shutil
from pathlib import Path

import damage_cases as D
import fuzz_cases as F
import pytest

from gcalign.app.registry import COMMANDS
from gcalign.io import results

#: how each writer is run on its small scenario (damage_cases.make_files), the output last
WRITERS: dict[str, list[str]] = {
    "simulate": ["simulate", "FL.yaml"], "navigate": ["navigate", "FL.yaml"],
    "align": ["align", "S.yaml"], "transfer": ["align", "TR.yaml"],
    "northfind": ["northfind", "NF.yaml"], "calibrate": ["calibrate", "CAL.yaml"],
    "observability": ["observability", "CAL.yaml"], "realtime": ["realtime", "RT.yaml"],
    "modulate": ["modulate", "MO.yaml"], "batch": ["batch", "SW.yaml", "-w", "1"],
    "allan": ["allan", "S.yaml"],
    **{f"export-{fmt}": ["export", "nav.h5", "--format", fmt]
       for fmt in ("csv", "mat", "i2nav-nav", "psins-avp")},
    "plot": ["plot", "nav.h5"],
}
FRACTIONS = (0.0, 1 / 3, 2 / 3, 1.0)  #: of the writer's size; 1.0: all but its last byte


def test_every_registered_command_has_a_full_disk_case():
    assert set(COMMANDS) <= set(WRITERS), set(COMMANDS) - set(WRITERS)


def _size(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*")) if path.is_dir() else \
        path.stat().st_size


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The scenarios, and the navigation file that export and plot read."""
    d = tmp_path_factory.mktemp("disk")
    for name, data in (("S", F.S), ("FL", F.FLIGHT), ("NF", F.NORTHFIND),
                       ("CAL", F.CALIBRATE), ("RT", F.REALTIME), ("MO", F.MODULATE)):
        (d / f"{name}.yaml").write_text(F.emit(data))
    (d / "SW.yaml").write_text(F.emit(F.SWEEP))
    D._transfer_scenario(d)
    res = D._cli(["navigate", d / "FL.yaml", "-o", d / "nav.h5"])
    assert res.exit_code == 0, res.stderr
    return d


def _run(folder: Path, argv: list[str], out: Path, limit: int | None):
    import os

    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    here = os.getcwd()
    os.chdir(folder)
    try:
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
        return D._cli([*argv, "-o", out])
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
        os.chdir(here)


def _runs(path: Path) -> int:
    """The number of runs in a batch's results file (opening it checks that it is whole)."""
    import h5py

    with h5py.File(path, "r") as f:
        return len(f["batch/runs/seed"])


#: writers whose five runs take over a second (the figures, the MAT file, a worker pool)
SLOW = ("plot", "transfer", "batch")


@pytest.mark.parametrize("writer", [pytest.param(w, marks=pytest.mark.slow) if w in SLOW
                                    else w for w in WRITERS])
def test_a_full_disk_under_every_writer_is_one_line_and_leaves_nothing(folder, writer,
                                                                         tmp_path):
    argv = WRITERS[writer]
    whole = tmp_path / "whole" / ("out" if writer == "plot" else "out.h5")
    res = _run(folder, argv, whole, None)
    assert res.exit_code == 0, res.stderr
    size = max(p.stat().st_size for p in whole.rglob("*")) if whole.is_dir() else _size(whole)
    for fraction in FRACTIONS:
        limit = max(0, min(int(fraction * size), size - 1))
        out_dir = tmp_path / f"at{limit}"
        out = out_dir / ("out" if writer == "plot" else "out.h5")
        res = _run(folder, argv, out, limit)
        what = f"{writer} under ulimit -f {limit} B of {size}"
        if res.exit_code == 0 and limit == size - 1 and out.is_file():
            # its last byte: the same run's file is not the same size every time (realtime's
            # came out 64 bytes smaller with 3 more bytes of text: HDF5 lays out its metadata
            # as the writes come) and this one fitted; then it is whole and within the limit
            assert _size(out) <= limit and D._cli(["show", out]).exit_code == 0, what
            shutil.rmtree(out_dir, ignore_errors=True)
            continue
        assert res.exit_code == 1, (what, res.exit_code, res.stderr, res.exception)
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in res.stderr, (what, res.stderr)
        assert lines[0].startswith("error: cannot write ") and "File too large" in lines[0], \
            (what, lines)
        left = [p.name for p in out_dir.rglob("*") if p.is_file()
                or p.name.endswith(results.TMP_SUFFIX)] if out_dir.exists() else []
        if writer == "batch" and "out.h5" in left:
            # a loaded machine took longer than REBUILD_EVERY_S: the rebuild of the runs
            # journaled by then fitted, the last one did not; that file stays whole
            assert _runs(out) < _runs(whole), what
            left.remove("out.h5")
        # a batch keeps the journal of the runs it finished, for --resume (docs/batch.md)
        assert left in ([], ["out.h5.journal.jsonl"] if writer == "batch" else []), \
            (what, left)
        assert not [p for p in folder.rglob("*") if p.name.endswith(results.TMP_SUFFIX)], what
        shutil.rmtree(out_dir, ignore_errors=True)


def test_a_refused_write_leaves_hdf5_a_file_it_can_read_back(tmp_path):
    """What crashed ``observability`` under ``ulimit -f 256``: HDF5 wrote a block, the
    write was refused, then HDF5 read the block back and got nothing (a segmentation
    fault). The guard gives back what HDF5 wrote, past the refusal too, and the run ends
    with the write error."""
    fd = (tmp_path / "g").open("w+b")
    guard = results._GuardedFile(fd.fileno())
    guard.write(b"a" * 10)
    guard.error = OSError(27, "File too large")  # as a refused write records it
    guard._size = 10
    guard.seek(5)
    guard.write(b"b" * 200_000)  # held in memory: the disk refused
    guard.seek(0)
    buf = bytearray(200_010)
    assert guard.readinto(buf) == 200_010
    assert bytes(buf) == b"a" * 5 + b"b" * 200_000 + bytes(5)
    assert guard.seek(0, 2) == 200_005
    guard.truncate(7)
    assert guard.seek(0, 2) == 7 and guard.seek(0) == 0 and guard.read(9) == b"aaaaabb\0\0"


def test_a_refused_write_ends_write_fields_before_its_groups_and_attributes(tmp_path):
    """The generic writer asks, like every writer of the results module, whether the file
    system refused a write before it makes a group or writes an attribute, not only before
    a dataset: a full disk ends the run there, in one line, with nothing kept."""
    from dataclasses import dataclass, field

    from gcalign.errors import GcalignError
    from gcalign.io.stored import write_fields
    from gcalign.schema import stored

    @dataclass
    class Settings:
        rate_hz: float = field(metadata=stored("Hz", attr=True))

    @dataclass
    class Run:
        settings: Settings = field(metadata=stored(None))

    seen: dict[str, object] = {}  # (atomic_h5 turns whatever ends it into the write error)
    with pytest.raises(GcalignError, match=r"cannot write .*r\.h5: File too large"):
        with results.atomic_h5(tmp_path / "r.h5") as f:
            results._WRITING[-1][1].error = OSError(27, "File too large")  # as refused
            try:
                write_fields(f, Run(Settings(100.0)))
            except GcalignError as err:
                seen.update(error=str(err), groups=list(f))
    assert "File too large" in str(seen.get("error")) and seen["groups"] == [], seen
    assert list(tmp_path.iterdir()) == []
