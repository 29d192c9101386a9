"""What `gcalign modulate` reports beside the series: the last hour of any run, the ratios
to the unrotated run (at the last hour, of the maxima, of the RMS), an unrotated scheme
without a cycle, the misalignment × rate terms and the Schuler warning for every modulated
error. Short runs; reference values from the stored series and the invariant
report (independent routes) or from the literal scheme's parity (a third of the biases)."""

from __future__ import annotations

import math

import h5py
import numpy as np
import pytest
from rich.console import Console

from gcalign.app.modulate.run import report_hours, run_modulate, seed_scenario
from gcalign.app.modulate.tables import modulate_table
from gcalign.modulate.invariants import invariant_report
from gcalign.modulate.schemes import builtin_scheme
from gcalign.modulate.terms import ErrorTerms
from gcalign.units import ARCSEC


def _render(summary: dict, width: int = 200) -> str:
    console = Console(width=width, record=True, file=open("/dev/null", "w"))  # noqa: SIM115
    console.print(modulate_table(summary))
    return console.export_text()


def test_the_last_hour_is_always_reported():
    assert report_hours(6.0) == [1.0, 4.0, 6.0]
    assert report_hours(48.0) == [1.0, 4.0, 12.0, 24.0, 48.0]
    assert report_hours(72.0) == [1.0, 4.0, 12.0, 24.0, 72.0]
    assert report_hours(0.5) == [0.5]


@pytest.fixture(scope="module")
def short_run():
    """fixed against seed-12 for 2.5 h at 10 Hz (the seed's biases; 1 Hz samples its 12 s
    turns too coarsely for the linear model's 0.5 %), series kept in memory."""
    sc = seed_scenario(["fixed", "seed-12"], rate=10.0, hours=2.5, source="test")
    f = h5py.File("mem-summary.h5", "w", driver="core", backing_store=False)
    summary = run_modulate(sc, sink=f)[0]
    return summary, f


def test_last_hour_in_json_and_table_agrees_with_the_linear_model(short_run):
    s, _ = short_run
    assert s["report_hours"] == [1.0, 2.5]
    for name in ("fixed", "seed-12"):
        r = s["schemes"][name]
        assert list(r["horizontal_error_m"]) == ["1h", "2.5h"]
        assert r["horizontal_error_m"]["2.5h"] == r["final_horizontal_error_m"]
        # two routes: navigation and the linear model at the last hour (0.5 % + 2 m)
        assert r["horizontal_error_m"]["2.5h"] == pytest.approx(
            r["linear"]["horizontal_error_m"]["2.5h"], rel=0.005, abs=2.0)
    text = _render(s)
    assert "2.5 h" in text and "lin. 2.5 h" in text


def test_ratios_to_fixed_from_the_stored_series(short_run):
    """The RMS from the stored rows, the maxima from the summary; seed-12 behaves as the
    unrotated IMU with a third of the biases (its cycle mean is diag(−1, 1, 1)/3), so every
    ratio tends to 3; within the first cycles (62.4 min each) it lies between 2 and 4.5."""
    s, f = short_run
    fixed, lit = s["schemes"]["fixed"], s["schemes"]["seed-12"]
    assert fixed["ratio_to_fixed"] is None
    q = lit["ratio_to_fixed"]
    assert q["last_hour"] == pytest.approx(fixed["horizontal_error_m"]["2.5h"]
                                           / lit["horizontal_error_m"]["2.5h"], rel=1e-12)
    assert q["max"] == pytest.approx(fixed["max_horizontal_error_m"]
                                     / lit["max_horizontal_error_m"], rel=1e-12)
    rms = {}
    for name in ("fixed", "seed-12"):
        pos = f[f"modulate/{name}/error/pos"][:]
        rms[name] = math.sqrt(np.mean(pos[:, 0]**2 + pos[:, 1]**2))
        assert s["schemes"][name]["rms_horizontal_error_m"] == pytest.approx(rms[name],
                                                                             rel=1e-9)
    assert q["rms"] == pytest.approx(rms["fixed"] / rms["seed-12"], rel=1e-9)
    assert 2.0 < q["last_hour"] < 4.5 and 2.0 < q["max"] < 4.5
    row = next(x for x in _render(s).splitlines() if x.strip().startswith("seed-12")
               and "fixed" not in x and f"{q['last_hour']:.3g}" in x)
    assert row.split()[-3:] == [f"{q[k]:.3g}" for k in ("last_hour", "max", "rms")], row
    assert "fixed ÷ at 2.5 h" in _render(s)


def test_no_number_cut_at_80_columns(short_run):
    """The 72 h table's columns (five report hours, max, linear model, three ratios) at 80
    columns: every cell whole, no "…" (rich shortens cells that do not fit)."""
    s, _ = short_run
    s = {**s, "report_hours": [1.0, 4.0, 12.0, 24.0, 72.0],
         "schemes": {n: {**r, "horizontal_error_m": {f"{h:g}h": 79609.0 for h in
                                                       (1, 4, 12, 24, 72)},
                         "max_horizontal_error_m": 79613.0}
                     for n, r in s["schemes"].items()}}
    text = _render(s, width=80)
    assert "…" not in text, text
    assert max(len(x) for x in text.splitlines()) <= 80
    assert "79,609" in text and "79,613" in text


def test_an_unrotated_scheme_has_no_cycle(short_run):
    s, _ = short_run
    assert s["schemes"]["fixed"]["cycle_s"] is None
    assert s["schemes"]["seed-12"]["cycle_s"] == pytest.approx(3744.0)
    row = next(x for x in _render(s).splitlines() if x.strip().startswith("fixed")
               and "—" in x and "nav" not in x)
    assert row


def test_misalignment_terms_reported_net_peak_and_mean():
    """A gyro misalignment M_xz = 10″ (x senses the z rate) on four-position-12: the JSON
    carries the invariant report's net, peak and cycle mean, and the peak is at least that of
    one 180° turn about z, |∫ C e_x dθ| = 2·M_xz (closed form), though the net may be 0."""
    mis = [[0, 0, 10], [0, 0, 0], [0, 0, 0]]
    sc = seed_scenario(["four-position-12"], rate=1.0, hours=0.5, source="test",
                       gyro={"misalignment_arcsec": mis}, accel={})
    s = run_modulate(sc)[0]
    r = s["schemes"]["four-position-12"]
    terms = ErrorTerms(gyro_misalignment=np.array(mis, float) * ARCSEC)
    rep = invariant_report(builtin_scheme("four-position-12"), terms)
    for part in ("net", "peak", "offset"):
        np.testing.assert_allclose(r[f"misalignment_{part}_arcsec"],
                                   getattr(rep, f"misalignment_{part}") / ARCSEC, atol=1e-9)
    assert max(r["misalignment_peak_arcsec"]) >= 2 * 10 - 1e-6
    assert "M term" in _render(s) and f"{max(r['misalignment_peak_arcsec']):.2g}" in _render(s)


def test_schuler_warning_names_every_modulated_error():
    rep = invariant_report(builtin_scheme("dual-16-improved"))
    assert rep.warnings
    assert all("scale-factor and misalignment" in w for w in rep.warnings)
