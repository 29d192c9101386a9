"""Every capability on arrays: the library route gives the command line's numbers bit for bit,
and the physics of the seeds through the library route alone (specs 001-004).

Each bit-identity test runs a small scenario through ``gcalign.run`` (the command line's
route: scenario, checks, adapter, summary, results file) and the same numbers, written out
in SI as a user with arrays would, through the core function; the summary's numbers are
the core's arrays through the summary's own unit conversion, so equality is exact.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import gcalign
from gcalign import units as u
from gcalign.nav import earth
from gcalign.northfind import (
    NorthfindSetup,
    estimate_northfind,
    position_angles,
    run_northfind,
    simulate_table,
)

# ------------------------------------------------------------------------ north-finding


def test_northfind_array_route_gives_the_cli_numbers_bit_for_bit():
    sc = gcalign.example("northfind", {"northfind.sweep": None, "northfind.azimuth_deg": 48.0,
                                       "northfind.positions": 8, "northfind.dwell_s": 5.0,
                                       "northfind.repeats": 3})
    res = gcalign.run("northfind", sc, seed=7)
    # the scenario's numbers in SI, as a user with plain arrays writes them
    setup = NorthfindSetup(
        azimuths=np.array([48.0]) * u.DEG, lat=40.0 * u.DEG, positions=8, dwell_s=5.0,
        rate_hz=100.0, tilt=10.0 * u.DEG, tilt_direction=0.0, tilt_direction_ref="table",
        repeats=3, gyro_bias=0.02 * u.DPH, gyro_arw=0.002582 * u.DPSH,
        accel_bias=np.array([20.0, 20.0]) * u.UG, accel_vrw=154.9 * u.UGPSHZ)
    rng = np.random.default_rng(7)
    data = simulate_table(setup, rng)
    est = estimate_northfind(data.gyro, data.accel, data.theta, setup.lat, data.gravity,
                             azimuth_true=setup.azimuths[:, None])
    assert est.azimuth_error is not None
    for i, name in enumerate(est.methods):
        m = res["methods"][name]
        assert m["estimates_deg"] == np.mod(np.degrees(est.azimuth[i].T), 360.0).ravel().tolist()
        assert m["errors_deg"] == np.degrees(est.azimuth_error[i].T).ravel().tolist()
    assert res["tilt_est_deg"] == np.degrees(est.tilt.T).ravel().tolist()
    # the whole-run function on the same setup and seed, and the command's typed result
    from gcalign.app.registry import COMMANDS

    for full in (run_northfind(setup, np.random.default_rng(7)),
                 COMMANDS["northfind"].execute(sc, 7).result):
        assert np.array_equal(full.azimuth_est, est.azimuth)
        assert np.array_equal(full.azimuth_error, est.azimuth_error)
        assert np.array_equal(full.tilt_est, est.tilt)


def test_northfind_level_table_azimuth_is_exact_on_noise_free_means():
    """Seed 001 eqs. 4, 8: on a level table the gyro at table angle θ reads the earth rate
    along the turned reference axis, ω(θ) = Ω cos L cos(θ - ψ) (a = Ω cos L cos ψ,
    b = Ω cos L sin ψ), the accelerometers read nothing; ψ = atan2(b, a) by every method."""
    lat, theta = 40.0 * u.DEG, position_angles(6)
    psi = np.radians([0.0, 30.0, 135.0, 200.0, 359.0])
    gyro = earth.OMEGA_IE * np.cos(lat) * np.cos(theta[None, :] - psi[:, None])  # (5, 6)
    est = estimate_northfind(gyro, np.zeros((5, 6, 2)), theta, lat, 9.8, azimuth_true=psi)
    assert est.azimuth_error is not None and est.azimuth_error.shape == (4, 5)
    assert np.abs(est.azimuth_error).max() < 1e-12
    assert np.abs(est.tilt).max() == 0.0


@pytest.mark.parametrize(
    ("change", "text"),
    [
        (dict(gyro=np.zeros((2, 5))), "gyro must have shape (..., 6)"),
        (dict(accel=np.zeros((2, 6))), "accel must have shape (2, 6, 2)"),
        (dict(theta=np.zeros(2)), "theta must have shape (n,) with n >= 3"),
        (dict(gyro=np.full((2, 6), np.nan)), "gyro must be finite"),
        (dict(lat=np.pi / 2), "lat must satisfy |lat| < pi/2"),
        (dict(g=0.0), "g must be a finite gravity > 0"),
        (dict(azimuth_true=np.zeros(3)), "azimuth_true must broadcast to the leading shape"),
        (dict(methods=["magic"]), "methods must be drawn from"),
    ],
)
def test_northfind_array_inputs_are_checked_by_name(change, text):
    args = dict(gyro=np.zeros((2, 6)), accel=np.zeros((2, 6, 2)), theta=position_angles(6),
                lat=0.7, g=9.8)
    args |= change
    with pytest.raises(ValueError) as err:
        estimate_northfind(**args)
    assert text in str(err.value)


@pytest.mark.slow  # child processes (in-process: test_cli_northfind.py::test_bad_options_exit_2)
@pytest.mark.parametrize("args", [["--positions", "1"], ["--dwell", "0"]])
def test_northfind_bad_setting_exits_2_with_one_line(args):
    res = subprocess.run([sys.executable, "-m", "gcalign", "northfind", *args, "--json"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 2, res.stderr
    lines = [ln for ln in (res.stdout + res.stderr).splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in lines[0], lines


# ------------------------------------------------------------- calibration, observability

_GYRO = {"bias_dph": [0.01, -0.01, 0.01], "arw_dprh": 0.001, "scale_ppm": [100, -100, 100]}
_ACCEL = {"bias_ug": [50, -50, 50], "vrw_ugrhz": 10, "scale_ppm": [-100, 100, -100]}
_SEGMENTS = [  # (kind, duration s, accel m/s², speed m/s, rate °/s, angle °, name)
    ("hold", 20.0, None, None, None, None, "static"),
    ("accelerate", None, 6.5, 60.0, None, None, "ground roll"),
    ("pitch", None, None, None, 2.0, 10.0, "pitch-up"),
    ("pitch", None, None, None, 2.0, 0.0, "level-off"),
    ("turn", None, None, None, 9.0, -90.0, "turn right"),
    ("hold", 10.0, None, None, None, None, "cruise"),
]
CALIBRATE = {
    "name": "cal-small", "site": {"lat_deg": 38.0, "lon_deg": 121.0},
    "imu": {"rate_hz": 25, "seed": 1, "gyro": _GYRO, "accel": _ACCEL},
    "motion": {"kind": "flight", "segments": [
        {k: v for k, v in zip(("kind", "duration_s", "accel_mps2", "speed_mps", "rate_dps",
                                "angle_deg", "name"), s, strict=True) if v is not None}
        for s in _SEGMENTS]},
    "calibrate": {"q": {"arw_dprh": 0.001, "vrw_ugrhz": 10}},
    "observability": {"covariance": False},
}


def _flight_arrays():
    """Truth, ideal increments and manoeuvres of CALIBRATE's flight from the core alone."""
    from gcalign.calibrate import motion_spans
    from gcalign.sim.imu import ideal_imu
    from gcalign.sim.motions import FlightSegment, flight

    d = u.DEG
    segments = [FlightSegment(k, dur, acc, spd, None if r is None else r * d,
                              None if a is None else a * d, name)
                for k, dur, acc, spd, r, a, name in _SEGMENTS]
    motion = flight(np.zeros(3), segments)
    site = np.array([38.0 * d, 121.0 * d, 0.0])
    truth, ideal = ideal_imu(motion, site, 1.0 / 25.0)
    return truth, ideal, motion_spans(motion, float(truth.t[-1])), site


