"""Seeds in lockstep (gcalign.align.lockstep, the lanes kernel, a batch's chunks) against
each run alone, to the bit: the lockstep changes where a run's numbers are computed, not
one operation."""

from __future__ import annotations

import copy
import itertools

import numpy as np
import pytest

from gcalign.align import kernel as K
from gcalign.align.cycles import loop_gains
from gcalign.align.stages import Stage
from gcalign.nav.earth import WGS84

N = 301  # not a multiple of the strides below
L = K.LANES


@pytest.fixture(scope="module")
def lanes_data():
    """LANES runs of noisy increments and an odometer-like reference; run 3 has one
    increment beyond the series' range (the step redone by the exact branch)."""
    rng = np.random.default_rng(5)
    D = np.zeros((N + 1, 9, L))
    D[:, 0:3] = 1e-6 * rng.standard_normal((N + 1, 3, L))
    D[:, 2] += 1e-5
    D[:, 5] = 0.098
    D[:, 3:6] += 1e-4 * rng.standard_normal((N + 1, 3, L))
    D[:, 7] = 10.0 + 0.01 * rng.standard_normal((N + 1, L))
    D[100, 0:3, 3] = 0.2
    D[N, 0:6] = 0.0
    st0 = np.zeros((L, K.STATE_SIZE))
    st0[:, 0], st0[:, 9] = 1.0, 0.8
    st0[:, 4:9] = 1e-3 * rng.standard_normal((L, 5))
    return D, st0


@pytest.mark.parametrize(("mode", "body", "reverse"),
                         list(itertools.product((K.ATTITUDE, K.LEVEL, K.COMPASS),
                                                (True, False), (False, True))))
def test_lanes_kernel_is_the_single_kernel_to_the_bit(lanes_data, mode, body, reverse):
    D, st0 = lanes_data
    data = np.ascontiguousarray(D.reshape(N + 1, 9 * L))
    E = WGS84.params()
    g = loop_gains(Stage(20.0, 280.0, 0.707), 0.8, 0.0, "double-oscillator")
    sg = -1.0 if reverse else 1.0
    for stride, row_from in ((1, 0), (7, 5)):
        st = st0.copy()
        m = K.stored_rows(0, N, stride)
        idx, q = np.empty(m - row_from, np.int64), np.empty((m - row_from, 4, L))
        rows = K.gyrocompass_range_lanes(st, data, body, 0.01, 0, N, reverse, sg, sg, E, g,
                                         mode, stride, row_from, idx, q)
        assert rows == m
        for s in range(L):
            one = st0[s].copy()
            i1, q1 = np.empty(m, np.int64), np.empty((m, 4))
            K.gyrocompass_range(one, np.ascontiguousarray(D[:N, 0:3, s]),
                                np.ascontiguousarray(D[:N, 3:6, s]),
                                np.ascontiguousarray(D[:, 6:9, s]), body, 0.01, 0, N,
                                reverse, sg, sg, E, g, mode, stride, i1, q1)
            assert np.array_equal(one, st[s]), (stride, s)
            assert np.array_equal(i1[row_from:], idx) and np.array_equal(q1[row_from:],
                                                                         q[:, :, s])
    assert not np.array_equal(st[3], st[4])  # the runs differ: the comparison can fail


SMALL = {  # the seed 000 §5.3 moving base shortened: 50 s of data, T2 = 40 s
    "name": "lockstep",
    "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0},
    "imu": {"rate_hz": 100,
            "gyro": {"bias_dph": [0.01, 0.01, 0.01], "arw_dprh": 0.001},
            "accel": {"bias_ug": [50, 50, 50], "vrw_ugrhz": 10}},
    "motion": {"kind": "moving", "attitude_deg": [0, 0, 30], "duration_s": 50,
               "segments": [{"duration_s": 10}, {"duration_s": 10, "accel_mps2": 1.0},
                            {"duration_s": 10, "rate_dps": [0, 0, -1]},
                            {"duration_s": 20}]},
    "align": {"coarse": {"method": "given", "error_deg": [1, 1, 10]}, "mode": "full-cycle",
              "t1_s": 10, "t2_s": 40, "t3_s": 45, "stages": [{"passes": 3}],
              "level_s": 10, "azimuth_poles": "double-oscillator",
              "aiding": {"source": "odometer", "noise_mps": 0.01}},
}


