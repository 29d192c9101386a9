"""`gcalign allan`: the Allan deviation against a second route (plain NumPy from the
definition), the fitted terms against closed forms, and the command's habits (every
recording layout, a simulate results file, the at-rest check, bad input)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from cli_checks import assert_bad_run
from typer.testing import CliRunner

from gcalign import units as u
from gcalign.allan import FLAT, allan_deviation, fit_terms
from gcalign.allan.curve import AllanCurve
from gcalign.cli import app
from gcalign.io.recorded import read_recording

runner = CliRunner()
DATA = Path(__file__).parent / "data"


def cli(*args):
    return runner.invoke(app, [str(a) for a in args])


def numpy_oadev(inc: np.ndarray, ts: float, m: int) -> float:
    """Overlapping Allan deviation from its definition (IEEE Std 952 C.2), no allantools:
    cluster means of the rate over every start k, half the mean squared difference of
    successive clusters. The mean rate is taken off first (σ does not depend on it): the
    running sum of the vertical accelerometer's g reaches 1.8e6 m/s over lasergyro's
    1847 s, and its round-off moved σ(100 s) = 8.5 µg by 7e-8."""
    rate = (inc - inc.mean()) / ts
    c = np.concatenate([[0.0], np.cumsum(rate)])
    means = (c[m:] - c[:-m]) / m  # mean of samples k .. k+m-1, every k
    d = means[m:] - means[:-m]
    return float(np.sqrt(0.5 * np.mean(d**2)))


@pytest.mark.slow
def test_lasergyro_against_plain_numpy(lasergyro):
    """σ at τ = 1, 10, 100 s of all six sensors of the real recording: allantools under
    gcalign and the definition in NumPy agree to 1e-9."""
    imu = read_recording(lasergyro)
    c_g = allan_deviation(imu.dtheta, imu.ts)
    c_a = allan_deviation(imu.dv, imu.ts)
    for tau in (1.0, 10.0, 100.0):
        m = int(round(tau / imu.ts))
        assert np.isclose(c_g.tau, tau).any()  # on the grid: no interpolation
        for j in range(3):
            ref_g = numpy_oadev(imu.dtheta[:, j], imu.ts, m)
            ref_a = numpy_oadev(imu.dv[:, j], imu.ts, m)
            assert c_g.at(tau)[j] == pytest.approx(ref_g, rel=1e-9)
            assert c_a.at(tau)[j] == pytest.approx(ref_a, rel=1e-9)
    # the clusters of the interval: K = ⌊N/m⌋
    k = c_g.clusters[np.isclose(c_g.tau, 100.0)][0]
    assert k == len(imu.t) // 10000


def test_numpy_route_can_fail():
    """The second route sees a one-sample shift of one cluster (it is not a copy)."""
    rng = np.random.default_rng(3)
    x = rng.normal(0, 1e-6, 5000)
    assert numpy_oadev(x, 0.01, 10) != pytest.approx(numpy_oadev(np.roll(x, 1) * 1.01, 0.01,
                                                                 10), rel=1e-6)


def _exact_curve(Q, N, B, K, ts=0.01, n=2_000_000) -> AllanCurve:
    """σ(τ) of the four terms, exactly (no noise), with the clusters of n samples."""
    from gcalign.allan import cluster_sizes

    m = cluster_sizes(n)
    tau = m * ts
    s = np.sqrt(3 * Q**2 / tau**2 + N**2 / tau + FLAT**2 * B**2 + K**2 * tau / 3)
    return AllanCurve(tau=tau, adev=s[:, None], clusters=n // m, samples=n, ts=ts)


def test_fit_reads_exact_curves():
    """On σ(τ) computed from the closed forms (IEEE Std 952 C.1) every term comes back to
    1e-6, each over the τ range where it is the largest, and the model lies on the curve."""
    # crossings at 0.05 s (Q, N), 5 s (N, B) and 300 s (B, K) of a 20000 s run
    Q, N, B, K = 1.92e-6, 1.485e-5, 1e-5, 6.64e-7
    curve = _exact_curve(Q, N, B, K)
    fit = fit_terms(curve)
    for name, true in (("quantization", Q), ("white", N), ("instability", B), ("rate_rw", K)):
        t = fit.terms[name]
        assert t.value[0] == pytest.approx(true, rel=1e-6), name
        a, b = t.tau_range[0]
        assert a <= b
        assert t.lo[0] < true < t.hi[0]
    ranges = [fit.terms[n].tau_range[0] for n in ("quantization", "white", "instability",
                                                  "rate_rw")]
    assert all(ranges[i][1] < ranges[i + 1][0] for i in range(3))  # in order of slope
    assert fit.misfit[0] < 1e-6


def test_fit_says_what_it_cannot_resolve():
    """White noise alone: the white term to its interval, the others not resolved, each
    with an upper bound the curve allows (no invented value)."""
    rng = np.random.default_rng(7)
    ts, N = 0.01, 2e-4
    curve = allan_deviation(rng.normal(0, N * math.sqrt(ts), (200_000, 1)), ts)
    fit = fit_terms(curve)
    w = fit.terms["white"]
    assert w.lo[0] <= N <= w.hi[0]
    assert (w.hi[0] - w.lo[0]) / 2 / N < 0.01
    for name in ("quantization", "instability", "rate_rw"):
        t = fit.terms[name]
        assert np.isnan(t.value[0]) and np.isfinite(t.bound[0]), name
    # the bound is real: a bias instability at the bound would show at the longest τ
    b = fit.terms["instability"].bound[0]
    assert FLAT * b <= curve.hi[-1, 0] * (1 + 1e-12)
    assert fit.misfit[0] < 3


@pytest.mark.slow
def test_cli_lasergyro(tmp_path, lasergyro):
    """The real recording (compressed, as it ships): exit 0, the JSON keys named as the
    scenario's imu keys, the curve in /allan with units, and the disturbance said."""
    out = tmp_path / "lg.h5"
    res = cli("allan", DATA / "lasergyro.imu.xz", "-o", out, "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert set(s["gyro"]) == {"quantum_arcsec", "arw_dprh", "bias_instability_dph",
                              "bias_rw_dphrh"}
    assert set(s["accel"]) == {"quantum_ugs", "vrw_ugrhz", "bias_instability_ug",
                               "bias_rw_ughrh"}
    imu = read_recording(lasergyro)
    ref = numpy_oadev(imu.dtheta[:, 2], imu.ts, 1000) / u.DPH
    assert s["adev_at"]["gyro_dph"][1][2] == pytest.approx(ref, rel=1e-9)
    assert any("do not describe the gyro curves" in w for w in s["warnings"])
    assert not s["at_rest"]["moving"]  # a parked vehicle, disturbed but not driving
    with h5py.File(out) as f:
        assert f["allan/gyro/adev"].attrs["units"] == "rad/s"
        assert f["allan/accel/terms/white/value"].shape == (3,)
    show = cli("show", out)
    assert show.exit_code == 0, show.output


