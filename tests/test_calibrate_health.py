"""The calibration filter's consistency checks (gcalign.calibrate.health): the band of a
mean NIS from the χ² distribution, a warning below and above it, and one for a σ that
grows without a measurement holding it; the real recording trips both."""

from __future__ import annotations

import copy
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from calibrate_cases import tiny_flight

import gcalign
from gcalign.calibrate.health import health_warnings, mean_nis_band

ROOT = Path(__file__).resolve().parents[1]
FLIGHT = tiny_flight(measure="both")


def test_band_of_one_epoch_is_the_chi2_band():
    """χ² of 2 dof is exponential: its quantile p is −2 ln(1 − p)."""
    lo, hi = mean_nis_band(1, 2)
    assert lo == pytest.approx(-2 * math.log(0.975), rel=1e-12)
    assert hi == pytest.approx(-2 * math.log(0.025), rel=1e-12)


def test_band_of_many_epochs_narrows_as_the_normal_limit():
    """Mean of K χ²_m: m ± 1.96 √(2m/K) for large K."""
    k, m = 100_000, 2
    lo, hi = mean_nis_band(k, m)
    half = 1.959964 * math.sqrt(2 * m / k)
    assert lo == pytest.approx(m - half, abs=1e-4) and hi == pytest.approx(m + half, abs=1e-4)


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    out = tmp_path_factory.mktemp("health") / "c.h5"
    return gcalign.run("calibrate", copy.deepcopy(FLIGHT), output=out)


def test_a_consistent_filter_says_nothing(flight):
    r = flight.value
    lo, hi = mean_nis_band(*r.standardized.shape)
    assert lo < r.nis.mean() < hi  # simulated with the filter's own noise model
    assert flight.warnings == ()  # position and velocity measured: no σ left to grow


def test_nis_below_and_above_its_band_warn(flight):
    r = flight.value
    (low,) = health_warnings(replace(r, nis=r.nis * 1e-3), "run: ")
    assert low.startswith("run: mean NIS") and " is below its 95 % band " in low
    m = r.standardized.shape[1]
    assert f"the innovations {math.sqrt(r.nis.mean() * 1e-3 / m):.2g}× the size" in low
    (high,) = health_warnings(replace(r, nis=r.nis * 10))
    assert " is above its 95 % band " in high and "too optimistic" in high


def test_a_sigma_growing_tenfold_warns(flight):
    r = flight.value
    sigma = r.sigma.copy()
    sigma[-1, 8] = 10.5 * sigma[0, 8]  # dh
    (line,) = health_warnings(replace(r, sigma=sigma))
    assert line.startswith("dh: σ grew from ") and "(10×)" in line
    sigma[-1, 8] = 9.9 * sigma[0, 8]
    assert health_warnings(replace(r, sigma=sigma)) == []


@pytest.mark.slow
def test_the_parked_recording_warns_of_both():
    """configs/lasergyro_calibrate.yaml: zero-velocity σ 0.2 m/s on a vehicle that sways
    by millimetres per second (NIS ~1e-4), and height, not measured, free to drift."""
    res = gcalign.run("calibrate", ROOT / "configs/lasergyro_calibrate.yaml")
    nis, dh = res.warnings
    assert "is below its 95 % band" in nis and res["nis"]["mean"] < 1e-3
    assert dh.startswith("dh: σ grew from 10 to ") and np.isfinite(res["states"]["dh"]["sigma"])
