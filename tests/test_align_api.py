"""The alignment on arrays (:func:`gcalign.align.gyrocompass.align`): the same numbers as the
command line's route to the last bit, for every mode and compensation; the static steady
state of DESIGN.md through the arrays alone; refusals that name the argument."""

from __future__ import annotations

import copy
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

import gcalign
from gcalign import units as u
from gcalign.align.gains import azimuth_gains
from gcalign.align.gyrocompass import AlignSettings, TruthRows, align, timeline, truth_samples
from gcalign.align.stages import Stage
from gcalign.errors import InputError, ScenarioError
from gcalign.nav import earth
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm, misalignment

ROOT = Path(__file__).resolve().parents[1]
T_Z = 280.0


def small(mode: str, compensation: str, realtime: bool = True, aiding: str = "nav") -> dict:
    """The built-in moving-base scenario, shortened (T2 = 60 s, T3 = 70 s, 3 passes), with
    a noise-free reference velocity (the arrays route is given the same one)."""
    d = yaml.safe_load((ROOT / "configs/seed000_moving_full_cycle.yaml").read_text())
    d["motion"]["duration_s"] = 80
    d["output"] = {"rate_hz": "full"}
    d["align"].update(mode=mode, compensation=compensation, realtime=realtime, t2_s=60,
                      t3_s=70, level_s=20, aiding={"source": aiding, "noise_mps": 0.0})
    d["align"]["stages"] = [{"t_xy_s": 20, "t_z_s": T_Z, "xi": 0.707}]
    if mode != "conventional":
        d["align"]["stages"][0]["passes"] = 3
    return d


COMPENSATIONS = ("none", "one-off", "continued")
CASES = [("conventional", "continued", True),  # real time: one pass through T3
         *[("conventional", c, False) for c in COMPENSATIONS],
         *[(m, c, True) for m in ("full-cycle", "half-cycle") for c in COMPENSATIONS]]


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The scenario's increments and truth as `gcalign simulate` stores them (seed 3)."""
    sim = gcalign.run("simulate", small("full-cycle", "continued"), seed=3,
                      output=tmp_path_factory.mktemp("sim") / "sim.h5")
    return sim.imu(), sim.truth()


def _settings(mode: str, compensation: str, realtime: bool) -> AlignSettings:
    return AlignSettings(
        mode=mode, t1_s=10.0, t2_s=60.0, t3_s=70.0, realtime=realtime,  # type: ignore[arg-type]
        compensation=compensation, coarse="given",  # type: ignore[arg-type]
        coarse_offset=tuple(np.radians([1.0, 1.0, 10.0])),  # type: ignore[arg-type]
        azimuth_poles="double-oscillator", level_s=20.0,
        stages=(Stage(20.0, T_Z, 0.707, None if mode == "conventional" else 3),),
        passes=1 if mode == "conventional" else 3)


def _array_route(imu, truth, settings: AlignSettings, body: bool = False):
    vref = truth.v_n
    if body:  # an odometer: the forward speed in the body frame
        speed = np.einsum("kji,kj->ki", euler_to_dcm(truth.att), truth.v_n)[:, 1]
        vref = np.stack([np.zeros_like(speed), speed, np.zeros_like(speed)], -1)
    i1 = timeline(settings, imu.ts, len(imu)).i1
    return align(imu.dtheta, imu.dv, imu.ts, truth.pos[0], settings, earth=WGS84,
                 position_t1=truth.pos[i1], vref=vref, vref_body=body, truth_att=truth.att,
                 t0=imu.t[0] - imu.ts)


def _assert_same_as_file(res, path: Path) -> None:
    with h5py.File(path) as f:
        r = f["align/result"]
        for name in ("coarse_att", "att_t2", "att_t3", "truth_t2", "truth_t3", "error_t2",
                     "error_t3", "phi_t2", "phi_t3"):
            value = getattr(res, name)
            assert (name not in r and value is None) or np.array_equal(r[name][()], value), name
        assert r.attrs["equivalent_s"] == res.equivalent_s
        assert f["align"].attrs["t3_s"] == res.t3
        assert len([k for k in f["align"] if k.startswith("pass_")]) == len(res.passes)
        for rec, att, err, phi in zip(res.passes, res.pass_att, res.pass_errors, res.pass_phi,
                                      strict=True):
            p = f[f"align/pass_{rec.index + 1:02d}"]
            assert p.attrs["direction"] == rec.direction and p.attrs["kind"] == rec.kind
            for name, a in (("t", rec.t), ("att", att), ("error", err), ("phi", phi),
                            ("gains", rec.gains)):
                assert (name not in p and a is None) or np.array_equal(p[name][()], a), name


