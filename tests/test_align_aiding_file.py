"""Alignment on a moving base with the reference velocity read from a file (aiding source
``file``): the simulated seed-000 moving base aided by its own truth written as an ENU or
NED velocity CSV or an odometer CSV aligns as the built-in simulated aiding does; the real
MEMS vehicle aided by the FOG solution's velocity (what is physically possible there);
one-line refusals (no common time, a file that does not cover the window, keys of
another source)."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
import scipy  # scipy.io is loaded on first use (scipy's lazy submodules)
import yaml
from cli_checks import assert_bad_run
from lazy import lazy_attr
from test_align_api import small
from typer.testing import CliRunner

import gcalign
from conftest import ROOT
from gcalign.cli import app
from gcalign.io.recorded import read_reference, reference_at
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm

Rotation = lazy_attr("scipy.spatial.transform", "Rotation")

runner = CliRunner()
MAT = ROOT / "tests/data/transfer_align_fog_mems.mat"


@pytest.fixture(scope="module")
def truth(tmp_path_factory):
    sim = gcalign.run("simulate", small("half-cycle", "one-off"), seed=3,
                      output=tmp_path_factory.mktemp("sim") / "sim.h5")
    return sim.truth()


def _write(path, header: str, t, cols) -> str:
    rows = np.column_stack([t, *cols])
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(x)) for x in r)
                                              for r in rows) + "\n")
    return str(path)


@pytest.mark.parametrize("kind", ["velocity-enu", "velocity-ned", "odometer"])
def test_velocity_file_aligns_as_the_simulated_reference(truth, tmp_path, kind):
    """The truth's velocity at the sample times, written to a file and read back, is the
    reference the simulated aiding gives with zero noise: the same alignment (to the
    round-off of the text and of the interpolation at the nodes)."""
    v = truth.v_n
    if kind == "velocity-enu":
        path = _write(tmp_path / "v.csv", "t,ve,vn,vu", truth.t, v.T)
    elif kind == "velocity-ned":
        path = _write(tmp_path / "v.csv", "t,vn,ve,vd", truth.t, [v[:, 1], v[:, 0], -v[:, 2]])
    else:
        speed = np.einsum("kji,kj->ki", euler_to_dcm(truth.att), v)[:, 1]
        path = _write(tmp_path / "odo.csv", "t,speed", truth.t, [speed])
    simulated = "odometer" if kind == "odometer" else "nav"
    want = gcalign.run("align", small("half-cycle", "one-off", aiding=simulated), seed=3,
                       output=tmp_path / "sim.h5")
    sc = small("half-cycle", "one-off")
    sc["align"]["aiding"] = {"source": "file", "path": path, "format": kind}
    got = gcalign.run("align", sc, seed=3, output=tmp_path / "file.h5")
    np.testing.assert_allclose(got["error_t3_deg"], want["error_t3_deg"], atol=1e-9)
    for a, b in zip(got["passes"], want["passes"], strict=True):
        np.testing.assert_allclose(a["error_deg"], b["error_deg"], atol=1e-9)
    # and the file matters: without it the moving base is far off
    none = small("half-cycle", "one-off", aiding="none")
    off = gcalign.run("align", none, seed=3, output=tmp_path / "none.h5")
    assert np.abs(np.subtract(off["error_t3_deg"], want["error_t3_deg"])).max() > 0.1


def _mems_scenario(tmp_path, data, aiding: dict) -> str:
    lat, lon, h = read_reference(MAT).pos[0]  # the FOG solution's first epoch
    sc = {"name": "mems", "imu_file": str(data), "site": {
              "lat_deg": float(np.degrees(lat)), "lon_deg": float(np.degrees(lon)),
              "height_m": float(h)},
          "align": {"coarse": {"method": "inertial"}, "mode": "conventional",
                    "start_s": 0.11, "t1_s": 10, "t2_s": 99.8, "t3_s": 99.8,
                    "aiding": aiding, "stages": [{"t_xy_s": 10, "t_z_s": 50, "xi": 0.707}]}}
    path = tmp_path / "mems.yaml"
    path.write_text(yaml.safe_dump(sc))
    return str(path)


def _align_json(tmp_path, scenario: str) -> dict:
    res = runner.invoke(app, ["align", scenario, "-o", str(tmp_path / "a.h5"), "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_mems_aided_by_the_fog_velocity(tmp_path):
    """The MEMS vehicle (11.5-15.8 m/s, roll ±33°) aligned with the FOG solution's velocity.

    Heading: the gyrocompass finds north from the horizontal earth rate ω_ie cos L; an east
    gyro bias ε_E moves it by ε_E/(ω_ie cos L). The stored eb0 (≈ 200 °/h) resolved with
    the FOG attitude gives |ε_E| ≈ 200 °/h against ω_ie cos L = 12.4 °/h: a floor of many
    radians, i.e. no heading is physically possible from these gyros, whatever the
    aiding; the heading is printed, not checked. With eb0 and db0 removed the residual
    biases are unknown, so the heading is not checked either.

    Level: what aiding can fix. The level loops read every acceleration the reference
    velocity does not explain as tilt; with the FOG velocity the vertical is found to
    better than 0.1° (biases removed), against several times that without aiding."""
    m = scipy.io.loadmat(MAT)
    eb0, db0, mu0 = (m[k].ravel() for k in ("eb0", "db0", "mu0"))
    ref = read_reference(MAT)
    att, _, pos = reference_at(ref, ref.t[(ref.t >= 10) & (ref.t <= 99.8)])
    C_mu = Rotation.from_rotvec(mu0).as_matrix()
    eps_n = np.einsum("kij,j->ki", euler_to_dcm(att) @ C_mu, eb0)
    horizontal = WGS84.omega_ie * np.cos(pos[0, 0])
    floor = np.abs(eps_n[:, 0].mean()) / horizontal
    print(f"east gyro bias {np.degrees(eps_n[:, 0].mean()) * 3600:.1f} °/h, ω_ie cos L "
          f"{np.degrees(horizontal) * 3600:.2f} °/h: heading floor {floor:.1f} rad")
    assert floor > 10  # no gyrocompass heading from this MEMS with its biases

    fixed = tmp_path / "mems_nobias.mat"
    mimu = m["mimu"].copy()
    mimu[:, 0:3] -= eb0 * 0.01
    mimu[:, 3:6] -= db0 * 0.01
    scipy.io.savemat(fixed, {"mimu": mimu, "fogavp": m["fogavp"]})
    tilt = {}
    for data in (MAT, fixed):
        for name, aiding in (("file", {"source": "file", "path": str(MAT),
                                       "format": "psins-mat"}), ("none", {"source": "none"})):
            s = _align_json(tmp_path, _mems_scenario(tmp_path, data, copy.deepcopy(aiding)))
            t3 = 0.1 + s["t3_s"]
            C_mems = euler_to_dcm(reference_at(ref, [t3])[0][0]) @ C_mu
            D = euler_to_dcm(np.radians(s["attitude_t3_deg"])) @ C_mems.T
            tilt[data is fixed, name] = np.degrees(np.arccos(np.clip(D[2, 2], -1, 1)))
            yaw_error = (s["attitude_t3_deg"][2] - np.degrees(dcm_to_euler(C_mems)[2]) + 180
                         ) % 360 - 180
            print(f"biases removed {data is fixed}, aiding {name}: tilt of the vertical "
                  f"{tilt[data is fixed, name]:.3f}°, heading error {yaw_error:.1f}° "
                  "(vs FOG ∘ mu0)")
    assert tilt[True, "file"] < 0.1 and tilt[True, "file"] < tilt[True, "none"] / 5


def test_aiding_file_refusals(tmp_path):
    """One line, exit 2, no file: a velocity file with no common time, one that does not
    cover the alignment window, one with a gap inside it (accepted when max_gap_s says the
    gap is harmless), the file keys with another source."""
    def run(*args):
        return runner.invoke(app, ["align", *map(str, args)])

    far = _write(tmp_path / "far.csv", "t,ve,vn,vu", np.arange(1000.0, 1100.0),
                 [np.zeros(100)] * 3)
    assert_bad_run(run, tmp_path, [_mems_scenario(tmp_path, MAT, {
        "source": "file", "path": far, "format": "velocity-enu"})], "align.aiding:",
        "no common time")
    short = _write(tmp_path / "short.csv", "t,ve,vn,vu", np.arange(0.0, 50.0),
                   [np.zeros(50)] * 3)
    assert_bad_run(run, tmp_path, [_mems_scenario(tmp_path, MAT, {
        "source": "file", "path": short, "format": "velocity-enu"})], "align.aiding:",
        "covers 0.000 .. 49.000 s")
    # a gap of 20 s in a 1 Hz file inside the window: no velocity drawn across it
    t = np.concatenate([np.arange(0.0, 40.0), np.arange(60.0, 101.0)])
    gap = _write(tmp_path / "gap.csv", "t,ve,vn,vu", t, [np.zeros(len(t))] * 3)
    assert_bad_run(run, tmp_path, [_mems_scenario(tmp_path, MAT, {
        "source": "file", "path": gap, "format": "velocity-enu"})], "align.aiding:",
        "no epoch for 21.000 s after 39.000 s", "longer than max_gap_s 2 s")
    res = runner.invoke(app, ["align", _mems_scenario(tmp_path, MAT, {
        "source": "file", "path": gap, "format": "velocity-enu", "max_gap_s": 30}),
        "-o", str(tmp_path / "gap.h5")])
    assert res.exit_code == 0, res.output  # a gap the user says is harmless
    assert_bad_run(run, tmp_path, [_mems_scenario(tmp_path, MAT, {
        "source": "none", "path": short})], "path", "applies to source 'file' only")
    assert_bad_run(run, tmp_path, [_mems_scenario(tmp_path, MAT, {
        "source": "file", "path": short})], "format", "missing")


def test_no_error_against_a_reference_across_its_gap(tmp_path):
    """A reference with 12 s cut out inside the alignment: refused naming the gap (an error
    against a line drawn across it is not a measurement); reference.max_gap_s accepts it."""
    m = scipy.io.loadmat(MAT)
    fog = m["fogavp"]
    keep = (fog[:, 9] < 50.0) | (fog[:, 9] > 62.0)
    cut = tmp_path / "cut.mat"
    scipy.io.savemat(cut, {"fogavp": fog[keep]})
    sc = yaml.safe_load(open(_mems_scenario(tmp_path, MAT, {"source": "none"})))
    sc["reference"] = {"path": str(cut), "format": "psins-mat"}
    path = tmp_path / "ref.yaml"
    path.write_text(yaml.safe_dump(sc))

    def run(*args):
        return runner.invoke(app, ["align", *map(str, args)])

    assert_bad_run(run, tmp_path, [path], "reference:", "no epoch for 12.100 s after 49.900 s",
                   "reference.max_gap_s")
    sc["reference"]["max_gap_s"] = 20
    path.write_text(yaml.safe_dump(sc))
    assert run(path, "-o", tmp_path / "ok.h5").exit_code == 0


def test_align_errors_against_the_reference(tmp_path):
    """configs/mems_fog.yaml: the errors at T2, T3 and per pass are against the FOG
    solution (error_source "reference"), equal to the estimate minus the reference
    interpolated here; the file keeps it under /reference (no /truth), the table and the
    figures say "reference"; a reference that does not cover the window is refused."""
    import h5py
    from rich.console import Console

    from gcalign.app.align.plots import figures
    from gcalign.app.align.tables import align_table

    s = _align_json(tmp_path, str(ROOT / "configs/mems_fog.yaml"))
    assert s["error_source"] == "reference"
    r_att = reference_at(read_reference(MAT), [0.1 + s["t3_s"]])[0][0]
    want = np.subtract(s["attitude_t3_deg"], np.degrees(r_att))
    want[1:] = (want[1:] + 180) % 360 - 180
    np.testing.assert_allclose(s["error_t3_deg"], want, atol=1e-9)
    with h5py.File(tmp_path / "a.h5") as f:
        assert "reference" in f and "truth" not in f
        figs = figures(f, "mems")
    assert "vs reference" in figs["align_attitude"].texts[0].get_text()
    console = Console(width=200, record=True)
    console.print(align_table(s))
    text = console.export_text()
    assert "reference at T3" in text and "estimate − reference" in text

    sc = yaml.safe_load((ROOT / "configs/mems_fog.yaml").read_text())
    sc["align"]["start_s"] = 0.0
    sc["imu_file"] = sc["reference"]["path"] = sc["align"]["aiding"]["path"] = str(MAT)
    sc["align"]["aiding"] = {"source": "none"}
    path = tmp_path / "early.yaml"
    path.write_text(yaml.safe_dump(sc))
    assert_bad_run(lambda *a: runner.invoke(app, ["align", *map(str, a)]), tmp_path,
                   [path], "reference:", "covers 0.100 .. 100.000 s", "align.start_s")


def test_aiding_paths_are_taken_from_the_scenario_folder(tmp_path, truth, monkeypatch):
    """align.aiding.path relative to the scenario file, run from another folder; and a
    batch's absolute paths (gcalign.io.scenario.recording.absolute_paths)."""
    from gcalign.io.scenario.recording import absolute_paths

    _write(tmp_path / "v.csv", "t,ve,vn,vu", truth.t, truth.v_n.T)
    sc = small("conventional", "continued")
    sc["align"]["aiding"] = {"source": "file", "path": "v.csv", "format": "velocity-enu"}
    (tmp_path / "sc.yaml").write_text(yaml.safe_dump(sc))
    monkeypatch.chdir(ROOT)
    res = runner.invoke(app, ["align", str(tmp_path / "sc.yaml"), "-o", str(tmp_path / "a.h5")])
    assert res.exit_code == 0, res.output
    absolute_paths(sc, tmp_path)
    assert sc["align"]["aiding"]["path"] == str(tmp_path / "v.csv")
