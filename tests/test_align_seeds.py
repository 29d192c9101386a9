"""Seed 000 findings on the configs of `configs/` and the mechanism behind them, and
alignment on the real recorded file `lasergyro.imu`.

Expected values come from physics (the linear compass loop's transient, the forgetting
time of a loop, the closed-form steady state) and from the seed (§5.2 Table 1, §5.3, §6.1,
§6.2); for the real file, from its known heading (yaw −90.6°, tests/data/README.md).
docs/results.md tables the numbers beside the seed's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gcalign.align.cycles import loop_gains
from gcalign.align.gains import azimuth_gains, heading_transient
from gcalign.align.stages import Stage
from gcalign.app.align.run import run_alignment
from gcalign.app.data import scenario_data
from gcalign.io.scenario import load_scenario, parse_scenario
from gcalign.nav import earth

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
SEEDS = range(1, 21)
MODES = ("conventional", "full-cycle", "half-cycle")
IDEAL = {"gyro": {}, "accel": {}}
LAT = np.radians(45.7796)


def scenario(name: str, t_z: float | None = None, imu: dict | None = None, **align):
    """A config with T_z, the IMU errors and align fields replaced."""
    sc, _ = load_scenario(CONFIGS / name)
    d = sc.model_dump(mode="json", exclude_none=True)
    if t_z is not None:
        d["align"]["stages"][0]["t_z_s"] = t_z
    if imu is not None:
        d["imu"] = {**d["imu"], **imu}
    d["align"].update(align)
    return parse_scenario(d, name)


def yaw_by_mode(sc, seeds=SEEDS) -> dict[str, np.ndarray]:
    """Yaw error at T3 (deg) of each mode, every mode on the same data of each seed."""
    out: dict[str, list] = {m: [] for m in MODES}
    for seed in seeds:
        data = scenario_data(sc, seed)
        for mode in MODES:
            sc.align.mode = mode
            out[mode].append(np.degrees(run_alignment(sc, data).error_t3[2]))
    return {m: np.array(v) for m, v in out.items()}


def transient_deg(psi0_deg: float, t: float, t_z: float) -> float:
    """Heading error (deg) of the linear compass loop t seconds after it started."""
    g, (r_m, _) = float(earth.gravity(LAT)), earth.radii(LAT)
    return psi0_deg * heading_transient(t, azimuth_gains(t_z, 0.707, g, r_m, "a"), g, r_m)


# ------------------------------------------------------------- §5.3: the mechanism


@pytest.mark.slow
def test_cycles_converge_where_one_pass_cannot_ideal_imu_tz300():
    """T_z = 300 s, ideal IMU and speed reference, the (1, 1, 10)° coarse error, one data
    set for the three modes. The conventional loop (60 s level phase, then compass from
    70 s to T3 = 330 s) is still in its transient at T3: the linear loop's response to the
    10° start, 10°·h(260 s), predicts it. Five compass passes (1450 s ≈ 4.8 T_z) leave
    nothing of the start."""
    sc = scenario("seed000_moving_full_cycle.yaml", 300, IDEAL,
                  aiding={"source": "odometer", "noise_mps": 0.0})
    yaw = {m: e[0] for m, e in yaw_by_mode(sc, [1]).items()}
    predicted = transient_deg(10.0, 330.0 - 10.0 - 60.0, 300.0)  # −0.368°
    assert abs(yaw["conventional"]) > 0.1
    assert yaw["conventional"] == pytest.approx(predicted, rel=0.03)
    assert abs(yaw["full-cycle"]) < 1e-3


@pytest.mark.slow
def test_modes_agree_when_one_pass_converges_ideal_imu_tz100():
    """T_z = 100 s: a pass forgets its start (σ·230 s = 14.5, e^−14.5 ≈ 5e-7), so with an
    ideal IMU every mode ends at the truth (all within 1e-3°)."""
    sc = scenario("seed000_moving_full_cycle.yaml", 100, IDEAL,
                  aiding={"source": "odometer", "noise_mps": 0.0})
    for mode, e in yaw_by_mode(sc, [1]).items():
        assert abs(e[0]) < 1e-3, mode


@pytest.mark.slow
def test_modes_agree_within_the_noise_at_tz100():
    """Our IMU and odometer noise at T_z = 100 s (the _tz100 configs), 20 seeds: the last
    forward pass of full- and half-cycle starts from a state it forgets, so they agree seed
    by seed (< 1e-3°); the conventional median |yaw| differs from theirs by less than two
    standard errors of a median (1.25 σ/√n each)."""
    sc, _ = load_scenario(CONFIGS / "seed000_moving_full_cycle_tz100.yaml")
    yaw = yaw_by_mode(sc)
    np.testing.assert_allclose(yaw["full-cycle"], yaw["half-cycle"], atol=1e-3)
    se = 1.25 * np.std(yaw["full-cycle"], ddof=1) / np.sqrt(len(SEEDS))
    med = {m: np.median(np.abs(e)) for m, e in yaw.items()}
    assert abs(med["conventional"] - med["full-cycle"]) < 2 * np.sqrt(2) * se


@pytest.mark.slow
def test_analytic_coarse_starts_on_the_steady_state_so_no_mode_differs():
    """The seed's §5.3 as stated (biases only, ideal speed reference, analytic coarse
    alignment on 10 s of static data) at T_z = 300 s: the analytic coarse alignment has the
    gyrocompass's own steady-state errors (φ_E = −∇_N/g, φ_N = ∇_E/g,
    φ_U = −ε_E/(ω_ie cos L) + φ_N tan L; tests/test_coarse.py, tests/test_gyrocompass.py),
    so the loop has no transient to shed: the three modes agree to 2e-3°, while the
    (1, 1, 10)° start separates them by more than 0.1°."""
    biases = {"gyro": {"bias_dph": [0.01] * 3}, "accel": {"bias_ug": [50] * 3}}
    aid = {"source": "odometer", "noise_mps": 0.0}
    analytic = scenario("seed000_moving_full_cycle.yaml", 300, biases, aiding=aid,
                        coarse={"method": "analytic"})
    yaw = {m: e[0] for m, e in yaw_by_mode(analytic, [1]).items()}
    assert max(yaw.values()) - min(yaw.values()) < 2e-3
    given = scenario("seed000_moving_full_cycle.yaml", 300, biases, aiding=aid)
    yaw = {m: e[0] for m, e in yaw_by_mode(given, [1]).items()}
    assert abs(yaw["conventional"] - yaw["full-cycle"]) > 0.1


@pytest.mark.slow
def test_section_5_3_reproduces_at_the_configs_tz():
    """The configs (T_z = 280 s, our IMU, odometer noise): conventional well above both
    cycle modes, each median |yaw| within a factor 2 of the seed's (0.1845°, 0.0248°,
    0.0373°)."""
    sc, _ = load_scenario(CONFIGS / "seed000_moving_full_cycle.yaml")
    med = {m: np.median(np.abs(e)) for m, e in yaw_by_mode(sc).items()}
    assert med["conventional"] > 3 * max(med["full-cycle"], med["half-cycle"])
    for mode, seed_value in zip(MODES, (0.1845, 0.0248, 0.0373), strict=True):
        assert seed_value / 2 < med[mode] < 2 * seed_value, (mode, med[mode])


# ------------------------------------------------------------- §6.1: the first T_z


@pytest.mark.parametrize("poles", ["double-oscillator", "oscillator-overdamped"])
@pytest.mark.parametrize("t_z", [100.0, 200.0])
def test_heading_after_the_first_tz_section_6_1(poles, t_z):
    """Seed §6.1: with ξ = 0.707 the heading error "falls to within 4-6 % of its start at
    the first T_z, or lower". Static base, ideal IMU, coarse error (1, 1, 10)°, 60 s level
    phase, then the compass loop: at T_z after its start the kernel's heading is the linear
    loop's h(T_z) (−0.99 % method a, −0.19 % method b; Ω and T_z drop out), well below
    4 %. What is 4-6 % is method a's first overshoot, −6.2 % at 0.70 T_z (method b: +3.7 %
    at that time), which the kernel also follows."""
    level = 60.0
    d = {"name": "first-tz", "site": {"lat_deg": 45.7796, "lon_deg": 126.6705},
         "motion": {"kind": "static", "attitude_deg": [0, 0, 30],
                    "duration_s": 10 + level + t_z + 1},
         "align": {"coarse": {"method": "given", "error_deg": [1, 1, 10]},
                   "mode": "conventional", "realtime": False, "t1_s": 10,
                   "t2_s": 10 + level + t_z, "t3_s": 10 + level + t_z, "level_s": level,
                   "azimuth_poles": poles,
                   "stages": [{"t_xy_s": 20, "t_z_s": t_z, "xi": 0.707}]}}
    sc = parse_scenario(d, "first-tz")
    run = run_alignment(sc, scenario_data(sc, 1))
    rec = run.passes[0]
    t_compass = rec.t - rec.t[0] - level
    yaw = np.degrees(run.pass_errors[0][:, 2]) / 10.0  # fraction of the 10° start
    gains = loop_gains(Stage(20.0, t_z, 0.707), LAT, 0.0, poles)
    g, (r_m, _) = float(earth.gravity(LAT)), earth.radii(LAT)
    az = azimuth_gains(t_z, 0.707, g, r_m, poles)
    assert np.allclose([az.k1, az.k2, az.k3, az.k4], gains[6:], rtol=1e-12)
    h_tz = heading_transient(t_z, az, g, r_m)
    assert yaw[-1] == pytest.approx(h_tz, abs=1e-3)  # 0.1 % of the start
    assert abs(yaw[-1]) < 0.04
    t_peak = 0.70 * t_z
    k = int(np.argmin(np.abs(t_compass - t_peak)))
    assert yaw[k] == pytest.approx(heading_transient(t_peak, az, g, r_m), abs=2e-3)
    if poles == "double-oscillator":
        after = t_compass > 0.6 * t_z
        assert 0.04 < np.max(np.abs(yaw[after])) < 0.065


def test_linear_heading_transient_two_routes():
    """gains.heading_transient (canonical form of φ_U(s)/ψ0) against the physical-state
    model (δv_N, φ_E, φ_U, ω_cU) integrated by the matrix exponential."""
    from scipy.linalg import expm

    g, r = 9.8, 6.4e6
    omega = earth.OMEGA_IE * np.cos(LAT)
    for poles in ("double-oscillator", "oscillator-overdamped"):
        k = azimuth_gains(150.0, 0.707, g, r, poles)
        A = np.array([[-k.k1, g, 0, 0], [-(1 + k.k2) / r, 0, -omega, 0], [0, 0, 0, 1],
                      [k.k3 / omega, 0, 0, -k.k4]])
        for t in (0.0, 50.0, 105.0, 150.0, 300.0):
            physical = (expm(A * t) @ [0, 0, 1.0, 0])[2]
            assert heading_transient(t, k, g, r) == pytest.approx(physical, abs=1e-9)


# ------------------------------------------------------------- §5.2 and §6.2


@pytest.mark.slow
def test_swing_compensation_section_5_2():
    errors = {}
    for comp in ("none", "one_off", "continued"):
        sc, _ = load_scenario(CONFIGS / f"seed000_swing_{comp}.yaml")
        run = run_alignment(sc, scenario_data(sc, 1))
        errors[comp] = np.degrees(run.error_t3)
        # Truth at 813 s, from the seed's own swing (the seed prints yaw 26.7693).
        np.testing.assert_allclose(np.degrees(run.truth_t3), [1.9021, 2.8532, 26.7639],
                                   atol=1e-4)
    # none: the T2 attitude is 13 s old; the swing moved it by degrees (seed: -1.89, -2.86, 3.24).
    assert np.all(np.abs(errors["none"]) > 1.0)
    np.testing.assert_allclose(errors["none"][:2], [-1.90, -2.85], atol=0.02)
    for comp in ("one_off", "continued"):
        assert np.abs(errors[comp]).max() < 0.1  # heading floor of our IMU
        assert np.abs(errors[comp][:2]).max() < 0.05


@pytest.mark.slow
@pytest.mark.parametrize("base", ["swing", "moving"])
def test_two_stage_variable_beats_fixed_section_6_2(base):
    def heading(name):
        sc, _ = load_scenario(CONFIGS / name)
        return np.array([abs(np.degrees(run_alignment(sc, scenario_data(sc, s)).error_t3[2]))
                         for s in SEEDS])

    fixed = heading(f"seed000_two_stage_{base}_fixed.yaml")
    variable = heading(f"seed000_two_stage_{base}_variable.yaml")
    assert np.median(variable) < np.median(fixed)


REAL = CONFIGS / "lasergyro_align.yaml"


@pytest.mark.parametrize("start_s", [0.0, 600.0, 1200.0])
@pytest.mark.parametrize("offset_yaw", [0.0, 5.0, -5.0])
def test_real_lasergyro_heading(start_s, offset_yaw):
    sc, _ = load_scenario(REAL)
    sc.align.start_s = start_s
    sc.align.coarse.offset_deg = [0.0, 0.0, offset_yaw]
    run = run_alignment(sc, scenario_data(sc))
    pitch, roll, yaw = np.degrees(run.att_t2)
    assert yaw == pytest.approx(-90.6, abs=0.1)
    assert 0.6 < pitch < 1.2 and 0.1 < roll < 0.6