def _calibration_errors():
    from gcalign.estimation import ins_error as ie
    from gcalign.sim.errors import ImuErrors, SensorErrors

    gyro = SensorErrors(bias=np.array(_GYRO["bias_dph"]) * u.DPH,
                        noise=np.full(3, _GYRO["arw_dprh"]) * u.DPSH,
                        scale=np.array(_GYRO["scale_ppm"], float) * u.PPM)
    accel = SensorErrors(bias=np.array(_ACCEL["bias_ug"], float) * u.UG,
                         noise=np.full(3, float(_ACCEL["vrw_ugrhz"])) * u.UGPSHZ,
                         scale=np.array(_ACCEL["scale_ppm"], float) * u.PPM)
    x = np.zeros(ie.N_STATES)
    x[ie.PHI] = np.array([20.0, -20.0, 1800.0]) * u.ARCSEC  # the default initial error
    x[ie.EB], x[ie.DB], x[ie.DKG], x[ie.DKA] = gyro.bias, accel.bias, gyro.scale, accel.scale
    return x, ImuErrors(gyro=gyro, accel=accel)


def _seed_p0(site: np.ndarray) -> tuple[float, ...]:
    """The seed's P0 list (spec 002 §2) in SI at `site`, 1 m of position in radians."""
    r_m, r_n = earth.WGS84.radii(site[0])
    r_m, r_n = r_m + site[2], r_n + site[2]
    return tuple(np.concatenate([np.array([20.0, 20.0, 1800.0]) * u.ARCSEC, [0.2] * 3,
                                 [1.0 / r_m, 1.0 / (r_n * np.cos(site[0])), 1.0],
                                 np.full(3, 0.01) * u.DPH, np.full(3, 50.0) * u.UG,
                                 np.full(6, 100.0) * u.PPM]))


