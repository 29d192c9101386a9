"""Physical bounds in the scenario schema (gcalign.io.scenario.bounds): values no instrument
or vehicle presents are refused in one line naming the field, the value and the allowed
range with its reason, by the run and by `validate`; every shipped config, sweep and
built-in scenario stays inside them."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pytest
from typer.testing import CliRunner

from gcalign.app.batch.sweep import load_sweep
from gcalign.cli import app
from gcalign.io.scenario import bounds as B
from gcalign.io.scenario import parse_scenario

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = sorted((ROOT / "configs").glob("*.yaml"))
SWEEPS = sorted((ROOT / "configs" / "sweeps").glob("*.yaml"))
BUILTIN = sorted(p.name for p in resources.files("gcalign.scenarios").iterdir()
                 if p.name.endswith(".yaml"))
runner = CliRunner()


def _refused(res, field: str, value: str, bound: B.Bound) -> str:
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1, res.output
    line = lines[0]
    assert f"{field}: must be within {bound.range()} ({bound.why}), got {value}" in line, line
    return line


def test_a_rate_beyond_any_gyro_is_refused_by_realtime(tmp_path):
    """``--set realtime.cases.0.steps.0.rate_dps=1e9`` printed 144000″ beside a closed form
    of 1.44e10″ with exit 0 (the rate turns 556 times between two 5 kHz samples)."""
    out = tmp_path / "r.h5"
    args = ["--set", "realtime.cases.0.steps.0.rate_dps=1e9"]
    line = _refused(runner.invoke(app, ["realtime", *args, "-o", str(out)]),
                    "realtime.cases.0.steps.0.rate_dps", "1e+09", B.RATE_DPS)
    assert "[-3600, 3600] °/s" in line
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_a_dgnss_sigma_below_any_receiver_is_refused_by_calibrate(tmp_path):
    """``calibrate.sigma_v_mps=1e-300`` reported a NEES mean of 2.9e9 (R = σ² is zero)."""
    out = tmp_path / "c.h5"
    line = _refused(runner.invoke(app, ["calibrate", "--set", "calibrate.sigma_v_mps=1e-300",
                                        "-o", str(out)]),
                    "calibrate.sigma_v_mps", "1e-300", B.SIGMA_V_MPS)
    assert "[0.001, 1000] m/s" in line
    assert not out.exists()


def test_at_the_dgnss_floor_the_filter_is_consistent(tmp_path):
    """At σ_v = 1 mm/s (the floor) the NEES mean lies in the χ²₂₁ 95 % band: the bound
    refuses no value the filter handles."""
    res = runner.invoke(app, ["calibrate", "--set", f"calibrate.sigma_v_mps={B.SIGMA_V_MPS.lo}",
                              "-o", str(tmp_path / "c.h5"), "--json"])
    assert res.exit_code == 0, res.output
    nees = json.loads(res.stdout)["nees"]
    lo, hi = nees["band_95"]
    assert lo < nees["mean"] < hi


# A base for each section, a key, a value past its bound, how the message shows the value.
BEYOND = [
    ("seed003_table1", "realtime.cases.0.steps.0.rate_dps", "-4000", "-4000", B.RATE_DPS),
    ("seed003_rate20_async", "motion.steps.0.rate_dps", "5000", "5000", B.RATE_DPS),
    ("seed003_rate20_async", "realtime.filter.fs_hz", "1e9", "1e+09", B.SENSOR_RATE_HZ),
    ("seed003_rate20_async", "realtime.sensor.arw_dprh", "100", "100", B.ARW_DPRH),
    ("seed003_rate20_async", "realtime.tracker.r_std_arcsec", "1e-300", "1e-300",
     B.ATTITUDE_SIGMA_ARCSEC),
    ("seed003_rate20_async", "realtime.tracker.p0_omega_dps", "1e6", "1e+06", B.P0_RATE_DPS),
    ("seed003_rate20_async", "realtime.tracker.p0_alpha_dps2", "1e-9", "1e-09",
     B.P0_ANGULAR_ACCEL_DPS2),
    ("seed003_rate20_async", "realtime.tracker.p0_theta_arcsec", "1e-9", "1e-09",
     B.P0_ANGLE_ARCSEC),
    ("seed002_designed", "calibrate.sigma_p_m", "1e-9", "1e-09", B.SIGMA_P_M),
    ("seed002_designed", "calibrate.sigma_v_mps", "1e4", "10000", B.SIGMA_V_MPS),
    ("seed002_designed", "calibrate.p0_scale", "1e200", "1e+200", B.P0_SCALE),
    ("seed002_designed", "calibrate.p0.gyro_bias_dph", "1e-12", "1e-12", B.P0_GYRO_BIAS_DPH),
    ("seed002_designed", "calibrate.p0.attitude_arcsec", "[20, 20, 1e-9]", "1e-09",
     B.P0_ATTITUDE_ARCSEC),
    ("seed002_designed", "calibrate.q.arw_dprh", "1e3", "1000", B.ARW_DPRH),
    ("seed002_designed", "calibrate.q.vrw_ugrhz", "1e6", "1e+06", B.VRW_UGRHZ),
    ("seed000_moving_full_cycle", "imu.gyro.bias_dph", "[0, 1e5, 0]", "100000",
     B.GYRO_BIAS_DPH),
    ("seed000_moving_full_cycle", "imu.gyro.arw_dprh", "11", "11", B.ARW_DPRH),
    ("seed000_moving_full_cycle", "imu.gyro.scale_ppm", "-2e5", "-200000", B.SCALE_PPM),
    ("seed000_moving_full_cycle", "imu.accel.bias_ug", "1e6", "1e+06", B.ACCEL_BIAS_UG),
    ("seed000_moving_full_cycle", "imu.accel.vrw_ugrhz", "2e4", "20000", B.VRW_UGRHZ),
    ("seed000_moving_full_cycle", "motion.segments.1.accel_mps2", "1e4", "10000",
     B.ACCEL_MPS2),
    ("seed000_moving_full_cycle", "motion.segments.2.rate_dps", "[0, 0, -1e4]", "-10000",
     B.RATE_DPS),
    ("seed000_moving_full_cycle", "align.aiding.noise_mps", "1e9", "1e+09", B.NOISE_MPS),
    ("seed003_table1", "realtime.cases.4.steps.1.accel_dps2", "1e7", "1e+07",
     B.ANGULAR_ACCEL_DPS2),
]


@pytest.mark.parametrize(("base", "key", "text", "shown", "bound"), BEYOND,
                         ids=[f"{c[1]}={c[2]}" for c in BEYOND])
def test_validate_refuses_each_value_past_its_bound(base, key, text, shown, bound):
    res = runner.invoke(app, ["validate", str(ROOT / "configs" / f"{base}.yaml"),
                              "--set", f"{key}={text}"])
    _refused(res, key, shown, bound)


@pytest.mark.parametrize(("row", "key", "peak"), [
    ({"axis": "z", "profile": "trapezoid", "angle_deg": 180, "accel_s": 1e-3,
      "const_s": 0, "decel_s": 1e-3}, "angle_deg", "180000"),
    ({"axis": "z", "profile": "swing", "amplitude_deg": 90, "frequency_hz": 10,
      "duration_s": 1}, "amplitude_deg", "5654.87"),
])
def test_a_turn_whose_peak_rate_is_past_the_bound_is_refused(row, key, peak):
    """Rows given by times or as a swing imply their peak rate (angle over the trapezoid's
    effective time; 2π A f): the same bound holds it."""
    res = runner.invoke(app, ["validate", str(ROOT / "configs" / "seed003_table1.yaml"),
                              "--set", f"realtime.cases.0.steps.0={json.dumps(row)}"])
    assert res.exit_code == 2, res.output
    line = res.output.strip()
    assert f"realtime.cases.0.steps.0.{key}: the turn's peak rate must be within " \
           f"{B.RATE_DPS.range()} ({B.RATE_DPS.why}), got {peak} °/s" in line, line


@pytest.mark.parametrize("path", CONFIGS, ids=[p.name for p in CONFIGS])
def test_every_shipped_config_validates(path):
    res = runner.invoke(app, ["validate", str(path)])
    assert res.exit_code == 0, res.output


@pytest.mark.parametrize("name", BUILTIN)
def test_every_builtin_scenario_validates(name):
    text = resources.files("gcalign.scenarios").joinpath(name).read_text(encoding="utf-8")
    from gcalign.io.scenario.loader import loads

    parse_scenario(loads(text, name), name)


@pytest.mark.parametrize("path", SWEEPS, ids=[p.name for p in SWEEPS])
def test_every_variant_of_every_shipped_sweep_validates(path):
    # load_sweep parses and preflights every variant before anything runs (its contract)
    assert load_sweep(path).variants


@pytest.mark.parametrize("bound", [b for b in vars(B).values() if isinstance(b, B.Bound)])
def test_each_bound_admits_its_ends_and_refuses_past_them(bound):
    lo = -bound.hi if bound.magnitude else bound.lo
    assert bound(lo) == lo and bound(bound.hi) == bound.hi and bound(None) is None
    for past in (bound.hi * (1 + 1e-12), lo - max(abs(lo), 1.0) * 1e-12):
        with pytest.raises(ValueError, match=r"^must be within \S"):
            bound(past)
        with pytest.raises(ValueError):
            bound([lo, past])
