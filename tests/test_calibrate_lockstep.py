"""Calibration runs in lockstep (gcalign.calibrate.lockstep, the epochs kernel, a batch's
chunks) against each run alone, to the bit; and the kernel against the filter's general
loop, which it replaces on the seed's schedule.

The lockstep changes where a run's numbers are computed, not one operation: every run's
step is the same code whatever runs beside it, so its results are its single run's with
``np.array_equal``. The kernel is the loop's operations written out in NumPy's order; the
two meet to the bit wherever NumPy's scalar sine and cosine are the C library's (the
loop's other transcendental calls); the test holds them to 1e-13 of each field's scale and
says in its message when they differ at all.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from calibrate_cases import SHORT, short, site

from gcalign.calibrate import Settings, calibrate, combine_increments, draw_truth
from gcalign.calibrate import filter as F
from gcalign.calibrate.data import combine_increments_numpy
from gcalign.calibrate.lockstep import LANES, calibrate_runs
from gcalign.estimation import ins_error as ie

FIELDS = ("t", "estimate", "sigma", "truth", "nees", "innovation", "standardized", "nis",
          "att", "v_n", "pos", "index", "updated", "sigma_z")

CHANGES = [{}, {"measure": "position"}, {"measure": "both", "components": "3d"},
           {"feedback": False, "measure": "both"}, {"p0_scale": 1.0, "gnss_noise": False}]


@pytest.fixture(scope="module")
def flights():
    """Four runs of the 162 s flight, truth drawn from P0 (p0_scale 1) and noisy sensors;
    they share one truth (one noise-free simulation), as the seeds of a variant do."""
    P0 = ie.initial_covariance(site("short"), 1.0)
    rng = np.random.default_rng(11)
    return [short(draw_truth(P0, rng), noise=True, seed=40 + i) for i in range(4)]


def _differ_by_round_off(pairs) -> None:
    """Each (name, got, want) equal within 1e-13 of its scale; xfail (saying which) when one
    is not equal to the bit, which a NumPy whose transcendental functions are not the C
    library's would cause."""
    differ = []
    for name, x, y in pairs:
        x, y = np.asarray(x, float), np.asarray(y, float)
        assert x.shape == y.shape, name
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-13 * max(np.abs(y).max(), 1e-300),
                                   err_msg=name)
        if not np.array_equal(x, y):
            differ.append(name)
    if differ:
        pytest.xfail(f"round-off only (NumPy's sin/cos/atan2 are not libm's here): {differ}")


def _loop_route(data, s, rng, on_rows=None):
    """calibrate through the general loop (the kernel route switched off)."""
    plan = F._plan(data, s, rng)
    return F._finish(plan, F._loop(plan, on_rows))


@pytest.mark.parametrize("change", CHANGES)
def test_each_run_in_lockstep_is_its_single_run_to_the_bit(flights, change):
    s = Settings(**change)
    many = calibrate_runs([(d, s, np.random.default_rng([i, 3])) for i, d in
                           enumerate(flights)])
    for i, (d, got) in enumerate(zip(flights, many, strict=True)):
        want = calibrate(d, s, np.random.default_rng([i, 3]))
        assert not isinstance(got, Exception), got
        for f in FIELDS:
            a, b = getattr(got, f), getattr(want, f)
            assert (a is None and b is None) or np.array_equal(a, b), (i, f)
    assert many[0].nees is not None and not np.array_equal(many[0].nees, many[1].nees)


@pytest.mark.parametrize("change", CHANGES)
def test_the_kernel_is_the_general_loop(flights, change):
    """The kernel route (calibrate on the seed's schedule) against the loop it replaces,
    field by field."""
    s = Settings(**change)
    d = flights[0]
    a, b = calibrate(d, s, np.random.default_rng(2)), _loop_route(d, s, np.random.default_rng(2))
    _differ_by_round_off([(f, getattr(a, f), getattr(b, f)) for f in FIELDS
                          if getattr(b, f) is not None])


