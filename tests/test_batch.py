"""`gcalign batch`: sweep validation, the engine (local pool, Dask), journal and resume.

The reference for every aggregate is the same sweep run another way (one worker, an
uninterrupted batch, the single-run pipeline): a batch must not change the numbers.
"""

from __future__ import annotations

import copy
import json
import shutil
import socket
import subprocess
import sys
import time
from concurrent.futures import Future
from importlib import resources
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from gcalign.app.batch.backends import WorkerLost, local_workers
from gcalign.app.batch.engine import _tasks, run_batch
from gcalign.app.batch.overrides import apply_override
from gcalign.app.batch.runs import kernel_cache_stats, run_chunk, run_summary, warm_up
from gcalign.app.batch.store import Journal, journal_path
from gcalign.app.batch.sweep import load_sweep, sweep_from_mapping
from gcalign.cli import app
from gcalign.errors import ScenarioError
from gcalign.io.scenario import parse_scenario

runner = CliRunner()

# The seed 000 §5.3 moving scenario shortened: 80 s of data, T2 = 60 s, 3 passes.
SMALL = {
    "name": "small-moving",
    "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0},
    "imu": {"rate_hz": 100,
            "gyro": {"bias_dph": [0.01, 0.01, 0.01], "arw_dprh": 0.001},
            "accel": {"bias_ug": [50, 50, 50], "vrw_ugrhz": 10}},
    "motion": {"kind": "moving", "attitude_deg": [0, 0, 30], "duration_s": 80,
               "segments": [{"duration_s": 10}, {"duration_s": 10, "accel_mps2": 1.0},
                            {"duration_s": 10, "rate_dps": [0, 0, -1]},
                            {"duration_s": 10, "rate_dps": [0, 0, 1]}, {"duration_s": 40}]},
    "align": {"coarse": {"method": "given", "error_deg": [1, 1, 10]}, "mode": "full-cycle",
              "t1_s": 10, "t2_s": 60, "t3_s": 70, "stages": [{"passes": 3}], "level_s": 20,
              "azimuth_poles": "double-oscillator",
              "aiding": {"source": "odometer", "noise_mps": 0.01}},
}
GRID = {"align.mode": ["conventional", "full-cycle", "half-cycle"],
        "align.stages.0.t_z_s": [40, 60]}
METRICS = ["error_t3_deg", "passes.0.error_deg"]


def write_sweep(folder: Path, name: str = "sweep", **over) -> Path:
    d = {"name": name, "base": copy.deepcopy(SMALL), "grid": copy.deepcopy(GRID), "seeds": 4,
         "metrics": list(METRICS)}
    d.update(over)
    p = folder / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    return p


def batch_cli(*args):
    return runner.invoke(app, ["batch", *map(str, args)])


