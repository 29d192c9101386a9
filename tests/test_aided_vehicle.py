"""gcalign's aided navigation on the independent simulated vehicle of the KF-GINS benchmark
(``benchmarks/vehicle``, its 6 min drive: a stop, town turns, a 60 s GNSS outage across a
U-turn, a figure-eight; 200 Hz A15-grade IMU with Gauss–Markov biases and scale factors,
1 Hz fixes with per-epoch σ 0.05–0.5 m, the antenna 1 m above the IMU), run as a user runs
it (``gcalign calibrate`` on the simulator's gcalign.yaml) and held to bounds from physics
and consistency, never to an earlier output of gcalign:

* the outage found where the file has it, and no update inside it;
* NIS in its χ² band overall and in each σ bin of the fixes (R from each fix's σ);
* position NEES at the fixes in a band; every navigation error within 4 of the filter's σ;
* every sensor estimate within 3 of its own σ of the simulator's truth;
* the drift in the outage below the free-inertial bound of the IMU's errors
  (:mod:`benchmarks.vehicle.bounds`);
* outside the outage, the solution closer to the truth than the fixes are.
"""

from __future__ import annotations

import sys

import h5py
import numpy as np
import pytest
from scipy.stats import chi2
from typer.testing import CliRunner

from conftest import ROOT

if str(ROOT) not in sys.path:  # `pytest` run without `python -m`: the repository's root
    sys.path.insert(0, str(ROOT))

from benchmarks.vehicle import bounds, dataset, files, solution  # noqa: E402
from gcalign.cli import app  # noqa: E402

runner = CliRunner()


