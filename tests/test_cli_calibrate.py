"""`gcalign calibrate` end to end (seed 002): the built-in designed take-off, the JSON
contract, the results file, `show` and `plot`, the comparison of measurements and
take-offs (must-show 4), real data (must-show 5), batch Monte Carlo, bad input (must-show 7).

References are independent of the command: the injected errors are the scenario's (or a draw
recomputed here from P0), the measured increments are those of ``gcalign simulate``'s
streamed simulation, and the real-data heading is the header's and the gyrocompass's.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from calibrate_cases import DESIGNED, SHORT
from cli_checks import assert_bad_input
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.estimation import ins_error as ie
from gcalign.units import ARCSEC, DPH, PPM, UG

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()

SHORT_CAL = {**copy.deepcopy(SHORT), "name": "short-cal",
             "imu": {"rate_hz": 100, "seed": 2,
                     "gyro": {"bias_dph": [0.01, -0.01, 0.01], "arw_dprh": 0.001,
                              "scale_ppm": [100, -100, 100]},
                     "accel": {"bias_ug": [50, -50, 50], "vrw_ugrhz": 10,
                               "scale_ppm": [-100, 100, -100]}},
             "calibrate": {"navigation_rate_hz": 25, "conventional_segments": 5}}


def _cal(*args: str):
    return runner.invoke(app, ["calibrate", *map(str, args)])


def _write(tmp_path: Path, data: dict, name: str = "sc.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    return p


@pytest.fixture(scope="module")
def builtin(tmp_path_factory):
    """The built-in run (the designed 590 s take-off), its summary and results file."""
    out = tmp_path_factory.mktemp("builtin") / "designed.h5"
    res = _cal("--json", "-o", out)
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), out


def test_builtin_equals_configs_copy():
    from gcalign.cli.common import builtin_text

    assert builtin_text("seed002_designed.yaml") == DESIGNED.read_text(encoding="utf-8")


def test_builtin_json_contract(builtin):
    """The JSON contract: measure, units (SI) and per state truth, estimate, sigma,
    sigma0 in SI; the injected truth is the scenario's imu errors and φ0 = [20″, −20″, 30′]."""
    s, _ = builtin
    assert s["measure"] == "velocity" and s["aiding"] == "dgnss"
    assert list(s["units"]) == list(ie.STATE_NAMES) == list(s["states"])
    assert s["units"]["ebx"] == "rad/s" and s["units"]["dbx"] == "m/s^2"
    assert s["units"]["dKgx"] == "1" and s["units"]["dL"] == "rad"
    # display_scale keyed by state like units and display_units: SI × scale = display unit
    assert list(s["display_scale"]) == list(s["display_units"]) == list(s["units"])
    assert s["display_scale"]["ebx"] == pytest.approx(1 / DPH)
    assert s["display_scale"]["dbx"] == pytest.approx(1 / UG)
    assert s["display_scale"]["dKgx"] == pytest.approx(1 / PPM)
    assert s["display_scale"]["phiE"] == pytest.approx(1 / ARCSEC)
    assert s["display_scale"]["dvU"] == 1.0 and s["display_units"]["dvU"] == "m/s"
    st = s["states"]
    for name in ie.STATE_NAMES:
        assert {"truth", "estimate", "sigma", "sigma0"} <= set(st[name])
    assert st["ebx"]["truth"] == pytest.approx(0.01 * DPH)
    assert st["dby"]["truth"] == pytest.approx(-50 * UG)
    assert st["dKax"]["truth"] == pytest.approx(-100 * PPM)
    assert st["phiU"]["injected"] == pytest.approx(np.radians(0.5))
    # sigma0 is the filter's P0: 10 × the seed's list
    assert st["ebz"]["sigma0"] == pytest.approx(0.1 * DPH)
    assert st["dKgz"]["sigma0"] == pytest.approx(1000 * PPM)
    assert s["navigation_rate_hz"] == 25 and s["filter_rate_hz"] == 1
    assert s["epochs"] == 591 and len(s["segments"]) == 21
    assert s["nees"]["dof"] == 21 and len(s["normalized_error"]) == 21
    # every state ends within 3σ of the truth, and the observable ones converged
    assert max(abs(x) for x in s["normalized_error"]) < 3
    assert st["dKgz"]["sigma"] < 0.1 * st["dKgz"]["sigma0"]


