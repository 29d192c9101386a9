"""Seed 000 findings on the configs of `configs/` (our IMU errors: the seed does not state
its own), and alignment on the real recorded file `lasergyro.imu`.

Expected directions come from the seed (§5.2 Table 1, §5.3, §6.2) and, for the real file,
from its known heading (yaw −90.6°, /work/shared/data/README.md). docs/results.md tables the
numbers beside the seed's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gcalign.app.align.run import run_alignment
from gcalign.app.data import scenario_data
from gcalign.io.scenario import load_scenario

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
SEEDS = range(1, 21)


def heading_errors(name: str, seeds=SEEDS, **overrides) -> np.ndarray:
    """|yaw error| at T3 (deg) over seeds."""
    sc, _ = load_scenario(CONFIGS / name)
    for k, v in overrides.items():
        setattr(sc.align, k, v)
    out = []
    for seed in seeds:
        run = run_alignment(sc, scenario_data(sc, seed))
        out.append(abs(np.degrees(run.error_t3[2])))
    return np.array(out)


def test_swing_compensation_section_5_2():
    errors = {}
    for comp in ("none", "one_off", "continued"):
        sc, _ = load_scenario(CONFIGS / f"seed000_swing_{comp}.yaml")
        run = run_alignment(sc, scenario_data(sc, 1))
        errors[comp] = np.degrees(run.error_t3)
    # none: the T2 attitude is 13 s old; the swing moved it by degrees (seed: -1.89, -2.86, 3.24).
    assert np.all(np.abs(errors["none"]) > 1.0)
    np.testing.assert_allclose(errors["none"][:2], [-1.90, -2.85], atol=0.02)
    for comp in ("one_off", "continued"):
        assert np.abs(errors[comp]).max() < 0.05 * 3  # heading floor of our IMU ≈ 0.1°
        assert np.abs(errors[comp][:2]).max() < 0.05


@pytest.mark.slow
def test_moving_modes_section_5_3():
    conv = heading_errors("seed000_moving_conventional.yaml")
    full = heading_errors("seed000_moving_full_cycle.yaml")
    half = heading_errors("seed000_moving_half_cycle.yaml")
    # Our IMU makes the heading noise-limited (median ≈ 0.08-0.09°): a T_z = 100 s loop
    # forgets its start within one 290 s pass, so later passes add little; the cycles still
    # win at T3 because the conventional loop meets the last turn (320-330 s) in real
    # time. Seeded, so the medians are fixed numbers (docs/results.md).
    assert np.median(full) < np.median(conv)
    assert np.median(half) < np.median(conv)


def test_moving_modes_ideal_imu_cycles_beat_conventional():
    """The seed's mechanism without sensor noise: on 290 s of data the conventional loop
    has not finished its transient at T3 (no level phase, as the seed), the cycles have."""
    ideal = {
        "gyro": {"bias_dph": [0, 0, 0], "arw_dprh": 0},
        "accel": {"bias_ug": [0, 0, 0], "vrw_ugrhz": 0},
    }
    results = {}
    for mode in ("conventional", "full_cycle", "half_cycle"):
        sc, _ = load_scenario(CONFIGS / f"seed000_moving_{mode}.yaml")
        sc.imu = sc.imu.model_validate({**sc.imu.model_dump(), **ideal})
        sc.align.level_s = 0.0
        sc.align.aiding.noise_mps = 0.0
        run = run_alignment(sc, scenario_data(sc, 1))
        results[mode] = abs(np.degrees(run.error_t3[2]))
    assert results["full_cycle"] < results["conventional"] / 3
    assert results["half_cycle"] < results["conventional"] / 3


@pytest.mark.slow
@pytest.mark.parametrize("base", ["swing", "moving"])
def test_two_stage_variable_beats_fixed_section_6_2(base):
    fixed = heading_errors(f"seed000_two_stage_{base}_fixed.yaml")
    variable = heading_errors(f"seed000_two_stage_{base}_variable.yaml")
    assert np.median(variable) < np.median(fixed)


REAL = CONFIGS / "lasergyro_align.yaml"


@pytest.mark.skipif(
    not (CONFIGS / "../../shared/data/lasergyro.imu").resolve().is_file(),
    reason="shared/data/lasergyro.imu is not beside the repository",
)
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