def test_cli_moving_recording_is_said(tmp_path):
    """PSINS's MEMS vehicle (12 m/s): the recording is not at rest, and the command says so
    with the numbers, as align and calibrate do."""
    res = cli("allan", DATA / "transfer_align_fog_mems.mat", "--format", "psins-mat",
              "--lat", 34, "--lon", 108, "-o", tmp_path / "m.h5", "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert s["at_rest"]["moving"]
    line = next(w for w in s["warnings"] if "takes the IMU to be at rest" in w)
    assert "mg from their median" in line and "velocity change" in line


@pytest.mark.slow
def test_cli_simulate_file_and_scenario(tmp_path):
    """A `gcalign simulate` results file of a static IMU: the ARW and VRW it was given come
    back within their intervals; --scenario writes a scenario that validates as it is."""
    sc = {"name": "still", "site": {"lat_deg": 34.0, "lon_deg": 108.0},
          "motion": {"kind": "static", "duration_s": 600.0},
          "imu": {"rate_hz": 100.0, "seed": 3,
                  "gyro": {"arw_dprh": 0.05}, "accel": {"vrw_ugrhz": 50.0}}}
    path = tmp_path / "still.yaml"
    path.write_text(yaml.safe_dump(sc))
    sim = tmp_path / "sim.h5"
    assert cli("simulate", path, "-o", sim).exit_code == 0
    out_yaml = tmp_path / "noise.yaml"
    res = cli("allan", sim, "-o", tmp_path / "a.h5", "--json", "--scenario", out_yaml)
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    for triad, key, true in (("gyro", "arw_dprh", 0.05), ("accel", "vrw_ugrhz", 50.0)):
        t = s[triad][key]
        for j in range(3):
            lo, hi = t["interval"][j]
            assert lo <= true <= hi, (triad, j, t)
    assert not [w for w in s["warnings"] if "at rest" in w]
    written = yaml.safe_load(out_yaml.read_text())
    assert written["imu"]["gyro"]["arw_dprh"] == pytest.approx([0.05] * 3, rel=0.02)
    assert cli("validate", out_yaml).exit_code == 0


def test_cli_bad_window(tmp_path):
    assert_bad_run(cli, tmp_path, ["allan", DATA / "lasergyro.imu.xz", "--start", 5000],
                   "allan.start_s", "past the end")
    assert_bad_run(cli, tmp_path, ["allan", DATA / "lasergyro.imu.xz", "--duration", 0.03],
                   "allan", "samples")


def test_filter_model_from_the_fits():
    """Bias instability → one Gauss–Markov process whose Allan deviation peaks at the flat
    level, in the middle of the flicker's τ range; a rate random walk alone → a random
    walk of density K; nothing → a random constant; white noise → the filter's Q."""
    from gcalign.allan.processes import filter_model
    from gcalign.sim.errors import gm_allan_variance

    Q, N, B, K = 1.92e-6, 1.485e-5, 1e-5, 6.64e-7
    full = _exact_curve(Q, N, B, K)
    no_flicker = _exact_curve(Q, N, 0.0, 2e-6)
    three = AllanCurve(full.tau, np.hstack([full.adev, no_flicker.adev, full.adev * 0]),
                       full.clusters, full.samples, full.ts)
    fit = fit_terms(three)
    m = filter_model(fit, fit)
    assert m.kinds[:3] == ("gauss-markov", "random-walk", "constant")
    assert m.kinds[6:] == ("constant",) * 6
    lo, hi = fit.terms["instability"].tau_range[0]
    mid = math.sqrt(lo * hi)
    peak = math.sqrt(gm_allan_variance(np.array([mid]), m.std[0], m.tau[0])[0])
    assert peak == pytest.approx(FLAT * B, rel=1e-3)
    assert m.density[1] == pytest.approx(2e-6, rel=1e-6)
    assert m.arw == pytest.approx(N, rel=1e-6)
    from gcalign.estimation.ins_error import SensorProcesses

    p = SensorProcesses.of(m.kinds, np.nan_to_num(m.std), np.nan_to_num(m.tau, nan=1.0),
                           np.nan_to_num(m.density))
    assert p.beta[0] == pytest.approx(1 / m.tau[0]) and p.q[1] == pytest.approx(4e-12)


@pytest.mark.slow
def test_cli_scenario_on_stdout(tmp_path):
    """`--scenario -`: the scenario alone on stdout (the table on stderr), a static base at
    the recording's site and header attitude; with --json it is refused (one stdout)."""
    res = runner.invoke(app, ["allan", str(DATA / "lasergyro.imu.xz"), "-o",
                              str(tmp_path / "a.h5"), "--scenario", "-"])
    assert res.exit_code == 0, res.output
    sc = yaml.safe_load(res.stdout)
    assert sc["motion"]["attitude_deg"][2] == pytest.approx(-90.6, abs=0.01)
    assert sc["site"]["lat_deg"] == pytest.approx(34.246048)
    assert set(sc["imu"]) >= {"rate_hz", "gyro", "accel"}
    assert_bad_run(cli, tmp_path, ["allan", DATA / "lasergyro.imu.xz", "--json",
                                   "--scenario", "-"], "--scenario")
