"""Input files are bounded before they are read: a 2 GB sparse CSV, ``.imu`` or GNSS file,
or a small ``.xz`` that decompresses to gigabytes, is refused in seconds naming the limit
(``GCALIGN_MAX_INPUT_MB``; a NUL byte where text is expected at the block that holds it),
never read whole ("out of memory" under a 4 GB limit) nor parsed for minutes."""

from __future__ import annotations

import lzma
import time

import pytest
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.errors import ScenarioError
from gcalign.io.recorded import read_gnss, read_recording

runner = CliRunner()
GB2 = 2 << 30


def _sparse(path, size=GB2):
    with open(path, "wb") as f:
        f.truncate(size)  # a hole: no disk used, 2 GB of NUL when read
    return path


def _bomb(path, unit: bytes, copies: int):
    """An .xz of `copies` concatenated streams, each `unit` compressed: a file of a few
    hundred kB that decompresses to copies × len(unit) bytes."""
    stream = lzma.compress(unit, preset=0)
    path.write_bytes(stream * copies)
    return path


def _refused(args, tmp_path, *words, bound_s=10.0):
    t0 = time.perf_counter()
    res = runner.invoke(app, [*args, "-o", str(tmp_path / "o.h5")])
    took = time.perf_counter() - t0
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    for w in words:
        assert w in lines[0], lines[0]
    assert took < bound_s, took
    assert not (tmp_path / "o.h5").exists()
    return lines[0]


@pytest.mark.parametrize("name", ["big.csv", "big.imu"])
def test_a_2_gb_sparse_recording_is_refused_from_its_size(tmp_path, name):
    p = _sparse(tmp_path / name)
    _refused(["align", "--imu-file", str(p)], tmp_path, str(p),
             "needs 2048 MB of input data, more than the limit 1024 MB", "GCALIGN_MAX_INPUT_MB",
             bound_s=5.0)


def test_a_2_gb_sparse_gnss_file_is_refused_from_its_size(tmp_path):
    p = _sparse(tmp_path / "gnss.txt")
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError, match="GCALIGN_MAX_INPUT_MB"):
        read_gnss(p)
    assert time.perf_counter() - t0 < 5.0  # from its size, before reading any of its 2 GB


def test_nul_bytes_where_text_is_expected_stop_at_the_first_block(tmp_path):
    """2 GB of compressed NUL bytes named .csv.xz: refused at the first 16 MB block."""
    p = _bomb(tmp_path / "zeros.csv.xz", bytes(64 << 20), 32)
    assert p.stat().st_size < 400_000
    _refused(["align", "--imu-file", str(p)], tmp_path, str(p), "binary data",
             "NUL byte at offset 0", bound_s=10.0)


def test_a_decompression_past_the_limit_is_refused_naming_it(tmp_path, monkeypatch):
    """Text rows of zeros, 2 GB decompressed from 1 MB: decompression stops at the limit
    (here 32 MB, so that the test is quick; the default 1024 MB takes about 7 s)."""
    monkeypatch.setenv("GCALIGN_MAX_INPUT_MB", "32")
    p = _bomb(tmp_path / "rows.csv.xz", b"0,0,0,0,0,0,0\n" * (4 << 20), 36)
    line = _refused(["align", "--imu-file", str(p)], tmp_path, f"{p} (decompressed, at "
                    "least)", "GCALIGN_MAX_INPUT_MB", bound_s=10.0)
    assert "more than the limit 32 MB" in line


@pytest.mark.slow  # about 7 s: 1 GB decompressed under the default limit
def test_a_2_gb_xz_of_zero_rows_is_refused_in_seconds_under_the_default_limit(tmp_path):
    p = _bomb(tmp_path / "rows.csv.xz", b"0,0,0,0,0,0,0\n" * (4 << 20), 36)
    _refused(["align", "--imu-file", str(p)], tmp_path, "GCALIGN_MAX_INPUT_MB",
             "more than the limit 1024 MB", bound_s=30.0)


def test_parsing_text_is_held_against_the_memory_limit(tmp_path, monkeypatch):
    rows = "".join(f"{0.01 * k:.2f},0,0,0,0,0,0.0981\n" for k in range(1, 200_001))
    p = tmp_path / "r.csv"
    p.write_text(rows)
    monkeypatch.setenv("GCALIGN_MAX_MEMORY_MB", "5")
    with pytest.raises(ScenarioError, match=r"parsing .* MB of text: needs .* "
                       "GCALIGN_MAX_MEMORY_MB"):
        read_recording(p)


def test_a_recording_under_the_limits_is_read_as_before(lasergyro):
    imu = read_recording(lasergyro)
    assert len(imu.t) == 184_718
