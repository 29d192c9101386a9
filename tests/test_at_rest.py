"""Aiding that assumes a parked vehicle, on recordings that drive (spec 005, "Safety on
recordings"): the unexplained velocity of a base at rest (zero on ideal static data, a
few cm/s on the parked lasergyro vehicle, metres per second on the MEMS vehicle), and the
warnings of ``align`` without aiding and ``calibrate`` with zero-velocity updates on the
MEMS recording (12 m/s), with the measured numbers."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from conftest import ROOT
from gcalign.align.coarse import unexplained_velocity
from gcalign.app.at_rest import TILT_RAD
from gcalign.cli import app
from gcalign.io.recorded import read_recording
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import euler_to_dcm

runner = CliRunner()
MAT = ROOT / "tests/data/transfer_align_fog_mems.mat"
SITE = {"lat_deg": 34.426, "lon_deg": 111.434, "height_m": 172.6}


def test_unexplained_velocity_of_a_base_at_rest(lasergyro):
    """Ideal static increments: nothing unexplained, even with a 300 ppm accelerometer
    scale error (fitted); a 1 m/s² push for 2 s in the middle (then a stop): about the
    2 m/s it adds, less what a tilt absorbs; the parked lasergyro vehicle: centimetres per
    second over 300 s; the MEMS vehicle: metres per second within 30 s."""
    lat, ts, n = np.radians(34.0), 0.01, 30000
    C_bn = euler_to_dcm([0.02, -0.01, 1.0]).T
    g = float(WGS84.gravity(lat))
    dtheta = np.tile(C_bn @ WGS84.omega_ie_n(lat) * ts, (n, 1))
    dv = np.tile(C_bn @ np.array([0.0, 0.0, g]) * ts, (n, 1))
    assert unexplained_velocity(dtheta, dv, ts, lat) < 1e-4
    assert unexplained_velocity(dtheta, dv * (1 + 3e-4), ts, lat) < 1e-4
    push = dv.copy()
    push[15000:15200] += C_bn @ np.array([0.0, 1.0, 0.0]) * ts  # +2 m/s north...
    push[15200:15400] -= C_bn @ np.array([0.0, 1.0, 0.0]) * ts  # ... and back to rest
    assert 0.5 < unexplained_velocity(dtheta, push, ts, lat) < 2.0

    lg = read_recording(lasergyro)
    k = int(300 / lg.ts)
    still = unexplained_velocity(lg.dtheta[:k], lg.dv[:k], lg.ts, lg.site[0], lg.site[2])
    mems = read_recording(MAT)
    k = int(30 / mems.ts)
    moving = unexplained_velocity(mems.dtheta[:k], mems.dv[:k], mems.ts, np.radians(34.4))
    print(f"unexplained velocity: lasergyro 300 s {still:.3f} m/s, MEMS 30 s {moving:.2f} m/s")
    assert still < 0.05 < TILT_RAD * g * 300
    assert moving > 2 * TILT_RAD * g * 30


def _json(res) -> dict:
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.strip().splitlines()[-1])


def _scenario(tmp_path, section: str, body: dict, reference: bool = False) -> str:
    sc = {"name": "mems", "imu_file": str(MAT), "site": SITE, section: body}
    if reference:
        sc["reference"] = {"path": str(MAT)}
    path = tmp_path / f"{section}.yaml"
    path.write_text(yaml.safe_dump(sc))
    return str(path)


ALIGN = {"coarse": {"method": "inertial"}, "mode": "conventional", "start_s": 0.11,
         "t1_s": 10, "t2_s": 99.8, "t3_s": 99.8, "aiding": {"source": "none"},
         "stages": [{"t_xy_s": 10, "t_z_s": 50, "xi": 0.707}]}


@pytest.mark.parametrize("reference", [False, True])
def test_align_of_a_driving_recording_without_aiding_warns(tmp_path, reference):
    res = runner.invoke(app, ["align", _scenario(tmp_path, "align", ALIGN, reference),
                              "-o", str(tmp_path / "a.h5"), "--json"])
    s = _json(res)
    lines = [w for w in s["warnings"] if w.startswith("align.aiding.source: 'none' takes")]
    assert len(lines) == 1, s["warnings"]
    print(lines[0])
    if reference:
        assert "moves at 11.5-15.8 m/s and 1387 m over the 99.8 s window" in lines[0]
    else:
        assert "velocity change of" in lines[0] and "a tilt of 1e-3 rad gives" in lines[0]
        change = float(lines[0].split("velocity change of ")[1].split(" m/s")[0])
        assert change > 5  # the 11.5 -> 15.8 m/s of the drive, and its turns
    assert "warning: align.aiding.source: 'none' takes" in res.stderr
    # the aided run does not warn
    aided = dict(ALIGN, aiding={"source": "file", "path": str(MAT), "format": "psins-mat"})
    s = _json(runner.invoke(app, ["align", _scenario(tmp_path, "align", aided, reference),
                                  "-o", str(tmp_path / "b.h5"), "--json"]))
    assert not [w for w in s["warnings"] if "at rest" in w]


def test_zero_velocity_calibration_of_a_driving_recording_warns(tmp_path):
    body = {"aiding": "zero-velocity", "coarse": {"method": "inertial", "duration_s": 10},
            "start_s": 0.11, "duration_s": 99, "measure": "velocity", "gnss_noise": False,
            "filter_rate_hz": 1}
    s = _json(runner.invoke(app, ["calibrate", _scenario(tmp_path, "calibrate", body),
                                  "-o", str(tmp_path / "c.h5"), "--json"]))
    lines = [w for w in s["warnings"] if w.startswith("calibrate.aiding: 'zero-velocity'")]
    assert len(lines) == 1, s["warnings"]
    print(lines[0])
    assert "velocity change of" in lines[0] and "mean NIS" in lines[0]
    assert s["nis"]["mean"] > s["nis"]["band_95"][1]


def test_the_parked_vehicle_does_not_warn(tmp_path):
    for cmd, config in (("align", "lasergyro_align.yaml"),
                        ("calibrate", "lasergyro_calibrate.yaml")):
        s = _json(runner.invoke(app, [cmd, str(ROOT / "configs" / config), "-o",
                                      str(tmp_path / f"{cmd}.h5"), "--json"]))
        assert not [w for w in s["warnings"] if "at rest" in w or "parked" in w], s["warnings"]
