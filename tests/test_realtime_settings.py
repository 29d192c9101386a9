"""Bad settings of a real-time run are rejected with one line naming the setting
(gcalign.realtime.settings, cases; must-show 7, the parts below the command line)."""

from __future__ import annotations

import pytest

from gcalign.realtime import (
    FilterSettings,
    PulseSettings,
    Settings,
    TrackerSettings,
    accel_case,
    swing_case,
)
from gcalign.realtime.cases import check_case
from gcalign.units import DEG


def _swing(f):
    return swing_case("s", DEG, f, 12.0)


BAD = [
    ("pulse rate above the solution rate", lambda: Settings(pulses=PulseSettings(rate_hz=2000.0)),
     "pulses.rate_hz: must be ≤ solution_hz = 1000 Hz"),
    ("async pulse rate above the solution rate",
     lambda: Settings(pulses=PulseSettings(mode="async", rate_hz=1500.0)),
     "pulses.rate_hz: must be ≤ solution_hz"),
    ("filter order < 1", lambda: FilterSettings(nav_order=0),
     "filter.nav_order: must be an integer ≥ 1"),
    ("alignment order < 1", lambda: FilterSettings(align_order=-3),
     "filter.align_order: must be an integer ≥ 1"),
    ("notch at Nyquist", lambda: FilterSettings(notch_hz=2500.0),
     "filter.notch_hz: must be in (0, 2500) Hz"),
    ("notch above Nyquist", lambda: FilterSettings(notch_hz=3000.0), "filter.notch_hz"),
    ("sample rate not a multiple of the solution rate",
     lambda: Settings(filter=FilterSettings(fs_hz=4800.0)),
     "filter.fs_hz: must be a whole multiple of solution_hz = 1000 Hz, got 4800 Hz"),
    ("solution rate above the sample rate", lambda: Settings(solution_hz=10000.0),
     "filter.fs_hz: must be a whole multiple"),
    ("Qc = 0", lambda: TrackerSettings(qc=0.0), "tracker.qc: must be a finite number > 0"),
    ("Qc < 0", lambda: TrackerSettings(qc=-1.0), "tracker.qc: must be a finite number > 0"),
    ("R = 0", lambda: TrackerSettings(r=0.0), "tracker.r: must be a finite number > 0"),
    ("R < 0", lambda: TrackerSettings(r=-1e-12), "tracker.r: must be a finite number > 0"),
    ("swing frequency above Nyquist", lambda: check_case(_swing(600.0), Settings()),
     "steps.0.frequency_hz: a swing must be below the Nyquist frequency of the 1000 Hz "
     "attitude solution (500 Hz), got 600 Hz"),
    ("swing frequency zero", lambda: _swing(0.0), "swing: frequency must be > 0"),
    ("settle time longer than the case",
     lambda: check_case(_swing(1.0), Settings(settle_s=12.0)), "settle_s: must be shorter"),
    ("cut-off above Nyquist", lambda: FilterSettings(nav_cutoff_hz=2600.0),
     "filter.nav_cutoff_hz: must be in (0, 2500) Hz"),
    ("pulses not on solution instants", lambda: Settings(pulses=PulseSettings(rate_hz=300.0)),
     "pulses.rate_hz: must divide solution_hz"),
    ("unknown predictor", lambda: Settings(predictors=("kalman",)), "predictors: must be"),
    ("ramp that cannot reach its rate",
     lambda: accel_case("r", 0.1 * DEG, 15 * DEG, 12.0), "ramp: reaching"),
]


@pytest.mark.parametrize(("what", "make", "message"), BAD, ids=[b[0] for b in BAD])
def test_bad_settings_raise_one_line_naming_the_setting(what, make, message):
    with pytest.raises(ValueError) as info:
        make()
    text = str(info.value)
    assert message in text
    assert "\n" not in text


def test_defaults_are_the_spec_proposals():
    s = Settings()
    assert (s.filter.fs_hz, s.solution_hz, s.samples_per_solution) == (5000.0, 1000.0, 5)
    assert (s.filter.align_order, s.filter.nav_order) == (180, 40)
    assert (s.filter.notch_hz, s.filter.notch_q) == (400.0, 10.0)
    assert (s.filter.align_cutoff_hz, s.filter.nav_cutoff_hz) == (100.0, 200.0)
    assert s.tracker.qc == 1.0
    assert s.delay_s is None  # T from the chain