@pytest.mark.parametrize("mode, compensation, realtime", CASES)
def test_array_route_is_the_command_route_bit_for_bit(simulated, tmp_path, mode,
                                                      compensation, realtime):
    imu, truth = simulated
    cli = gcalign.run("align", small(mode, compensation, realtime), seed=3,
                      output=tmp_path / "a.h5")
    res = _array_route(imu, truth, _settings(mode, compensation, realtime))
    _assert_same_as_file(res, cli.path)
    assert cli["error_t3_deg"] == np.degrees(res.error_t3).tolist()
    assert [p["error_deg"] for p in cli["passes"]] == [
        np.degrees(e).tolist() for e in res.pass_end_errors]


def test_odometer_reference_bit_for_bit(simulated, tmp_path):
    imu, truth = simulated
    cli = gcalign.run("align", small("half-cycle", "one-off", aiding="odometer"), seed=3,
                      output=tmp_path / "a.h5")
    res = _array_route(imu, truth, _settings("half-cycle", "one-off", True), body=True)
    _assert_same_as_file(res, cli.path)


def test_recorded_file_bit_for_bit(tmp_path):
    """The real recording: inertial coarse alignment, no truth; the arrays read by the io
    reader, the settings those of configs/lasergyro_align.yaml."""
    from gcalign.app.data import read_data_file

    cli = gcalign.run("align", ROOT / "configs/lasergyro_align.yaml", output=tmp_path / "l.h5")
    imu, _ = read_data_file(ROOT / "tests/data/lasergyro.imu.xz")
    s = AlignSettings(mode="conventional", t1_s=60.0, t2_s=400.0, t3_s=400.0,
                      coarse="inertial", azimuth_poles="oscillator-overdamped",
                      stages=(Stage(20.0, 100.0, 0.707),))
    sc = gcalign.load(ROOT / "configs/lasergyro_align.yaml")
    stride = sc.output.stride(1.0 / imu.ts, len(imu) * imu.ts)
    res = align(imu.dtheta, imu.dv, imu.ts, imu.site, s, t0=imu.t[0] - imu.ts, stride=stride)
    assert res.error_t3 is None and res.pass_truth is None
    _assert_same_as_file(res, cli.path)
    assert cli["attitude_t3_deg"] == np.degrees(res.att_t3).tolist()


def test_gcalign_run_returns_the_typed_result(tmp_path):
    res = gcalign.run("align", small("conventional", "continued"), seed=3,
                      output=tmp_path / "a.h5")
    assert res.value is not None and res["error_t3_deg"] == np.degrees(
        res.value.error_t3).tolist()
    assert gcalign.read(res.path).value is None and gcalign.read(res.path) == res


# ------------------------------------------------------------------ physics, arrays alone

LAT = np.radians(45.7796)


def static_imu(att, seconds: float, ts: float = 0.01, gyro_bias_b=(0, 0, 0),
               accel_bias_b=(0, 0, 0)):
    """Increments of a still IMU at `att` with constant biases (body frame)."""
    C_bn = euler_to_dcm(att).T
    w_b = C_bn @ WGS84.omega_ie_n(LAT) + np.asarray(gyro_bias_b, float)
    f_b = C_bn @ np.array([0.0, 0.0, float(WGS84.gravity(LAT))]) + np.asarray(accel_bias_b,
                                                                              float)
    n = int(round(seconds / ts))
    return np.tile(w_b * ts, (n, 1)), np.tile(f_b * ts, (n, 1)), ts


