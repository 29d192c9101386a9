"""The consistency checks of in-flight calibration (gcalign.estimation.health) on transfer
alignment: the mean NIS against the 95 % band of a mean over the run's epochs, a σ growing
past 10× its P0. A simulated case whose R is the master's noise passes; the same case with
R 100× too large (σ 10×) fails, as the real file does (its R, the demo's, is about 6× the
noise: mean NIS 0.16 for 6 dof), shown in the table and in the JSON."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
from transfer_cases import case, write_scenario
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.estimation.health import mean_nis_band
from gcalign.transfer import transfer_align
from gcalign.transfer.filter import P0_SIGMA_DEFAULT
from gcalign.units import ARCMIN

SEED = 3
runner = CliRunner()


def _run(c, **settings):
    """The command's route: from the master's attitude (φ0 = −C_nb μ, so φ's P0 is the
    demo's 10°, not the case's 0.1°), attitude feedback on."""
    p0 = (*(P0_SIGMA_DEFAULT[0],) * 3, *c.settings.p0_sigma[3:])
    s = replace(c.settings, **{"p0_sigma": p0, "attitude_feedback": True, **settings})
    return transfer_align(c.dtheta, c.dv, c.t, c.master, s)


def test_a_filter_whose_r_is_the_noise_passes_and_one_ten_times_wider_fails():
    """Mean NIS of 199 epochs × 6 dof: band 6 ± 1.96 √(12/199) ≈ [5.53, 6.49]. With every
    R σ 10× the noise, S ≥ 100 R_true: the innovations' share of it falls by that factor
    and the filter's own P, wider with a wider R, adds back only part (measured 0.12)."""
    c = case(SEED)
    r = _run(c)
    lo, hi = mean_nis_band(len(r.nis), 6)
    assert lo == pytest.approx(5.53, abs=0.01) and hi == pytest.approx(6.49, abs=0.01)
    assert lo < r.nis.mean() < hi
    assert r.health_warnings() == []
    wide = _run(c, r_sigma=tuple(10 * x for x in c.settings.r_sigma))
    (line,) = wide.health_warnings("wide R: ")
    assert line.startswith("wide R: mean NIS ") and " is below its 95 % band " in line
    assert wide.nis.mean() < lo / 10, wide.nis.mean()


def test_a_sigma_without_a_measurement_warns():
    """Attitude matching alone never measures δv: with P0 δv 0.01 m/s its σ grows with the
    accelerometer bias' σ, 1000 µg ≈ 0.01 m/s², to about 0.2 m/s in 20 s (20×); with
    velocity matching too it does not grow."""
    c = case(SEED)
    p0 = (*(P0_SIGMA_DEFAULT[0],) * 3, *(0.01,) * 3, *c.settings.p0_sigma[6:])
    lines = _run(c, matching="attitude", p0_sigma=p0).health_warnings()
    grown = [w for w in lines if ": σ grew from 0.01 to " in w]
    assert [w.split(":")[0] for w in grown] == ["dvE", "dvN", "dvU"], lines
    assert all(" m/s (" in w for w in grown)
    assert _run(c, p0_sigma=p0).health_warnings() == []
    assert all(" m/s (" in w for w in grown)


@pytest.mark.parametrize("wide", [False, True])
def test_the_command_shows_the_check(tmp_path, wide):
    sigma = 10 * 1.0 if wide else 1.0  # the case's master noise: 1′, 0.02 m/s
    p = write_scenario(case(SEED), tmp_path, r={"attitude_arcmin": sigma,
                                                "velocity_mps": 0.02 * sigma / 1.0})
    res = runner.invoke(app, ["align", str(p), "--json", "-o", str(tmp_path / "o.h5")])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["nis"]["consistent"] is (not wide)
    lo, hi = s["nis"]["band_95_of_mean"]
    assert (lo < s["nis"]["mean"] < hi) is (not wide)
    nis_lines = [w for w in s["warnings"] if w.startswith("mean NIS")]
    assert len(nis_lines) == int(wide), s["warnings"]
    res = runner.invoke(app, ["show", str(tmp_path / "o.h5")])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert ("the mean lies OUTSIDE its band" in text) is wide
    assert ("warning: mean NIS" in text) is wide
    assert s["states"]["mux"]["sigma0"] == pytest.approx(60 * ARCMIN)  # the demo's P0
