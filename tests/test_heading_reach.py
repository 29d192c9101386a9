"""Can the gyros find north? `gcalign align` warns, with the numbers, when the heading is
out of reach of a gyrocompass: a horizontal gyro drift ε leaves a heading error of
ε/(ω_ie cos L) whatever the loops do (DESIGN.md, "Static steady state")."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from gcalign.cli import app

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()
OMEGA_IE_DPH = 7.2921151467e-5 * 180 / math.pi * 3600  # 15.041 °/h


def _warnings(tmp_path, scenario: str, *sets: str) -> list[str]:
    args = ["align", str(ROOT / scenario), "-o", str(tmp_path / "a.h5"), "--json"]
    for s in sets:
        args += ["--set", s]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return [w for w in json.loads(res.stdout)["warnings"] if "out of reach" in w]


def _number(text: str, before: str) -> float:
    return float(text.split(before)[0].split()[-1].rstrip("×°"))


def test_a_gyro_bias_of_the_earth_rate_order_warns_with_its_floor(tmp_path):
    """configs/static.yaml (45.78°N, yaw 30°, level): a bias of 1 °/h on each axis has a
    horizontal part of √2 °/h at any yaw, against ω_ie cos L = 10.49 °/h a floor of
    √2/10.49 rad = 7.7°; 0.01 °/h (0.077°) says nothing."""
    omega_h = OMEGA_IE_DPH * math.cos(math.radians(45.7796))
    lines = _warnings(tmp_path, "configs/static.yaml", "imu.gyro.bias_dph=[1, 1, 1]")
    assert len(lines) == 1 and lines[0].startswith("imu.gyro.bias_dph:"), lines
    assert _number(lines[0], "°/h against") == pytest.approx(math.sqrt(2), rel=5e-3)
    assert f"{omega_h:.3g} °/h" in lines[0]
    floor = _number(lines[0], "; the yaw")
    assert floor == pytest.approx(math.degrees(math.sqrt(2) / omega_h), rel=1e-2)
    assert _warnings(tmp_path, "configs/static.yaml", "imu.gyro.bias_dph=[0.01, 0.01, 0.01]") == []


def test_a_noisy_gyro_warns_with_its_heading_noise(tmp_path):
    """ARW 0.5 °/√h over the window the command states (T1 … T2): ARW/(Ω √T), 9.6° for
    the 290 s of the default window."""
    lines = _warnings(tmp_path, "configs/static.yaml", "imu.gyro.arw_dprh=0.5")
    assert len(lines) == 1 and lines[0].startswith("imu.gyro.arw_dprh:"), lines
    T = float(lines[0].split("over the ")[1].split(" s window")[0])
    omega_h = OMEGA_IE_DPH * math.cos(math.radians(45.7796)) / 3600
    noise = math.degrees(math.radians(0.5 / 60) / (math.radians(omega_h) * math.sqrt(T)))
    assert _number(lines[0], "; the yaw") == pytest.approx(noise, rel=1e-2)


def test_the_mems_recording_cannot_find_north(tmp_path):
    """configs/mems_fog.yaml (the README's first recorded-data command, yaw error −69°):
    strapped down from the FOG's attitude, the MEMS gyros drift 263 °/h horizontally;
    PSINS's own estimate of this unit's biases (eb0: −213.6, 158.9 °/h on the level axes,
    the vehicle within 3.5° of level and heading) gives 266 °/h. ω_ie cos L at 34.4°N is
    12.4 °/h: 21× the rate a gyrocompass must measure."""
    import scipy.io

    eb0 = scipy.io.loadmat(ROOT / "tests/data/transfer_align_fog_mems.mat")["eb0"].ravel()
    lines = _warnings(tmp_path, "configs/mems_fog.yaml")
    assert len(lines) == 1 and lines[0].startswith("reference ("), lines
    drift = _number(lines[0], "°/h against")
    assert drift == pytest.approx(np.hypot(eb0[0], eb0[1]) / (math.pi / 180 / 3600), rel=0.05)
    assert "12.4 °/h at 34.4°" in lines[0]
    assert _number(lines[0], "the rate it must measure") == pytest.approx(drift / 12.4, rel=0.01)
