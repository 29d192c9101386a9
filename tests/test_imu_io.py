"""Tests of gcalign.io.imu_files: the real PSINS file, bad inputs, and the CSV round trip."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from gcalign.io.imu_files import (
    ImuFileError,
    read_csv_imu,
    read_imu_file,
    read_psins_imu,
    write_csv_imu,
)
from gcalign.nav import earth
from gcalign.sim.imu import ImuData
from gcalign.units import ARCSEC, DEG

PSINS_HEADER = """% a PSINS-format test file
% three header rows follow
1.0 -2.0 30.0 0.5 -0.25 0.0
34.0 108.0 380.0 5.0 10.0 9.780327
0.1 0.1 0.1 125 125 125
"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


# ------------------------------------------------------------------ real file


@pytest.fixture(scope="module", name="laser")
def _laser(lasergyro) -> ImuData:
    return read_psins_imu(lasergyro)


def test_lasergyro_header_and_size(laser, lasergyro):
    d = laser
    assert len(d) == 184_718
    assert d.dtheta.shape == d.dv.shape == (184_718, 3)
    assert d.ts == pytest.approx(0.01, abs=1e-15)
    np.testing.assert_allclose(d.site, [34.246048 * DEG, 108.909664 * DEG, 380.0], rtol=1e-15)
    np.testing.assert_allclose(d.att0, np.array([0.0, 0.0, -90.6]) * DEG, rtol=1e-15)
    np.testing.assert_array_equal(d.v0_n, [0.0, 0.0, 0.0])
    assert d.meta["g"] == 9.780327
    assert d.meta["gyro_scale_arcsec"] == [0.1, 0.1, 0.1]
    assert d.meta["accel_scale_ugs"] == [125.0, 125.0, 125.0]
    # t = t0 + ts * (1..N): end time of each increment.
    assert d.t[0] == pytest.approx(0.01, abs=1e-15)
    assert d.t[-1] == pytest.approx(1847.18, abs=1e-9)
    assert d.source == str(lasergyro)


def test_lasergyro_first_rows_conversion(laser):
    # First three rows of the file, by hand: "0 0 2 0 0 80", "0 0 7 0 0 80", "0 0 7 0 2 80".
    counts = np.array([[0, 0, 2, 0, 0, 80], [0, 0, 7, 0, 0, 80], [0, 0, 7, 0, 2, 80]], float)
    dtheta = counts[:, :3] * 0.1 * ARCSEC  # 0.1″ per count
    dv = counts[:, 3:] * 125e-6 * 9.780327  # 125 µg·s per count, g from header 2
    np.testing.assert_allclose(laser.dtheta[:3], dtheta, rtol=1e-15, atol=0)
    np.testing.assert_allclose(laser.dv[:3], dv, rtol=1e-15, atol=0)
    assert laser.dv[0, 2] == pytest.approx(0.09780327, rel=1e-15)  # 80 counts ≈ 1 g·10 ms


def test_lasergyro_physics(laser):
    d = laser
    lat, h = d.site[0], d.site[2]
    # Specific force at rest: |mean f| = local normal gravity (9.7955 m/s² here, not the
    # header's equatorial 9.780327, which is 0.15 % smaller).
    f = d.dv.mean(axis=0) / d.ts
    assert np.linalg.norm(f) == pytest.approx(earth.gravity(lat, h), rel=1e-3)
    # Gyro: the whole-file mean is the earth rate (disturbed base averages out).
    w = d.dtheta.mean(axis=0) / d.ts
    assert np.linalg.norm(w) == pytest.approx(earth.OMEGA_IE, rel=0.10)
    # Forward axis points about east (yaw -90.6°): body x (right) ≈ south, so the
    # horizontal earth rate ω cos L shows up negative on x; the vertical one on z.
    assert w[0] == pytest.approx(-earth.OMEGA_IE * np.cos(lat), rel=0.05)
    assert w[2] == pytest.approx(earth.OMEGA_IE * np.sin(lat), rel=0.05)


def test_lasergyro_is_fast(lasergyro):
    """No pathological slowness (the 1 s bound of the reader is benchmarks/bench_core.py's:
    on a loaded machine a wall-clock bound here would be flaky)."""
    start = time.perf_counter()
    read_imu_file(lasergyro)
    assert time.perf_counter() - start < 30.0