def _calibration_arrays(seed: int):
    from gcalign.calibrate import Settings, calibrate, flight_from_ideal

    truth, ideal, spans, site = _flight_arrays()
    x, errors = _calibration_errors()
    data = flight_from_ideal(truth, ideal, x, errors, np.random.default_rng(seed), spans)
    settings = Settings(p0_sigma=_seed_p0(site), arw=0.001 * u.DPSH, vrw=10.0 * u.UGPSHZ)
    return data, calibrate(data, settings, np.random.default_rng([seed, 3]))


def test_calibrate_array_route_gives_the_cli_numbers_bit_for_bit():
    from gcalign.app.registry import COMMANDS
    from gcalign.estimation import ins_error as ie

    sc = gcalign.load(CALIBRATE)
    res = gcalign.run("calibrate", sc, seed=4)
    _, r = _calibration_arrays(4)
    assert r.error is not None and r.nees is not None
    for i, name in enumerate(ie.STATE_NAMES):
        st = res["states"][name]
        assert (st["estimate"], st["sigma"], st["truth"]) == (
            float(r.estimate[-1, i]), float(r.sigma[-1, i]), float(r.truth[-1, i])), name
    assert res["nees"]["final"] == float(r.nees[-1])
    assert res["normalized_error"] == (r.error[-1] / r.sigma[-1]).tolist()
    # the typed result of the command's run is the core's, array for array
    typed = COMMANDS["calibrate"].execute(sc, 4).result
    for name in ("t", "estimate", "sigma", "truth", "nees", "innovation", "att", "v_n", "pos"):
        assert np.array_equal(getattr(typed, name), getattr(r, name)), name


def test_calibrate_heading_beats_the_static_floor_only_after_the_ground_roll():
    """Spec 002 §3, §7 item 5: at rest the heading is tied to the east gyro bias,
    φU = −εE/(Ω cos L), so no static run can know it better than σ(εE)/(Ω cos L) (0.48° for
    the filter's 0.1°/h); the ground roll's acceleration separates them and σ(φU) falls far
    below that floor, with the final error inside 3σ for every state."""
    from gcalign.estimation import ins_error as ie

    _, r = _calibration_arrays(4)
    assert r.error is not None
    phi_u, eps_e = ie.PHI.start + 2, ie.EB.start
    floor = r.sigma[0, eps_e] / (earth.OMEGA_IE * np.cos(38.0 * u.DEG))
    static_end = int(np.searchsorted(r.t, 20.0))
    assert r.sigma[static_end, phi_u] > floor
    assert r.sigma[-1, phi_u] < floor / 3.0
    assert np.all(np.abs(r.error[-1] / r.sigma[-1]) < 3.0)