def _band(mean_of: int, dof: int, p: float = 0.99) -> tuple[float, float]:
    """The two-sided `p` band of the mean of `mean_of` independent χ²(dof)."""
    n = mean_of * dof
    return chi2.ppf((1 - p) / 2, n) / mean_of, chi2.ppf((1 + p) / 2, n) / mean_of


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The short drive simulated, written, calibrated; (dataset, results file, solution)."""
    tmp = tmp_path_factory.mktemp("vehicle")
    ds = dataset.simulate(dataset.Config(route="short", seed=1))
    paths = files.write(ds, tmp / "run")
    out = tmp / "gcalign.h5"
    res = runner.invoke(app, ["calibrate", str(paths["gcalign_yaml"]), "-o", str(out)])
    assert res.exit_code == 0, res.output
    return ds, out, solution.read_gcalign(out)


@pytest.mark.slow
def test_outage_found_and_not_updated_inside(run):
    ds, out, _ = run
    (a, b), = ds.fixes.outages
    with h5py.File(out) as f:
        o = f["calibrate/outages"]
        t0 = float(o.attrs["t0"])
        found = list(zip(o["start"][()] + t0, o["end"][()] + t0, strict=True))
        upd = f["calibrate/runs/00/update_t"][()] + t0
    assert found == [pytest.approx((ds.sow(a), ds.sow(b)), abs=1e-6)]
    # every fix of the file within the IMU's span is used once, and nothing else: an update
    # is stored at the first navigation sample after its fix (within the IMU's 5 ms)
    t_fix = ds.sow(ds.fixes.t)
    t_fix = t_fix[t_fix <= ds.sow(ds.t[-1])]
    assert len(upd) == len(t_fix)
    lag = upd - t_fix
    assert np.all((lag >= 0) & (lag < 0.005)), (lag.min(), lag.max())


@pytest.mark.slow
def test_nis_in_band_overall_and_by_sigma_bin(run):
    """The simulator draws each fix's noise from the σ its file states, and gcalign's R is
    that σ²: the NIS (3 dof) has mean 3 whatever the σ, within the 99 % band of that many
    independent χ²₃ (an optimal filter's innovations are white), in every bin."""
    _, out, _ = run
    with h5py.File(out) as f:
        g = f["calibrate/runs/00"]
        nis, sig = g["nis"][()], g["sigma_z"][()]
    lo, hi = _band(len(nis), 3)
    assert lo < nis.mean() < hi, (nis.mean(), lo, hi)
    for a, b in solution.SIGMA_BINS:
        m = (sig[:, 0] >= a) & (sig[:, 0] < b)
        if m.sum() >= 20:
            lo, hi = _band(int(m.sum()), 3)
            assert lo < nis[m].mean() < hi, ((a, b), int(m.sum()), nis[m].mean())


@pytest.mark.slow
def test_errors_within_the_filters_sigma(run):
    """Against the simulator's truth: at every filter epoch each position and velocity
    error within 4σ of the filter's own σ, the heading within 4σ(φ_U); the position NEES
    at the fixes (outside the outage) in the 99 % band of its mean with one independent
    epoch in ten (the errors are correlated over the filter's memory)."""
    ds, out, sol = run
    with h5py.File(out) as f:
        g = f["calibrate/runs/00"]
        sigma = g["sigma"][()]
    e = solution.errors(sol, ds)
    k = np.searchsorted(sol.t, sol.sigma_t - 1e-9)
    assert np.abs(sol.t[k] - sol.sigma_t).max() < 1e-6
    z_p = e["pos"][k] / sol.sigma_pos_ned
    sig_v = sigma[:, [4, 3, 5]]  # ENU -> NED (σ of v_D is σ of v_U)
    z_v = e["vel"][k] / sig_v
    z_yaw = e["att"][k, 2] / sigma[:, 2]
    assert np.abs(z_p).max() < 4 and np.abs(z_v).max() < 4 and np.abs(z_yaw).max() < 4, (
        np.abs(z_p).max(0), np.abs(z_v).max(0), np.abs(z_yaw).max())
    nees = solution.nees_by_bin(sol, ds, e["pos"])
    n = sum(b["epochs"] for b in nees)
    mean = sum(b["nees"] * b["epochs"] for b in nees if b["epochs"]) / n
    lo, hi = _band(n // 10, 3)
    assert lo < mean < hi, (mean, lo, hi)


@pytest.mark.slow
def test_sensor_estimates_within_three_sigma(run):
    """At the end, every bias and scale factor (gyro and accelerometer, three axes) within
    3 of its own σ of the truth drawn by the simulator (the Gauss–Markov processes)."""
    ds, _, sol = run
    z = np.array(solution.table(sol, ds)["sensors_in_sigma"])
    assert np.abs(z).max() < 3, z


@pytest.mark.slow
def test_outage_drift_within_the_free_inertial_bound(run):
    """In the outage, the horizontal and vertical errors stay below the bound of the
    free-inertial error equations driven by what the solution carries into it (its errors
    and what its sensor estimates leave of the truth's), the white noise at 3σ."""
    ds, out, sol = run
    (a, b), = ds.fixes.outages
    e = solution.errors(sol, ds)
    with h5py.File(out) as f:
        g = f["calibrate/runs/00"]
        est = g["estimate"][()]
    k0 = int(np.searchsorted(sol.t, ds.sow(a) + 1e-9))  # the first sample after the last fix
    j = int(np.searchsorted(sol.sigma_t, ds.sow(a) + 1e-9))  # the filter's epoch there
    assert abs(sol.sigma_t[j] - sol.t[k0]) < 1e-6
    i = int(np.searchsorted(ds.t, sol.t[k0] - ds.config.sow0 - 1e-9))
    s = ds.sensors
    truth = np.stack([s.gyro_bias[i], s.accel_bias[i], s.gyro_scale[i], s.accel_scale[i]])

    def frd(v, sign):
        return np.array([v[1], v[0], sign * v[2]])

    estimate = np.stack([frd(est[j, 9:12], -1), frd(est[j, 12:15], -1),
                         frd(est[j, 15:18], 1), frd(est[j, 18:21], 1)])
    t, b_h, b_v = bounds.outage_bound(ds, sol.t[k0] - ds.config.sow0, b, e["pos"][k0],
                                      e["vel"][k0], e["att"][k0], estimate - truth)
    m = (sol.t > sol.t[k0]) & (sol.t < ds.sow(b))
    tt = sol.t[m] - ds.config.sow0
    err_h = np.hypot(e["pos"][m, 0], e["pos"][m, 1])
    err_v = np.abs(e["pos"][m, 2])
    print(f"outage drift: horizontal {err_h.max():.3f} m (bound {b_h[-1]:.3f}), vertical "
          f"{err_v.max():.3f} m (bound {b_v[-1]:.3f})")
    assert np.all(err_h <= np.interp(tt, t, b_h)) and np.all(err_v <= np.interp(tt, t, b_v))
    # and the bound is not empty: the drift is a real part of it
    assert err_h.max() > 0.1 * b_h[-1] and err_v.max() > 0.1 * b_v[-1]


@pytest.mark.slow
def test_closer_to_the_truth_than_the_fixes(run):
    """Outside the outage the solution is closer to the truth than the fixes are: its RMS
    error below the RMS of the fixes' own σ, north, east and down."""
    ds, _, sol = run
    e = solution.errors(sol, ds)
    m = ~solution.outage_mask(sol.t, ds)
    rms = np.sqrt((e["pos"][m] ** 2).mean(0))
    fix_rms = np.sqrt((ds.fixes.sigma_ned**2).mean(0))
    assert np.all(rms < fix_rms), (rms, fix_rms)
