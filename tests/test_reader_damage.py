"""Damaged recorded-data files, read by every reader (tests/reader_damage.py): a corrupt
``.xz``, gzip data named ``.xz``, a MAT file with a zeroed block, text named ``.mat`` and
the rest of its damages are one line naming the file (exit 2), never an internal error."""

from __future__ import annotations

import lzma

import pytest
import reader_damage as R
from typer.testing import CliRunner

from gcalign.cli import app

CASES = R.cases()
#: one file per reader in the fast suite (a compressed one where the reader takes them);
#: the other layouts of read_recording (plain, .gz, CSV, uncompressed MAT) are slow
FAST = ("rec.imu.xz", "mimu.mat", "rec.i2nav.txt", "gnss.txt", "sol.pos", "vel.csv",
        "odo.csv", "avp.mat", "ref.nav", "ref.csv")


@pytest.mark.parametrize("case", [
    c if c.source.name in FAST else pytest.param(c, marks=pytest.mark.slow)
    for c in CASES], ids=lambda c: c.id)
def test_a_damaged_file_is_refused_naming_it_or_read_as_data(case, tmp_path):
    cls, message = R.outcome(case, tmp_path)
    assert not R.broken(case, cls), (cls, message)


def test_the_reader_fuzz_counts_every_file_damage_and_reader():
    assert len(R.sources()) == 15 and len(R.DAMAGES) == 14
    assert len({c.reader for c in CASES}) == 10 and len(CASES) == 155


@pytest.mark.parametrize("name, content, args, words", [
    ("c.imu.xz", b"corrupt", [], ("not .xz data",)),
    ("g.imu.xz", "gzip", [], ("holds gzip (.gz) data, not .xz: rename it g.imu.gz",)),
    ("z.imu.xz", "zeroed", [], ("damaged .xz data, cannot decompress",)),
    ("t.mat", b"hello\n1 2 3\n", ["--format", "psins-mat"], ("text, not a MATLAB file",)),
    ("m.mat", "zeroed mat", ["--format", "psins-mat"],
     ("not a MATLAB file that scipy.io.loadmat reads",)),
])
def test_the_damaged_inputs_of_the_hostile_round_are_exit_2_naming_the_file(
        tmp_path, lasergyro, name, content, args, words):
    """The four reproductions: a corrupt .xz (LZMAError), gzip named .xz, a MAT file with a
    zeroed block, text named .mat were "internal error", exit 1."""
    import gzip
    import io

    import numpy as np
    import scipy.io

    raw = lasergyro.read_bytes()[:200_000]
    if content == "gzip":
        content = gzip.compress(raw)
    elif content == "zeroed":
        b = bytearray(lzma.compress(raw))
        b[len(b) // 2:len(b) // 2 + 4096] = bytes(4096)
        content = bytes(b)
    elif content == "zeroed mat":
        buf = io.BytesIO()
        scipy.io.savemat(buf, {"mimu": np.random.default_rng(1).normal(size=(2000, 7))},
                         do_compression=True)
        b = bytearray(buf.getvalue())
        b[len(b) // 2:len(b) // 2 + 4096] = bytes(4096)
        content = bytes(b)
    p = tmp_path / name
    p.write_bytes(content)
    res = CliRunner().invoke(app, ["align", "--imu-file", str(p), *args, "-o",
                                   str(tmp_path / "o.h5")])
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and str(p) in lines[0], res.stderr
    for w in words:
        assert w in lines[0], lines[0]
    assert not (tmp_path / "o.h5").exists()