@pytest.mark.parametrize("n", [2, 4, 5])
def test_increments_combined_by_the_kernel_are_the_numpy_form(n):
    """combine_increments (numba) against its NumPy form, rotations from 1e-9 to 1e-2 rad
    a sample (both branches of the rotation vector's series; 1e-2 rad is 57 °/s at 100 Hz),
    a trailing incomplete group: to the bit where NumPy's transcendental functions are the
    C library's. Beyond (0.01–0.3 rad a sample) NumPy's vector arctan2 leaves libm's by an
    ulp in a few per cent of its calls (decision 015): there the two agree to round-off."""
    rng = np.random.default_rng(n)
    N = 4000 * n + n - 1
    dv = rng.standard_normal((N, 3)) * 0.05 + [0.0, 0.0, 0.098]
    pairs = []
    for lo, hi in ((-9, -2), (-2, -0.5)):
        dth = rng.standard_normal((N, 3)) * 10.0 ** rng.uniform(lo, hi, (N, 1))
        phi, out = combine_increments(dth, dv, n)
        want_phi, want_dv = combine_increments_numpy(dth, dv, n)
        assert phi.shape == (4000, 3)
        pairs += [(f"phi 1e{lo}", phi, want_phi), (f"dv 1e{lo}", out, want_dv)]
    for name, x, y in pairs[2:]:
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-13 * np.abs(y).max(), err_msg=name)
    _differ_by_round_off(pairs[:2])


def test_the_solution_rows_are_the_loop_s(flights):
    """What ``on_rows`` hears (the solution at every navigation sample, handed over every
    64 epochs by the kernel) is what the loop hands over, epoch by epoch."""
    def collect(out):
        return lambda t, q, v, p: out.append(np.hstack([t[:, None], q, v, p]))

    got, want = [], []
    calibrate(flights[1], Settings(), np.random.default_rng(4), on_rows=collect(got))
    _loop_route(flights[1], Settings(), np.random.default_rng(4), on_rows=collect(want))
    assert len(got) == len(want) > 100  # the start, then one call per epoch
    np.testing.assert_allclose(np.vstack(got), np.vstack(want), rtol=0, atol=1e-12)
    assert np.array_equal(np.vstack(got)[:, 0], np.vstack(want)[:, 0])


def test_runs_that_cannot_share_run_alone_and_failures_stay_their_own(flights):
    """A run with the smoother (the general loop), one of other settings (its own group),
    one whose data break its update (NaN increments) and one whose settings are refused:
    each result or error is the run's own."""
    bad = copy.copy(flights[2])
    dth = bad.dtheta.copy()
    dth[100:] = np.nan
    object.__setattr__(bad, "dtheta", dth)
    runs = [(flights[0], Settings(), np.random.default_rng(1)),
            (flights[1], Settings(smoother=True), np.random.default_rng(2)),
            (flights[2], Settings(measure="position"), np.random.default_rng(3)),
            (bad, Settings(), np.random.default_rng(4)),
            (flights[3], Settings(filter_rate=0.3), np.random.default_rng(5)),
            (flights[3], Settings(), np.random.default_rng(6))]
    many = calibrate_runs(runs)
    for k in (0, 1, 2, 5):
        d, s, _ = runs[k]
        want = calibrate(d, s, np.random.default_rng(k + 1))
        assert np.array_equal(many[k].nees, want.nees), k
    assert many[1].smoothed is not None
    assert isinstance(many[3], np.linalg.LinAlgError)
    with pytest.raises(np.linalg.LinAlgError):
        calibrate(bad, Settings(), np.random.default_rng(4))
    assert "filter_rate" in str(many[4])


