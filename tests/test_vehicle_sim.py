"""The independent vehicle simulator of the aided-navigation benchmark
(``benchmarks/vehicle``): its closed forms against finite differences, its increments
against its own strapdown from the true start, its sensor processes and GNSS noise against
their stated statistics, its files read back by gcalign's readers (a second, independent
writer of the KF-GINS layouts those readers take)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
import yaml

from conftest import ROOT

if str(ROOT) not in sys.path:  # `pytest` run without `python -m`: the repository's root
    sys.path.insert(0, str(ROOT))

from benchmarks.vehicle import dataset, earth, files, gnss, imu, route  # noqa: E402
from benchmarks.vehicle.check import strapdown_errors  # noqa: E402
from benchmarks.vehicle.trajectory import Trajectory, dcm_to_euler, euler_to_dcm  # noqa: E402


def _richardson(f, t, h):
    """d/dt f at `t` by central differences extrapolated from h and 2h (error O(h⁴))."""
    d1 = (f(t + h) - f(t - h)) / (2 * h)
    d2 = (f(t + 2 * h) - f(t - 2 * h)) / (4 * h)
    return (4 * d1 - d2) / 3


def _smooth_times(traj: Trajectory, n: int, margin: float, seed: int = 3) -> np.ndarray:
    """`n` random times at least `margin` s from any join of the motion."""
    rng = np.random.default_rng(seed)
    joins = traj.join_times()
    t = rng.uniform(1.0, traj.duration - 1.0, 4 * n)
    far = np.min(np.abs(t[:, None] - joins[None, :]), axis=1) > margin
    return t[far][:n]


def test_route_speed_and_heading_are_their_own_derivatives():
    r = route.short()
    traj = Trajectory(r)
    t = _smooth_times(traj, 300, 0.01)
    s, v, a, j = r.speed(t)
    h = 1e-3
    np.testing.assert_allclose(_richardson(lambda x: r.speed(x)[0], t, h), v, atol=1e-9)
    np.testing.assert_allclose(_richardson(lambda x: r.speed(x)[1], t, h), a, atol=1e-8)
    np.testing.assert_allclose(_richardson(lambda x: r.speed(x)[2], t, h), j, atol=1e-7)
    # heading against distance: ψ' = κ, κ' as stated, away from the curvature's joins
    s_q = np.linspace(1.0, r.speed(r.duration)[0] - 1.0, 3000)
    far = np.min(np.abs(s_q[:, None] - np.asarray(r.c_s0)[None, :]), axis=1) > 0.05
    s_q = s_q[far]
    psi, k, dk = r.heading(s_q)
    np.testing.assert_allclose(_richardson(lambda x: r.heading(x)[0], s_q, 1e-3), k, atol=1e-10)
    np.testing.assert_allclose(_richardson(lambda x: r.heading(x)[1], s_q, 1e-3), dk, atol=1e-9)
    # the designed turns: a U-turn turns the heading by 180°, a figure-eight by 0
    marks = {m[0]: m[1:] for m in r.marks}
    for name, want in (("U-turn 1", 180.0), ("figure-eight", 0.0)):
        s_ends = r.speed(np.array(marks[name]))[0]
        turned = np.degrees(np.diff(r.heading(s_ends)[0]))[0]
        assert turned == pytest.approx(want, abs=1e-9)
    # every stop is a stop: ṡ = 0 through it
    assert np.all(r.speed(np.linspace(0.0, 19.99, 50))[1] == 0.0)


def test_trajectory_position_velocity_attitude_rates_agree():
    """Finite differences of the closed forms: the geodetic rates give the NED velocity
    through the radii, the velocity's rate is ``a_ned``, and C_b^n turns at
    Ċ_b^n = C_b^n [ω_ib^b ×] − [ω_in^n ×] C_b^n."""
    traj = Trajectory(route.short())
    t = _smooth_times(traj, 200, 0.02)
    h = 2e-3
    st = traj.state(t)
    r_m, r_n = earth.radii(st.lat)
    dlat = _richardson(lambda x: traj.state(x).lat, t, h)
    dlon = _richardson(lambda x: traj.state(x).lon, t, h)
    dh = _richardson(lambda x: traj.state(x).h, t, h)
    v = np.column_stack([dlat * (r_m + st.h), dlon * (r_n + st.h) * np.cos(st.lat), -dh])
    # (latitude's rounding, 1e-16 rad, is 3e-7 m/s in these differences)
    np.testing.assert_allclose(v, st.v_ned, atol=1e-6)
    np.testing.assert_allclose(_richardson(lambda x: traj.state(x).v_ned, t, h), st.a_ned,
                               atol=1e-7)
    dC = _richardson(lambda x: traj.state(x).C_nb, t, h)

    def skew(w):
        z = np.zeros(len(w))
        return np.stack([np.stack([z, -w[:, 2], w[:, 1]], -1),
                         np.stack([w[:, 2], z, -w[:, 0]], -1),
                         np.stack([-w[:, 1], w[:, 0], z], -1)], -2)

    w_in = earth.omega_ie_n(st.lat) + earth.omega_en_n(st.lat, st.h, st.v_ned)
    np.testing.assert_allclose(dC, st.C_nb @ skew(st.omega_ib_b) - skew(w_in) @ st.C_nb,
                               atol=1e-8)
    # Euler angles and matrices are each other's
    d = np.column_stack(dcm_to_euler(st.C_nb)) - st.euler  # yaw unwrapped along the drive
    np.testing.assert_allclose((d + np.pi) % (2 * np.pi) - np.pi, 0, atol=1e-12)
    # parked: the IMU feels the earth's rate and gravity only
    park = traj.state(np.array([5.0]))
    w_ie_b = park.C_nb[0].T @ earth.omega_ie_n(park.lat)[0]
    np.testing.assert_allclose(park.omega_ib_b[0], w_ie_b, atol=1e-18)
    np.testing.assert_allclose(park.f_b[0], park.C_nb[0].T @ [0, 0, -earth.gravity(
        park.lat[0], park.h[0])], atol=1e-14)


def test_ideal_increments_navigate_to_the_truth():
    """70 s of the short drive (a stop, 10 m/s, a braked 90° turn at 5 m/s, speeding up):
    the simulator's own ECEF strapdown from the true start stays on the closed-form truth
    to 20 µm, 2 µm/s and 1e-9 rad; the same increments one sample late do not (the check
    sees a timing error of 5 ms)."""
    ds = dataset.simulate(dataset.Config(route="short", duration_s=70.0))
    e = strapdown_errors(ds)
    assert max(e["pos_ned_m"]) < 2e-5, e["pos_ned_m"]
    assert max(e["vel_ned_mps"]) < 2e-6, e["vel_ned_mps"]
    assert max(e["att_rad"]) < 1e-9, e["att_rad"]
    late = dataset.Dataset(**{**vars(ds), "ideal_dtheta": np.roll(ds.ideal_dtheta, 1, 0),
                              "ideal_dv": np.roll(ds.ideal_dv, 1, 0)})
    e_late = strapdown_errors(late, samples=6000)  # to 30 s: the start from the stop
    assert max(e_late["pos_ned_m"]) > 1e-3 and max(e_late["att_rad"]) > 1e-6


@pytest.mark.slow
def test_ideal_increments_over_the_whole_short_drive():
    """The 6 min drive (a U-turn, a figure-eight at 7 m/s, speeds to 12 m/s): strapdown
    and truth within 0.1 mm, 1e-6 m/s and 1e-9 rad. (The 30 min drive: 0.10 mm, 2.4e-7 m/s
    and 3.1e-10 rad, ``python benchmarks/vehicle_sim.py DIR --check``.)"""
    ds = dataset.simulate(dataset.Config(route="short"))
    e = strapdown_errors(ds)
    assert max(e["pos_ned_m"]) < 1e-4, e
    assert max(e["vel_ned_mps"]) < 1e-6 and max(e["att_rad"]) < 1e-9, e


def test_gauss_markov_is_stationary_with_its_correlation():
    """20000 processes: variance σ² at every step and the lag correlation e^{−kΔt/τ}
    (within 5 standard errors)."""
    rng = np.random.default_rng(7)
    sigma, tau, dt = 2.0, 0.5, 0.1
    x = imu.gauss_markov(rng, 40, sigma, tau, dt, width=20000)
    n = x.shape[1]
    var = (x**2).mean(1)
    assert np.all(np.abs(var / sigma**2 - 1) < 5 * np.sqrt(2 / n))
    for lag in (1, 5, 20):
        rho = (x[:-lag] * x[lag:]).mean(1).mean() / sigma**2
        assert rho == pytest.approx(np.exp(-lag * dt / tau), abs=5 / np.sqrt(n))


def test_measured_increments_carry_the_stated_errors():
    """Measured minus (1 + s) ideal minus b Δt is the white noise: its standard deviation
    per sample is ARW √Δt and VRW √Δt (KF-GINS's units converted), and the drawn biases
    and scale factors are of the stated σ."""
    ds = dataset.simulate(dataset.Config(route="short", duration_s=30.0, seed=5))
    s, dt, e = ds.sensors, ds.dt, ds.config.errors.si()
    n_g = ds.dtheta - (1 + s.gyro_scale) * ds.ideal_dtheta - s.gyro_bias * dt
    n_a = ds.dv - (1 + s.accel_scale) * ds.ideal_dv - s.accel_bias * dt
    m = n_g.size
    assert n_g.std() / (e["arw"] * np.sqrt(dt)) == pytest.approx(1, abs=5 / np.sqrt(2 * m))
    assert n_a.std() / (e["vrw"] * np.sqrt(dt)) == pytest.approx(1, abs=5 / np.sqrt(2 * m))
    assert abs(n_g.mean()) < 5 * e["arw"] * np.sqrt(dt / m)
    # 0.027 °/h, 15 mGal, 300 ppm: the A15 of KF-GINS's example
    assert e["gbstd"] == pytest.approx(0.027 * np.pi / 180 / 3600)
    assert e["abstd"] == pytest.approx(15e-5) and e["asstd"] == pytest.approx(3e-4)
    # slowly varying over 30 s (τ = 4 h): the first and last values within 0.2 σ
    assert np.all(np.abs(s.gyro_bias[-1] - s.gyro_bias[0]) < 0.2 * e["gbstd"])


def test_gnss_sigma_noise_outage_and_lever_arm():
    traj = Trajectory(route.short())
    lever = np.array([0.5, -0.3, -1.0])
    marks = {m[0]: m[1:] for m in traj.route.marks}
    u = marks["U-turn 1"]
    windows = gnss.outage_windows([0.5 * (u[0] + u[1])])
    f = gnss.fixes(traj, lever, windows, np.random.default_rng(1), np.random.default_rng(2),
                   end=150.0)
    # the σ profile: 0.05-0.5 m horizontally, down 1.5 times, stated to 0.1 mm
    assert f.sigma_ned[:, 0].min() >= 0.05 and f.sigma_ned[:, 0].max() <= 0.5
    np.testing.assert_allclose(f.sigma_ned[:, 2], np.round(1.5 * f.sigma_ned[:, 0], 4))
    # the outage: 60 s between the last fix and the next, centred on the U-turn
    (a, b), = f.outages
    assert b - a == 60.0 and a in f.t and b in f.t
    assert not np.any((f.t > a) & (f.t < b))
    assert a < u[0] and u[1] < b
    assert np.all(np.diff(f.t)[np.diff(f.t) != 60.0] == 1.0)
    # the noise, in metres, against its σ: χ² of 3 per epoch on average
    r_m, r_n = earth.radii(f.truth_lat)
    d = np.column_stack([(f.lat - f.truth_lat) * (r_m + f.truth_h),
                         (f.lon - f.truth_lon) * (r_n + f.truth_h) * np.cos(f.truth_lat),
                         -(f.h - f.truth_h)]) / f.sigma_ned
    assert (d**2).sum(1).mean() == pytest.approx(3, abs=5 * np.sqrt(6 / len(d)))
    # the antenna sits at C_b^n l from the IMU (NED, to 1 µm)
    st = traj.state(f.t)
    r_m, r_n = earth.radii(st.lat)
    ant = np.column_stack([(f.truth_lat - st.lat) * (r_m + st.h),
                           (f.truth_lon - st.lon) * (r_n + st.h) * np.cos(st.lat),
                           -(f.truth_h - st.h)])
    np.testing.assert_allclose(ant, st.C_nb @ lever, atol=1e-6)


def test_sigma_profile_fills_every_bin():
    """The benchmark's 30 min of σ (seed 1, the σ stream of :mod:`dataset`): every bin of
    its NEES table gets at least 15 % of the epochs."""
    rng = np.random.default_rng(np.random.SeedSequence(1).spawn(5)[3])
    sig = gnss.sigma_profile(rng, np.arange(1.0, 1801.0))
    for lo, hi in ((0.05, 0.1), (0.1, 0.2), (0.2, 0.5)):
        assert ((sig >= lo) & (sig < hi + 1e-12)).mean() > 0.15


def test_same_seed_same_numbers():
    cfg = dataset.Config(route="short", duration_s=5.0, seed=11)
    a, b = dataset.simulate(cfg), dataset.simulate(cfg)
    c = dataset.simulate(dataset.Config(route="short", duration_s=5.0, seed=12))
    for name in ("dtheta", "dv"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
        assert not np.array_equal(getattr(a, name), getattr(c, name))
    assert np.array_equal(a.fixes.lat, b.fixes.lat) and a.start.euler.tolist() == \
        b.start.euler.tolist()


def test_files_read_back_by_gcalign(tmp_path):
    """The KF-GINS layouts as gcalign reads them: the IMU text (FRD -> RFU, stamps in
    seconds of week), the GNSS text (σ north, east, down -> east, north, up) and the truth
    as an i2nav-nav reference; and KF-GINS's configuration holds this run's start, σ,
    noise and lever arm."""
    from gcalign.io.recorded.aiding import read_gnss
    from gcalign.io.recorded.imu import Layout, read_recording
    from gcalign.io.recorded.reference import read_reference

    ds = dataset.simulate(dataset.Config(route="short", duration_s=40.0, seed=4))
    p = files.write(ds, tmp_path / "run")
    rec = read_recording(p["imu"], Layout(format="i2nav"))
    frd_to_rfu = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
    np.testing.assert_allclose(rec.t, ds.sow(ds.t), atol=1e-9)
    np.testing.assert_allclose(rec.dtheta, ds.dtheta @ frd_to_rfu.T, rtol=1e-14, atol=1e-20)
    np.testing.assert_allclose(rec.dv, ds.dv @ frd_to_rfu.T, rtol=1e-14, atol=1e-20)
    fx = read_gnss(p["gnss"], "i2nav-gnss")
    np.testing.assert_allclose(fx.t, ds.sow(ds.fixes.t))
    np.testing.assert_allclose(fx.sigma_enu, ds.fixes.sigma_ned[:, [1, 0, 2]])
    np.testing.assert_allclose(fx.pos[:, :2], np.column_stack([ds.fixes.lat, ds.fixes.lon]),
                               atol=1e-13)
    ref = read_reference(p["truth"], "i2nav-nav")
    np.testing.assert_allclose(ref.t, ds.sow(ds.t), atol=1e-9)
    np.testing.assert_allclose(ref.v_n, ds.truth.v_ned[:, [1, 0, 2]] * [1, 1, -1], atol=1e-9)
    # the truth's attitude in gcalign's ENU/RFU Euler angles is the same rotation
    C_frd_ned = euler_to_dcm(*ds.truth.euler.T)
    ned_to_enu = frd_to_rfu  # the same swap of the first two axes and sign of the third
    from gcalign.nav.rotation import euler_to_dcm as g_euler_to_dcm
    np.testing.assert_allclose(g_euler_to_dcm(ref.att), ned_to_enu @ C_frd_ned @ frd_to_rfu.T,
                               atol=1e-9)
    cfg = yaml.safe_load(p["kfgins_yaml"].read_text())
    s = ds.start
    assert cfg["initpos"] == pytest.approx([np.degrees(s.lat), np.degrees(s.lon), s.h],
                                           abs=1e-6)  # deg to 1e-12, m to 1e-6
    assert cfg["initvel"] == pytest.approx(s.v_ned.tolist(), abs=1e-10)
    assert cfg["starttime"] == pytest.approx(float(ds.sow(ds.t[0])), abs=1e-9)
    assert cfg["antlever"] == list(ds.config.lever_frd)
    assert cfg["imunoise"]["corrtime"] == 4 and cfg["imunoise"]["gbstd"] == [0.027] * 3
    assert euler_to_dcm(*np.radians(cfg["initatt"])) == pytest.approx(
        euler_to_dcm(*s.euler), abs=1e-10)
    # the gcalign scenario starts from the same state, in ENU and body RFU
    sc = yaml.safe_load(p["gcalign_yaml"].read_text())
    init = sc["initial"]
    np.testing.assert_allclose(g_euler_to_dcm(np.radians(init["att_deg"])),
                               ned_to_enu @ euler_to_dcm(*s.euler) @ frd_to_rfu.T, atol=1e-12)
    assert init["v_enu_mps"] == pytest.approx([s.v_ned[1], s.v_ned[0], -s.v_ned[2]])
    assert [init["lat_deg"], init["lon_deg"], init["height_m"]] == pytest.approx(
        [np.degrees(s.lat), np.degrees(s.lon), s.h])
    lever = sc["calibrate"]["files"]["position"]["lever_arm_m"]
    assert lever == pytest.approx(frd_to_rfu @ np.array(ds.config.lever_frd))
    # the start's drawn errors are those of the file: the φ between given and true
    C_err = euler_to_dcm(*s.euler) @ ds.truth.C_nb[0].T  # exp(−[φ×])
    anti = 0.5 * np.array([C_err[2, 1] - C_err[1, 2], C_err[0, 2] - C_err[2, 0],
                           C_err[1, 0] - C_err[0, 1]])  # −sin|φ| φ/|φ|
    np.testing.assert_allclose(anti, -s.phi * np.sinc(np.linalg.norm(s.phi) / np.pi),
                               atol=1e-12)