# ------------------------------------------------------------------ PSINS, small files


def test_psins_small_file_and_dispatch(tmp_path):
    p = write(tmp_path, "small.imu", PSINS_HEADER + "1 -2 3 0 0 80\n\n% a comment\n4 5 6 1 -1 79\n")
    d = read_imu_file(p)
    assert len(d) == 2
    assert d.ts == pytest.approx(0.01)
    np.testing.assert_allclose(d.t, [5.01, 5.02], rtol=1e-15)
    np.testing.assert_allclose(d.dtheta[1], np.array([4, 5, 6]) * 0.1 * ARCSEC, rtol=1e-15)
    np.testing.assert_allclose(d.dv[1], np.array([1, -1, 79]) * 125e-6 * 9.780327, rtol=1e-15)
    np.testing.assert_allclose(d.att0, np.array([1.0, -2.0, 30.0]) * DEG, rtol=1e-15)
    np.testing.assert_allclose(d.v0_n, [0.5, -0.25, 0.0])
    # Unknown extension: sniffed as PSINS from the leading % comment.
    q = write(tmp_path, "small.dat", p.read_text())
    np.testing.assert_array_equal(read_imu_file(q).dv, d.dv)


@pytest.mark.parametrize(
    "text, expected",
    [
        (PSINS_HEADER + "1 2 3 4 5\n", r"bad\.imu:6: expected 6 columns \(gyro x"),
        (PSINS_HEADER + "1 2 3 4 5 6\n1 2 x 4 5 6\n", r"bad\.imu:7: field 3 \(gyro z\).*'x'"),
        (PSINS_HEADER, r"bad\.imu: no data rows after line 5"),
        (PSINS_HEADER + "1 2 3 4 5 nan\n", r"bad\.imu:6: field 6 \(accel z\) must be finite"),
        ("% only a comment\n1 2 3 4 5 6\n", r"ends after 1 of 3 header rows"),
        (
            "% c\n0 0 0 0 0\n",
            r"bad\.imu:2: PSINS header row 1 \(initial state\) must have 6 numbers",
        ),
        (
            "0 0 0 0 0 0\n34 108 380 0 0 9.78\n0.1 0.1 0.1 125 125 125\n",
            r"sampling interval, ms\) must lie in \[0\.0001, 10000\], got 0\.0",
        ),
        (
            "0 0 0 0 0 0\n34 108 380 0 ten 9.78\n",
            r"bad\.imu:2: field 5 \(interval_ms\) must be a number, got 'ten'",
        ),
    ],
)
def test_psins_bad_inputs(tmp_path, text, expected):
    p = write(tmp_path, "bad.imu", text)
    with pytest.raises(ImuFileError, match=expected) as info:
        read_psins_imu(p)
    assert "\n" not in str(info.value)
    assert isinstance(info.value, ValueError)


def test_missing_file_and_hdf5(tmp_path):
    with pytest.raises(ImuFileError, match=r"nope\.imu: file not found"):
        read_imu_file(tmp_path / "nope.imu")
    with pytest.raises(ImuFileError, match=r"nope\.csv: file not found"):
        read_csv_imu(tmp_path / "nope.csv")
    with pytest.raises(ImuFileError, match="is a directory"):
        read_csv_imu(tmp_path)
    with pytest.raises(ImuFileError, match=r"run\.h5: HDF5 IMU files .* results module"):
        read_imu_file(tmp_path / "run.h5")
    blob = tmp_path / "blob.bin"
    blob.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(64))
    with pytest.raises(ImuFileError, match="is an HDF5 file"):
        read_imu_file(blob)


# ------------------------------------------------------------------ CSV


def random_imu(rng: np.random.Generator, n: int = 50, ts: float = 0.01) -> ImuData:
    t = 12.5 + ts * np.arange(1, n + 1)
    return ImuData(
        t=t,
        dtheta=rng.normal(0.0, 1e-4, (n, 3)),
        dv=rng.normal(0.0, 1e-2, (n, 3)) + [0.0, 0.0, 0.098],
        ts=ts,
    )


