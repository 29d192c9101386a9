"""Every capability on arrays: the library route gives the command line's numbers bit for bit,
and the physics of the seeds through the library route alone (specs 001-004).

Each bit-identity test runs a small scenario through ``gcalign.run`` (the command line's
route: scenario, checks, adapter, summary, results file) and the same numbers, written out
in SI as a user with arrays would, through the core function; the summary's numbers are
the core's arrays through the summary's own unit conversion, so equality is exact.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import gcalign
from gcalign import units as u
from gcalign.nav import earth
from gcalign.northfind import (
    NorthfindSetup,
    estimate_northfind,
    position_angles,
    run_northfind,
    simulate_table,
)

# ------------------------------------------------------------------------ north-finding


def test_northfind_array_route_gives_the_cli_numbers_bit_for_bit():
    sc = gcalign.example("northfind", {"northfind.sweep": None, "northfind.azimuth_deg": 48.0,
                                       "northfind.positions": 8, "northfind.dwell_s": 5.0,
                                       "northfind.repeats": 3})
    res = gcalign.run("northfind", sc, seed=7)
    # the scenario's numbers in SI, as a user with plain arrays writes them
    setup = NorthfindSetup(
        azimuths=np.array([48.0]) * u.DEG, lat=40.0 * u.DEG, positions=8, dwell_s=5.0,
        rate_hz=100.0, tilt=10.0 * u.DEG, tilt_direction=0.0, tilt_direction_ref="table",
        repeats=3, gyro_bias=0.02 * u.DPH, gyro_arw=0.002582 * u.DPSH,
        accel_bias=np.array([20.0, 20.0]) * u.UG, accel_vrw=154.9 * u.UGPSHZ)
    rng = np.random.default_rng(7)
    data = simulate_table(setup, rng)
    est = estimate_northfind(data.gyro, data.accel, data.theta, setup.lat, data.gravity,
                             azimuth_true=setup.azimuths[:, None])
    assert est.azimuth_error is not None
    for i, name in enumerate(est.methods):
        m = res["methods"][name]
        assert m["estimates_deg"] == np.mod(np.degrees(est.azimuth[i].T), 360.0).ravel().tolist()
        assert m["errors_deg"] == np.degrees(est.azimuth_error[i].T).ravel().tolist()
    assert res["tilt_est_deg"] == np.degrees(est.tilt.T).ravel().tolist()
    # the whole-run function on the same setup and seed: the same arrays
    full = run_northfind(setup, np.random.default_rng(7))
    assert np.array_equal(full.azimuth_est, est.azimuth)
    assert np.array_equal(full.azimuth_error, est.azimuth_error)


def test_northfind_level_table_azimuth_is_exact_on_noise_free_means():
    """Seed 001 eqs. 4, 8: on a level table the gyro at table angle θ reads the earth rate
    along the turned reference axis, ω(θ) = Ω cos L cos(θ - ψ) (a = Ω cos L cos ψ,
    b = Ω cos L sin ψ), the accelerometers read nothing; ψ = atan2(b, a) by every method."""
    lat, theta = 40.0 * u.DEG, position_angles(6)
    psi = np.radians([0.0, 30.0, 135.0, 200.0, 359.0])
    gyro = earth.OMEGA_IE * np.cos(lat) * np.cos(theta[None, :] - psi[:, None])  # (5, 6)
    est = estimate_northfind(gyro, np.zeros((5, 6, 2)), theta, lat, 9.8, azimuth_true=psi)
    assert est.azimuth_error is not None and est.azimuth_error.shape == (4, 5)
    assert np.abs(est.azimuth_error).max() < 1e-12
    assert np.abs(est.tilt).max() == 0.0


@pytest.mark.parametrize(
    ("change", "text"),
    [
        (dict(gyro=np.zeros((2, 5))), "gyro must have shape (..., 6)"),
        (dict(accel=np.zeros((2, 6))), "accel must have shape (2, 6, 2)"),
        (dict(theta=np.zeros(2)), "theta must have shape (n,) with n >= 3"),
        (dict(gyro=np.full((2, 6), np.nan)), "gyro must be finite"),
        (dict(lat=np.pi / 2), "lat must satisfy |lat| < pi/2"),
        (dict(g=0.0), "g must be a finite gravity > 0"),
        (dict(azimuth_true=np.zeros(3)), "azimuth_true must broadcast to the leading shape"),
        (dict(methods=["magic"]), "methods must be drawn from"),
    ],
)
def test_northfind_array_inputs_are_checked_by_name(change, text):
    args = dict(gyro=np.zeros((2, 6)), accel=np.zeros((2, 6, 2)), theta=position_angles(6),
                lat=0.7, g=9.8)
    args |= change
    with pytest.raises(ValueError) as err:
        estimate_northfind(**args)
    assert text in str(err.value)


@pytest.mark.parametrize("args", [["--positions", "1"], ["--dwell", "0"]])
def test_northfind_bad_setting_exits_2_with_one_line(args):
    res = subprocess.run([sys.executable, "-m", "gcalign", "northfind", *args, "--json"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 2, res.stderr
    lines = [ln for ln in (res.stdout + res.stderr).splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in lines[0], lines