@pytest.mark.parametrize("mode", ["conventional", "full-cycle"])
def test_static_steady_state_is_the_closed_form(mode):
    """Static base, constant biases, given start (1°, 1°, 10°) off: the attitude at T2
    settles at DESIGN.md's steady state φ_E = −∇_N/g + K_U1 δv_N/g, φ_N = ∇_E/g,
    φ_U = −ε_E/(ω_ie cos L) + φ_N tan L − (1 + K_U2) δv_N/(R Ω), with the compass loop's
    δv_N = Ω K_U4 (ε_U − Ω φ_E0)/K_U3 (biases resolved in ENU)."""
    att = np.radians([0.0, 0.0, 30.0])
    gyro_b, accel_b = np.array([0.02, -0.01, 0.05]) * u.DPH, np.array([50.0, 30.0, 80.0]) * u.UG
    t2 = 1500.0 if mode == "conventional" else 760.0
    dth, dv, ts = static_imu(att, t2, gyro_bias_b=gyro_b, accel_bias_b=accel_b)
    truth = np.tile(att, (len(dth) + 1, 1))
    s = AlignSettings(mode=mode, t1_s=0.0, t2_s=t2, t3_s=t2, coarse="given",
                      coarse_offset=tuple(np.radians([1.0, 1.0, 10.0])),  # type: ignore[arg-type]
                      azimuth_poles="double-oscillator", level_s=60.0,
                      stages=(Stage(20.0, 100.0, 0.707),))
    res = align(dth, dv, ts, [LAT, 0.0, 0.0], s, truth_att=truth)
    assert res.t2 == t2 and len(res.passes) == (1 if mode == "conventional" else 5)
    C = euler_to_dcm(att)
    eps, nab = C @ gyro_b, C @ accel_b
    g = float(earth.gravity(LAT))
    r_m, _ = earth.radii(LAT)
    omega = earth.OMEGA_IE * np.cos(LAT)
    az = azimuth_gains(100.0, 0.707, g, r_m, "double-oscillator")
    phi_n, phi_e0 = nab[0] / g, -nab[1] / g
    dvn = omega * az.k4 * (eps[2] - omega * phi_e0) / az.k3
    expected = np.array([phi_e0 + az.k1 * dvn / g, phi_n,
                         -eps[0] / omega + phi_n * np.tan(LAT) - (1 + az.k2) * dvn / (r_m * omega)])
    phi = misalignment(euler_to_dcm(res.att_t2), euler_to_dcm(res.truth_t2))
    assert res.phi_t2 is not None and np.array_equal(phi, res.phi_t2)
    np.testing.assert_allclose(phi, expected, rtol=0.01)


def test_ideal_static_imu_aligns_from_analytic_coarse():
    """No sensor error: analytic coarse over 10 s, then the loops; heading within 1e-6°."""
    att = np.radians([1.0, -2.0, 123.0])
    dth, dv, ts = static_imu(att, 400.0)
    s = AlignSettings(mode="conventional", t1_s=10.0, t2_s=400.0, t3_s=400.0, level_s=60.0,
                      stages=(Stage(20.0, 100.0, 0.707),))
    res = align(dth, dv, ts, [LAT, 0.0, 0.0], s, truth_att=np.tile(att, (len(dth) + 1, 1)))
    assert np.degrees(np.abs(res.error_t3)).max() < 1e-6, np.degrees(res.error_t3)


# ------------------------------------------------------------------ refusals


@pytest.mark.parametrize("change, field", [
    ({"dv": np.zeros((10, 3))}, "dv"),
    ({"dtheta": np.zeros((100, 4))}, "dtheta"),
    ({"ts": 0.0}, "ts"),
    ({"ts": float("nan")}, "ts"),
    ({"site": [np.radians(86.0), 0.0, 0.0]}, "site"),
    ({"site": [0.1, 0.2]}, "site"),
    ({"settings": AlignSettings(t1_s=5.0, t2_s=50.0, t3_s=50.0, level_s=1.0)}, "t2_s"),
    ({"settings": AlignSettings(coarse="given", t2_s=5.0, t3_s=5.0, t1_s=1.0, level_s=1.0)},
     "coarse"),
    ({"vref": np.zeros((5, 3))}, "vref"),
    ({"stride": 0}, "stride"),
])
def test_refusals_name_the_argument(change, field):
    dth, dv, ts = static_imu(np.zeros(3), 20.0)
    args = {"dtheta": dth, "dv": dv, "ts": ts, "site": [LAT, 0.0, 0.0],
            "settings": AlignSettings(t1_s=5.0, t2_s=15.0, t3_s=15.0, level_s=1.0)}
    nan = dth.copy()
    nan[7, 1] = np.nan
    kwargs = {k: v for k, v in change.items() if k not in args}
    args.update({k: v for k, v in change.items() if k in args})
    with pytest.raises(InputError, match=f"^{field}: ") as err:
        align(**args, **kwargs)
    assert err.value.field == field
    with pytest.raises(InputError, match="^dtheta: must be finite"):
        align(nan, dv, ts, [LAT, 0.0, 0.0], args["settings"])


@pytest.mark.parametrize("kwargs, field", [
    ({"mode": "sideways"}, "mode"),
    ({"t3_s": 200.0}, "t3_s"),
    ({"mode": "full-cycle", "passes": 4}, "passes"),
    ({"level_s": 400.0}, "level_s"),
    ({"t1_s": float("inf")}, "t1_s"),
])
def test_settings_refusals(kwargs, field):
    with pytest.raises(InputError, match=f"^{field}: "):
        AlignSettings(**{"t2_s": 300.0, "t3_s": 330.0, **kwargs})