def test_csv_round_trip_bit_exact(tmp_path):
    imu = random_imu(np.random.default_rng(7))
    p = tmp_path / "imu.csv"
    write_csv_imu(p, imu)
    back = read_imu_file(p)
    np.testing.assert_array_equal(back.t, imu.t)
    np.testing.assert_array_equal(back.dtheta, imu.dtheta)
    np.testing.assert_array_equal(back.dv, imu.dv)
    assert back.ts == pytest.approx(imu.ts, rel=1e-12)
    assert back.meta["columns"] == ["t", "dtheta_x", "dtheta_y", "dtheta_z", "dv_x", "dv_y", "dv_z"]
    assert back.site is None and back.att0 is None


def test_csv_whitespace_comments_no_header(tmp_path):
    imu = random_imu(np.random.default_rng(8), n=5)
    rows = "\n".join(
        " ".join(f"{x:.17g}" for x in r) + "  # row"
        for r in np.column_stack([imu.t, imu.dtheta, imu.dv])
    )
    p = write(tmp_path, "imu.txt", "# whitespace file\n\n" + rows + "\n")
    back = read_imu_file(p)
    np.testing.assert_array_equal(back.dv, imu.dv)
    assert back.meta["columns"] is None and back.meta["delimiter"] == "whitespace"
    assert read_csv_imu(p, ts=imu.ts).ts == imu.ts
    with pytest.raises(ImuFileError, match=r"imu\.txt:4: time jumps .* interval is 0\.02"):
        read_csv_imu(p, ts=0.02)  # an interval the time stamps contradict


@pytest.mark.parametrize(
    "text, kwargs, expected",
    [
        ("t,a,b,c,d,e,f\n0.01,1,2,3,4,5\n", {}, r"x\.csv:2: expected 7 columns \(t, dtheta_x"),
        ("0.01,1,2,3,4,5,6\n0.02,1,2,3,4,five,6\n", {}, r"x\.csv:2: field 6 \(dv_y\).*'five'"),
        ("# nothing\n\n", {}, r"x\.csv: no data rows"),
        ("t,a,b,c,d,e,f\n", {}, r"x\.csv: no data rows after line 1"),
        (
            "0.01,0,0,0,0,0,0\n0.03,0,0,0,0,0,0\n0.02,0,0,0,0,0,0\n",
            {},
            r"x\.csv:3: time must increase strictly, got t = 0\.02 after 0\.03",
        ),
        ("0.01,0,0,0,0,0,0\n0.01,0,0,0,0,0,0\n", {}, r"x\.csv:2: time must increase"),
        ("0.01,0,0,0,0,0,0\n0.02,0,0,0,0,0,0\n", {"ts": 0.0}, r"ts must be > 0 s, got 0\.0"),
        ("0.01,0,0,0,0,0,0\n0.02,0,0,0,0,0,0\n", {"ts": -1}, r"ts must be > 0 s, got -1\.0"),
        ("0.01,0,0,0,0,0,0\n", {}, r"one sample only, cannot infer ts"),
        ("0.01,0,0,inf,0,0,0\n", {"ts": 0.01}, r"x\.csv:1: field 4 \(dtheta_z\) must be finite"),
    ],
)
def test_csv_bad_inputs(tmp_path, text, kwargs, expected):
    p = write(tmp_path, "x.csv", text)
    with pytest.raises(ImuFileError, match=expected) as info:
        read_csv_imu(p, **kwargs)
    assert "\n" not in str(info.value)


def test_csv_with_a_gap_is_refused_naming_the_line(tmp_path):
    """Silent garbage in recorded data (robustness class 6): a gap in the time stamps is
    refused (the interval comes from the median step; the line after the gap is named)."""
    t = np.r_[0.01 * np.arange(1, 11), 0.5]  # one dropped stretch at the end
    data = np.column_stack([t, np.zeros((11, 6))])
    p = tmp_path / "gap.csv"
    np.savetxt(p, data, delimiter=",", fmt="%.17g")
    with pytest.raises(ImuFileError, match=r"gap\.csv:11: time jumps from 0\.1 to 0\.5 s"):
        read_csv_imu(p)
