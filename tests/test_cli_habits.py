"""What a user expects of any command line, one behaviour per test: file names
that say what was overridden, keys that cannot matter refused or shown, progress on long
runs, --version, completion, `example`, `--set`, scalar biases, bare `gcalign`, recorded
data with `--imu-file` and `--lat/--lon/--height`, batch over a list of files."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from align_cases import small_align
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.cli.common import output_name, tag

ROOT = Path(__file__).resolve().parents[1]
REAL = ROOT / "tests/data/lasergyro.imu.xz"
runner = CliRunner()


def run_in(folder: Path, *args) -> object:
    """`gcalign ARGS` with the working directory `folder` (default outputs go to runs/)."""
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        return runner.invoke(app, [str(a) for a in args])
    finally:
        os.chdir(cwd)


# ------------------------------------------------------------------ output names


def test_default_names_carry_every_override_and_the_random_seed(tmp_path):
    p = small_align(tmp_path)
    plain = run_in(tmp_path, "align", p)
    conv = run_in(tmp_path, "align", p, "--mode", "conventional")
    many = run_in(tmp_path, "align", p, "--mode", "half-cycle", "--compensation", "one-off",
                  "--t2", "50", "--seed", "7", "--set", "align.stages.0.t_z_s=200")
    for res in (plain, conv, many):
        assert res.exit_code == 0, res.output
    names = sorted(f.name for f in (tmp_path / "runs").iterdir())
    assert names == [
        "seed000-moving-full-cycle-align-conventional-rng1.h5",
        "seed000-moving-full-cycle-align-half-cycle-one-off-t2_50-t_z200-rng7.h5",
        "seed000-moving-full-cycle-align-rng1.h5"]
    with h5py.File(tmp_path / "runs" / names[0]) as f:  # the file says what it holds
        assert json.loads(f.attrs["summary_json"])["mode"] == "conventional"
        assert "align.mode: conventional" in f.attrs["scenario_yaml"]


def test_northfind_sweep_and_tilt_runs_do_not_overwrite_each_other(tmp_path):
    for args in ([], ["--tilt", "5"], ["--sweep", "0:360:30"], ["--azimuth", "48"],
                 ["--method", "coordinate", "--method", "naive"]):
        res = run_in(tmp_path, "northfind", "--positions", "8", "--dwell", "10", *args)
        assert res.exit_code == 0, res.output
    names = sorted(f.name for f in (tmp_path / "runs").iterdir())
    assert len(names) == 5  # five runs, five files
    for word in ("tilt5", "sweep_0-360-30", "azimuth48", "coordinate+naive"):
        assert sum(f"-{word}-" in n for n in names) == 1, (word, names)
    assert all(n.startswith("seed001-simulation-northfind-") and "-positions8-dwell10" in n
               and n.endswith("-rng1.h5") for n in names)


def test_tags_and_long_names():
    assert tag("align.mode", "conventional") == "conventional"
    assert tag("align.passes", 7) == "passes7"
    assert tag("align.t3_s", "measured") == "measured"
    assert tag("imu.gyro.bias_dph", 0.02) == "gyro_bias0.02"
    assert tag("imu_file", Path("data/run 3.imu.xz")) == "imu-run_3"
    assert tag("init", "runs/lasergyro-align.h5") == "init-lasergyro-align"
    long = output_name("s", "align", 1, [(f"imu.gyro.k{i}", float(i)) for i in range(20)])
    assert len(long.name) < 100 and long.name.endswith("-rng1.h5")
    other = output_name("s", "align", 1, [(f"imu.gyro.k{i}", float(i) + 1) for i in range(20)])
    assert other != long  # the hash keeps different overrides apart


def test_replacing_a_run_of_other_inputs_warns(tmp_path):
    p = small_align(tmp_path)
    assert run_in(tmp_path, "align", p).exit_code == 0
    again = run_in(tmp_path, "align", p)  # the same run again: silent
    assert "replaced" not in again.stderr
    p.write_text(p.read_text().replace("noise_mps: 0.01", "noise_mps: 0.02"))
    edited = run_in(tmp_path, "align", p, "--json")
    assert edited.exit_code == 0
    assert "replaced runs/seed000-moving-full-cycle-align-rng1.h5, a run of other inputs" in \
        edited.stderr
    assert any("replaced" in w for w in json.loads(edited.stdout)["warnings"])


# ------------------------------------------------------------------ keys that cannot matter


def test_compensation_in_real_time_conventional_mode_is_a_visible_warning(tmp_path):
    res = runner.invoke(app, ["align", str(small_align(tmp_path)), "--mode", "conventional",
                              "--compensation", "one-off", "-o", str(tmp_path / "a.h5"),
                              "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["compensation"] == "real time"
    line = ("align.compensation: 'one-off' cannot matter in real-time conventional mode")
    assert any(w.startswith(line) for w in s["warnings"])
    assert f"warning: {line}" in res.stderr  # on stderr, and under the table
    shown = runner.invoke(app, ["show", str(tmp_path / "a.h5")])
    assert "warning: align.compensation" in shown.stdout.replace("\n", " ")


def test_simulated_imu_keys_with_recorded_data_are_a_visible_warning(tmp_path):
    sc = {"name": "real", "imu_file": str(REAL), "imu": {"gyro": {"bias_dph": 5}},
          "align": {"coarse": {"method": "inertial"}, "mode": "conventional", "t1_s": 60,
                    "t2_s": 130, "t3_s": 130}}
    p = tmp_path / "r.yaml"
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "r.h5"), "--json"])
    assert res.exit_code == 0, res.output
    warnings = json.loads(res.stdout)["warnings"]
    assert any(w.startswith("imu.gyro.bias_dph: cannot matter with recorded data")
               for w in warnings)
    v = runner.invoke(app, ["validate", str(p), "--json"])
    assert v.exit_code == 0 and json.loads(v.stdout)["warnings"] == [
        w for w in warnings if w.startswith("imu.")]


def test_analytic_coarse_alignment_on_a_swinging_base_warns(tmp_path):
    """The base swings by degrees during [0, T1]: the static double-vector method gives a
    heading far off (here by more than 10°), and says why."""
    sc = yaml.safe_load((ROOT / "configs/seed000_swing_none.yaml").read_text())
    sc["motion"]["duration_s"] = 40
    sc["align"].update({"coarse": {"method": "analytic"}, "t2_s": 30, "t3_s": 30,
                        "level_s": 10})
    p = tmp_path / "swing.yaml"
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "s.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    coarse_err = (s["coarse_attitude_deg"][2] - 30.0 + 180.0) % 360.0 - 180.0
    assert abs(coarse_err) > 10.0
    assert any(w.startswith("align.coarse.method: 'analytic' assumes a still base, but the "
                            "base turned by up to") for w in s["warnings"])
    # a still base, same method: no warning
    sc["motion"] = {"kind": "static", "attitude_deg": [0, 0, 30], "duration_s": 40}
    p.write_text(yaml.safe_dump(sc))
    res = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "t.h5"), "--json"])
    assert res.exit_code == 0 and json.loads(res.stdout)["warnings"] == []


@pytest.mark.parametrize("align, message", [
    ({"coarse": {"method": "given", "duration_s": 10}},
     "align.coarse.duration_s: removed; the coarse window is [start_s, t1_s]"),
    ({"passes": 5}, "align.passes: removed; the pass count is the sum of the stages' passes"),
    ({"coarse": {"method": "inertial", "error_deg": [0, 0, 5]}},
     "align.coarse.error_deg: cannot matter with method 'inertial'"),
    ({"coarse": {"method": "given", "offset_deg": [0, 0, 5]}},
     "align.coarse.offset_deg: cannot matter with method 'given'"),
])
def test_one_key_per_quantity(tmp_path, align, message):
    res = runner.invoke(app, ["align", str(small_align(tmp_path, **align))])
    assert res.exit_code == 2 and message in res.stderr, res.output


def test_given_coarse_alignment_at_t1_zero(tmp_path):
    """`given` needs no coarse window: T1 = 0 is allowed (it used to demand a duration)."""
    res = runner.invoke(app, ["align", str(small_align(tmp_path, t1_s=0)), "-o",
                              str(tmp_path / "a.h5"), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["t1_s"] == 0.0


def test_passes_option_sets_the_last_stage(tmp_path):
    p = small_align(tmp_path, stages=[{"t_z_s": 100, "passes": 1}, {"t_z_s": 200}])
    res = runner.invoke(app, ["align", str(p), "--passes", "5", "-o", str(tmp_path / "a.h5"),
                              "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert [p["stage"] for p in s["passes"]] == [1, 2, 2, 2, 2]
    assert [x["passes"] for x in s["stages"]] == [1, 4]


# ------------------------------------------------------------------ progress


def unstyled(text: str) -> str:
    """`text` without terminal escape sequences (colours, cursor moves)."""
    return re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text)


@pytest.mark.slow
def test_progress_bar_when_a_terminal_is_forced(tmp_path, monkeypatch):
    sc = {"name": "static", "site": {"lat_deg": 45, "lon_deg": 126},
          "motion": {"kind": "static", "duration_s": 60}}
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(sc))
    monkeypatch.setenv("GCALIGN_PROGRESS", "always")
    res = runner.invoke(app, ["navigate", str(p), "-o", str(tmp_path / "n.h5")])
    assert res.exit_code == 0, res.output
    assert "\x1b[" in res.stderr  # drawn as on a terminal
    bar = unstyled(res.stderr)
    assert "navigate navigating (data s)" in bar
    assert "100% 60/60" in bar  # done/total in the unit the description names
    assert "navigating" not in res.stdout  # the table's stream holds no bar
    for args, line in ((["simulate", p, "-o", tmp_path / "s.h5"], "simulate simulating "
                        "(data s)"),
                       (["align", small_align(tmp_path), "-o", tmp_path / "a.h5"],
                        "align simulating (data s)"),
                       (["plot", tmp_path / "a.h5", "-o", tmp_path / "figs"], "plot figures")):
        other = runner.invoke(app, [str(a) for a in args])
        assert other.exit_code == 0, other.output
        bar = unstyled(other.stderr)
        assert line in bar and "100%" in bar, bar
        drawn = [x for x in bar.replace("\r", "\n").splitlines() if not x.startswith("wrote ")]
        assert all(len(x) <= 80 for x in drawn)  # one line (the path written may be longer)
    monkeypatch.setenv("GCALIGN_PROGRESS", "auto")  # not a terminal: nothing
    res = runner.invoke(app, ["navigate", str(p), "-o", str(tmp_path / "n.h5")])
    assert res.exit_code == 0 and "navigating" not in res.stderr


def test_compute_says_what_it_measured(tmp_path):
    res = runner.invoke(app, ["align", str(small_align(tmp_path)), "-o",
                              str(tmp_path / "a.h5"), "--json"])
    s = json.loads(res.stdout)
    assert 0 < s["compute_s"] < s["wall_s"]
    assert "compute (the passes)" in res.stderr and " wall" in res.stderr


# ------------------------------------------------------------------ standard habits


def test_version_and_bare_gcalign():
    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0 and res.stdout.strip() == "gcalign 0.1.0"
    res = runner.invoke(app, [])
    assert res.exit_code == 0 and "Usage:" in res.stdout and "example" in res.stdout


def test_top_level_help_lists_what_exists():
    from gcalign.app.registry import COMMANDS

    res = runner.invoke(app, ["--help"])
    assert res.exit_code == 0
    for c in COMMANDS.values():
        assert c.help in res.stdout.replace("\n  ", " ").replace("  ", " ") or c.name in \
            res.stdout
    seeds = [c.help for c in COMMANDS.values() if "(seed " in c.help]
    assert ("seeds 000-004" not in res.stdout) and all(
        s.rsplit("(seed ", 1)[1][:3] in res.stdout for s in seeds)


def test_flags_take_no_value_and_help_keeps_brackets():
    res = runner.invoke(app, ["align", "--help"])
    assert "--json " in res.stdout and "<bool>" not in res.stdout
    res = runner.invoke(app, ["batch", "--help"])
    assert 'pip install -e ".[dask]"' in " ".join(res.stdout.split())


def test_shell_completion(monkeypatch):
    import typer.completion

    # --show-completion is a flag: typer asks the process tree for the shell, which a test
    # run need not have (seen: exit 1, "Shell  not supported", under some launchers)
    monkeypatch.setattr(typer.completion, "_get_shell_name", lambda: "bash")
    res = runner.invoke(app, ["--show-completion"], prog_name="gcalign")
    assert res.exit_code == 0 and "_GCALIGN_COMPLETE" in res.stdout
    env = {"_GCALIGN_COMPLETE": "complete_bash", "COMP_WORDS": "gcalign ali", "COMP_CWORD": "1"}
    assert runner.invoke(app, [], env=env, prog_name="gcalign").stdout.split() == ["align"]


def test_example_lists_and_prints_the_built_in_scenarios(tmp_path):
    listed = runner.invoke(app, ["example", "--json"])
    assert listed.exit_code == 0
    examples = json.loads(listed.stdout)["examples"]
    assert {"align", "northfind", "calibrate", "observability", "realtime"} <= set(examples)
    text = runner.invoke(app, ["example", "align"]).stdout
    assert text == (ROOT / "configs/seed000_moving_full_cycle.yaml").read_text()
    mine = tmp_path / "mine.yaml"
    mine.write_text(text)
    a = runner.invoke(app, ["align", str(mine), "-o", str(tmp_path / "a.h5"), "--json"])
    b = runner.invoke(app, ["align", "-o", str(tmp_path / "b.h5"), "--json"])
    assert json.loads(a.stdout)["error_t3_deg"] == json.loads(b.stdout)["error_t3_deg"]
    bad = runner.invoke(app, ["example", "navigate"])
    assert bad.exit_code == 2
    assert f"'navigate' has no built-in scenario; built-in: {', '.join(examples)}" in bad.stderr


def test_set_any_key_with_yaml_values(tmp_path):
    p = small_align(tmp_path)
    res = runner.invoke(app, ["align", str(p), "-o", str(tmp_path / "a.h5"), "--json",
                              "--set", "align.stages.0.t_z_s=200", "--set",
                              "imu.gyro.bias_dph=[0.02, 0, 0]", "--set", "align.t3_s=measured"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["stages"][0]["t_z_s"] == 200.0 and s["t3_source"] == "measured"
    with h5py.File(tmp_path / "a.h5") as f:
        stored = f.attrs["scenario_yaml"]
    assert "imu.gyro.bias_dph:\n- 0.02" in stored  # the file records the overrides
    for args, message in ((["--set", "align.modee=x"], "--set align.modee: align.modee: "
                           "unknown key"),
                          (["--set", "align.mode"], "--set: expected KEY=VALUE"),
                          (["--mode", "conventional", "--set", "align.mode=half-cycle"],
                           "--set align.mode: also given by an option"),
                          (["--set", "align.mode=sideways"], "align.mode: Input should be")):
        res = runner.invoke(app, ["align", str(p), *args])
        assert res.exit_code == 2 and message in res.stderr, (args, res.output)


def test_validate_takes_set_too(tmp_path):
    res = runner.invoke(app, ["validate", str(small_align(tmp_path)), "--set",
                              "align.mode=half-cycle", "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    assert values["align.mode"]["value"] == "half-cycle"


def test_scalar_biases_and_scale_factors_mean_all_axes(tmp_path):
    from gcalign.io.scenario import parse_scenario
    from gcalign.units import DPH, PPM, UG

    sc = parse_scenario({"imu": {"gyro": {"bias_dph": 5, "scale_ppm": -20},
                                 "accel": {"bias_ug": -50}}})
    err = sc.imu.errors()
    np.testing.assert_allclose(err.gyro.bias, [5 * DPH] * 3)
    np.testing.assert_allclose(err.gyro.scale, [-20 * PPM] * 3)
    np.testing.assert_allclose(err.accel.bias, [-50 * UG] * 3)
    res = runner.invoke(app, ["align", str(small_align(tmp_path)), "--set",
                              "imu.gyro.bias_dph=0.05", "-o", str(tmp_path / "a.h5")])
    assert res.exit_code == 0, res.output


# ------------------------------------------------------------------ recorded data


def test_imu_file_option_replaces_the_simulation(tmp_path):
    """A simulated scenario run on the recording instead: the site from the file's header,
    no truth, and the simulation's sections gone (not warned about: the option replaces
    them)."""
    p = small_align(tmp_path, coarse={"method": "inertial"}, mode="conventional", t1_s=60,
                    t2_s=400, t3_s=400, level_s=60, aiding={"source": "none"},
                    azimuth_poles="oscillator-overdamped",
                    stages=[{"t_xy_s": 20, "t_z_s": 100, "xi": 0.707}])
    res = runner.invoke(app, ["align", str(p), "--imu-file", str(REAL), "-o",
                              str(tmp_path / "r.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["source"] == str(REAL) and s["error_t3_deg"] is None and s["seed"] is None
    assert s["attitude_t3_deg"][2] == pytest.approx(-90.6, abs=0.1)  # the file's heading
    assert s["warnings"] == []
    assert "recorded data: no truth" in res.stderr
    missing = runner.invoke(app, ["align", str(p), "--imu-file", str(tmp_path / "no.imu")])
    assert missing.exit_code == 2 and "--imu-file: " in missing.stderr


def test_imu_file_option_of_navigate_and_calibrate(tmp_path, lasergyro):
    """The other commands that run on recorded data take --imu-file too: the same recording
    (plain here, xz in the config) gives calibrate the same estimates, and a simulated
    navigate scenario runs on the file instead (no truth, the name says which file)."""
    cal = ROOT / "configs/lasergyro_calibrate.yaml"
    own = runner.invoke(app, ["calibrate", str(cal), "-o", str(tmp_path / "a.h5"), "--json"])
    other = run_in(tmp_path, "calibrate", cal, "--imu-file", lasergyro, "--json")
    assert own.exit_code == 0 and other.exit_code == 0, other.output
    a, b = json.loads(own.stdout), json.loads(other.stdout)
    assert b["source"] == str(lasergyro) and b["output"].endswith(
        "lasergyro-calibrate-calibrate-imu-lasergyro.h5")
    assert a["states"] == b["states"]
    nav = run_in(tmp_path, "navigate", ROOT / "configs/seed000_moving_full_cycle.yaml",
                 "--imu-file", lasergyro, "--init", "header", "--duration", "60", "--json")
    assert nav.exit_code == 0, nav.output
    s = json.loads(nav.stdout)
    assert s["final_error"] is None and s["duration_s"] == pytest.approx(60.0)
    assert s["source"] == str(lasergyro)
    assert s["output"] == "runs/seed000-moving-full-cycle-navigate-duration60-imu-lasergyro-" \
        "header.h5"  # no -rngN: recorded data have no random seed


def test_a_csv_without_a_site_asks_for_lat_lon_height(tmp_path, lasergyro):
    """A bare CSV has no header: the error says how to give the site, and --lat/--lon/
    --height give it (the PSINS file's header site, for comparison)."""
    from gcalign.io.imu_files import read_imu_file, write_csv_imu

    imu = read_imu_file(lasergyro)
    n = 20000
    cut = type(imu)(t=imu.t[:n], dtheta=imu.dtheta[:n], dv=imu.dv[:n], ts=imu.ts)
    csv = tmp_path / "cut.csv"
    write_csv_imu(csv, cut)
    res = runner.invoke(app, ["navigate", str(csv), "--init", "header"])
    assert res.exit_code == 2
    assert "cut.csv does not give the site (a CSV file has no header); give " \
           "--lat/--lon/--height" in res.stderr
    res = runner.invoke(app, ["navigate", str(csv), "--lat", "34.246048", "--lon",
                              "108.909664", "--height", "380", "-o", str(tmp_path / "n.h5"),
                              "--json"])
    assert res.exit_code == 2 and "initial: " in res.stderr  # a CSV has no attitude:
    assert "--reference" in res.stderr and "initial: {att_deg" in res.stderr  # the 3 ways
    al = tmp_path / "al.yaml"
    al.write_text(yaml.safe_dump({"name": "cut", "imu_file": str(csv), "align": {
        "coarse": {"method": "inertial"}, "mode": "conventional", "t1_s": 60, "t2_s": 150,
        "t3_s": 150}}))
    a = runner.invoke(app, ["align", str(al), "--lat", "34.246048", "--lon", "108.909664",
                            "--height", "380", "-o", str(tmp_path / "a.h5"), "--json"])
    assert a.exit_code == 0, a.output
    res = runner.invoke(app, ["navigate", str(csv), "--lat", "34.246048", "--lon",
                              "108.909664", "--height", "380", "--init",
                              str(tmp_path / "a.h5"), "-o", str(tmp_path / "n.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["final_state"]["position_deg_m"][2] == pytest.approx(380.0)
    assert s["final_state"]["position_deg_m"][0] == pytest.approx(34.246048, abs=1e-3)


def test_lat_alone_names_the_missing_field(tmp_path, lasergyro):
    from gcalign.io.imu_files import read_imu_file, write_csv_imu

    imu = read_imu_file(lasergyro)
    csv = tmp_path / "c.csv"
    write_csv_imu(csv, type(imu)(t=imu.t[:100], dtheta=imu.dtheta[:100], dv=imu.dv[:100],
                                 ts=imu.ts))
    res = runner.invoke(app, ["navigate", str(csv), "--lat", "34"])
    assert res.exit_code == 2 and "site.lon_deg" in res.stderr


# ------------------------------------------------------------------ batch of files


def test_batch_over_a_plain_list_of_scenario_files(tmp_path):
    files = []
    for mode in ("conventional", "half-cycle"):
        d = yaml.safe_load(small_align(tmp_path, mode=mode).read_text())
        f = tmp_path / f"{mode}.yaml"
        f.write_text(yaml.safe_dump(d))
        files.append(f)
    out = tmp_path / "b.h5"
    res = runner.invoke(app, ["batch", *map(str, files), "--seeds", "2", "--workers", "1",
                              "-o", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["runs"] == 4 and s["ok"] == 4 and s["command"] == "align"
    assert [v["overrides"] for v in s["variants"]] == [{"scenario": "conventional.yaml"},
                                                       {"scenario": "half-cycle.yaml"}]
    # the same numbers as the single runs of those files and seeds
    one = runner.invoke(app, ["align", str(files[1]), "--seed", "2", "-o",
                              str(tmp_path / "one.h5"), "--json"])
    yaw = json.loads(one.stdout)["error_t3_deg"]
    with h5py.File(out) as f:
        r = f["batch/runs"]
        sel = (r["variant"][()] == 1) & (r["seed"][()] == 2)
        np.testing.assert_array_equal(r["metrics"]["error_t3_deg"][()][sel][0], yaw)
    bad = runner.invoke(app, ["batch", str(ROOT / "configs/sweeps/seed000_modes.yaml"),
                              "--command", "calibrate"])  # a sweep says its command
    assert bad.exit_code == 2 and "--command: applies to a list of scenario files" in bad.stderr


@pytest.mark.parametrize("first", [True, False])
def test_a_file_of_a_batch_that_fails_its_checks_is_named(tmp_path, first):
    """Whichever place it has in the list, the file is named, not 'grid: variant'."""
    good, bad = small_align(tmp_path, mode="conventional"), tmp_path / "late.yaml"
    d = yaml.safe_load(good.read_text())
    d["align"]["t2_s"] = d["motion"]["duration_s"] + 100
    d["align"]["t3_s"] = d["align"]["t2_s"] + 10
    bad.write_text(yaml.safe_dump(d))
    files = [bad, good] if first else [good, bad]
    out = tmp_path / "b.h5"
    res = runner.invoke(app, ["batch", *map(str, files), "-o", str(out)])
    assert res.exit_code == 2 and not out.exists(), res.output
    assert res.stderr.startswith(f"error: {bad}: align.t2_s: ") and "grid" not in res.stderr


def test_top_help_names_each_seed_once():
    """The seeds come from the commands' help lines, whatever follows their '(seed N)'."""
    res = runner.invoke(app, ["--help"], prog_name="gcalign", env={"COLUMNS": "200"})
    assert res.exit_code == 0
    assert "Algorithms of the seed papers 000, 001, 002, 003, 004;" in " ".join(res.output.split())
