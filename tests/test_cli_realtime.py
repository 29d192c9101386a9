"""`gcalign realtime` end to end (seed 003): the built-in Table 1 in the seed's semi-physical
setting and its JSON contract, `show`, the results file, `plot`, options, a single case from
a turntable motion, batch metrics, `validate`, and bad input (exit 2, one line, no file).

Reference values come from physics or the seed: before prediction the latched heading lags
by ω·T (72″ at 5 °/s, T = 4 ms), α·T per second on the ramps, 2A·sin(πfT) on the swings;
T of the designed chain is N/(2Fs) plus the notch's closed-form DC delay; against the truth
the seed's fixed 4 ms leaves the notch's 40.65 µs uncompensated (ω·40.65 µs).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from cli_checks import assert_bad_run
from lazy import lazy_module
from typer.testing import CliRunner

from gcalign.cli import app

signal = lazy_module("scipy.signal")

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()
ARCSEC = math.pi / 180 / 3600
SEED_AFTER = {"rate": 0.3, "accel": 0.4, "swing": 1.0}  # ″, seed Table 1, semi-physical


def _run(*args: str):
    return runner.invoke(app, ["realtime", *args])


def _notch_delay_s(f0=400.0, q=10.0, fs=5000.0) -> float:
    """Closed-form DC group delay of scipy's notch, 1 − (a1 + 2a2)/(1 + a1 + a2) samples."""
    _, a = signal.iirnotch(f0, q, fs=fs)
    return (1 - (a[1] + 2 * a[2]) / (1 + a[1] + a[2])) / fs


@pytest.fixture(scope="module")
def builtin(tmp_path_factory):
    out = tmp_path_factory.mktemp("rt") / "table1.h5"
    res = _run("--json", "-o", str(out))
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), out, res.output


def _small(tmp_path: Path, name="small", **realtime) -> Path:
    """A 3 s scenario with one uniform-rate and one swing case; `realtime` updates the
    section (None removes a key)."""
    section = {"semi_physical": False, "cases": [
        {"name": "rate 10°/s", "steps": [{"axis": "z", "profile": "rate", "rate_dps": 10,
                                           "duration_s": 3}]},
        {"name": "swing", "steps": [{"axis": "z", "profile": "swing", "amplitude_deg": 5,
                                      "frequency_hz": 0.5, "duration_s": 3}]}]}
    section.update(realtime)
    d = {"name": name, "site": {"lat_deg": 34.25, "lon_deg": 108.9, "height_m": 400},
         "imu": {"seed": 3}, "realtime": {k: v for k, v in section.items() if v is not None}}
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False, allow_unicode=True))
    return p


# ---------------------------------------------------------------------------- built-in

def test_builtin_equals_configs_copy():
    from gcalign.app.registry import COMMANDS, builtin_text

    text = (ROOT / "configs/seed003_table1.yaml").read_text()
    assert builtin_text(COMMANDS["realtime"].builtin or "") == text


@pytest.mark.slow
def test_builtin_json_contract(builtin):
    s, out, _ = builtin
    assert s["output"] == str(out) and out.is_file()
    assert s["semi_physical"] is True and s["reference"] == "seed"
    assert s["filter_delay_ms"] == 4.0 and s["delay_intervals"] == pytest.approx(4.0)
    # the designed chain: FIR of order 40 at 5 kHz (N/(2Fs) = 4 ms) + the notch's DC delay
    assert s["chain_delay_ms"] == pytest.approx(4.0 + _notch_delay_s() * 1e3, abs=1e-9)
    assert s["chain_delay_ms"] == pytest.approx(4.0406, abs=1e-4)
    assert s["predictors"] == ["none", "taylor", "kalman-ls"]
    cases = s["cases"]
    assert len(cases) == 13
    assert [c["motion"] for c in cases] == ["rate"] * 4 + ["accel"] * 4 + ["swing"] * 4 + ["rate"]
    assert [c["pulses"] for c in cases] == ["synchronous"] * 12 + ["asynchronous"]
    for c in cases:
        assert set(c["after_max_arcsec"]) == set(c["after_rms_arcsec"]) == set(s["predictors"])
        assert c["component"] == "yaw" and c["axis"] == [0.0, 0.0, 1.0]
        has = {k for k in ("rate_dps", "accel_dps2", "amplitude_deg", "frequency_hz") if k in c}
        assert has == {"rate": {"rate_dps"}, "accel": {"rate_dps", "accel_dps2"},
                       "swing": {"amplitude_deg", "frequency_hz"}}[c["motion"]]
        assert c["n_pulses"] > 0
    assert [c["rate_dps"] for c in cases[:4]] == [5, 10, 15, 20]
    assert [c["accel_dps2"] for c in cases[4:8]] == [5, 10, 15, 20]
    assert {c["rate_dps"] for c in cases[4:8]} == {15}
    assert [c["frequency_hz"] for c in cases[8:12]] == [0.1, 0.4, 0.8, 1.0]
    assert cases[0]["seed_before"] == "72″" and cases[11]["seed_after"] == "< 1″"


