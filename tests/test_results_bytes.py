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