def test_more_runs_than_lanes_are_split(flights):
    runs = [(flights[i % 4], Settings(), np.random.default_rng(i)) for i in range(LANES + 2)]
    many = calibrate_runs(runs)
    for i in (0, LANES, LANES + 1):
        want = calibrate(flights[i % 4], Settings(), np.random.default_rng(i))
        assert np.array_equal(many[i].nees, want.nees)


# 120 s of the short flight's manoeuvres at 100 Hz, navigated at 25 Hz (a batch variant)
SMALL = {**copy.deepcopy(SHORT), "name": "lockstep-cal",
         "imu": {"rate_hz": 100, "gyro": {"bias_dph": [0.01, -0.01, 0.01], "arw_dprh": 0.001},
                 "accel": {"bias_ug": [50, -50, 50], "vrw_ugrhz": 10}},
         "calibrate": {"navigation_rate_hz": 25, "truth": "draw", "p0_scale": 1}}


@pytest.mark.parametrize("change", [{}, {"measure": "both", "feedback": False}])
@pytest.mark.slow
def test_seeds_in_lockstep_give_each_run_s_summary_to_the_bit(change):
    """summaries_of_seeds against the summary of each seed's own run (`gcalign calibrate
    --seed`), every field but the timing."""
    from gcalign.app.batch.runs import noise_free_key
    from gcalign.app.calibrate.run import execute, summaries_of_seeds
    from gcalign.io.scenario import parse_scenario

    d = copy.deepcopy(SMALL)
    d["calibrate"].update(change)
    sc = parse_scenario(d)
    seeds = [1, 2, 5]
    many = summaries_of_seeds(sc, seeds, noise_free_key(sc))
    for seed, got in zip(seeds, many, strict=True):
        want = execute(sc, seed).summary
        assert isinstance(got, dict), got
        assert {k: v for k, v in got.items() if k != "compute_s"} == \
            {k: v for k, v in want.items() if k != "compute_s"}, seed
    assert many[0]["nees"]["final"] != many[1]["nees"]["final"]  # seeds differ


def test_a_chunk_of_calibrate_seeds_gives_the_metrics_of_each_run():
    """A batch worker's chunk (run_chunk: lockstep by variant) against run_task run by run,
    with a seed that fails."""
    from gcalign.app.batch.runs import run_chunk, run_task

    base = {"command": "calibrate", "variant": 0, "vkey": "c0", "scenario": SMALL,
            "source": "test", "metrics": ["nees.final", "normalized_error", "nis.mean",
                                          "states.ebz.estimate"]}
    tasks = [dict(base, seed=s) for s in (1, 2, -1, 4)]
    alone = [run_task(t) for t in tasks]
    chunk = run_chunk(tasks)
    strip = [{k: v for k, v in r.items() if k != "wall_s"} for r in alone]
    assert [{k: v for k, v in r.items() if k != "wall_s"} for r in chunk] == strip
    assert [r["status"] for r in chunk] == ["ok", "ok", "failed", "ok"]
    assert len({r["wall_s"] for r in chunk}) == 1  # one lockstep, its wall time shared


def test_a_single_run_hands_the_kernel_its_own_increments(flights, monkeypatch):
    """One run (a recording can be hours long) goes to the kernel without a copy of its
    increments; the lanes of a lockstep are packed."""
    import gcalign.calibrate._kernel as kernel

    seen = []
    epochs = kernel.epochs

    def spy(k0, k1, ends, dtheta, dv, *rest):
        seen.append((dtheta, dv))
        return epochs(k0, k1, ends, dtheta, dv, *rest)

    monkeypatch.setattr(kernel, "epochs", spy)
    calibrate(flights[0], Settings(), np.random.default_rng(1))
    assert np.shares_memory(seen[0][0], flights[0].dtheta)
    assert np.shares_memory(seen[0][1], flights[0].dv)
    calibrate_runs([(d, Settings(), np.random.default_rng(1)) for d in flights[:2]])
    assert seen[1][0].shape[0] == 2 and not np.shares_memory(seen[1][0], flights[0].dtheta)