def test_builtin_before_prediction_is_the_delay_closed_form(builtin):
    """Seed's metric, T = 4 ms exactly, Δt = 0: ω·T = 72/144/216/288″; α·T = 72…288″/s on
    the ramps (and the held 15 °/s gives 216″); 2A sin(πfT) on the swings — within 1 %."""
    cases = builtin[0]["cases"]
    T = 4e-3
    for c in cases[:4]:
        assert c["before_max_arcsec"] == pytest.approx(c["rate_dps"] * 3600 * T, rel=0.01)
    for c in cases[4:8]:
        assert c["before_slope_arcsec_per_s"] == pytest.approx(c["accel_dps2"] * 3600 * T,
                                                               rel=0.01)
        assert c["before_max_arcsec"] == pytest.approx(15 * 3600 * T, rel=0.01)
    for c in cases[8:12]:
        want = 2 * 10 * 3600 * abs(math.sin(math.pi * c["frequency_hz"] * T))
        assert c["before_max_arcsec"] == pytest.approx(want, rel=0.01)
    assert cases[0]["before_max_arcsec"] == pytest.approx(72.0, rel=0.005)


def test_builtin_after_prediction_reaches_the_seed_claims_on_its_metric(builtin):
    """kalman-ls on the seed's metric: < 0.3″ / 0.4″ / 1″ (seed Table 1, semi-physical), and
    ≥ 99 % of the lag removed; against the truth the fixed 4 ms leaves the notch's delay,
    at least 90 % of ω·40.65 µs on the uniform-rate cases."""
    s = builtin[0]
    notch = _notch_delay_s()
    for c in s["cases"][:12]:
        after = c["after_max_arcsec"]["kalman-ls"]
        assert after < SEED_AFTER[c["motion"]], c["name"]
        assert after < 0.01 * c["before_max_arcsec"]
        assert c["after_rms_arcsec"]["kalman-ls"] <= after
        assert c["after_max_arcsec"]["none"] == pytest.approx(c["before_max_arcsec"])
    for c in s["cases"][:4]:
        floor = c["rate_dps"] * 3600 * notch
        assert c["truth"]["after_max_arcsec"]["kalman-ls"] > 0.9 * floor
        assert c["truth"]["after_max_arcsec"]["kalman-ls"] < floor + 0.5


def test_builtin_lags_and_the_asynchronous_case(builtin):
    """Seed Fig. 4: at uniform rate the INS lags the table by T_chain + Δt; the 13th case's
    Δt (FPGA counter at 1 µs) sweeps the solution interval, and its before-prediction peak
    is ω (T + max Δt)."""
    s = builtin[0]
    for c in s["cases"][:4]:
        assert c["lag_ms"] == pytest.approx(s["chain_delay_ms"], abs=0.02)
        assert c["dt_us"] == {"min": 0.0, "max": 0.0}
    a = s["cases"][12]
    assert a["pulse_rate_hz"] == 100 and a["dt_us"]["min"] < 20 and a["dt_us"]["max"] > 980
    assert s["chain_delay_ms"] + 0.4 < a["lag_ms"] < s["chain_delay_ms"] + 0.6
    want = 20 * 3600 * (4e-3 + a["dt_us"]["max"] * 1e-6)
    assert a["before_max_arcsec"] == pytest.approx(want, rel=0.01)
    assert a["after_max_arcsec"]["kalman-ls"] < 0.5