def runs_of(path: Path) -> list[tuple[int, int]]:
    with h5py.File(path, "r") as f:
        r = f["batch/runs"]
        return list(zip(r["variant"][()].tolist(), r["seed"][()].tolist(), strict=True))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The small sweep with one local worker: summary, sweep file and output."""
    folder = tmp_path_factory.mktemp("ref")
    sweep = write_sweep(folder)
    out = folder / "ref.h5"
    res = batch_cli(sweep, "--workers", 1, "-o", out, "--json")
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), sweep, out


# ------------------------------------------------------------------ sweep model


def test_grid_is_a_cartesian_product_in_grid_order(tmp_path):
    sw = load_sweep(write_sweep(tmp_path))
    assert len(sw.variants) == 6 and sw.seed_values == range(1, 5)
    assert sw.variants[1].overrides == {"align.mode": "conventional", "align.stages.0.t_z_s": 60}
    assert sw.run_keys()[:5] == [(0, 1), (0, 2), (0, 3), (0, 4), (1, 1)]
    assert sw.command == "align"  # from the base's align section
    sc = parse_scenario(copy.deepcopy(sw.variants[5].scenario))
    assert sc.align.mode == "half-cycle" and sc.align.stages[0].t_z_s == 60
    # The base gives no stages: the default stage list was filled in, its defaults kept.
    assert sc.align.stages[0].t_xy_s == 20.0 and len(sc.align.stages) == 1


def test_seed_start_and_command_from_northfind_section(tmp_path):
    base = str(Path(resources.files("gcalign")).parent / "configs/seed001_simulation.yaml")
    sw = sweep_from_mapping({"base": base, "seeds": 3, "seed_start": 10,
                               "grid": {"northfind.tilt_deg": [0, 5]}}, "s.yaml", tmp_path)
    assert sw.command == "northfind" and list(sw.seed_values) == [10, 11, 12]


def test_apply_override_checks_the_schema_not_only_the_mapping():
    base = parse_scenario(copy.deepcopy(SMALL))
    d = copy.deepcopy(SMALL)
    apply_override(d, "align.coarse.error_deg.2", 5.0, base)
    assert d["align"]["coarse"]["error_deg"] == [1, 1, 5.0]
    with pytest.raises(ScenarioError, match=r"align.mdoe: unknown key; align has: .*mode"):
        apply_override(copy.deepcopy(SMALL), "align.mdoe", "x", base)
    with pytest.raises(ScenarioError, match=r"no item 5; align.stages has 1 item\(s\): index 0"):
        apply_override(copy.deepcopy(SMALL), "align.stages.5.t_z_s", 100, base)
    with pytest.raises(ScenarioError, match="single value"):
        apply_override(copy.deepcopy(SMALL), "align.t2_s.x", 1, base)
    # An optional section the base leaves out is still checked against its model.
    no_align = {k: v for k, v in copy.deepcopy(SMALL).items() if k != "align"}
    base2 = parse_scenario(copy.deepcopy(no_align))
    with pytest.raises(ScenarioError, match="align.foo: unknown key"):
        apply_override(copy.deepcopy(no_align), "align.foo", 1, base2)
    d2 = copy.deepcopy(no_align)
    apply_override(d2, "align.mode", "conventional", base2)
    assert d2["align"] == {"mode": "conventional"}


@pytest.mark.parametrize(("grid", "message"), [
    ({"align.mdoe": ["full-cycle"]}, "grid: align.mdoe = 'full-cycle': align.mdoe: unknown key"),
    ({"align.mode": []}, "grid: align.mode = []: empty list of values"),
    ({"align.stages.5.t_z_s": [100]}, "align.stages.5: no item 5; align.stages has 1 item"),
    ({"align.mode": ["fast"]}, "grid: align.mode = 'fast': align.mode: Input should be"),
    ({"align.stages.0.passes": [3, 4]},
     "grid: align.stages.0.passes = 4: align.stages: mode 'full-cycle' needs an odd number"),
])
def test_bad_grid_exits_2_before_any_run(tmp_path, grid, message):
    out = tmp_path / "o.h5"
    res = batch_cli(write_sweep(tmp_path, grid=grid), "-o", out)
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], res.stderr
    assert "Traceback" not in res.output
    assert not out.exists() and not journal_path(out).exists()
    checked = runner.invoke(app, ["validate", str(tmp_path / "sweep.yaml")])
    assert checked.exit_code == 2 and checked.stderr == res.stderr  # validate says the same


def test_validate_of_a_sweep_says_what_the_batch_would_run(tmp_path):
    res = runner.invoke(app, ["validate", str(write_sweep(tmp_path)), "--json"])
    assert res.exit_code == 0, res.output
    sw = json.loads(res.stdout)["sweep"]
    assert (sw["command"], sw["runs"], sw["seeds"], sw["metrics"]) == ("align", 24, [1, 2, 3, 4],
                                                                       METRICS)
    assert sw["variants"][:2] == ["align.mode=conventional, align.stages.0.t_z_s=40",
                                  "align.mode=conventional, align.stages.0.t_z_s=60"]
    ran = runner.invoke(app, ["align", str(tmp_path / "sweep.yaml")])
    assert ran.exit_code == 2 and "a sweep file (it has 'base'): run it with gcalign batch" \
        in ran.stderr
    shown = runner.invoke(app, ["validate", str(tmp_path / "sweep.yaml")])
    assert shown.exit_code == 0 and "valid" in shown.stdout
    assert [ln.split()[1:4] for ln in shown.stdout.splitlines() if "│ runs" in ln] == [
        ["runs", "│", "24"]]


def test_a_grid_key_that_cannot_matter_is_a_warning_of_validate_and_batch(tmp_path):
    """Conventional real-time alignment runs on to T3: compensation cannot matter, and the
    two variants come out the same; both commands say so before anything runs."""
    base = copy.deepcopy(SMALL)
    base["align"] |= {"mode": "conventional", "stages": [{}]}
    p = write_sweep(tmp_path, base=base, grid={"align.compensation": ["none", "continued"]},
                    seeds=1)
    line = "align.compensation: 'none' cannot matter in real-time conventional mode"
    checked = runner.invoke(app, ["validate", str(p), "--json"])
    assert checked.exit_code == 0 and line in json.loads(checked.stdout)["warnings"][0]
    res = batch_cli(p, "--workers", 1, "--json", "-o", tmp_path / "w.h5")
    assert res.exit_code == 0, res.output
    assert res.stderr.startswith(f"warning: {line}")
    assert line in json.loads(res.stdout)["warnings"][0]
    a, b = (v["stats"]["error_t3_deg"] for v in json.loads(res.stdout)["variants"])
    assert a == b  # what the warning says


def test_bad_sweep_keys_and_options(tmp_path):
    has = "the sweep has: name, base, command, cases, grid, seeds, seed_start, metrics"
    res = batch_cli(write_sweep(tmp_path, frobnicate=1))
    assert res.exit_code == 2 and f"frobnicate: unknown key; {has}" in res.stderr
    with pytest.raises(ScenarioError) as err:  # the misspelt key is named, not the base
        sweep_from_mapping({"bse": "s.yaml", "grid": {}, "Seeds": 2}, "sw.yaml")
    assert str(err.value).splitlines() == [f"sw.yaml: bse: unknown key; {has}",
                                           f"sw.yaml: Seeds: unknown key; {has}"]
    res = batch_cli(write_sweep(tmp_path, seeds=0))
    assert res.exit_code == 2 and "seeds: must be a whole number" in res.stderr
    res = batch_cli(write_sweep(tmp_path), "--workers", 0)
    assert res.exit_code == 2 and "--workers" in res.stderr
    res = batch_cli(write_sweep(tmp_path), "--workers", 2, "--scheduler", "tcp://x:1")
    assert res.exit_code == 2


def test_unknown_metric_stops_the_batch_with_exit_2(tmp_path):
    out = tmp_path / "m.h5"
    sweep = write_sweep(tmp_path, grid={}, seeds=2, metrics=["error_t9_deg"])
    res = batch_cli(sweep, "--workers", 1, "-o", out)
    assert res.exit_code == 2, res.output
    assert "metric 'error_t9_deg'" in res.stderr and "error_t3_deg" in res.stderr


def test_cases_are_crossed_with_the_grid_and_applied_first(tmp_path):
    """A case sets several keys together; variants = cases × grid, the case first in the
    overrides and in the canonical order; a grid value is applied after the case's."""
    cases = {"noisy": {}, "quiet": {"imu.gyro": {"bias_dph": [0.01, 0.01, 0.01]},
                                    "imu.accel.vrw_ugrhz": 0, "align.stages.0.t_z_s": 30}}
    sw = load_sweep(write_sweep(tmp_path, cases=cases))
    assert list(sw.grid) == ["case", "align.mode", "align.stages.0.t_z_s"]
    assert sw.grid["case"] == ["noisy", "quiet"] and sw.cases == cases
    assert len(sw.variants) == 12
    v = sw.variants[7]
    assert v.overrides == {"case": "quiet", "align.mode": "conventional",
                           "align.stages.0.t_z_s": 60}
    assert v.label == "case=quiet, align.mode=conventional, align.stages.0.t_z_s=60"
    sc = parse_scenario(copy.deepcopy(v.scenario))
    assert sc.imu.gyro.arw_dprh == [0.0, 0.0, 0.0] and sc.imu.accel.vrw_ugrhz == [0.0] * 3
    assert sc.imu.gyro.bias_dph == [0.01] * 3 and sc.align.stages[0].t_z_s == 60  # grid wins
    noisy = parse_scenario(copy.deepcopy(sw.variants[1].scenario))
    assert noisy.imu.gyro.arw_dprh == [0.001] * 3
    assert len(set(sw.keys)) == 12  # every variant its own runs