@pytest.mark.parametrize("change", [
    {},
    {"mode": "half-cycle", "compensation": "one-off"},
    {"mode": "conventional", "realtime": False, "compensation": "none"},
    {"coarse": {"method": "inertial"}, "aiding": {"source": "nav", "noise_mps": 0.01},
     "stages": [{"t_xy_s": 10, "t_z_s": 30, "xi": 0.7, "passes": 1}, {"passes": 4}]},
])
@pytest.mark.slow
def test_seeds_in_lockstep_give_each_run_s_summary_to_the_bit(change):
    """summaries_of_seeds (17 seeds: a full group of LANES and one alone) against the
    summary of each seed's own run (`gcalign align --seed`), every field but the timing."""
    _compare_summaries(change, list(range(3, 3 + L + 1)))


def test_a_few_seeds_in_lockstep_give_each_run_s_summary_to_the_bit():
    """The same on four seeds (a group that the lockstep fills with copies of its first)."""
    _compare_summaries({}, [1, 2, 7, 9])


def _compare_summaries(change: dict, seeds: list[int]) -> None:
    from gcalign.app.align.run import execute, summaries_of_seeds
    from gcalign.app.batch.runs import noise_free_key
    from gcalign.io.scenario import parse_scenario

    d = copy.deepcopy(SMALL)
    d["align"].update(change)
    sc = parse_scenario(d)
    many = summaries_of_seeds(sc, seeds, noise_free_key(sc))
    for seed, got in zip(seeds, many, strict=True):
        want = execute(sc, seed).summary
        assert isinstance(got, dict), got
        assert {k: v for k, v in got.items() if k != "compute_s"} == \
            {k: v for k, v in want.items() if k != "compute_s"}, seed
    assert many[0]["error_t3_deg"] != many[1]["error_t3_deg"]  # seeds differ


def test_a_chunk_of_seeds_gives_the_metrics_of_each_run():
    """A batch worker's chunk (run_chunk: lockstep by variant) against run_task run by run,
    with a seed that fails and a variant of another command in between."""
    from gcalign.app.batch.runs import run_chunk, run_task

    base = {"command": "align", "variant": 0, "vkey": "v0", "scenario": SMALL,
            "source": "test", "metrics": ["error_t3_deg", "last_pass_error.std_deg",
                                          "passes.1.error_deg"]}
    tasks = [dict(base, seed=s) for s in (1, 2, -1, 4, 5)]
    alone = [run_task(t) for t in tasks]
    chunk = run_chunk(tasks)
    strip = [{k: v for k, v in r.items() if k != "wall_s"} for r in alone]
    assert [{k: v for k, v in r.items() if k != "wall_s"} for r in chunk] == strip
    assert [r["status"] for r in chunk] == ["ok", "ok", "failed", "ok", "ok"]


@pytest.mark.parametrize("source", ["odometer", "nav"])
def test_windows_of_seeds_share_what_no_seed_changes(source):
    """collect with a `shared` dict (the seeds of a variant in a batch) gives each seed the
    window it gets alone, field by field to the bit, the truth rows taken from the first."""
    from gcalign.app.align.run import alignment_inputs
    from gcalign.app.batch.runs import noise_free_key
    from gcalign.app.data import scenario_data, stream_of
    from gcalign.io.scenario import parse_scenario

    d = copy.deepcopy(SMALL)
    d["align"]["aiding"]["source"] = source
    sc = parse_scenario(d)
    shared: dict = {}
    got = []
    for seed in (1, 2, 3):
        stream = stream_of(scenario_data(sc, seed, noise_free_key(sc)))
        kw, _ = alignment_inputs(sc, stream, shared=shared)
        alone, _ = alignment_inputs(sc, stream_of(scenario_data(sc, seed)))
        for name in ("dtheta", "dv", "vref", "position_t1"):
            assert np.array_equal(kw[name], alone[name]), (seed, name)
        assert np.array_equal(kw["truth_att"].samples, alone["truth_att"].samples)
        assert np.array_equal(kw["truth_att"].att, alone["truth_att"].att)
        got.append(kw)
    assert got[2]["truth_att"].att is got[0]["truth_att"].att  # shared, not gathered again
    assert not np.array_equal(got[0]["vref"], got[1]["vref"])  # each seed its own noise