def test_calibrate_recorded_array_route_gives_the_cli_numbers_bit_for_bit(lasergyro):
    """Recorded data of a parked vehicle (the PSINS lasergyro file): the user's own arrays,
    a coarse alignment over the first 60 s, then zero-velocity aiding to 120 s."""
    from gcalign.align.coarse import inertial_frame_coarse
    from gcalign.calibrate import Settings, calibrate, parked_data
    from gcalign.estimation import ins_error as ie
    from gcalign.io.imu_files import read_imu_file

    res = gcalign.run("calibrate", gcalign.load({
        "name": "parked", "imu_file": str(lasergyro),
        "calibrate": {"aiding": "zero-velocity", "coarse": {"method": "inertial",
                                                            "duration_s": 60},
                      "duration_s": 120, "gnss_noise": False}}))
    imu = read_imu_file(lasergyro)
    assert imu.site is not None
    n60 = int(round(60.0 / imu.ts))
    att = inertial_frame_coarse(imu.dtheta[:n60], imu.dv[:n60], imu.ts, *imu.site)
    n120 = int(round(120.0 / imu.ts))
    data = parked_data(imu.dtheta[n60:n120], imu.dv[n60:n120], imu.ts, att, imu.site, t0=60.0)
    r = calibrate(data, Settings(p0_sigma=_seed_p0(imu.site), gnss_noise=False))
    assert res["coarse_attitude_deg"] == np.degrees(att).tolist()
    for i, name in enumerate(ie.STATE_NAMES):
        st = res["states"][name]
        assert (st["estimate"], st["sigma"]) == (float(r.estimate[-1, i]),
                                                 float(r.sigma[-1, i])), name
    assert res["attitude_deg"] == np.degrees(r.att[-1]).tolist()


def test_observability_array_route_gives_the_cli_numbers_bit_for_bit():
    from gcalign.calibrate import ObservabilitySettings, Settings, observability, trajectory

    res = gcalign.run("observability", gcalign.load(CALIBRATE))
    truth, ideal, spans, _ = _flight_arrays()
    traj = trajectory(truth.t, truth.att, truth.v_n, truth.pos, ideal.dtheta, ideal.dv)
    # the default scaling is P0, written as the scenario converts it (°/h, µg → SI)
    tab = observability(traj, spans, ObservabilitySettings(covariance=False),
                        Settings(p0_sigma=_seed_p0(truth.pos[0])))
    assert res["scaling"] == tab.scaling == "p0"
    assert res["rank_final"] == int(tab.rank_cum[-1])
    assert res["degree_final"] == tab.eta_cum[-1].tolist()
    for i, seg in enumerate(res["segments"]):
        assert seg["rank"] == int(tab.rank[i]) and seg["tom_rank"] == int(tab.tom_rank[i])
        assert list(seg["degree"].values()) == tab.eta[i].tolist()
        assert seg["null_residual"] == float(tab.null_residual[i])


def test_observability_of_a_static_segment():
    """Spec 002 §7 items 2-3 through the array route: at rest, level and at yaw 0, the
    columns of δλ (velocity matching), δKgx, δKax and δKay are zero (η = 0); the closed-form
    null space has at least 10 independent directions (three φ-bias pairs, δλ, and each
    scale factor tied to its bias through the constant ω_ib^b and f^b), so the rank is at
    most 11; the flight's ground roll then raises it."""
    from gcalign.calibrate import ObservabilitySettings, Span, observability, trajectory
    from gcalign.estimation import ins_error as ie
    from gcalign.sim.imu import ideal_imu
    from gcalign.sim.motions import Static

    site = np.array([38.0 * u.DEG, 121.0 * u.DEG, 0.0])
    truth, ideal = ideal_imu(Static((0.0, 0.0, 0.0), 20.0), site, 0.04)
    traj = trajectory(truth.t, truth.att, truth.v_n, truth.pos, ideal.dtheta, ideal.dv)
    tab = observability(traj, (Span("static", 0.0, 20.0),),
                        ObservabilitySettings(covariance=False))
    names = list(ie.STATE_NAMES)
    for name in ("dlam", "dKgx", "dKax", "dKay"):
        assert tab.eta[0, names.index(name)] == 0.0, name
    assert 0 < tab.rank[0] <= 21 - 10
    truth, ideal, spans, _ = _flight_arrays()
    flight = observability(trajectory(truth.t, truth.att, truth.v_n, truth.pos, ideal.dtheta,
                                      ideal.dv), spans, ObservabilitySettings(covariance=False))
    assert flight.rank_cum[0] == tab.rank[0] and flight.rank_cum[1] > tab.rank[0]


