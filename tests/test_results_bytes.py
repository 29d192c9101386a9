"""Results files damaged byte by byte (tests/results_bytes.py): show, export and plot of a
file whose compressed block no longer decompresses, or whose HDF5 structure is damaged,
are one line naming the file (they were "internal error")."""

from __future__ import annotations

import pytest
import results_bytes as RB


@pytest.mark.parametrize("command", RB.COMMANDS)
def test_a_corrupted_compressed_block_is_refused_naming_the_dataset(results_of_every_kind,
                                                                   tmp_path, command):
    src = results_of_every_kind["navigate"]
    case = RB.offsets(src, "navigate")[0]
    assert case.where.startswith("chunk of ")
    bad = RB.damaged(src, case, tmp_path / "bad.h5")
    cls, line = RB.read_back(bad, command, tmp_path)
    assert cls == "refused", (cls, line)
    assert f"dataset {case.where.removeprefix('chunk of ')} cannot be read: its stored data " \
        "is damaged" in line, line


@pytest.mark.slow  # ten kinds × eight damages × three read-backs, about a minute
def test_every_byte_damage_of_every_kind_is_refused_or_harmless(results_of_every_kind,
                                                                 tmp_path):
    tally, broken = RB.count(tmp_path, results_of_every_kind)
    assert broken == [], broken
    assert tally["refused"] > 0


def _endless_heap(path):
    """A results-like file whose first global-heap object claims a length of about 2^64:
    HDF5 loops forever reading the text attribute stored there."""
    import struct

    import h5py
    import numpy as np

    with h5py.File(path, "w") as f:
        f.attrs["gcalign_version"] = "0"
        for i in range(3):
            f.create_dataset(f"d{i}", data=np.arange(3.0)).attrs["units"] = np.array(
                "m", dtype=h5py.string_dtype())
    b = bytearray(path.read_bytes())
    obj = b.find(b"GCOL") + 16  # the collection's header, then its first object
    assert struct.unpack("<HHIQ", bytes(b[obj:obj + 16]))[3] == 1  # object 1: "m"
    b[obj + 8:obj + 16] = bytes(x ^ 0xFF for x in b[obj + 8:obj + 16])
    path.write_bytes(bytes(b))
    return path


@pytest.mark.parametrize("command", ["show", "export", "plot"])
def test_a_heap_that_sends_hdf5_into_an_endless_loop_is_refused_in_seconds(
        tmp_path, monkeypatch, command):
    """Seen in the byte damage of a north-finding file: show, export and plot hung."""
    import time

    from gcalign.io import results

    monkeypatch.setattr(results, "PROBE_S", 1.0)
    bad = _endless_heap(tmp_path / "heap.h5")
    t0 = time.perf_counter()
    cls, line = RB.read_back(bad, command, tmp_path)
    assert cls == "refused", (cls, line)
    assert "a damaged HDF5 file: HDF5 did not get through its metadata in 1 s" in line, line
    assert time.perf_counter() - t0 < 5.0