@pytest.mark.slow
def test_builtin_show_file_and_plot(builtin, tmp_path):
    s, out, output = builtin
    assert "275″" in output and "async" in output  # the table, on stderr under --json
    shown = runner.invoke(app, ["show", str(out), "--json"])
    assert shown.exit_code == 0, shown.output
    again = json.loads(shown.stdout)
    assert again["kind"] == "realtime" and again["cases"] == s["cases"]
    table = runner.invoke(app, ["show", str(out)])
    assert table.exit_code == 0 and "rate 20°/s async" in table.output
    assert "4.0406" in table.output  # the designed chain's own delay beside T
    with h5py.File(out, "r") as f:
        g = f["realtime"]
        assert g.attrs["reference"] == "seed" and g.attrs["delay"] == 4e-3
        assert sorted(g["cases"]) == [f"{i:02d}" for i in range(13)]
        assert len(g["filter/h"]) == 41 and "notch_b" in g["filter"]
        # the stored arrays give the summary's numbers back
        for i in (0, 7, 11, 12):
            c = g["cases"][f"{i:02d}"]
            t = c["t"][()]
            keep = t >= g.attrs["settle_s"]
            e = np.angle(np.exp(1j * (c["predicted/kalman-ls"][()] - c["ins_ref"][()])))
            if s["cases"][i]["motion"] == "accel":  # corners excluded
                for tc in (1.0, 1.0 + 15 / s["cases"][i]["accel_dps2"]):
                    keep &= np.abs(t - tc) > g.attrs["corner_s"]
            got = np.max(np.abs(e[keep, 2])) / ARCSEC
            assert got == pytest.approx(s["cases"][i]["after_max_arcsec"]["kalman-ls"],
                                        rel=1e-9)
            for name in ("latched", "truth", "ins_ref"):
                assert c[name].shape == (len(t), 3) and c[name].attrs["units"] == "rad"
    plots = runner.invoke(app, ["plot", str(out), "-o", str(tmp_path / "png"), "--json"])
    assert plots.exit_code == 0, plots.output
    names = sorted(Path(p).stem for p in json.loads(plots.stdout)["figures"])
    assert names == sorted([f"realtime_case{i:02d}" for i in range(13)]
                           + ["realtime_filter", "realtime_lag"])