def test_window_of_a_longer_record_gives_the_same_result():
    """Only the samples the alignment reads need be held: the window lo .. hi of a longer
    record, placed by first_sample, gives the whole record's result."""
    dth, dv, ts = static_imu(np.radians([0.5, 0.2, 40.0]), 120.0)
    s = AlignSettings(mode="half-cycle", start_s=20.0, t1_s=10.0, t2_s=60.0, t3_s=80.0,
                      level_s=10.0, stages=(Stage(20.0, 100.0, 0.707),))
    whole = align(dth, dv, ts, [LAT, 0.0, 0.0], s)
    tl = timeline(s, ts, len(dth))
    part = align(dth[tl.lo:tl.hi], dv[tl.lo:tl.hi], ts, [LAT, 0.0, 0.0], s,
                 first_sample=tl.lo, samples=len(dth))
    assert np.array_equal(whole.att_t3, part.att_t3) and whole.t3 == part.t3 == 80.0
    with pytest.raises(InputError, match="^dtheta: covers samples"):
        align(dth[tl.lo + 1:tl.hi], dv[tl.lo + 1:tl.hi], ts, [LAT, 0.0, 0.0], s,
              first_sample=tl.lo + 1, samples=len(dth))
    assert copy.copy(s) == s


@pytest.mark.parametrize("overrides, message", [
    ({"align.t2_s": 5000, "align.t3_s": 5000}, "align.t2_s: 5000.0 s (+ start_s 0.0 s) is past "
     "the end of the data"),
    ({"site": {"lat_deg": 86.0, "lon_deg": 116.0, "height_m": 0.0}},
     "site.lat_deg: gyrocompassing needs |latitude| < 85°, got 86°"),
])
def test_the_cores_refusals_name_the_scenario_field(tmp_path, overrides, message):
    """A recorded file's length and site are known only when it is read: the core refuses,
    the command names the scenario's field (exit 2), and no file is left."""
    sc = gcalign.load(ROOT / "configs/lasergyro_align.yaml", overrides)
    with pytest.raises(ScenarioError) as err:
        gcalign.run("align", sc, output=tmp_path / "x.h5")
    assert str(err.value).startswith(message) and err.value.exit_code == 2
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("t3, stride", [(80.0, 7), ("measured", 1)])
def test_truth_at_its_samples_alone_gives_the_whole_truth_result(t3, stride):
    """A long run need hold the truth only where the alignment reads it
    (truth_samples: at 7-sample output, about 1/7 of the samples): the truth given at
    those rows alone gives the result of the truth at every sample, to the bit, errors
    along the passes included; a row short is refused, naming truth_att."""
    dth, dv, ts = static_imu(np.radians([0.5, 0.2, 40.0]), 120.0)
    rng = np.random.default_rng(2)
    truth = np.radians([0.5, 0.2, 40.0]) + 1e-5 * rng.standard_normal((len(dth) + 1, 3))
    s = AlignSettings(mode="full-cycle", t1_s=10.0, t2_s=60.0, t3_s=t3, level_s=10.0,
                      coarse="given", stages=(Stage(20.0, 100.0, 0.707),))
    whole = align(dth, dv, ts, [LAT, 0.0, 0.0], s, truth_att=truth, stride=stride)
    k = truth_samples(s, ts, len(dth), stride)
    assert len(k) < (len(dth) + 1) / stride + 20 if stride > 1 else k[-1] == len(dth)
    part = align(dth, dv, ts, [LAT, 0.0, 0.0], s, truth_att=TruthRows(k, truth[k]),
                 stride=stride)
    for name in ("coarse_att", "att_t2", "truth_t2", "error_t2"):
        assert np.array_equal(getattr(whole, name), getattr(part, name)), name
    if t3 != "measured":  # a measured T3 is T2 plus the wall time of the passes
        assert np.array_equal(whole.att_t3, part.att_t3)
        assert np.array_equal(whole.error_t3, part.error_t3)
    else:  # wherever it falls, its truth is held
        assert part.truth_t3 is not None and np.array_equal(part.truth_t3, truth[
            round(part.t3 / ts)])
    for a, b, ea, eb, ta, tb in zip(whole.passes, part.passes, whole.pass_errors,
                                    part.pass_errors, whole.pass_truth, part.pass_truth,
                                    strict=True):
        assert np.array_equal(a.q_nb, b.q_nb) and np.array_equal(ea, eb)
        assert np.array_equal(ta, tb) and np.array_equal(ta, truth[a.samples])
    spread_w, spread_p = whole.last_pass_spread(), part.last_pass_spread()
    assert spread_w is not None and spread_p is not None
    assert np.array_equal(spread_w.std, spread_p.std)
    with pytest.raises(InputError, match="^truth_att: has no row at sample"):
        short = np.delete(k, len(k) // 2)
        align(dth, dv, ts, [LAT, 0.0, 0.0], s, truth_att=TruthRows(short, truth[short]),
              stride=stride)
