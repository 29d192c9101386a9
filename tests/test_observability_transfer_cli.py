"""`gcalign observability` on a transfer-alignment scenario (spec 006; the command of seed
002, dispatched on ``align.mode: transfer``): one run per matching on a simulated case (a
PSINS .mat of :mod:`transfer_cases`), the JSON in the command's shape, the results file and
its figures, ``--matching`` against ``--set``, refusals; the real file (slow).

Expected values from the model's structure, not from a run:

* velocity: μ enters neither F nor the velocity rows of H, so its TOM columns are zero
  (η = 0, separation 0, listed unobservable, rank ≤ 12) and, with P0 diagonal, the filter
  never changes its covariance: σ(μ) = σ0;
* attitude: δv and ∇ reach neither the attitude rows of H nor φ (zero columns: exactly 6
  unobservable); the vehicle rolls about its body y axis only, so (φ along the forward
  axis d, μ along C(μ)ᵀ e_y ≈ e_y) is unobservable but for the earth rate: the weakest
  combination is that vector, μ_y stays far less observed than μ_x, μ_z;
* attitude + velocity: φ along d is a tilt the velocity sees (f^n × φ), so every μ is
  observed: no zero column, each μ's σ cut by more than 10.
"""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from cli_checks import assert_bad_input
from transfer_cases import case, write_scenario
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.units import ARCMIN

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "configs" / "psins_transfer_fog_mems.yaml"
MATCHINGS = ("attitude+velocity", "velocity", "attitude")
MU = ("mux", "muy", "muz")
runner = CliRunner()


def _obs(*args):
    return runner.invoke(app, ["observability", *map(str, args)])


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    """The three matchings on one simulated case: {matching: (summary, results file)}."""
    folder = tmp_path_factory.mktemp("tobs")
    c = case(3)
    path = write_scenario(c, folder)
    out = {}
    for m in MATCHINGS:
        h5 = folder / f"{m}.h5"
        res = _obs(path, "--matching", m, "--json", "-o", h5)
        assert res.exit_code == 0, res.output
        out[m] = (json.loads(res.stdout), h5)
    return c, path, out


def _forward_combination(c, s):
    """The unit vector of (φ = d, μ = J_l(μ)⁻¹ e_y) in the P0-scaled states, d the forward
    axis at heading 30°: the tangent of the roll axis' unobservable set. Turning the slave
    by s about d, C_m C(μ') = exp([s d×]) C_m C(μ), gives C(μ') = exp([s e_y×]) C(μ), whose
    rotation vector moves by s J_l(μ)⁻¹ e_y = s (e_y − ½ μ × e_y + …)."""
    from gcalign.transfer.model import left_jacobian_inv

    x = dict.fromkeys(s["states"], 0.0)
    yaw = np.radians(30.0)
    x["phiE"], x["phiN"] = -np.sin(yaw), np.cos(yaw)
    x.update(zip(MU, left_jacobian_inv(c.mu) @ [0.0, 1.0, 0.0], strict=True))
    y = np.array([x[n] / s["sigma0"][n] for n in s["states"]])
    return y / np.linalg.norm(y)


def test_velocity_matching_leaves_mu_at_its_p0(sim):
    _, _, out = sim
    s, _ = out["velocity"]
    assert s["mode"] == "transfer" and s["matching"] == "velocity"
    assert s["unobservable"] == list(MU) and s["rank_final"] <= 12
    for n in MU:
        assert s["degree_final"][s["states"].index(n)] == 0.0
        assert s["separation"][n] == 0.0 and s["weakest"]["vector"][n] == 0.0
        assert s["sigma_final"][n] == pytest.approx(s["sigma0"][n], rel=1e-12)
        assert s["covariance_degree_final"][n] == pytest.approx(1.0, rel=1e-12)
        assert all(w["covariance_degree"][n] == pytest.approx(1.0, rel=1e-12)
                   for w in s["cumulative"])


def test_attitude_matching_leaves_the_roll_axis_mu_poorly_observed(sim):
    c, _, out = sim
    s, _ = out["attitude"]
    assert s["unobservable"] == ["dvE", "dvN", "dvU", "dbx", "dby", "dbz"]
    assert s["rank_final"] == 9  # 15 − the 6 zero columns; the roll axis weak, not zero
    w = np.array([s["weakest"]["vector"][n] for n in s["states"]])
    assert np.abs(w - _forward_combination(c, s)).max() < 0.02
    assert s["weakest"]["ratio"] < 1e-2
    sig = {n: s["sigma_final"][n] / ARCMIN for n in MU}
    assert sig["muy"] > 10.0 and max(sig["mux"], sig["muz"]) < sig["muy"] / 10, sig
    sep = s["separation"]
    assert sep["muy"] < 0.1 * min(sep["mux"], sep["muz"]), sep


def test_attitude_and_velocity_observe_every_mu(sim):
    _, _, out = sim
    s, _ = out["attitude+velocity"]
    assert s["unobservable"] == [] and s["rank_final"] == s["tom_rank_final"] == 15
    for n in MU:
        assert s["covariance_degree_final"][n] > 10.0, n
        assert s["separation"][n] > 0.1, (n, s["separation"])
    # μ_y against attitude alone: separated by the velocity (a tilt along d)
    assert s["separation"]["muy"] > 10 * out["attitude"][0]["separation"]["muy"]


