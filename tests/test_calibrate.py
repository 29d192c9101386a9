"""The calibration filter (gcalign.calibrate) against physics and its own statistics (spec 002
§6 items 9–11, must-shows 3–7).

* Ideal data: the estimates stay at zero (to the strapdown kernel's own 25 Hz error, which
  falls as ts²); noise-free DGNSS: every state stays within 3σ and the observable ones
  converge to the injected errors.
* Monte Carlo with the truth drawn from the filter's own P0: NEES in the χ²₂₁ band, NIS and
  whitened innovations consistent with N(0, 1).
* Covariance: an added measurement never increases P, constant states never gain σ, the
  RTS smoother gains nothing on the constants (Φ = [[·, ·], [0, I]], Q = 0 there) and
  only improves the navigation-error history.
* The seed's findings in direction (static poor, εz poor, designed beats conventional).
* Real data: zero-velocity fine alignment on lasergyro.imu beside the gyrocompass.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from calibrate_cases import SITE, TS, conventional, designed_590, section_41_set, short_set
from scipy.stats import chi2

from gcalign.calibrate import (
    Settings,
    calibrate,
    covariance_run,
    draw_truth,
    flight_from_ideal,
    proposed_truth,
    simulate_flight,
    zero_velocity_data,
)
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.nav.earth import WGS84
from gcalign.sim.imu import ideal_imu
from gcalign.units import DEG

ROOT = Path(__file__).resolve().parents[1]
DATA = (ROOT / "../shared/data/lasergyro.imu").resolve()
IMU = ie.IMU


def _flight(case, x_true=None, arw=0.0, vrw=0.0, seed=0, ts=TS):
    motion, names = case()
    x = np.zeros(21) if x_true is None else x_true
    return simulate_flight(motion, SITE, ts, x, arw, vrw, np.random.default_rng(seed), names)


@pytest.fixture(scope="module")
def designed_cov():
    data = _flight(designed_590)
    return {m: covariance_run(data.truth, Settings(measure=m)) for m in ie.MEASUREMENTS}


# --------------------------------------------------------------------------- ideal data


def test_ideal_data_estimates_stay_at_zero():
    """Must-show 3: no sensor errors, no noise, no initial errors: the estimates stay 0.
    What is left is the 25 Hz strapdown's own error in fast turns (4e-5 m/s per second at
    9°/s and 26 m/s²): below 1e-2 σ, and 16× smaller at 100 Hz (it is second order in ts)."""
    worst = {}
    for ts in (TS, 0.01):
        r = calibrate(_flight(short_set, ts=ts), Settings(measure="both", gnss_noise=False))
        worst[ts] = np.abs(r.estimate / r.sigma).max()
        assert np.abs(r.innovation[:, :2]).max() < 2e-4 and np.abs(r.innovation[:, 2:]).max() < 2e-3
    assert worst[TS] < 1e-2
    assert worst[0.01] < worst[TS] / 8


def test_noise_free_dgnss_converges_to_the_injected_errors():
    """Must-show 3: the spec's injected errors, exact DGNSS and no sensor noise on the 590 s
    designed take-off: every state stays within 3σ at every epoch, and every sensor error
    whose σ fell at least twofold (the observable ones) is recovered to 25 % of its value."""
    data = _flight(designed_590, proposed_truth())
    for measure in ie.MEASUREMENTS:
        r = calibrate(data, Settings(measure=measure, gnss_noise=False))
        assert np.abs(r.error / r.sigma).max() < 3.0
        observable = r.sigma[0, IMU] / r.sigma[-1, IMU] >= 2.0
        assert observable.sum() >= 7
        rel = np.abs(r.error[-1, IMU] / r.truth[-1, IMU])[observable]
        assert rel.max() < 0.25, dict(zip(np.array(ie.STATE_NAMES[9:])[observable], rel.round(3),
                                          strict=True))


# --------------------------------------------------------------------------- Monte Carlo


def _monte_carlo(measure: str, runs: int, seed: int):
    motion, names = short_set()
    segments = _flight(short_set).segments
    truth, ideal = ideal_imu(motion, SITE, TS, substeps=4)
    s = Settings(measure=measure, p0_scale=1.0)
    P0 = ie.initial_covariance(SITE, 1.0)
    rng = np.random.default_rng(seed)
    nees, nis, white = [], [], []
    for _ in range(runs):
        data = flight_from_ideal(truth, ideal, draw_truth(P0, rng), ie.ARW_DEFAULT,
                                 ie.VRW_DEFAULT, rng, segments)
        r = calibrate(data, s, rng)
        nees.append(r.nees)
        nis.append(r.nis)
        white.append(r.standardized)
    return np.array(nees), np.array(nis), np.concatenate(white)


@pytest.mark.slow
@pytest.mark.parametrize("measure", ie.MEASUREMENTS)
def test_monte_carlo_consistency(measure):
    """Must-show 3, spec §6 item 10: 100 runs, truth ~ N(0, P0) at p0_scale 1, IMU noise at
    the Q densities, DGNSS noise at R. The run-averaged NEES is inside the χ²₂₁ 95 % band
    at ≥ 90 % of the epochs (epochs share the constant draws, so they are not independent)
    and inside the 99.9 % band at all; mean NIS is in its 95 % band; each whitened
    innovation has mean 0 (4 standard errors) and variance 1 (99.9 % band)."""
    runs = 100
    nees, nis, white = _monte_carlo(measure, runs, seed=1)
    anees = nees.mean(0)
    lo, hi = chi2.ppf([0.025, 0.975], 21 * runs) / runs
    assert np.mean((anees > lo) & (anees < hi)) >= 0.9
    lo, hi = chi2.ppf([0.0005, 0.9995], 21 * runs) / runs
    assert np.all((anees > lo) & (anees < hi)), (anees.min(), anees.max())
    m = white.shape[1]
    lo, hi = chi2.ppf([0.025, 0.975], nis.size * m) / nis.size
    assert lo < nis.mean() < hi
    n = len(white)
    assert np.all(np.abs(white.mean(0)) < 4 / np.sqrt(n))
    lo, hi = chi2.ppf([0.0005, 0.9995], n) / n
    assert np.all((white.var(0) > lo) & (white.var(0) < hi)), white.var(0)


# --------------------------------------------------------------------------- covariance


def test_more_measurements_never_increase_sigma(designed_cov):
    """Must-show 3, spec §6 item 11: along the same trajectory P(both) ≤ P(velocity) and
    ≤ P(position) for every state at every epoch (Riccati monotonicity)."""
    both = designed_cov["both"].sigma
    for other in ("velocity", "position"):
        assert np.all(both <= designed_cov[other].sigma * (1 + 1e-9))


def test_filter_sigma_ranks_the_same(designed_cov):
    """The filter's own σ (linearised on its estimate, not on the truth) keeps the order to
    1e-3 and equals the truth-linearised covariance run to 1 %."""
    data = _flight(designed_590, proposed_truth(), ie.ARW_DEFAULT, ie.VRW_DEFAULT, seed=4)
    final = {m: calibrate(data, Settings(measure=m), np.random.default_rng(5)).sigma[-1]
             for m in ie.MEASUREMENTS}
    assert np.all(final["both"] <= np.minimum(final["velocity"], final["position"]) * 1.001)
    for m in ie.MEASUREMENTS:
        np.testing.assert_allclose(final[m], designed_cov[m].sigma[-1], rtol=1e-2)


def test_constant_states_never_gain_sigma(designed_cov):
    """Spec §6 item 11: the twelve sensor errors have no process noise, so their σ never
    increases, in the covariance run and in the filter."""
    for run in designed_cov.values():
        assert np.all(np.diff(run.sigma[:, IMU], axis=0) <= 1e-12 * run.sigma[:-1, IMU])
    r = calibrate(_flight(short_set, proposed_truth(), ie.ARW_DEFAULT, ie.VRW_DEFAULT),
                  Settings(), np.random.default_rng(1))
    assert np.all(np.diff(r.sigma[:, IMU], axis=0) <= 1e-12 * r.sigma[:-1, IMU])


# --------------------------------------------------------------------------- options


def test_feed_forward_agrees_with_closed_loop():
    """For errors drawn from P0 at p0_scale 1 on the 162 s trajectory the linearised
    (feed-forward) filter and the closed loop are the same estimator to first order: final
    sensor estimates within 0.1σ, corrected attitude within 1e-3°, same σ to 5e-3 (the
    linearisation points differ by the estimation errors)."""
    P0 = ie.initial_covariance(SITE, 1.0)
    rng = np.random.default_rng(3)
    data = _flight(short_set, draw_truth(P0, rng), ie.ARW_DEFAULT, ie.VRW_DEFAULT, seed=6)
    closed = calibrate(data, Settings(p0_scale=1.0), np.random.default_rng(9))
    free = calibrate(data, Settings(p0_scale=1.0, feedback=False), np.random.default_rng(9))
    d = (closed.estimate[-1, IMU] - free.estimate[-1, IMU]) / closed.sigma[-1, IMU]
    assert np.abs(d).max() < 0.1
    assert np.abs(closed.att[-1] - free.att[-1]).max() < 1e-3 * DEG
    np.testing.assert_allclose(free.sigma, closed.sigma, rtol=5e-3)
    assert free.nees.mean() == pytest.approx(closed.nees.mean(), rel=0.05)


def test_rts_smoother_gains_nothing_on_the_constants():
    """What the post-flight smoother gains: for the sensor errors (constants, no process
    noise) the smoothed σ at every epoch equals the final filtered σ and the smoothed
    estimate is the final one (to 2e-2 σ: the exact composition of the corrections is
    second order); the navigation errors gain, most at the start (φU at t = 0 from 30′·10
    down to its end-of-flight σ), and the smoothed σ never exceeds the filtered one."""
    data = _flight(short_set, proposed_truth(), ie.ARW_DEFAULT, ie.VRW_DEFAULT, seed=2)
    r = calibrate(data, Settings(smoother=True), np.random.default_rng(7))
    s = r.smoothed
    assert s is not None
    final = np.broadcast_to(r.sigma[-1, IMU], s.sigma[:, IMU].shape)
    np.testing.assert_allclose(s.sigma[:, IMU], final, rtol=1e-6)
    assert np.all(np.abs(s.estimate[:, IMU] - r.estimate[-1, IMU]) < 2e-2 * r.sigma[-1, IMU])
    assert np.all(s.sigma <= r.sigma * (1 + 1e-9))
    assert s.sigma[0, ie.IDX["phiU"]] < 0.1 * r.sigma[0, ie.IDX["phiU"]]
    # the smoothed initial attitude error is consistent with the truth
    err0 = (s.estimate[0, ie.PHI] - r.truth[0, ie.PHI]) / s.sigma[0, ie.PHI]
    assert np.all(np.abs(err0) < 3.0)


@pytest.mark.parametrize(
    ("settings", "field"),
    [
        (Settings(measure="attitude"), "measure"),
        (Settings(sigma_v=0.0), "sigma_v"),
        (Settings(measure="position", sigma_p=-1.0), "sigma_p"),
        (Settings(p0_scale=0.0), "p0_scale"),
        (Settings(filter_rate=2.0), "filter_rate"),  # 25 Hz / 2 Hz is not an integer
        (Settings(filter_rate=50.0), "filter_rate"),  # faster than the navigation
        (Settings(filter_rate=-1.0), "filter_rate"),
        (Settings(discretization="euler"), "discretization"),
        (Settings(arw=-1e-6), "arw"),
    ],
)
def test_bad_settings_exit_2_with_one_line(settings, field):
    """Must-show 7: bad input raises ScenarioError (exit code 2) with one line naming the field."""
    data = _flight(short_set)
    with pytest.raises(ScenarioError) as exc:
        calibrate(data, settings, np.random.default_rng(0))
    assert exc.value.exit_code == 2
    msg = str(exc.value)
    assert msg.startswith(field) and "\n" not in msg and "got" in msg


def test_other_filter_rates_run():
    """5 Hz and 0.5 Hz divide 25 Hz; the 5 Hz filter sees five times the measurements."""
    data = _flight(short_set, proposed_truth(), ie.ARW_DEFAULT, ie.VRW_DEFAULT)
    fast = calibrate(data, Settings(filter_rate=5.0), np.random.default_rng(0))
    slow = calibrate(data, Settings(filter_rate=0.5), np.random.default_rng(0))
    n = len(data.dtheta)  # 151.84 s: the last incomplete filter step is not used
    assert len(fast.t) - 1 == n // 5 and len(slow.t) - 1 == n // 50
    assert fast.t[1] == pytest.approx(0.2) and slow.t[1] == pytest.approx(2.0)


# --------------------------------------------------------------------------- seed findings


def test_seed_findings_in_direction(designed_cov):
    """Must-show 4 (spec §1, §5), velocity matching: the static stage leaves every sensor
    error where it was (σ within 1 % of P0) except ∇x, ∇y, which it excites "partly" (seed
    §5.2: σ falls by 5–20 %: the level tilts and ∇x, ∇y are observed only together); εz
    stays poor (final σ ≥ 0.8 σ0); the designed
    590 s take-off beats the conventional one (its first 6 stages) on every scale factor and
    on ∇x, ∇y by more than 5×."""
    vel = designed_cov["velocity"]
    after_static = vel.sigma[int(round(60.0))]
    ratio = after_static / vel.sigma[0]
    level = [ie.IDX["dbx"], ie.IDX["dby"]]
    assert np.all((ratio[level] > 0.8) & (ratio[level] < 0.95))
    assert np.all(np.delete(ratio[IMU], [3, 4]) > 0.99)
    assert vel.sigma[-1, ie.IDX["ebz"]] > 0.8 * vel.sigma[0, ie.IDX["ebz"]]
    conv = covariance_run(_flight(conventional).truth, Settings(measure="velocity")).sigma[-1]
    designed = vel.sigma[-1]
    assert np.all(designed[ie.DKG] < conv[ie.DKG]) and np.all(designed[ie.DKA] < conv[ie.DKA])
    assert np.all(designed[ie.DB][:2] < conv[ie.DB][:2] / 5)


def test_section_41_covariance_degree_is_at_least_one():
    """PSINS kfstat degree σ(0)/σ(t) along the §4.1 set: every sensor error ≥ 1, and the
    heading (φU) gains more than tenfold in the ground roll."""
    data = _flight(section_41_set)
    run = covariance_run(data.truth, Settings())
    deg = run.sigma[0] / run.sigma
    assert np.all(deg[:, IMU] >= 1 - 1e-12)
    assert deg[int(round(73.84)), ie.IDX["phiU"]] > 10


def test_calibration_time_590_s():
    """Must-show 6: one 590 s calibration (25 Hz navigation, 1 Hz filter, NEES against the
    truth) within 0.5 s warm; asserted here as at most 1 s of this process's CPU time, best
    of three (the machine is shared); benchmarks/bench_calibrate.py prints the wall-clock
    median."""
    data = _flight(designed_590, proposed_truth(), ie.ARW_DEFAULT, ie.VRW_DEFAULT)
    calibrate(data, Settings(), np.random.default_rng(0))
    best = np.inf
    for _ in range(3):
        start = time.process_time()
        calibrate(data, Settings(), np.random.default_rng(0))
        best = min(best, time.process_time() - start)
    assert best < 1.0


# --------------------------------------------------------------------------- real data


@pytest.mark.skipif(not DATA.is_file(), reason="shared/data/lasergyro.imu is not beside the repo")
@pytest.mark.parametrize("start_s", [0.0, 600.0, 1200.0])
def test_zero_velocity_alignment_on_lasergyro(start_s):
    """Must-show 5: the same filter as a zero-velocity fine alignment on the parked vehicle
    (100 Hz navigation, 1 Hz filter, inertial-frame coarse alignment over the first 60 s of
    the window, then 340 s of zero-velocity updates): yaw within 0.1° of −90.6° and within
    0.05° of the gyrocompass of configs/lasergyro_align.yaml at the same instant."""
    from gcalign.align.coarse import inertial_frame_coarse
    from gcalign.app.align.run import run_alignment
    from gcalign.app.data import scenario_data
    from gcalign.io.imu_files import read_imu_file
    from gcalign.io.scenario import load_scenario
    from gcalign.nav.strapdown import NavState

    imu = read_imu_file(DATA)
    ts = imu.ts
    i0 = int(round(start_s / ts))
    i1, i2 = i0 + int(round(60.0 / ts)), i0 + int(round(400.0 / ts))
    att1 = inertial_frame_coarse(imu.dtheta[i0:i1], imu.dv[i0:i1], ts, imu.site[0])
    start = NavState.from_euler(att1, np.zeros(3), imu.site)
    data = zero_velocity_data(np.arange(i2 - i1 + 1) * ts, imu.dtheta[i1:i2], imu.dv[i1:i2],
                              start)
    r = calibrate(data, Settings(gnss_noise=False))
    yaw = np.degrees(r.att[-1, 2])
    assert yaw == pytest.approx(-90.6, abs=0.1)
    sc, _ = load_scenario(ROOT / "configs" / "lasergyro_align.yaml")
    sc.align.start_s = start_s
    gyrocompass = np.degrees(run_alignment(sc, scenario_data(sc)).att_t2)
    assert yaw == pytest.approx(gyrocompass[2], abs=0.05)
    np.testing.assert_allclose(np.degrees(r.att[-1, :2]), gyrocompass[:2], atol=0.01)


def test_designed_trajectory_envelope():
    """Spec §3 and §6 item 13 on the stand-in: 590 s in total, 90 m/s after the ground roll
    (89.96 m/s after 13.84 s), a 60° climb at the end of the pitch-up, 165 m/s for the
    roll and turns, a net heading change of a whole turn (left 180, right 90, left 90,
    left 180), and the spec's envelope (independent check: 7987 m, 14.85 km)."""
    data = _flight(designed_590)
    tr, seg = data.truth, {sp.name: sp for sp in data.segments}
    assert tr.t[-1] == pytest.approx(590.0)

    def at(t):
        return int(round(t / TS))

    speed = np.linalg.norm(tr.v_n, axis=1)
    assert speed[at(seg["ground roll"].end)] == pytest.approx(89.96, abs=1e-6)
    assert np.degrees(tr.att[at(seg["pitch-up"].end), 0]) == pytest.approx(60.0, abs=1e-9)
    assert speed[at(seg["roll left"].start)] == pytest.approx(164.96, abs=1e-6)
    assert np.degrees(tr.att[-1, 2] - tr.att[0, 2]) == pytest.approx(360.0, abs=1e-9)
    r_m, r_n = WGS84.radii(SITE[0])
    north = (tr.pos[:, 0] - SITE[0]) * r_m
    east = (tr.pos[:, 1] - SITE[1]) * r_n * np.cos(SITE[0])
    assert tr.pos[:, 2].max() == pytest.approx(7987.0, rel=2e-3)
    assert np.hypot(north, east).max() == pytest.approx(14850.0, rel=2e-2)


def test_settings_are_frozen_values():
    s = Settings()
    assert replace(s, measure="both").measure == "both" and s.measure == "velocity"