@pytest.mark.slow
def test_figures_carry_the_data(builtin):
    """The case figure's before panel is the latched error; the filter figure's magnitude
    is 0 dB at DC; the lag figure's first line is the first case's measured lag."""
    from gcalign.app.realtime.plots import figures

    s, out, _ = builtin
    with h5py.File(out, "r") as f:
        figs = figures(f, "t")
    ax = figs["realtime_case00"].axes[0]
    y = ax.lines[0].get_ydata()
    assert np.nanmax(np.abs(y[len(y) // 2:])) == pytest.approx(
        s["cases"][0]["before_max_arcsec"], rel=1e-6)
    mag = figs["realtime_filter"].axes[0].lines[-1].get_ydata()
    assert abs(mag[0]) < 1e-5  # dB at 0.125 Hz (the passband droop)
    lag = figs["realtime_lag"].axes[1].lines
    assert np.mean(lag[0].get_ydata()) == pytest.approx(s["cases"][0]["lag_ms"], rel=1e-9)


# ---------------------------------------------------------------------------- options, cases

def test_predictor_option_and_truth_reference(tmp_path):
    """--predictor selects; semi_physical: false puts T at the chain's delay and the
    reference at the truth, where kalman-ls is within 1″ at uniform rate."""
    res = _run(str(_small(tmp_path)), "--predictor", "kalman-ls", "--predictor", "none",
               "--json", "-o", str(tmp_path / "o.h5"))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["predictors"] == ["kalman-ls", "none"] and s["reference"] == "truth"
    assert s["filter_delay_ms"] == s["chain_delay_ms"]
    for c in s["cases"]:
        assert set(c["after_max_arcsec"]) == {"kalman-ls", "none"}
        assert c["after_max_arcsec"] == c["truth"]["after_max_arcsec"]
    assert s["cases"][0]["after_max_arcsec"]["kalman-ls"] < 1.0
    assert s["cases"][0]["before_max_arcsec"] == pytest.approx(
        10 * 3600 * s["chain_delay_ms"] * 1e-3, rel=0.01)
    # the option is recorded in the file's scenario text
    with h5py.File(tmp_path / "o.h5", "r") as f:
        assert "predictors" in f.attrs["scenario_yaml"]


def test_a_turntable_motion_is_one_case(tmp_path):
    """configs/seed003_rate20_async.yaml, shortened: one case from motion.kind: turntable,
    about a tilted axis here; the turned Euler angle is reported."""
    d = yaml.safe_load((ROOT / "configs/seed003_rate20_async.yaml").read_text())
    d["motion"]["duration_s"] = 3
    d["motion"]["steps"] = [{"axis": "x", "profile": "rate", "rate_dps": 20, "duration_s": 3}]
    p = tmp_path / "m.yaml"
    p.write_text(yaml.safe_dump(d, allow_unicode=True))
    res = _run(str(p), "--json", "-o", str(tmp_path / "m.h5"))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    (c,) = s["cases"]
    assert c["name"] == d["name"] and c["motion"] == "rate" and c["component"] == "pitch"
    assert c["pulses"] == "asynchronous" and c["duration_s"] == 3
    assert c["lag_ms"] == pytest.approx(s["chain_delay_ms"] + 0.5, abs=0.3)
    assert c["after_max_arcsec"]["kalman-ls"] < 1.0


def test_same_seed_same_numbers(tmp_path):
    p = _small(tmp_path)
    a, b, c = (json.loads(_run(str(p), "--json", "--seed", str(k), "-o",
                               str(tmp_path / f"{i}.h5")).stdout)
               for i, k in enumerate((5, 5, 6)))
    assert a["cases"] == b["cases"] and a["seed"] == 5
    assert a["cases"] != c["cases"]


def test_batch_metric_and_run_task(tmp_path):
    """The registry's default metric reads a number from the summary; a batch run of the
    small scenario gives it."""
    from gcalign.app.batch.runs import run_task
    from gcalign.app.registry import batchable

    metric = batchable()["realtime"].options.batch_metrics[0]
    assert metric == "cases.0.after_max_arcsec.kalman-ls"
    scenario = yaml.safe_load(_small(tmp_path).read_text())
    rec = run_task({"command": "realtime", "variant": 0, "vkey": "v", "seed": 1,
                    "scenario": scenario, "source": "t", "metrics": [metric]})
    assert rec["status"] == "ok", rec
    assert 0 < rec["metrics"][metric] < 1.0


@pytest.mark.slow
def test_validate_does_not_load_scipy_or_numba():
    """`gcalign validate` reads the realtime section without importing scipy or numba."""
    cfg = str(ROOT / "configs/seed003_table1.yaml")
    code = ("import sys\nfrom typer.testing import CliRunner\nfrom gcalign.cli import app\n"
            f"r = CliRunner().invoke(app, ['validate', {cfg!r}, '--json'])\n"
            "assert r.exit_code == 0, r.output\n"
            "print(sorted(m for m in ('numba', 'scipy') if m in sys.modules))\n"
            "print(r.stdout)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    first, rest = out.split("\n", 1)
    assert first == "[]"
    values = json.loads(rest)["values"]
    assert "realtime.delay (T)" in values and "realtime.cases.12" in values


# ---------------------------------------------------------------------------- bad input

def _bad(tmp_path: Path, args, field: str, *more: str):
    assert_bad_run(_run, tmp_path, args, field, *more)


SWING_600 = [{"name": "fast", "steps": [{"axis": "z", "profile": "swing", "amplitude_deg": 0.5,
                                         "frequency_hz": 600, "duration_s": 3}]}]


@pytest.mark.parametrize(
    ("change", "field", "more"),
    [
        ({"pulses": {"rate_hz": 2000}}, "realtime.pulses.rate_hz", ("≤ solution_hz = 1000",
                                                                     "got 2000")),
        ({"filter": {"nav_order": 0}}, "realtime.filter.nav_order", ("integer ≥ 1", "got 0")),
        ({"filter": {"notch_hz": 2500}}, "realtime.filter.notch_hz", ("Nyquist", "got 2500")),
        ({"filter": {"notch_hz": 3000}}, "realtime.filter.notch_hz", ("Nyquist",)),
        ({"filter": {"fs_hz": 4800}}, "realtime.filter.fs_hz", ("whole multiple",
                                                                 "got 4800 Hz")),
        ({"tracker": {"qc_rad2ps5": 0}}, "realtime.tracker.qc_rad2ps5", ("greater than 0",)),
        ({"tracker": {"qc_rad2ps5": -1}}, "realtime.tracker.qc_rad2ps5", ("got -1",)),
        ({"tracker": {"r_std_arcsec": 0}}, "realtime.tracker.r_std_arcsec",
         ("must be within [0.0001, 3600] ″", "got 0")),
        ({"cases": SWING_600}, "realtime.cases.0.steps.0.frequency_hz",
         ("Nyquist", "500 Hz", "got 600 Hz")),
        ({"predictors": ["kalman"]}, "realtime.predictors.0", ("got 'kalman'",)),
        ({"semi_physical": True, "delay_ms": 5}, "realtime.delay_ms", ("4 ms",)),
        ({"semi_physical": True, "pulses": {"rate_hz": 100}}, "realtime.pulses",
         ("semi_physical",)),
        ({"pulses": {"rate_hz": 300}}, "realtime.pulses.rate_hz", ("divide",)),
        ({"settle_s": 5}, "realtime.cases.0.settle_s", ("shorter than the case",)),
        ({"sensor": {"dither_hz": 0}}, "realtime.sensor.dither_hz", ("greater than 0",)),
        ({"filter": {"ordr": 3}}, "realtime.filter.ordr", ("unknown key",)),
    ],
)
def test_bad_realtime_section_exits_2(tmp_path, change, field, more):
    p = _small(tmp_path)
    d = yaml.safe_load(p.read_text())
    d["realtime"].update(change)
    p.write_text(yaml.safe_dump(d, allow_unicode=True))
    _bad(tmp_path, [str(p)], field, *more)


@pytest.mark.parametrize(
    ("change", "field", "more"),
    [
        ({"site": None}, "site", ("missing",)),
        ({"imu": {"seed": 1, "gyro": {"bias_dph": [0.01, 0, 0]}}}, "imu.gyro.bias_dph",
         ("realtime.sensor",)),
        ({"imu": {"seed": 1, "gyro": {"bias_gm": {"std_dph": 0.01, "tau_s": 100}}}},
         "imu.gyro.bias_gm", ("realtime.sensor", "'tau_s': [100.0, 100.0, 100.0]")),
        ({"imu": {"rate_hz": 100}}, "imu.rate_hz", ("5000 Hz", "got 100")),
        ({"motion": {"kind": "static", "duration_s": 3}}, "realtime.cases", ("not both",)),
    ],
)
def test_bad_scenario_exits_2(tmp_path, change, field, more):
    p = _small(tmp_path)
    d = yaml.safe_load(p.read_text())
    for k, v in change.items():
        if v is None:
            d.pop(k)
        else:
            d[k] = v
    p.write_text(yaml.safe_dump(d, allow_unicode=True))
    _bad(tmp_path, [str(p)], field, *more)


def test_motion_form_checks(tmp_path):
    """Without cases: a turntable motion is required, and its swing must be below Nyquist."""
    p = _small(tmp_path, cases=None)
    _bad(tmp_path, [str(p)], "motion.kind", "turntable")
    d = yaml.safe_load(p.read_text())
    d["motion"] = {"kind": "turntable", "duration_s": 3, "steps": SWING_600[0]["steps"]}
    p.write_text(yaml.safe_dump(d, allow_unicode=True))
    _bad(tmp_path, [str(p)], "motion.steps.0.frequency_hz", "Nyquist")


def test_bad_predictor_option_exits_2(tmp_path):
    _bad(tmp_path, [str(_small(tmp_path)), "--predictor", "foo"], "realtime.predictors.0",
         "got 'foo'")


@pytest.mark.slow
def test_show_and_plot_do_not_load_scipy_or_numba(builtin, tmp_path):
    """`gcalign show` and `gcalign plot` of a realtime file read it without the kernels."""
    _, out, _ = builtin
    code = ("import sys, json\nfrom typer.testing import CliRunner\nfrom gcalign.cli import app\n"
            f"a = CliRunner().invoke(app, ['show', {str(out)!r}])\n"
            f"b = CliRunner().invoke(app, ['plot', {str(out)!r}, '-o', {str(tmp_path)!r}])\n"
            "print(json.dumps([a.exit_code, b.exit_code, 'numba' in sys.modules, "
            "'scipy' in sys.modules]))\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert json.loads(res.stdout.strip().splitlines()[-1]) == [0, 0, False, False]


def test_ramp_corners_are_rows_of_the_headline_table(tmp_path):
    """A ramp's corner maxima (±corner_ms around the steps in α, excluded from the after
    columns) appear on their own row under the ramp, with the JSON's numbers, and the
    corner error exceeds the scored one (a step in α is not quadratic motion)."""
    ramp = {"name": "accel 20°/s²", "steps": [
        {"profile": "rest", "duration_s": 1},
        {"axis": "z", "profile": "ramp", "accel_dps2": 20, "rate_dps": 15,
         "duration_s": 2}]}
    res = _run(str(_small(tmp_path, cases=[ramp])), "--json", "-o", str(tmp_path / "r.h5"))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    c = s["cases"][0]
    cm = c["corner_max_arcsec"]
    assert cm["kalman-ls"] > c["after_max_arcsec"]["kalman-ls"]
    shown = runner.invoke(app, ["show", str(tmp_path / "r.h5")])
    assert shown.exit_code == 0, shown.output
    row = next(x for x in shown.output.splitlines() if "corners ±50 ms" in x)
    assert f"{cm['kalman-ls']:.3f}" in row and f"{cm['taylor']:.3f}" in row


def test_beyond_seed_config_runs_a_2hz_swing_and_a_rate_step(tmp_path):
    """configs/realtime_beyond_seed.yaml, shortened to 2 s per case: the 2 Hz swing before
    prediction is the closed form 2A·sin(π f T) (1 %), and the rate step's scored maximum
    holds its transient, above ω·T·(1/2) where the latched attitude lags by ω·T."""
    d = yaml.safe_load((ROOT / "configs/realtime_beyond_seed.yaml").read_text())
    d["realtime"]["cases"][0]["steps"][0]["duration_s"] = 2
    d["realtime"]["cases"][1]["steps"][1]["duration_s"] = 1
    p = tmp_path / "beyond.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False, allow_unicode=True))
    res = _run(str(p), "--json", "-o", str(tmp_path / "b.h5"))
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    swing, step = s["cases"]
    assert swing["motion"] == "swing" and step["motion"] == "rate"
    assert swing["before_max_arcsec"] == pytest.approx(swing["before_theory_arcsec"], rel=0.01)
    lag = 15 * 3600 * s["filter_delay_ms"] * 1e-3  # ω·T, ″
    assert step["after_max_arcsec"]["kalman-ls"] > 0.5 * lag


@pytest.mark.slow  # a 12 s case through a 60000-tap FIR: about 2 s
def test_a_fir_as_long_as_its_case_runs_in_seconds(tmp_path):
    """nav_order 59999 (an FIR spanning 12 s) on a 12 s case is within the case and the
    work limit: by direct convolution (3 channels × 6e4 taps × 6e4 samples) it took 21 s of
    CPU, and on the 13 default cases over 5 minutes; through FFTs 1.8 s. CPU time, not wall
    time, so that a loaded machine cannot fail it."""
    import time

    import fuzz_cases as F

    d = json.loads(json.dumps(F.REALTIME))
    d["realtime"]["cases"][0]["steps"][0]["duration_s"] = 12
    (tmp_path / "rt.yaml").write_text(F.emit(d))
    t0 = time.process_time()
    res = _run(str(tmp_path / "rt.yaml"), "--set", "realtime.filter.nav_order=59999",
               "--json", "-o", str(tmp_path / "o.h5"))
    cpu = time.process_time() - t0
    assert res.exit_code == 0, res.output
    assert cpu < 8.0, f"{cpu:.1f} s of CPU"
    # the latched heading still lags by the chain's delay: ω·T at 5 °/s, T = 6.0 s
    case = json.loads(res.stdout)["cases"][0]
    assert case["before_theory_arcsec"] == pytest.approx(5 * 3600 * 5.9999406, rel=1e-6)
    assert case["before_max_arcsec"] == pytest.approx(case["before_theory_arcsec"], rel=1e-3)