@pytest.mark.parametrize(("cases", "grid", "message"), [
    ({"q": {"imu.gyro.arw": 0}}, GRID, "cases: q: imu.gyro.arw = 0: imu.gyro.arw: unknown key"),
    ({"q": [1]}, GRID, "cases.q: must be a mapping"),
    ([], GRID, "cases: must be a non-empty mapping"),
    ({"q": {"align.stages.0.passes": 4}}, GRID,
     "cases: q: align.stages: mode 'full-cycle' needs an odd number"),
    ({"q": {}}, {"case": ["a"]}, "grid.case: reserved"),
])
def test_bad_cases_exit_2_before_any_run(tmp_path, cases, grid, message):
    out = tmp_path / "o.h5"
    res = batch_cli(write_sweep(tmp_path, cases=cases, grid=grid), "-o", out)
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], res.stderr
    assert not out.exists()


def test_cases_in_the_file_and_the_table(tmp_path):
    out = tmp_path / "c.h5"
    sweep = write_sweep(tmp_path, cases={"a": {}, "b": {"imu.accel.vrw_ugrhz": 0}},
                        grid={"align.mode": ["conventional"]}, seeds=2,
                        metrics=["error_t3_deg.2"])
    res = batch_cli(sweep, "--workers", 1, "-o", out, "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["cases"] == {"a": {}, "b": {"imu.accel.vrw_ugrhz": 0}}
    assert [v["overrides"]["case"] for v in s["variants"]] == ["a", "b"]
    assert s["variants"][0]["stats"]["error_t3_deg.2"]["units"] == "deg"
    with h5py.File(out, "r") as f:
        assert json.loads(f["batch"].attrs["cases_json"]) == s["cases"]
        assert f["batch/aggregate/v001"].attrs["case"] == "b"
    res = runner.invoke(app, ["show", str(out)])
    assert res.exit_code == 0 and "case=b" in res.stdout


# ------------------------------------------------------------------ engine


def test_batch_equals_single_runs(reference):
    """The batch's numbers are those of the single-run pipeline (`gcalign align --seed`),
    also with the noise-free simulation shared between seeds."""
    summary, sweep, out = reference
    sw = load_sweep(sweep)
    v = sw.variants[3]
    sc = parse_scenario(copy.deepcopy(v.scenario))
    from gcalign.app.align.run import alignment_summary, run_alignment
    from gcalign.app.data import scenario_data

    values = []
    for seed in sw.seed_values:
        data = scenario_data(sc, seed)
        s = alignment_summary(run_alignment(sc, data), data, sc.name)
        values.append(s["error_t3_deg"])
        cached = run_summary("align", sc, seed, cache_key="test")
        assert cached["error_t3_deg"] == s["error_t3_deg"]  # bit for bit
    st = summary["variants"][3]["stats"]["error_t3_deg"]
    arr = np.array(values)
    np.testing.assert_array_equal(st["mean"], arr.mean(0))
    np.testing.assert_array_equal(st["rms"], np.sqrt((arr**2).mean(0)))
    np.testing.assert_array_equal(st["p95"], np.percentile(arr, 95, axis=0))
    assert st["components"] == ["pitch", "roll", "yaw"] and st["units"] == "deg"


def test_noise_free_key_shared_only_where_the_simulation_is_the_same(tmp_path):
    """Variants that change mode, T_z or sensor errors share the noise-free simulation;
    a different motion, site or IMU rate does not."""
    from gcalign.app.batch.runs import noise_free_key

    sw = load_sweep(write_sweep(tmp_path, cases={"a": {}, "b": {"imu.gyro.arw_dprh": 0}}))
    keys = {noise_free_key(parse_scenario(copy.deepcopy(v.scenario))) for v in sw.variants}
    assert len(keys) == 1 and None not in keys
    for key, value in (("motion.duration_s", 70), ("site.lat_deg", 30.0), ("imu.rate_hz", 50)):
        d = copy.deepcopy(SMALL)
        apply_override(d, key, value, parse_scenario(copy.deepcopy(SMALL)))
        assert noise_free_key(parse_scenario(d)) not in keys, key


def test_same_aggregate_with_one_and_two_workers(reference, tmp_path):
    ref, sweep, ref_out = reference
    out = tmp_path / "w2.h5"
    res = batch_cli(sweep, "--workers", 2, "-o", out, "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["variants"] == ref["variants"]
    assert s["runs"] == s["ok"] == 24 and s["failed"] == 0 and s["complete"]
    assert runs_of(out) == runs_of(ref_out) == load_sweep(sweep).run_keys()
    assert not journal_path(out).exists()  # complete: the file holds everything
    with h5py.File(out, "r") as f:
        assert f.attrs["kind"] == "batch"
        assert json.loads(f.attrs["summary_json"])["variants"] == ref["variants"]
        g = f["batch/aggregate/v005"]
        assert g.attrs["align.mode"] == "half-cycle" and g.attrs["align.stages.0.t_z_s"] == 60
        np.testing.assert_array_equal(g["error_t3_deg/median"][()],
                                      ref["variants"][5]["stats"]["error_t3_deg"]["median"])
        assert f["batch/runs/metrics/error_t3_deg"].shape == (24, 3)
        assert f["batch/runs/metrics/error_t3_deg"].attrs["units"] == "deg"
    # `gcalign show` prints the batch table again from the file alone.
    res = runner.invoke(app, ["show", str(out)])
    assert res.exit_code == 0, res.output
    assert "gcalign batch: sweep" in res.stdout and "error_t3_deg" in res.stdout
    assert "half-cycle" in res.stdout


@pytest.mark.slow
def test_numba_cache_is_loaded_not_compiled_in_fresh_processes():
    """A fresh process (a single CLI run) loads the align kernels from the on-disk cache;
    pool workers forked after the parent's warm-up inherit them: no cache load, no compile."""
    warm_up()  # populates the on-disk cache if this checkout has none yet
    code = "import json; from gcalign.app.batch.runs import warm_up; print(json.dumps(warm_up()))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    stats = json.loads(out.stdout)
    assert stats["cache_hits"] >= 1 and stats["cache_misses"] == 0, stats
    backend = local_workers(1, "align")
    parent = kernel_cache_stats()
    try:
        for s in [backend.executor.submit(warm_up).result()]:
            if backend.start_method == "fork":  # inherited: nothing new loaded or compiled
                assert (s["cache_hits"], s["cache_misses"]) == (
                    parent["cache_hits"], parent["cache_misses"]), (s, parent)
            else:  # a fresh interpreter: loaded from the cache
                assert s["cache_misses"] == 0, s
    finally:
        backend.close()


def test_failing_runs_are_recorded_and_exit_1(tmp_path):
    # Loops of nanosecond periods pass validation but diverge: a result that is not finite
    # is a failed run (robustness class 6), recorded, the others go on.
    stages = [[{"t_xy_s": 20, "t_z_s": 60}], [{"t_xy_s": 1e-9, "t_z_s": 1e-9}]]
    sweep = write_sweep(tmp_path, grid={"align.stages": stages}, seeds=2,
                        metrics=["error_t3_deg"])
    out = tmp_path / "f.h5"
    res = batch_cli(sweep, "--workers", 1, "-o", out, "--json")
    assert res.exit_code == 1, res.output
    s = json.loads(res.stdout)
    assert (s["ok"], s["failed"]) == (2, 2)
    assert s["variants"][0]["ok"] == 2 and s["variants"][1]["failed"] == 2
    assert "not finite" in s["failures"][0]["error"]
    with h5py.File(out, "r") as f:
        status = [x.decode() for x in f["batch/runs/status"][()]]
        assert status == ["ok", "ok", "failed", "failed"]
        assert np.isnan(f["batch/runs/metrics/error_t3_deg"][2]).all()
        assert "diverged" in f["batch/runs/error"][2].decode()


class _FlakyBackend:
    """In-process executor whose worker "dies" whenever it meets seed 2 of variant 0."""

    workers = 2
    description = "fake"

    def __init__(self):
        self.submitted = []

    def submit(self, chunk):
        self.submitted.append([(t["variant"], t["seed"]) for t in chunk])
        fut = Future()
        if any((t["variant"], t["seed"]) == (0, 2) for t in chunk):
            fut.set_exception(WorkerLost("killed"))
        else:
            fut.set_result(run_chunk(chunk))
        return fut

    def wait(self, futures, timeout):
        return set(futures)

    def result(self, fut):
        return fut.result()

    def close(self, cancel=False):
        pass


def test_a_dying_worker_costs_only_its_own_run(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, grid={"align.mode": ["full-cycle"]}, seeds=6,
                                  metrics=["error_t3_deg"]))
    fake = _FlakyBackend()
    res = run_batch(sw, tmp_path / "k.h5", backend=fake, chunk_size=3)
    s = res.summary
    assert (s["ok"], s["failed"]) == (5, 1)
    assert "worker process died" in s["failures"][0]["error"] and s["failures"][0]["seed"] == 2
    # The chunk was retried run by run: its other runs were not lost.
    assert [(0, 1)] in fake.submitted and [(0, 3)] in fake.submitted
    assert runs_of(tmp_path / "k.h5") == sw.run_keys()


# ------------------------------------------------------------------ journal and resume


def test_resume_skips_a_torn_journal_line(tmp_path):
    sw = load_sweep(write_sweep(tmp_path, grid={"align.mode": ["full-cycle"]}, seeds=5,
                                  metrics=["error_t3_deg"]))
    out = tmp_path / "t.h5"
    tasks = _tasks(sw, sw.run_keys()[:3])
    journal = Journal(journal_path(out), {"type": "header"})
    journal.append(run_chunk(tasks))
    journal.close()
    with open(journal_path(out), "a") as f:
        f.write('{"type": "run", "variant": 0, "se')  # killed mid-write
    res = run_batch(sw, out, workers=1, resume=True)
    assert res.reused == 3 and res.summary["ok"] == 5
    assert runs_of(out) == sw.run_keys()
    fresh = run_batch(sw, tmp_path / "u.h5", workers=1)
    assert fresh.summary["variants"] == res.summary["variants"]


@pytest.fixture
def recorded(lasergyro, tmp_path) -> Path:
    """A folder with the first 80 s of lasergyro.imu (its header, then 100 Hz rows), a
    scenario that names it by a relative path, and a sweep of two windows of it."""
    folder = tmp_path / "A"
    (folder / "data").mkdir(parents=True)
    lines = lasergyro.read_text(encoding="utf-8").splitlines(keepends=True)
    (folder / "data" / "short.imu").write_text("".join(lines[:8000]), encoding="utf-8")
    base = {"imu_file": "data/short.imu",
            "align": {"coarse": {"method": "inertial"}, "mode": "conventional", "t1_s": 20,
                      "t2_s": 60, "t3_s": 60, "level_s": 10}}
    (folder / "base.yaml").write_text(yaml.safe_dump(base))
    (folder / "sweep.yaml").write_text(yaml.safe_dump(
        {"base": "base.yaml", "grid": {"align.start_s": [0, 10]}, "metrics": ["attitude_t2_deg"]}))
    return folder


def _change_latitude(recording: Path) -> None:
    """The same recording with another site latitude in its header (line 13 of PSINS)."""
    lines = recording.read_text(encoding="utf-8").splitlines(keepends=True)
    assert lines[12].startswith("34.24604800 ")
    lines[12] = "40" + lines[12][2:]
    recording.write_text("".join(lines), encoding="utf-8")


def _batch_of(folder: Path, *options) -> tuple[dict, str, str]:
    """The summary, stderr and fingerprint of the folder's sweep batched into out.h5."""
    res = batch_cli(folder / "sweep.yaml", "--workers", 1, "-o", folder / "out.h5", "--json",
                    *options)
    assert res.exit_code == 0, res.output
    with h5py.File(folder / "out.h5", "r") as f:
        return json.loads(res.stdout), res.stderr, str(f["batch"].attrs["fingerprint"])


def test_a_moved_or_copied_folder_resumes_its_batch(recorded, tmp_path):
    """A recording is known by its content, not its path: the batch of a folder moved or
    copied elsewhere resumes with every run finished, under the same fingerprint."""
    first, _, fingerprint = _batch_of(recorded)
    copied = shutil.copytree(recorded, tmp_path / "elsewhere" / "B")
    moved = Path(shutil.move(recorded, tmp_path / "C"))
    for folder in (copied, moved):
        summary, err, again = _batch_of(folder, "--resume")
        assert "2 of 2 run(s) already finished" in err
        assert again == fingerprint and summary["variants"] == first["variants"]


def test_a_recording_changed_in_place_runs_again(recorded):
    """The same path with another content: no run of the old recording is resumed, and the
    file then holds what a fresh batch of the new one gives."""
    first, _, fingerprint = _batch_of(recorded)
    _change_latitude(recorded / "data" / "short.imu")
    resumed, err, again = _batch_of(recorded, "--resume")
    assert "0 of 2 run(s) already finished" in err and again != fingerprint
    (recorded / "out.h5").unlink()
    fresh, _, _ = _batch_of(recorded)
    assert resumed["variants"] == fresh["variants"] != first["variants"]


def test_a_worker_reads_a_recording_changed_in_place_again(recorded):
    """A worker keeps a variant's scenario and recording as read between batches (a Dask
    worker lives on): the same variant of a changed recording is another one, read again,
    its numbers those of a single run."""
    from gcalign.app.batch.runs import run_task

    def run(sweep):
        return run_task(_tasks(sweep, [(0, 1)])[0])["metrics"]["attitude_t2_deg"]

    before = run(load_sweep(recorded / "sweep.yaml"))
    _change_latitude(recorded / "data" / "short.imu")
    sweep = load_sweep(recorded / "sweep.yaml")
    single = run_summary("align", parse_scenario(copy.deepcopy(sweep.variants[0].scenario)), 1)
    assert run(sweep) == single["attitude_t2_deg"] != before


@pytest.mark.slow
def test_resume_from_the_file_with_more_seeds_reuses_what_is_there(reference, tmp_path):
    ref, sweep, ref_out = reference
    out = tmp_path / "grow.h5"
    out.write_bytes(ref_out.read_bytes())  # complete batch of 4 seeds, no journal
    bigger = write_sweep(tmp_path, name="sweep", seeds=5)
    res = batch_cli(bigger, "--workers", 2, "-o", out, "--resume", "--json")
    assert res.exit_code == 0, res.output
    assert "24 of 30 run(s) already finished" in res.stderr
    s = json.loads(res.stdout)
    assert s["runs"] == s["ok"] == 30 and runs_of(out) == load_sweep(bigger).run_keys()
    fresh = run_batch(load_sweep(bigger), tmp_path / "fresh.h5", workers=2)
    assert fresh.summary["variants"] == s["variants"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_unreachable_scheduler_fails_fast_and_keeps_the_journal(tmp_path):
    sw_path = write_sweep(tmp_path, grid={"align.mode": ["full-cycle"]}, seeds=3,
                          metrics=["error_t3_deg"])
    sw = load_sweep(sw_path)
    out = tmp_path / "d.h5"
    journal = Journal(journal_path(out), {"type": "header"})
    journal.append(run_chunk(_tasks(sw, sw.run_keys()[:1])))
    journal.close()
    before = journal_path(out).read_bytes()
    t0 = time.monotonic()
    res = batch_cli(sw_path, "--scheduler", f"tcp://127.0.0.1:{_free_port()}", "-o", out,
                    "--resume")
    assert res.exit_code == 1, res.output
    assert time.monotonic() - t0 < 120  # no hang (the time bound: benchmarks/bench_batch.py)
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:" in res.stderr
    assert len(res.stderr.strip().splitlines()) <= 2 and "Traceback" not in res.output
    assert journal_path(out).read_bytes() == before and not out.exists()


@pytest.mark.slow
def test_dask_cluster_gives_the_local_numbers(reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    ref, sweep, _ = reference
    out = tmp_path / "dask.h5"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        res = batch_cli(sweep, "--scheduler", cluster.scheduler_address, "-o", out, "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["executor"].startswith("Dask scheduler tcp://127.0.0.1:")
    assert s["variants"] == ref["variants"]
    assert runs_of(out) == load_sweep(sweep).run_keys()


def test_northfind_sweep(tmp_path):
    base = str(Path(__file__).resolve().parents[1] / "configs/seed001_simulation.yaml")
    sweep = tmp_path / "nf.yaml"
    sweep.write_text(yaml.safe_dump({
        "base": base, "seeds": 3, "grid": {"northfind.tilt_deg": [0, 10]},
        "metrics": ["methods.coordinate.rms_error_deg", "methods.none.max_abs_error_deg"]}))
    res = batch_cli(sweep, "--workers", 1, "-o", tmp_path / "nf.h5", "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["command"] == "northfind" and s["ok"] == 6
    none = [v["stats"]["methods.none.max_abs_error_deg"]["mean"] for v in s["variants"]]
    coord = [v["stats"]["methods.coordinate.rms_error_deg"]["mean"] for v in s["variants"]]
    # Without compensation the 10° tilt costs degrees (≈ asin(tan L sin ε) = 8.4° at 40°N);
    # the coordinate method stays at the noise level.
    assert none[0] < 0.5 and 7.5 < none[1] < 9.5
    assert coord[1] < 0.1


def test_a_lost_scheduler_leaves_no_log_of_dask_or_tornado_on_stderr(caplog):
    """When the scheduler dies, Dask's client and tornado's IO loop (a gather in flight)
    log their errors with tracebacks; a batch's client silences both, so that its one line
    (lost the scheduler, rerun with --resume) is all stderr holds."""
    import logging

    from gcalign.app.batch.backends import _quiet_dask

    _quiet_dask()
    with caplog.at_level(logging.DEBUG):
        for name in ("distributed.client", "tornado.application"):
            logging.getLogger(name).error("Exception in callback: Stream is closed")
    assert caplog.records == []
