"""The streamed results datasets (:class:`gcalign.io.results.Series`): rows appended in
pieces of any size arrive whole and in order, chunks are written once, and what is held
between appends stays under one chunk per dataset."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from gcalign.io.results import Series


@pytest.mark.parametrize("pieces", [[1] * 300, [655] * 9, [4096, 1, 4095, 5000], [0, 7, 0]])
def test_rows_arrive_whole_and_in_order(tmp_path, pieces):
    rng = np.random.default_rng(3)
    a = rng.standard_normal((sum(pieces), 3))
    with h5py.File(tmp_path / "s.h5", "w") as f:
        s = Series(f.create_group("g"), {"t": (None, "s", None), "a": (3, "rad", "ENU")},
                   chunk_rows=256)
        k = 0
        for n in pieces:
            s.append(t=np.arange(k, k + n, dtype=float), a=a[k:k + n])
            k += n
            held = max(sum(map(len, rows)) for rows in s._held.values())
            assert held < 256  # never more than a chunk held back
        s.flush()
    with h5py.File(tmp_path / "s.h5") as f:
        assert np.array_equal(f["g/a"][()], a)
        assert np.array_equal(f["g/t"][()], np.arange(len(a), dtype=float))
        assert f["g/a"].attrs["units"] == "rad" and f["g/a"].attrs["frame"] == "ENU"
        assert f["g/a"].chunks == (256, 3) and f["g/a"].compression == "gzip"


def test_unflushed_rows_are_not_in_the_file(tmp_path):
    """What flush() is for: the rows after the last whole chunk are written only then."""
    with h5py.File(tmp_path / "s.h5", "w") as f:
        s = Series(f.create_group("g"), {"t": (None, "s", None)}, chunk_rows=100)
        s.append(t=np.arange(250.0))
        assert f["g/t"].shape == (200,)
        s.flush()
        assert f["g/t"].shape == (250,)