@pytest.mark.slow
def test_results_file_show_and_plot(builtin, tmp_path):
    s, out = builtin
    with h5py.File(out) as f:
        assert f.attrs["kind"] == "calibrate"
        g = f["calibrate/runs/00"]
        assert g["estimate"].shape == (591, 21) and g["sigma"].shape == (591, 21)
        assert g["innovation"].shape == (590, 2) and g["nees"].shape == (591,)
        assert g["estimate"].attrs["units"] == "SI"
        np.testing.assert_allclose(g["sigma"][-1], [s["states"][n]["sigma"]
                                                    for n in ie.STATE_NAMES])
        assert f["truth/pos"].shape == (14751, 3)
        assert list(f["truth/segment_names"].asstr()[()])[:2] == ["static", "ground roll"]
    res = runner.invoke(app, ["show", str(out)])
    assert res.exit_code == 0 and "dKgz" in res.output and "NEES" in res.output
    res = runner.invoke(app, ["plot", str(out), "-o", str(tmp_path), "--json"])
    assert res.exit_code == 0, res.output
    names = {Path(p).stem for p in json.loads(res.stdout)["figures"]}
    assert names == {"trajectory", "sensor_biases", "scale_factors", "sigma",
                     "navigation_errors", "innovations", "solution_errors"}


def test_data_are_the_simulated_imu_with_the_scenario_errors():
    """The filter's increments are ``gcalign simulate``'s (the streamed simulation of the
    scenario with its own errors and seed), combined four to a 25 Hz step."""
    from gcalign.app.calibrate.run import simulated_case
    from gcalign.app.data import gather, scenario_stream
    from gcalign.calibrate import combine_increments
    from gcalign.io.scenario import parse_scenario

    sc = parse_scenario(copy.deepcopy(SHORT_CAL), "short")
    case = simulated_case(sc, seed=5)
    run = gather(scenario_stream(sc, 5))
    dth, dv = combine_increments(run.imu.dtheta, run.imu.dv, 4)
    np.testing.assert_allclose(case.data.dtheta, dth, rtol=0, atol=1e-15)
    np.testing.assert_allclose(case.data.dv, dv, rtol=0, atol=1e-13)
    np.testing.assert_allclose(case.data.truth.pos, run.truth.pos[::4], rtol=0, atol=1e-12)


def test_truth_drawn_from_p0_with_the_seed(tmp_path):
    """--truth draw: all 21 injected errors ~ N(0, P0) from the run's seed (recomputed here),
    the same for the same seed, different for another."""
    from gcalign.calibrate import draw_truth

    p = _write(tmp_path, SHORT_CAL)
    got = {}
    for seed in (3, 3, 4):
        res = _cal(p, "--truth", "draw", "--seed", seed, "--json", "-o", tmp_path / f"{seed}.h5")
        assert res.exit_code == 0, res.output
        s = json.loads(res.stdout)
        got.setdefault(seed, []).append([s["states"][n]["injected"] for n in ie.STATE_NAMES])
        sigma0 = np.array([s["states"][n]["sigma0"] for n in ie.STATE_NAMES])
    assert got[3][0] == got[3][1] and got[3][0] != got[4][0]
    expected = draw_truth(np.diag(sigma0**2), np.random.default_rng([3, 2]))
    np.testing.assert_allclose(got[3][0], expected, rtol=1e-12)


