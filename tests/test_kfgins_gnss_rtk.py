"""KF-GINS's own GNSS solution, ``dataset/GNSS-RTK.txt`` of i2Nav-WHU/KF-GINS (a real
RTK solution of a vehicle near Wuhan; tests/data/README.md), read as position aiding by
``gcalign.io.recorded.aiding.read_gnss(..., "i2nav-gnss")``: every epoch and σ as the file
writes them (a plain parse of the same text is the second route), the σ north, east, down
turned into [east, north, up], and the file's own span and spacing."""

from __future__ import annotations

import hashlib
import lzma

import numpy as np
import pytest

from conftest import ROOT
from gcalign.io.recorded.aiding import read_gnss

GNSS_RTK_XZ = ROOT / "tests/data/GNSS-RTK.txt.xz"
SHA256 = "3c1ecf6d03121d695f59ea8383af5ec4233ef9ff1c33939b7c42caa609a94521"


@pytest.fixture(scope="module")
def rows() -> np.ndarray:
    text = lzma.decompress(GNSS_RTK_XZ.read_bytes())
    assert hashlib.sha256(text).hexdigest() == SHA256  # the file as KF-GINS publishes it
    return np.array([[float(x) for x in line.split()] for line in text.decode().splitlines()
                     if line.strip()])


def test_every_epoch_and_sigma_as_written(rows):
    fixes = read_gnss(GNSS_RTK_XZ, "i2nav-gnss")
    assert fixes.t.tolist() == rows[:, 0].tolist()
    np.testing.assert_array_equal(fixes.pos[:, 0], np.radians(rows[:, 1]))
    np.testing.assert_array_equal(fixes.pos[:, 1], np.radians(rows[:, 2]))
    np.testing.assert_array_equal(fixes.pos[:, 2], rows[:, 3])
    # σ north, east, down (the file) -> east, north, up (gcalign)
    np.testing.assert_array_equal(fixes.sigma_enu, rows[:, [5, 4, 6]])
    r = fixes.record
    assert r["epochs"] == 3413 and r["time_origin"] == "GNSS seconds of week"
    assert r["sigma_enu_median_m"] == [0.009, 0.01, 0.02]


def test_the_files_span_spacing_and_sigma_ranges(rows):
    """3413 fixes at 1 Hz from 456250 to 459662 s of week (57 min) with no gap; σ north
    0.009-0.031 m, east 0.007-0.025 m, down 0.015-0.080 m (RTK-fixed throughout); the
    vehicle within 1.3 km north-south, 1.1 km east-west, heights 18.7-35.4 m."""
    fixes = read_gnss(GNSS_RTK_XZ, "i2nav-gnss")
    assert (fixes.t[0], fixes.t[-1]) == (456250.0, 459662.0)
    assert np.all(np.diff(fixes.t) == 1.0)
    s_e, s_n, s_u = fixes.sigma_enu.T
    assert (s_n.min(), s_n.max()) == (0.009, 0.031)
    assert (s_e.min(), s_e.max()) == (0.007, 0.025)
    assert (s_u.min(), s_u.max()) == (0.015, 0.08)
    # the vertical is the weakest σ at all epochs but one
    assert np.count_nonzero(s_u < np.maximum(s_n, s_e)) == 1
    lat, lon, h = fixes.pos.T
    north = np.ptp(lat) * 6.3e6
    east = np.ptp(lon) * 6.4e6 * np.cos(lat.mean())
    assert 1.2e3 < north < 1.3e3 and 1.0e3 < east < 1.2e3
    assert (round(h.min(), 3), round(h.max(), 3)) == (18.657, 35.359)


def test_the_filter_takes_each_fixs_sigma_as_its_R(rows):
    """As calibrate's aiding (``files.position``), every epoch becomes a fix at its own
    time with R = diag(σN², σE², σD²) of its own row: the filter's noise of fix j is the
    file's row j (north, east, up), not one σ for all."""
    from gcalign.app.calibration_files import aiding_input
    from gcalign.calibrate.filter import Settings, _fix_noise
    from gcalign.io.scenario.calibrate import CalibrateConfig

    cfg = CalibrateConfig.model_validate({
        "aiding": "file", "measure": "position",
        "files": {"position": {"path": str(GNSS_RTK_XZ), "format": "i2nav-gnss"}}})
    t0 = float(rows[0, 0]) - 1.0
    t_run = np.arange(0.0, float(rows[-1, 0] - t0) + 1.0, 0.01)
    aid = aiding_input(cfg, t0, t_run)
    assert len(aid.fixes) == len(rows) and aid.info["sigma"] == "the file's, per fix"
    np.testing.assert_allclose(aid.fixes.t + t0, rows[:, 0], rtol=0, atol=1e-6)
    s = Settings(measure="position", components="3d", gnss_noise=False)
    R_fixed = np.eye(3)
    for j in (0, 1000, len(rows) - 1):
        R = _fix_noise(s, aid.fixes, j, R_fixed)
        np.testing.assert_array_equal(np.sqrt(np.diag(R)), rows[j, [4, 5, 6]])  # N, E, D
    assert aid.outages == () and aid.info["max_gap_s"] == 2.0
