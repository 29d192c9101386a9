"""The calibration filter as a GNSS/INS filter: fixes at their own epochs, outages,
3-D measurements, R per fix, sensor processes, the solution at every navigation sample.

Expected values from the model and from consistency: Van Loan on the whole model for the
processes' discretisation, the filter's own σ against the simulated truth (NEES, NIS in
their χ² bands), exact interpolation of noise-free fixes."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from aided_cases import settings, vehicle
from scipy.stats import chi2

from gcalign.calibrate import calibrate
from gcalign.calibrate.filter import _fix_stops
from gcalign.calibrate.fixes import Fixes, find_outages, inside
from gcalign.estimation import ins_error as ie
from gcalign.estimation.kalman import van_loan


def _mean_band(dof: int, n: int, level: float = 0.999) -> tuple[float, float]:
    """Band of the mean of n independent χ²_dof values."""
    return (chi2.ppf((1 - level) / 2, dof * n) / n, chi2.ppf((1 + level) / 2, dof * n) / n)


# ----------------------------------------------------------------------- the model


@pytest.mark.parametrize("tau, phi_tol, q_tol", [(600.0, 3e-4, 1e-3), (3600.0, 5e-5, 2e-4)])
def test_processes_discretised_as_van_loan_on_the_whole_model(tau, phi_tol, q_tol):
    F = ie.error_matrix(np.eye(3), [0.1, 0.2, 9.8], [0.01, 0.02, 0.1], [10, 5, 0],
                        [0.5, 0, 0])
    G, Qc = ie.noise_matrix(np.eye(3)), np.diag([1e-12] * 3 + [1e-8] * 3)
    pr = ie.SensorProcesses.of(["gauss-markov"] * 6 + ["random-walk"] * 3
                               + ["constant"] * 3, 1e-5, tau, 1e-6)
    Phi_c, Qd_c = van_loan(F, G, Qc, 1.0)
    Phi, Qd = ie.with_processes(Phi_c, Qd_c, pr, 1.0)
    Phi_x, Qd_x = van_loan(*pr.augment(F, G, Qc), 1.0)
    blk = (slice(0, 9), slice(9, 21))
    assert np.abs(Phi - Phi_x)[blk].max() < phi_tol * np.abs(Phi_x[blk]).max()
    assert np.abs(Qd - Qd_x).max() < q_tol * np.abs(Qd_x).max()
    # the sensors' own block is exact: e^{−dt/τ}, σ²(1 − e^{−2dt/τ}), q dt
    a = np.exp(-1.0 / tau)
    assert np.allclose(np.diag(Phi)[9:15], a, rtol=1e-14)
    assert np.allclose(np.diag(Qd)[9:15] - np.diag(Phi_c @ np.zeros((21, 21)))[9:15],
                       np.diag(Qd_x)[9:15], rtol=1e-9)
    assert np.allclose(np.diag(Qd_x)[9:15], 1e-10 * (1 - a * a), rtol=1e-9)
    assert np.allclose(np.diag(Qd_x)[15:18], 1e-12, rtol=1e-9)


def test_constant_sensors_leave_the_transition_as_it_was():
    pr = ie.SensorProcesses.of(["constant"] * 12, 0, 1, 0)
    assert pr.constant
    Phi, Qd = np.random.default_rng(1).standard_normal((2, 21, 21))
    P2, Q2 = ie.with_processes(Phi, Qd, pr, 1.0)
    assert np.array_equal(P2, Phi)


def test_three_d_measurement_rows_and_names():
    pos = np.array([0.5, 1.0, 100.0])
    H2 = ie.measurement_matrix("both", pos)
    H3 = ie.measurement_matrix("both", pos, components="3d")
    assert H3.shape == (6, 21) and np.array_equal(H3[[0, 1, 3, 4]], H2)
    assert H3[2, ie.IDX["dvU"]] == 1.0 and H3[5, ie.IDX["dh"]] == 1.0
    assert ie.measurement_names("position", "3d") == ("dpN", "dpE", "dpU")
    off, H = ie.lever_arm_terms("position", np.eye(3), np.zeros(3), np.zeros(3),
                                lever_p_b=[0.0, 0.0, 1.5], components="3d")
    assert off.tolist() == [0.0, 0.0, 1.5]  # an antenna above the IMU: 1.5 m up
    assert np.array_equal(H[:2], ie.lever_arm_terms("position", np.eye(3), np.zeros(3),
                                                    np.zeros(3), lever_p_b=[0, 0, 1.5])[1])


# ----------------------------------------------------------------------- the schedule


def test_steps_end_at_the_sample_closing_each_fix_and_outages_only_predict():
    t = np.arange(0, 30.001, 0.01)  # 3000 navigation steps at 100 Hz
    t_fix = np.array([0.004, 1.237, 2.237, 3.0, 3.001, 3.005, 20.5, 21.5])
    stops, unused = _fix_stops(t, Fixes(t=t_fix), S=100)
    ends = [(s.end, s.fix, round(s.frac, 6)) for s in stops]
    # 0.004 s lies 0.4 of the way through the first step; 1.237 s is 123 steps later, more
    # than a filter period (100): a predict-only step comes first
    assert ends[:4] == [(1, 0, 0.4), (101, None, 1.0), (124, 1, 0.7), (224, 2, 0.7)]
    # 3.0 s is sample 300 itself; 3.001 and 3.005 close the same sample 301: the later
    assert ends[4:6] == [(300, 3, 1.0), (301, 5, 0.5)] and unused == 1
    # then predict-only steps of 100 samples to the fix at 20.5 s, and to the end
    gap = [e for e, f, _ in ends[6:] if f is None and e < 2050]
    assert gap == list(range(401, 2050, 100))
    assert (2050, 6, 1.0) in ends and ends[-1] == (3000, None, 1.0)


def test_outages_listed_with_the_start_and_end_of_the_run():
    out = find_outages(np.arange(5.0, 50.0), 0.0, 60.0, 2.0)
    assert [(o.start, o.end) for o in out] == [(0.0, 5.0), (49.0, 60.0)]
    assert inside(np.array([0.0, 1.0, 5.0, 49.5]), out).tolist() == [False, True, False, True]
    assert find_outages(np.array([]), 0.0, 10.0, 2.0)[0].length == 10.0


# ----------------------------------------------------------------------- the filter


@pytest.fixture(scope="module")
def run():
    data, fixes, _ = vehicle(1)
    rows: list = []
    r = calibrate(data, settings(), on_rows=lambda *a: rows.append(a))
    return data, fixes, r, rows


def test_updates_only_at_fixes_and_the_solution_at_every_sample(run):
    data, fixes, r, rows = run
    t = np.concatenate([a[0] for a in rows])
    assert np.array_equal(t, data.t)  # every navigation sample once, in order
    assert r.updated.sum() == len(fixes.t) - r.fixes_unused
    out = find_outages(fixes.t, data.t[0], data.t[-1], 2.0)
    assert [(round(o.start, 2), round(o.end, 2)) for o in out] == [(149.37, 210.37)]
    # an update's epoch is the sample that closes its fix's time (< 10 ms later)
    in_gap = (r.t > out[0].start + data.ts) & (r.t < out[0].end)
    assert in_gap.sum() == 60 and not r.updated[in_gap].any()
    # the last row of each step is the corrected solution at the epoch
    last = np.concatenate([a[3][-1:] for a in rows[1:]])
    assert np.array_equal(last, r.pos[1:])
    # σ of the position grows in the outage and falls at the first fix after it
    k = np.flatnonzero(in_gap)
    s = np.hypot(r.sigma[:, 6] * 6.37e6, r.sigma[:, 7] * 5.5e6)
    assert s[k[-1]] > 5 * s[k[0] - 1] and s[k[-1] + 1] < 0.3 * s[k[-1]]


def test_noise_free_fixes_between_samples_agree_with_the_ins_to_a_millimetre():
    """Perfect sensors and start, fixes of σ 1 nm taken 3 ms past a sample (between two):
    compared with the INS at their own times, they leave the corrected solution on the truth
    to 2 mm; taken as if at the next sample, the solution lands v·7 ms off (0.1 m at 15 m/s)."""
    from aided_cases import _raw, gnss

    from gcalign.calibrate import flight_from_ideal, white_noise
    from gcalign.nav.navigate import position_error_enu

    raw = _raw()
    clean = flight_from_ideal(raw.truth, raw.imu, np.zeros(21), white_noise(0.0, 0.0),
                              np.random.default_rng(0))
    fx = gnss(clean, np.random.default_rng(1), 0.373, (), (1e-9, 1e-9))
    d = replace(clean, fixes=fx, ref_v_n=None, ref_pos=None)

    def worst(fixes: Fixes) -> float:
        r = calibrate(replace(d, fixes=fixes), settings(processes=None))
        err = position_error_enu(r.pos, clean.truth.pos[r.index])
        return float(np.abs(err[r.updated]).max())

    assert worst(fx) < 2e-3
    assert worst(replace(fx, t=np.ceil(fx.t * 100) / 100)) > 0.05


def test_nis_in_band_in_every_sigma_bin(run):
    """R from each fix's σ: the NIS of good (σ < 0.15 m) and poor (σ > 0.35 m) fixes alike
    in the band of their mean."""
    _, fixes, r, _ = run
    s = r.sigma_z[:, 0]
    for sel in (s < 0.15, s > 0.35):
        lo, hi = _mean_band(3, int(sel.sum()))
        assert lo < r.nis[sel].mean() < hi, (sel.sum(), r.nis[sel].mean())


def test_one_sigma_for_every_fix_is_inconsistent_by_bin(run):
    """The same data with one σ (0.25 m) for every fix: the good fixes' NIS falls below its
    band, the poor ones' above (what R from the file's σ avoids)."""
    data, fixes, _, _ = run
    flat = replace(data, fixes=replace(fixes, sigma_pos=None))
    r = calibrate(flat, settings(sigma_p=0.25))
    s = run[2].sigma_z[:, 0]
    lo, _ = _mean_band(3, int((s < 0.15).sum()))
    _, hi = _mean_band(3, int((s > 0.35).sum()))
    assert r.nis[s < 0.15].mean() < lo and r.nis[s > 0.35].mean() > hi


def test_height_held_by_3d_fixes_and_free_without(run):
    data, _, r3, _ = run
    r2 = calibrate(data, settings(components="horizontal"))
    e3, e2 = np.abs(r3.truth[:, ie.IDX["dh"]]), np.abs(r2.truth[:, ie.IDX["dh"]])
    assert e3.max() < 3.0 and e2.max() > 3 * e3.max()


def test_errors_within_their_sigma(run):
    _, _, r, _ = run
    nees = r.nees[20:]
    lo, hi = _mean_band(21, len(nees), 0.99999)
    # serially correlated: a loose band (the Monte Carlo test holds the tight one)
    assert 0.5 * lo < nees.mean() < 1.5 * hi
    z = r.error[-1] / r.sigma[-1]
    assert np.abs(z).max() < 4.0


@pytest.mark.slow
def test_monte_carlo_every_state_in_its_chi2_band():
    """60 runs of the vehicle (Gauss–Markov biases in the simulation and in the filter,
    fixes with their own σ, one 60 s outage): the mean of (e/σ)² of every state over runs
    and late epochs inside its χ²₁ band, and the NEES's mean in its χ²₂₁ band."""
    runs = 60
    ratio, nees = [], []
    for seed in range(runs):
        data, _, _ = vehicle(100 + seed)
        r = calibrate(data, settings())
        k = np.arange(30, len(r.t), 25)  # well apart epochs, after the start
        ratio.append((r.error[k] / r.sigma[k]) ** 2)
        nees.append(r.nees[k])
    ratio = np.concatenate(ratio)
    n = len(ratio)
    lo, hi = _mean_band(1, runs, 0.999)  # the runs are independent; epochs within one are not
    means = ratio.mean(0)
    bad = {ie.STATE_NAMES[i]: round(float(m), 2) for i, m in enumerate(means)
           if not lo < m < hi}
    assert not bad, (bad, (lo, hi), n)
    lo, hi = _mean_band(21, runs, 0.999)
    assert lo < np.concatenate(nees).mean() < hi