# ------------------------------------------------------------------ real-time attitude

REALTIME = {
    "name": "rt-small", "site": {"lat_deg": 34.25, "lon_deg": 108.9, "height_m": 400},
    "imu": {"seed": 11},
    "realtime": {"settle_s": 0.5, "cases": [
        {"name": "rate 10", "steps": [{"axis": "z", "profile": "rate", "rate_dps": 10,
                                       "duration_s": 2}]},
        {"name": "accel 10", "steps": [
            {"profile": "rest", "duration_s": 0.5},
            {"axis": "z", "profile": "ramp", "accel_dps2": 10, "rate_dps": 15,
             "duration_s": 1.5}]}]},
}


def _realtime_cases():
    from gcalign.realtime import accel_case, rate_case

    return (rate_case("rate 10", 10.0 * u.DEG, 2.0),
            accel_case("accel 10", 10.0 * u.DEG, 15.0 * u.DEG, 2.0, rest_s=0.5))


def test_realtime_array_route_gives_the_cli_numbers_bit_for_bit():
    from gcalign.app.registry import COMMANDS
    from gcalign.realtime import Settings, run_realtime

    sc = gcalign.load(REALTIME)
    res = gcalign.run("realtime", sc, seed=11)
    site = np.array([34.25 * u.DEG, 108.9 * u.DEG, 400.0])
    r = run_realtime(Settings(settle_s=0.5), np.random.default_rng(11), _realtime_cases(),
                     site=site)
    assert res["chain_delay_ms"] == r.chain_delay * 1e3
    for case, row, out in zip(r.cases, r.rows, res["cases"], strict=True):
        assert (out["name"], out["n_pulses"]) == (case.case.name, row.n_pulses)
        assert out["before_max_arcsec"] == row.before_max["truth"] / u.ARCSEC
        for p, st in row.stats.items():
            assert out["after_max_arcsec"][p] == st.max["truth"] / u.ARCSEC, p
            assert out["after_rms_arcsec"][p] == st.rms["truth"] / u.ARCSEC, p
    typed = COMMANDS["realtime"].execute(sc, 11).result
    for mine, theirs in zip(r.cases, typed.cases, strict=True):
        assert np.array_equal(mine.latched, theirs.latched)
        assert np.array_equal(mine.truth, theirs.truth)
        for p in mine.predicted:
            assert np.array_equal(mine.predicted[p], theirs.predicted[p]), p


@pytest.mark.parametrize(("chain", "order"), [("alignment", 180), ("navigation", 40)])
def test_realtime_lag_at_uniform_rate_is_the_fir_group_delay(chain, order):
    """Seed 003 eq. 1, spec 003 §2: a linear-phase FIR of order N delays by N/(2 Fs) (18 ms
    for the alignment chain's 180 at 5 kHz, 4 ms for the navigation chain's 40, whose notch
    adds its own low-frequency delay); at a uniform rate with the pulses on the solution
    instants (Δt = 0) the latched attitude lags the table by exactly the chain's delay."""
    from gcalign.realtime import FilterSettings, Settings, run_realtime

    settings = Settings(settle_s=0.5, filter=FilterSettings(chain=chain),
                        predictors=("none",))
    r = run_realtime(settings, np.random.default_rng(3), _realtime_cases()[:1])
    fs = settings.filter.fs_hz
    assert r.chain.fir_delay == pytest.approx(order / (2.0 * fs), rel=1e-12)
    assert r.chain_delay == pytest.approx(r.chain.fir_delay + r.chain.notch_delay, rel=1e-12)
    if chain == "alignment":
        assert r.chain.notch_delay == 0.0 and r.chain_delay == pytest.approx(0.018, rel=1e-12)
    assert r.rows[0].lag == pytest.approx(r.chain_delay, rel=1e-3)