def test_the_fir_window_names_are_scipys_windows_without_parameters():
    """The scenario checks the window by name (validate must not import scipy): every name
    it allows is a window scipy.signal designs without a parameter, and one that needs a
    parameter is not allowed."""
    from scipy import signal

    from gcalign.io.scenario.realtime import FIR_WINDOWS

    for name in FIR_WINDOWS:
        assert len(signal.get_window(name, 8)) == 8
    assert "kaiser" not in FIR_WINDOWS  # needs its beta


@pytest.mark.parametrize("pulses, message", [
    ({"mode": "async", "rate_hz": 100, "jitter_us": 1e12},
     "realtime.pulses.jitter_us: must be at most a tenth of the pulse period (1000 µs at 100 "
     "Hz"),
    ({"mode": "solution", "rate_hz": 100, "jitter_us": 5},
     "realtime.pulses.jitter_us: mode 'solution' puts the pulses on solution instants, so it "
     "cannot matter"),
    ({"mode": "solution", "rate_hz": 100, "drift_ppm": 50},
     "realtime.pulses.drift_ppm: mode 'solution'"),
    ({"mode": "async", "rate_hz": 0.5},
     "pulses.rate_hz: 0.5 Hz gives fewer than 2 pulses in the 1.5 s scored"),
    ({"mode": "solution", "rate_hz": 100, "offset_us": None},
     "realtime.pulses.offset_us: mode 'solution' puts each pulse this far after a solution "
     "instant: within [0, 1000) µs at 1000 Hz (null, a random first edge, is for mode async), "
     "got null"),
    ({"mode": "solution", "rate_hz": 100, "offset_us": 5000},
     "realtime.pulses.offset_us: mode 'solution' puts each pulse this far after a solution "
     "instant: within [0, 1000) µs at 1000 Hz (null, a random first edge, is for mode async), "
     "got 5000"),
])
def test_a_pulse_jitter_that_cannot_matter_or_leaves_no_pulse_is_refused(tmp_path, pulses,
                                                                         message):
    """jitter_us 1e12 on an asynchronous case left no pulse to score (an internal error);
    a jitter in mode 'solution', where the pulses fall on solution instants, was accepted in
    silence; an offset in mode 'solution' was refused as the core's offset_s, in s."""
    import fuzz_cases as F
    from cli_checks import assert_bad_input
    from typer.testing import CliRunner

    from gcalign.cli import app

    d = {**F.REALTIME, "realtime": {**F.REALTIME["realtime"], "pulses": pulses}}
    (tmp_path / "rt.yaml").write_text(F.emit(d))
    out = tmp_path / "o.h5"
    for argv in (["realtime", str(tmp_path / "rt.yaml"), "-o", str(out)],
                 ["validate", str(tmp_path / "rt.yaml")]):
        res = CliRunner().invoke(app, argv)
        assert_bad_input(res, out, message)


@pytest.mark.parametrize("sets, keys", [
    (["realtime.filter.align_order=1000000"], "realtime.filter.align_order"),
    (["realtime.filter.chain=alignment", "realtime.filter.nav_order=30",
      "realtime.filter.notch_hz=300"], "realtime.filter.nav_order, realtime.filter.notch_hz"),
])
def test_a_filter_key_of_the_chain_not_run_is_a_warning(tmp_path, sets, keys):
    """An align_order of 1e6 beside the navigation chain ran in silence (the alignment FIR
    is never designed then); the built-in Table 1, which sets only its chain's keys, warns of
    nothing."""
    import fuzz_cases as F
    from typer.testing import CliRunner

    from gcalign.cli import app

    (tmp_path / "rt.yaml").write_text(F.emit(F.REALTIME))
    args = [a for kv in sets for a in ("--set", kv)]
    for argv in (["realtime", str(tmp_path / "rt.yaml"), *args, "-o", str(tmp_path / "o.h5")],
                 ["validate", str(tmp_path / "rt.yaml"), *args]):
        res = CliRunner().invoke(app, argv)
        assert res.exit_code == 0, res.output
        assert f"{keys}: cannot matter with filter.chain" in res.stderr.replace("\n", " "), \
            res.stderr
    import gcalign
    from conftest import ROOT

    for name in ("seed003_table1", "seed003_rate20_async", "realtime_beyond_seed"):
        assert gcalign.load(ROOT / "configs" / f"{name}.yaml").realtime.unused() == [], name