def test_measure_option_and_smoother(tmp_path):
    """--measure both: four innovations (δvE, δvN, δpN, δpE); --smoother: the RTS smoother
    brings the initial heading σ down to (about) its end-of-flight value and leaves the
    sensor errors' σ as filtered."""
    p = _write(tmp_path, SHORT_CAL)
    res = _cal(p, "--measure", "both", "--smoother", "--json", "-o", tmp_path / "b.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["measure"] == "both" and s["innovation"]["names"] == ["dvE", "dvN", "dpN", "dpE"]
    assert s["nis"]["dof"] == 4
    sm = s["smoothed_initial"]["phiU"]
    assert sm["sigma"] < 0.1 * sm["filtered_sigma"]
    assert sm["sigma"] == pytest.approx(s["states"]["phiU"]["sigma"], rel=0.5)
    with h5py.File(tmp_path / "b.h5") as f:
        g = f["calibrate/runs/00"]
        np.testing.assert_allclose(g["smoothed/sigma"][:, 9:], np.broadcast_to(
            g["sigma"][-1, 9:], g["smoothed/sigma"][:, 9:].shape), rtol=1e-6)


@pytest.mark.slow
def test_compare_designed_and_conventional(tmp_path):
    """Must-show 4 on the real flights (the seed's Table 3): --compare runs velocity,
    position and both on the designed take-off and its first 6 stages on the same data.
    The designed flight ends with a smaller σ for every sensor error and measurement
    (the conventional one has no roll or turn); both ≤ min(velocity, position)."""
    out = tmp_path / "cmp.h5"
    res = _cal("--compare", "--json", "-o", out)
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    runs = {(r["label"], r["measure"]): r for r in s["runs"]}
    assert set(runs) == {(lab, m) for lab in ("designed", "conventional")
                         for m in ie.MEASUREMENTS}
    assert runs["conventional", "velocity"]["duration_s"] == pytest.approx(237.0)
    assert len(runs["conventional", "velocity"]["segments"]) == 6
    sensors = ie.STATE_NAMES[9:]
    for m in ie.MEASUREMENTS:
        d, c = runs["designed", m]["states"], runs["conventional", m]["states"]
        assert all(d[n]["sigma"] < c[n]["sigma"] for n in sensors), m
    for label in ("designed", "conventional"):
        b = runs[label, "both"]["states"]
        for n in sensors:
            assert b[n]["sigma"] <= 1.001 * min(runs[label, "velocity"]["states"][n]["sigma"],
                                                runs[label, "position"]["states"][n]["sigma"])
    assert "Table 3" in res.output or "Table 3" in res.stderr
    res = runner.invoke(app, ["plot", str(out), "-o", str(tmp_path / "p")])
    assert res.exit_code == 0, res.output


@pytest.mark.slow
def test_zero_velocity_alignment_on_lasergyro(tmp_path):
    """Must-show 5: the same filter as a zero-velocity fine alignment on the parked vehicle
    (configs/lasergyro_calibrate.yaml: inertial-frame coarse alignment over 60 s, then
    340 s of zero-velocity updates at 1 Hz, navigation at 100 Hz): yaw within 0.1° of the
    header's −90.6°, and within 0.05° of the gyrocompass of configs/lasergyro_align.yaml
    on the same window (pitch and roll within 0.01°)."""
    res = _cal(ROOT / "configs/lasergyro_calibrate.yaml", "--json", "-o", tmp_path / "z.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["aiding"] == "zero-velocity" and s["seed"] is None
    assert s["states"]["ebx"]["truth"] is None and s["nees"] is None
    yaw = s["attitude_deg"][2]
    assert yaw == pytest.approx(-90.6, abs=0.1)
    res = runner.invoke(app, ["align", str(ROOT / "configs/lasergyro_align.yaml"), "--json",
                              "-o", str(tmp_path / "a.h5")])
    assert res.exit_code == 0, res.output
    gyro = json.loads(res.stdout)["attitude_t2_deg"]
    assert yaw == pytest.approx(gyro[2], abs=0.05)
    np.testing.assert_allclose(s["attitude_deg"][:2], gyro[:2], atol=0.01)
    res = runner.invoke(app, ["plot", str(tmp_path / "z.h5"), "-o", str(tmp_path / "p"),
                              "--json"])
    names = {Path(p).stem for p in json.loads(res.stdout)["figures"]}
    assert "attitude" in names and "trajectory" not in names


@pytest.mark.slow
def test_batch_monte_carlo_matches_single_runs(tmp_path):
    """Batch over calibrate (truth drawn from P0 per seed, 2 workers): every run's metrics
    equal the single run of the same seed, and the default metrics are NEES and the
    normalised errors of the 21 states."""
    from gcalign.app.calibrate.run import execute
    from gcalign.io.scenario import parse_scenario

    base = copy.deepcopy(SHORT_CAL)
    base["calibrate"] |= {"truth": "draw", "p0_scale": 1}
    sweep = {"name": "mc", "base": base, "command": "calibrate", "seeds": 4}
    p = _write(tmp_path, sweep, "mc.yaml")
    res = runner.invoke(app, ["batch", str(p), "--workers", "2", "-o", str(tmp_path / "mc.h5"),
                              "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["failed"] == 0 and s["metrics"] == ["nees.final", "normalized_error"]
    with h5py.File(tmp_path / "mc.h5") as f:
        nees = f["batch/runs/metrics/nees.final"][()]
        seeds = f["batch/runs/seed"][()]
    for seed, value in zip(seeds, nees, strict=True):
        single = execute(parse_scenario(copy.deepcopy(base), "mc"), int(seed)).summary
        assert value == pytest.approx(single["nees"]["final"], rel=1e-12)


def test_window_and_zero_velocity_aiding_on_a_simulation(tmp_path):
    """calibrate.start_s / duration_s cut the flight (the INS starts from the truth there
    with the initial errors). Zero-velocity aiding on the 30 s static stage of a simulation
    is the lasergyro case with a known truth: consistent within 3σ, and the level tilt φN
    tied to ∇E (the static pair g φN = ∇E, DESIGN "static steady state"): its σ falls to
    the closed form σ_φ σ_∇/g / √(σ_φ² + (σ_∇/g)²) = 91.5″ of the two priors (200″,
    500 µg), within 10 %; φE stays above it (the heading prior, 300′, leaks into it through
    Ω cos L · φU)."""
    d = copy.deepcopy(SHORT_CAL)
    d["calibrate"] |= {"start_s": 20, "duration_s": 100}
    res = _cal(_write(tmp_path, d), "--json", "-o", tmp_path / "w.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["window_s"] == [20, 20, 120] and s["epochs"] == 101
    assert s["segments"][0]["t0_s"] == 20 and s["segments"][-1]["t1_s"] == 120
    d = copy.deepcopy(SHORT_CAL)
    d["motion"]["segments"][0]["duration_s"] = 60
    d["calibrate"] |= {"aiding": "zero-velocity", "duration_s": 60}
    res = _cal(_write(tmp_path, d), "--json", "-o", tmp_path / "z.h5")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["aiding"] == "zero-velocity"
    assert max(abs(x) for x in s["normalized_error"]) < 3
    st = s["states"]
    sp, sn = st["phiN"]["sigma0"], st["dbx"]["sigma0"] / 9.8
    closed = sp * sn / np.hypot(sp, sn)
    assert st["phiN"]["sigma"] == pytest.approx(closed, rel=0.1)
    assert st["phiE"]["sigma"] > st["phiN"]["sigma"]


def _bad(tmp_path: Path, args, field: str, *more: str):
    out = tmp_path / "out.h5"
    assert_bad_input(_cal(*args, "-o", out), out, field, *more)


@pytest.mark.parametrize(
    ("change", "field", "more"),
    [
        ({"calibrate": {"measure": "heading"}}, "calibrate.measure", ("'velocity'",)),
        ({"calibrate": {"sigma_v_mps": 0}}, "calibrate.sigma_v_mps",
         ("must be within [0.001, 1000] m/s", "got 0")),
        ({"calibrate": {"sigma_p_m": -1}}, "calibrate.sigma_p_m",
         ("must be within [0.001, 1e+06] m", "got -1")),
        ({"calibrate": {"p0_scale": 0}}, "calibrate.p0_scale",
         ("must be within [0.001, 1000]", "got 0")),
        ({"calibrate": {"p0": {"gyro_bias_dph": [0.01, 0, 0.01]}}},
         "calibrate.p0.gyro_bias_dph.1", ("greater than 0",)),
        ({"calibrate": {"filter_rate_hz": 2}}, "calibrate.filter_rate_hz",
         ("25 Hz divided by a whole number", "got 2")),
        ({"calibrate": {"navigation_rate_hz": 30}}, "calibrate.navigation_rate_hz",
         ("100 Hz divided by a whole number", "got 30")),
        ({"calibrate": {"duration_s": 1000}}, "calibrate.duration_s", ("after the end",)),
        ({"calibrate": {"smoother": "maybe"}}, "calibrate.smoother", ()),
        ({"motion": {"envelope": {"max_height_m": 900}}}, "motion.envelope.max_height_m",
         ("climbs 927 m", "900 m")),
        ({"motion": {"envelope": {"max_horizontal_m": 5000}}},
         "motion.envelope.max_horizontal_m", ("5000 m",)),
        ({"segment": {"kind": "pitch", "rate_dps": 2, "angle_deg": 20, "duration_s": 5}},
         "motion.segments", ("needs 10 s", "duration 5 s")),
        ({"segment": {"kind": "roll", "rate_dps": 0, "angle_deg": 20}},
         "motion.segments.2.rate_dps", ("greater than 0",)),
    ],
)
def test_bad_scenario_exits_2_with_one_line(tmp_path, change, field, more):
    """Must-show 7: unknown measurement, non-positive R or P0, a filter rate that does not
    divide the navigation rate, a navigation rate that does not divide the IMU rate, a
    window past the data, a trajectory leaving the envelope, a segment whose target cannot
    be reached at its rate within its duration: exit 2, one line naming the field."""
    d = copy.deepcopy(SHORT_CAL)
    for key, values in change.items():
        if key == "segment":
            d["motion"]["segments"][2] = values
        else:
            d[key] = {**d[key], **values}
    _bad(tmp_path, [_write(tmp_path, d)], field, *more)


@pytest.mark.parametrize(
    ("args", "field"),
    [(["--measure", "heading"], "calibrate.measure"),
     (["--truth", "random"], "calibrate.truth")],
)
def test_bad_options_exit_2(tmp_path, args, field):
    _bad(tmp_path, args, field)


def test_recorded_data_start_where_the_user_says(tmp_path):
    """Without a coarse alignment the start is the user's: a recording whose file has no
    header, with no initial keys and no reference, is refused naming the ways to give one;
    PSINS's header gives one (said in the JSON); a coarse alignment beside initial keys
    cannot matter and is refused."""
    mat = {"name": "rec", "imu_file": str(ROOT / "tests/data/transfer_align_fog_mems.mat"),
           "site": {"lat_deg": 34.0, "lon_deg": 108.0},
           "calibrate": {"coarse": {"method": "none"}}}
    _bad(tmp_path, [_write(tmp_path, mat)], "initial:", "gives no initial attitude",
         "initial: {att_deg")
    d = {"name": "rec", "imu_file": str(ROOT / "tests/data/lasergyro.imu.xz"),
         "calibrate": {"duration_s": 30}}
    res = runner.invoke(app, ["calibrate", str(_write(tmp_path, d)), "-o",
                              str(tmp_path / "h.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert s["start"]["source"] == "the file's header" and s["coarse_attitude_deg"] is None
    assert s["start"]["attitude_deg"][2] == pytest.approx(-90.6, abs=0.01)  # the header's yaw
    both = dict(d, initial={"att_deg": [0, 0, -90]},
                calibrate={"coarse": {"method": "inertial"}})
    _bad(tmp_path, [_write(tmp_path, both)], "calibrate.coarse.method", "cannot matter",
         "the start comes from initial")


def test_compare_needs_more_segments_than_the_conventional_take_off(tmp_path):
    d = copy.deepcopy(SHORT_CAL)
    d["calibrate"]["conventional_segments"] = 12
    _bad(tmp_path, [_write(tmp_path, d), "--compare"], "calibrate.conventional_segments",
         "more than 12 segments")


def test_validate_lists_the_sections():
    res = runner.invoke(app, ["validate", str(DESIGNED), "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    assert values["calibrate.navigation_rate_hz"]["value"] == "25 Hz"
    assert "observability.scaling" in values


def test_batch_seeds_share_the_trajectory_and_keep_their_numbers():
    """A batch's seeds (a cache key: the noise-free simulation shared) take the truth's
    trajectory from the first seed's (computed once, read-only) and get the flight each
    gets alone, field by field to the bit (the filter's runs: the slow test above)."""
    from dataclasses import fields

    from gcalign.app.batch.runs import noise_free_key
    from gcalign.app.calibrate.run import simulated_case
    from gcalign.io.scenario import parse_scenario

    d = copy.deepcopy(SHORT_CAL)
    d["calibrate"] |= {"truth": "draw", "p0_scale": 1}
    sc = parse_scenario(d, "mc")
    key = noise_free_key(sc)
    cases = []
    for seed in (3, 4):
        shared, alone = simulated_case(sc, seed, key), simulated_case(sc, seed)
        for f in fields(shared.data):
            a, b = getattr(shared.data, f.name), getattr(alone.data, f.name)
            if f.name == "truth":
                for g in fields(a):
                    assert np.array_equal(getattr(a, g.name), getattr(b, g.name)) \
                        if isinstance(getattr(a, g.name), np.ndarray) else \
                        getattr(a, g.name) == getattr(b, g.name), g.name
            elif isinstance(a, np.ndarray):
                assert np.array_equal(a, b), f.name
        for name, value in vars(shared.data.start).items():  # the INS start, perturbed
            assert np.array_equal(value, getattr(alone.data.start, name)), name
        cases.append(shared)
    assert cases[0].data.truth is cases[1].data.truth  # one trajectory for the seeds
    assert not cases[0].data.truth.f_b.flags.writeable
    assert not np.array_equal(cases[0].data.dtheta, cases[1].data.dtheta)