# -------------------------------------------------------------------- rotation modulation

PARITY = np.diag([-1.0, 1.0, 1.0])


def test_modulate_array_route_gives_the_cli_numbers_bit_for_bit():
    from gcalign.app.modulate.run import seed_scenario
    from gcalign.app.registry import COMMANDS
    from gcalign.modulate import ErrorTerms, analyse_scheme, builtin_scheme
    from gcalign.nav.earth import SEED004

    sc = seed_scenario(["fixed", "seed-12"], rate=1.0, hours=2.0)
    res = gcalign.run("modulate", sc)
    terms = ErrorTerms(gyro_bias=np.full(3, 0.01) * u.DPH,
                       accel_bias=np.full(3, 100.00167) * u.UG)
    typed = COMMANDS["modulate"].execute(sc).result
    for name in ("fixed", "seed-12"):
        a = analyse_scheme(builtin_scheme(name), terms, lat=45.7796 * u.DEG, earth=SEED004,
                           att0=np.zeros(3), duration=2.0 * 3600.0, name=name)
        out, lin = res["schemes"][name], a.linear
        assert lin is not None
        assert out["cycle_s"] == (None if name == "fixed" else a.invariants.period)
        assert out["peak_integral_C_s"] == a.invariants.peak_integral_C.tolist()
        assert out["scale_factor_net_arcsec"] == (a.invariants.scale_factor_net
                                                  / u.ARCSEC).tolist()
        assert out["linear"]["max_horizontal_error_m"] == float(lin.horizontal.max())
        assert out["linear"]["horizontal_error_m"] == {
            f"{h:g}h": float(lin.at(h)[0]) for h in res["report_hours"]}
        mine = typed[name]
        assert mine.linear is not None
        assert np.array_equal(mine.invariants.integral_C, a.invariants.integral_C)
        assert np.array_equal(mine.linear.horizontal, lin.horizontal)
        assert np.array_equal(mine.cycle.q, a.cycle.q)


def test_modulate_seed12_leaves_a_third_of_each_bias():
    """Spec 004 §2: the literal 12-step scheme has ∫_cycle C_s^b dt = 4(Ts+Tz)·C0·diag(−1,1,1)
    (C0 = I at position A), so the bias left is diag(−1,1,1)/3 of each constant bias; a
    dwell of 250 s and the seed's 12 s turn."""
    from gcalign.modulate import ErrorTerms, analyse_scheme, builtin_scheme

    eps, nab = np.array([1.0, -2.0, 3.0]) * 0.01 * u.DPH, np.array([50.0, 20.0, -80.0]) * u.UG
    a = analyse_scheme(builtin_scheme("seed-12", dwell=250.0),
                       ErrorTerms(gyro_bias=eps, accel_bias=nab))
    r = a.invariants
    assert r.period == pytest.approx(12 * (250.0 + 12.0), rel=1e-15)
    np.testing.assert_allclose(r.integral_C, 4 * (250.0 + 12.0) * PARITY, rtol=0,
                               atol=1e-12 * r.period)
    np.testing.assert_allclose(r.residual_gyro_bias, PARITY @ eps / 3, rtol=0,
                               atol=1e-13 * np.abs(eps).max())
    np.testing.assert_allclose(r.residual_accel_bias, PARITY @ nab / 3, rtol=0,
                               atol=1e-13 * np.abs(nab).max())
    assert a.linear is None  # no static base given: no linear model
    # the sampled cycle closes: after the 12 steps the mechanism is back at A
    assert a.cycle.t[0] == 0.0 and a.cycle.t[-1] < r.period
    np.testing.assert_allclose(np.abs(a.cycle.q[-1]), [1.0, 0.0, 0.0, 0.0], atol=1e-9)