def test_json_and_results_file_in_the_command_shape(sim):
    """The flight table's keys (segments, cumulative, rank_final, degree_final) with the
    run's windows; /observability with its attributes, the filter's σ per epoch."""
    _, _, out = sim
    s, h5 = out["attitude"]
    assert len(s["segments"]) == len(s["cumulative"]) == 2  # 20 s in windows of 10 s
    assert s["segments"][0]["name"] == "0–10 s" and s["cumulative"][-1]["t1_s"] == \
        pytest.approx(19.9)
    for row in s["segments"]:
        assert list(row["degree"]) == s["states"] and len(s["states"]) == 15
        assert list(row["covariance_degree"]) == s["covariance_states"]
    with h5py.File(h5) as f:
        g = f["observability"]
        assert g.attrs["mode"] == "transfer" and g.attrs["measure"] == "attitude"
        assert g["eta_cum"].shape == (2, 15) and g["cov_degree"].shape == (2, 15)
        assert g["sigma"].shape == (len(g["t"]), 15)
        np.testing.assert_allclose(g["sigma"][-1], [s["sigma_final"][n]
                                                    for n in s["covariance_states"]])


@pytest.mark.slow
def test_figures_show_and_the_set_route(sim):
    """Three figures; `show` prints the table again; --matching is --set
    align.transfer.matching."""
    _, path, out = sim
    s, h5 = out["attitude"]
    with h5py.File(h5) as f:
        from gcalign.app.registry import command

        figs = command("observability").figures(f, "sim")  # the command's, by its mode
    assert sorted(figs) == ["covariance_degree", "observability_cumulative",
                            "sigma_reduction"]
    assert len(figs["sigma_reduction"].axes) == 5  # φ, δv, ε, ∇, μ (15 states)
    res = runner.invoke(app, ["show", str(h5)])
    assert res.exit_code == 0 and "weakest combination" in res.output, res.output
    res = _obs(path, "--set", "align.transfer.matching=attitude", "--json", "-o",
               h5.with_name("set.h5"))
    assert res.exit_code == 0, res.output
    again = json.loads(res.stdout)
    assert again["separation"] == s["separation"] and again["weakest"] == s["weakest"]


def test_plot_of_a_file_without_the_filter_sigma_names_the_dataset(sim, tmp_path):
    """The σ per epoch lies beside the table, outside its checks: a file without it is
    refused in one line naming the dataset, no figure written."""
    _, _, out = sim
    for name in ("t", "sigma"):
        h5 = tmp_path / f"no_{name}.h5"
        h5.write_bytes(out["velocity"][1].read_bytes())
        with h5py.File(h5, "a") as f:
            del f[f"observability/{name}"]
        res = runner.invoke(app, ["plot", str(h5), "-o", str(tmp_path / name)])
        assert_bad_input(res, tmp_path / name / "sigma_reduction.png",
                         f"dataset /observability/{name} missing")


def test_matching_on_a_flight_and_bad_values_are_one_line(sim, tmp_path):
    _, path, _ = sim
    out = tmp_path / "o.h5"
    assert_bad_input(_obs("--matching", "velocity", "-o", out), out, "--matching",
                     "align.mode: transfer")
    assert_bad_input(_obs(path, "--matching", "speed", "-o", out), out,
                     "align.transfer.matching", "'speed'")
    assert_bad_input(_obs(path, "--set", "observability.window_s=0", "-o", out), out,
                     "observability.window_s")


@pytest.mark.slow
def test_the_real_file_by_matching(tmp_path):
    """configs/psins_transfer_fog_mems.yaml (heading within ±3°, roll ±33°): velocity
    leaves μ at P0; attitude leaves μ_y (the roll axis) at σ > 10′ with the weakest
    combination along (φ_N, μ_y) (forward ≈ north); both observe every μ."""
    s = {}
    for m in MATCHINGS:
        res = _obs(CONFIG, "--matching", m, "--json", "-o", tmp_path / f"{m}.h5")
        assert res.exit_code == 0, res.output
        s[m] = json.loads(res.stdout)
    v, a, av = s["velocity"], s["attitude"], s["attitude+velocity"]
    assert v["unobservable"] == list(MU)
    assert all(v["sigma_final"][n] == pytest.approx(v["sigma0"][n], rel=1e-12) for n in MU)
    assert a["sigma_final"]["muy"] / ARCMIN > 10.0
    assert max(a["sigma_final"]["mux"], a["sigma_final"]["muz"]) / ARCMIN < 2.0
    wa = a["weakest"]["vector"]
    assert wa["muy"] > 0.99 and wa["phiN"] == pytest.approx(
        0.1 * wa["muy"], rel=0.05)  # φ along north scaled by σμ/σφ = 1°/10°
    assert av["unobservable"] == [] and all(av["sigma_final"][n] / ARCMIN < 2.0 for n in MU)
    assert all("mean NIS" in " ".join(x["warnings"]) for x in s.values())  # the demo's R
    # its σ tables span the 21 filter states, the PWCS tables 15: the file reads back
    h5 = tmp_path / "attitude+velocity.h5"
    for args in (["show", h5], ["plot", h5, "-o", tmp_path / "figs"]):
        res = runner.invoke(app, list(map(str, args)))
        assert res.exit_code == 0, res.output
    assert len(list((tmp_path / "figs").glob("*.png"))) == 3
