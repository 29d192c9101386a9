"""Foundation commands end to end: simulate, navigate, show, validate; bad input."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.io.scenario.loader import loads

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()

SCENARIO = {
    "name": "swing-test",
    "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0},
    "imu": {
        "rate_hz": 100,
        "seed": 3,
        "gyro": {"bias_dph": [0.01, 0.01, 0.01], "arw_dprh": 0.001},
        "accel": {"bias_ug": [50, 50, 50], "vrw_ugrhz": 10},
    },
    "motion": {
        "kind": "swing",
        "attitude_deg": [0, 0, 30],
        "duration_s": 20,
        "swing": {"amplitude_deg": [2, 3, 4], "period_s": [10, 10, 20]},
    },
}


def write(tmp_path: Path, data, name="s.yaml") -> Path:
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return p


@pytest.mark.slow
def test_simulate_navigate_show_roundtrip(tmp_path):
    sim = tmp_path / "sim.h5"
    res = runner.invoke(app, ["simulate", str(write(tmp_path, SCENARIO)), "-o", str(sim), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["samples"] == 2000 and s["seed"] == 3 and s["output"] == str(sim)
    with h5py.File(sim) as f:
        assert f["imu/dtheta"].shape == (2000, 3) and f["truth/att"].shape == (2001, 3)
        assert f["imu/dtheta"].attrs["units"] == "rad" and f["truth/v_n"].attrs["frame"] == "ENU"
        assert yaml.safe_load(f.attrs["scenario_yaml"])["name"] == "swing-test"
    nav = tmp_path / "nav.h5"
    res = runner.invoke(app, ["navigate", str(sim), "-o", str(nav), "--json"])
    assert res.exit_code == 0, res.output
    n = json.loads(res.stdout)
    assert set(n["final_error"]) == {"attitude_deg", "velocity_mps", "position_m",
                                     "misalignment_deg"}
    assert n["output"] == str(nav)
    # 20 s of a navigation-grade IMU: small but non-zero errors.
    assert 0 < np.abs(n["final_error"]["velocity_mps"]).max() < 0.05
    shown = runner.invoke(app, ["show", str(nav), "--json"])
    assert shown.exit_code == 0 and json.loads(shown.stdout)["final_error"] == n["final_error"]


def test_a_flow_style_scenario_with_overrides_is_stored_as_text_that_reads_back(tmp_path):
    """A scenario written in flow style (JSON is) with --set: the stored text records the
    override after the scenario and still parses, so the file can be navigated."""
    sim, nav = tmp_path / "sim.h5", tmp_path / "nav.h5"
    src = write(tmp_path, json.dumps(SCENARIO), "flow.yaml")
    res = runner.invoke(app, ["simulate", str(src), "--set", "output.rate_hz=full", "-o", str(sim)])
    assert res.exit_code == 0, res.output
    with h5py.File(sim) as f:
        stored = loads(f.attrs["scenario_yaml"], "scenario_yaml")
    assert stored["name"] == "swing-test" and stored["output.rate_hz"] == "full"
    res = runner.invoke(app, ["navigate", str(sim), "-o", str(nav)])
    assert res.exit_code == 0, res.output


def test_an_override_repeated_on_a_file_that_records_it_is_recorded_once(tmp_path):
    """navigate --set KEY on a results file whose text records KEY already: the stored text
    gives KEY once, with the last value, and reads back."""
    sim, nav = tmp_path / "sim.h5", tmp_path / "nav.h5"
    src = write(tmp_path, SCENARIO)
    res = runner.invoke(app, ["simulate", str(src), "--set", "output.rate_hz=full", "-o", str(sim)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["navigate", str(sim), "--set", "output.rate_hz=50", "-o", str(nav)])
    assert res.exit_code == 0, res.output
    with h5py.File(nav) as f:
        text = f.attrs["scenario_yaml"]
    assert text.count("output.rate_hz") == 1 and loads(text, "t")["output.rate_hz"] == 50


def test_same_seed_same_file_numbers(tmp_path):
    p = write(tmp_path, SCENARIO)
    outs = []
    for i, seed in enumerate(["5", "5", "6"]):
        out = tmp_path / f"{i}.h5"
        assert (
            runner.invoke(app, ["simulate", str(p), "-o", str(out), "--seed", seed]).exit_code == 0
        )
        with h5py.File(out) as f:
            outs.append(f["imu/dtheta"][()])
    assert np.array_equal(outs[0], outs[1]) and not np.array_equal(outs[0], outs[2])


def test_validate_prints_si(tmp_path):
    res = runner.invoke(app, ["validate", str(write(tmp_path, SCENARIO)), "--json"])
    assert res.exit_code == 0, res.output
    v = json.loads(res.stdout)["values"]
    assert "4.84814e-08" in v["imu.gyro.bias_dph"]["si"]  # 0.01 °/h = 4.8481e-8 rad/s


def _bad(tmp_path, mutate):
    d = json.loads(json.dumps(SCENARIO))
    mutate(d)
    return d


@pytest.mark.parametrize(
    "content, field",
    [
        ("name: x\nsite: {lat_deg: 45\n", "YAML syntax error at line"),
        (lambda d: d["site"].update(latitude=4), "site.latitude: unknown key"),
        (lambda d: d["site"].update(lat_deg=95), "site.lat_deg"),
        (lambda d: d["imu"].update(rate_hz=-100), "imu.rate_hz"),
        (lambda d: d["motion"].update(kind="moving", swing=None), "motion.segments"),
        (lambda d: d["imu"]["gyro"].update(arw_dprh=-1), "imu.gyro.arw_dprh"),
        (lambda d: d["motion"].update(kind="orbit"), "motion.kind"),
    ],
)
@pytest.mark.parametrize("command", ["simulate", "navigate", "validate"])
def test_bad_scenario_exits_2(tmp_path, content, field, command):
    data = content if isinstance(content, str) else _bad(tmp_path, content)
    if isinstance(data, dict) and data["motion"].get("swing") is None:
        data["motion"].pop("swing", None)
    out = tmp_path / "out.h5"
    args = [command, str(write(tmp_path, data))] + (
        ["-o", str(out)] if command != "validate" else []
    )
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    assert field in res.output, res.output
    assert "Traceback" not in res.output and res.output.count("\n") <= 2
    assert not out.exists() and not list(tmp_path.glob(".*.tmp"))


def test_missing_and_foreign_files(tmp_path):
    res = runner.invoke(app, ["simulate", str(tmp_path / "nope.yaml")])
    assert res.exit_code == 2 and "file not found" in res.output
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = [1, 2, 3]
    for command in ("show", "navigate"):
        res = runner.invoke(app, [command, str(foreign)])
        assert res.exit_code == 2, res.output
        assert "not a gcalign results file" in res.output
    text = tmp_path / "text.h5"
    text.write_text("hello")
    res = runner.invoke(app, ["show", str(text)])
    assert res.exit_code == 2 and "not an HDF5 file" in res.output


def test_recorded_psins_file_navigates(tmp_path, lasergyro):
    p = write(tmp_path, {"name": "real", "imu_file": str(lasergyro)})
    res = runner.invoke(app, ["simulate", str(p), "-o", str(tmp_path / "r.h5"), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["samples"] == 184718


@pytest.mark.parametrize("compressed", [False, True])
def test_navigate_a_bare_psins_file(tmp_path, lasergyro, compressed):
    """The plain recording and its xz copy (read compressed) navigate alike."""
    data = ROOT / "tests/data/lasergyro.imu.xz" if compressed else lasergyro
    res = runner.invoke(app, ["navigate", str(data), "-o", str(tmp_path / "n.h5"), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["final_error"] is None and s["samples"] == 184718
    assert "recorded data" in res.stderr


def test_pole_latitude_rejected(tmp_path):
    d = json.loads(json.dumps(SCENARIO))
    d["site"]["lat_deg"] = -90
    res = runner.invoke(app, ["navigate", str(write(tmp_path, d))])
    assert res.exit_code == 2 and "site.lat_deg" in res.output and "poles" in res.output


REAL = ROOT / "tests/data/lasergyro.imu.xz"  # what configs/lasergyro_align.yaml reads


@pytest.mark.slow
def test_navigate_from_an_alignment_of_the_real_file(tmp_path):
    """Align lasergyro.imu (gyrocompass, T3 = 400 s), then navigate 600 s of the same data
    from its attitude at T3 with the height held: the table and the plot show the drift."""
    aligned = tmp_path / "align.h5"
    res = runner.invoke(app, ["align", str(ROOT / "configs/lasergyro_align.yaml"), "-o",
                              str(aligned)])
    assert res.exit_code == 0, res.output
    nav = tmp_path / "nav.h5"
    res = runner.invoke(app, ["navigate", str(REAL), "--init", str(aligned), "--duration", "600",
                              "-o", str(nav), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["init"].startswith("alignment") and s["start_s"] == pytest.approx(400.0)
    assert s["duration_s"] == pytest.approx(600.0) and s["vertical"] == "hold"
    assert s["final_error"] is None  # no truth
    with h5py.File(aligned) as f:
        yaw_t3 = np.degrees(f["align/result/att_t3"][2])
    assert s["final_state"]["attitude_deg"][2] == pytest.approx(yaw_t3, abs=0.1)
    # a parked vehicle: a drift of metres to tens of metres in 10 min, held height
    assert 1.0 < s["max_horizontal_displacement_m"] < 200.0
    assert s["final_state"]["position_deg_m"][2] == pytest.approx(380.0)
    res = runner.invoke(app, ["show", str(nav)])
    assert res.exit_code == 0 and "displacement from the start" in res.stdout
    res = runner.invoke(app, ["plot", str(nav), "-o", str(tmp_path / "plots"), "--json"])
    assert res.exit_code == 0, res.output
    assert [Path(p).name for p in json.loads(res.stdout)["figures"]] == ["navigate.png"]
    # data from another file than the alignment's is refused
    other = tmp_path / "other.imu.xz"
    other.write_bytes(REAL.read_bytes())
    res = runner.invoke(app, ["navigate", str(other), "--init", str(aligned)])
    assert res.exit_code == 2 and "align the same data" in res.output


@pytest.mark.slow
def test_long_runs_are_stored_at_the_output_rate_and_summed_increments_are_refused(tmp_path):
    """Beyond an hour the series are stored at 1 Hz: truth decimated, increments summed over
    each second (exact sums, row by row: noise makes every second differ), which navigation
    refuses; 'full' keeps every sample."""
    sc = {"name": "two-hours", "site": SCENARIO["site"],
          "imu": {"rate_hz": 20, "gyro": {"arw_dprh": 0.01}, "accel": {"vrw_ugrhz": 50}},
          "motion": {"kind": "static", "attitude_deg": [1, 2, 30], "duration_s": 7200}}
    sim = tmp_path / "sim.h5"
    res = runner.invoke(app, ["simulate", str(write(tmp_path, sc)), "-o", str(sim), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["output_rate_hz"] == 1.0
    with h5py.File(sim) as f:
        assert f["truth/t"].shape == (7201,) and f["imu/dtheta"].shape == (7200, 3)
        assert f["imu"].attrs["ts"] == 1.0 and f["imu"].attrs["summed_from_ts"] == 0.05
        assert f["imu/dtheta"].chunks is not None and f["imu/dtheta"].compression == "gzip"
        dth = f["imu/dtheta"][()]
    from gcalign.app.data import scenario_stream
    from gcalign.io.scenario import parse_scenario

    total = sum(b.dtheta.sum(0) for b in scenario_stream(parse_scenario(sc)).blocks())
    np.testing.assert_allclose(dth.sum(0), total, rtol=1e-12)
    res = runner.invoke(app, ["navigate", str(sim)])
    assert res.exit_code == 2 and "summed to 1 Hz" in res.output and "rate_hz: full" in res.output
    sc["output"] = {"rate_hz": "full"}
    full = tmp_path / "full.h5"
    res = runner.invoke(app, ["simulate", str(write(tmp_path, sc)), "-o", str(full)])
    assert res.exit_code == 0, res.output
    with h5py.File(full) as f:
        assert f["imu/dtheta"].shape == (144000, 3) and "summed_from_ts" not in f["imu"].attrs
        every = {n: f[f"imu/{n}"][()] for n in ("dtheta", "dv")}
    with h5py.File(sim) as f:
        for n, inc in every.items():
            np.testing.assert_allclose(f[f"imu/{n}"][()], inc.reshape(7200, 20, 3).sum(1),
                                       rtol=1e-12, atol=1e-16)
    res = runner.invoke(app, ["navigate", str(full), "-o", str(tmp_path / "nav.h5"), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["vertical"] == "hold"


def test_a_bad_stored_sample_interval_is_refused_in_one_wording_by_every_reader(tmp_path):
    """The /imu interval of a simulate file (every sample, or summed) is checked once: the
    figures' reader and navigation's say the same line (navigation divided by a zero
    interval before: an internal error)."""
    import shutil

    from gcalign.errors import ScenarioError
    from gcalign.io.results import imu_series, read_imu

    sim, bad = tmp_path / "sim.h5", tmp_path / "bad.h5"
    sc = dict(SCENARIO, motion={**SCENARIO["motion"], "duration_s": 1})
    res = runner.invoke(app, ["simulate", str(write(tmp_path, sc)), "-o", str(sim)])
    assert res.exit_code == 0, res.output
    for ts, got in ((0.0, "0.0"), (float("nan"), "nan"), ("fast", "'fast'"), (None, "nothing")):
        for summed in (False, True):
            shutil.copy(sim, bad)
            with h5py.File(bad, "a") as f:
                f["imu"].attrs.pop("ts") if ts is None else f["imu"].attrs.create("ts", ts)
                if summed:
                    f["imu"].attrs["summed_from_ts"] = 0.01
            line = (f"{bad}: /imu attribute 'ts' (sample interval, s) must be a positive "
                    f"number, got {got}")
            for read in (imu_series, read_imu):
                with pytest.raises(ScenarioError) as err:
                    read(bad)
                assert str(err.value) == line, (ts, summed, read)
    res = runner.invoke(app, ["navigate", str(bad), "-o", str(tmp_path / "n.h5")])
    assert (res.exit_code, res.stderr.strip()) == (2, f"error: {line}")
    assert not (tmp_path / "n.h5").exists()


def test_output_rate_must_divide_the_imu_rate(tmp_path):
    sc = dict(SCENARIO, output={"rate_hz": 3})
    res = runner.invoke(app, ["navigate", str(write(tmp_path, sc)), "-o", str(tmp_path / "n.h5")])
    assert res.exit_code == 2 and "output.rate_hz: 3 Hz does not divide" in res.output
    assert not (tmp_path / "n.h5").exists()
