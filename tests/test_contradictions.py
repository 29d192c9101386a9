"""Recorded data that contradict themselves are refused naming the likely fix, and no real,
correctly declared recording is (gcalign.io.recorded.consistency).

The reproductions are the real recordings of tests/data rewritten wrongly: lasergyro.imu's
gyro rates in deg/s declared rad/s, in deg/h declared deg/s, in rad/s declared deg/s, its
gyro x and y columns swapped, its increments in arc-seconds declared degrees (each gave a
heading off by 65-190° with exit 0); the FOG reference of transfer_align_fog_mems.mat as a
CSV with its attitude in radians (read as degrees: wrong errors against it), as a MAT avp
in degrees; the MEMS vehicle in x-forward axes declared y-forward (FLU as RFU), with the
reference or with a velocity aiding file. The real files, in their own layouts and in
every rewriting above when declared rightly, pass: the disturbed parked vehicle and the
vehicle rolling ±33°.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.io
import yaml
from cli_checks import assert_bad_input
from typer.testing import CliRunner

from conftest import LASERGYRO_XZ, ROOT
from gcalign import units as u
from gcalign.cli import app
from gcalign.io.recorded import consistency as K
from gcalign.io.recorded import read_recording, read_reference
from gcalign.io.recorded.axes import rotation_to_rfu
from gcalign.io.recorded.imu import Layout

runner = CliRunner()
MAT = ROOT / "tests" / "data" / "transfer_align_fog_mems.mat"


@pytest.fixture(scope="module")
def laser():
    return read_recording(LASERGYRO_XZ)


@pytest.fixture(scope="module")
def mems():
    return (read_recording(MAT, Layout(format="psins-mat", variable="mimu")),
            read_reference(MAT, "psins-mat", "fogavp"))


def _csv(path, t, gyro, accel):
    np.savetxt(path, np.column_stack([t, gyro, accel]), delimiter=",", fmt="%.12g",
               header="t,gx,gy,gz,ax,ay,az", comments="")
    return path


def _align(path, tmp_path, *options, **layout):
    """`gcalign align` of a scenario whose imu_file is `path` with the keys of `layout`."""
    sc = {"name": "r", "imu_file": {"path": str(path), "format": "csv", **layout},
          "site": {"lat_deg": 34.246048, "lon_deg": 108.909664, "height_m": 380},
          "align": {"coarse": {"method": "inertial"}, "mode": "conventional", "t1_s": 60,
                    "t2_s": 300, "t3_s": 300,
                    "stages": [{"t_xy_s": 20, "t_z_s": 100, "xi": 0.707}]}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sc))
    out = tmp_path / "o.h5"
    return runner.invoke(app, ["align", str(tmp_path / "s.yaml"), *options, "-o",
                               str(out)]), out


@pytest.mark.parametrize("scale, declared, likely", [
    (1 / u.DEG, "rad/s", "gyro looks like deg/s, declared rad/s"),
    (1 / u.DPH, "deg/s", "gyro looks like deg/h, declared deg/s"),
    (1.0, "deg/s", "gyro looks like rad/s, declared deg/s"),
])
def test_gyro_rates_in_other_units_are_refused_naming_the_unit(laser, tmp_path, scale,
                                                               declared, likely):
    """The rates of lasergyro.imu written in another unit than declared; a (gyro, accel)
    unit pair the reader takes, the accelerometers right (the gravity check holds)."""
    n = 60_000  # 600 s
    p = _csv(tmp_path / "r.csv", laser.t[:n], laser.dtheta[:n] / laser.ts * scale,
             laser.dv[:n] / laser.ts)
    res, out = _align(p, tmp_path, units={"gyro": declared, "accel": "m/s^2"})
    assert_bad_input(res, out, likely, "specific force turns", "check_consistency: false")


def test_increments_in_arcseconds_declared_degrees_are_refused(laser, tmp_path):
    n = 60_000
    p = _csv(tmp_path / "i.csv", laser.t[:n], laser.dtheta[:n] / u.ARCSEC, laser.dv[:n])
    res, out = _align(p, tmp_path, units={"gyro": "deg", "accel": "m/s"})
    assert_bad_input(res, out, "gyro looks like arcsec, declared deg")


def test_gyro_x_and_y_swapped_are_refused(laser, tmp_path):
    """Yaw 140.5° instead of -90.6° on lasergyro.imu, with exit 0."""
    n = 60_000
    p = _csv(tmp_path / "s.csv", laser.t[:n], laser.dtheta[:n][:, [1, 0, 2]], laser.dv[:n])
    res, out = _align(p, tmp_path)
    assert_bad_input(res, out, "gyro x and y look swapped", "read as y, x")


@pytest.mark.parametrize("fix", ["units", "columns"])
def test_the_same_files_declared_rightly_align_to_the_header_yaw(laser, tmp_path, fix):
    n = 60_000
    if fix == "units":
        p = _csv(tmp_path / "r.csv", laser.t[:n], laser.dtheta[:n] / laser.ts / u.DEG,
                 laser.dv[:n] / laser.ts)
        layout: dict = {"units": {"gyro": "deg/s", "accel": "m/s^2"}}
    else:
        p = _csv(tmp_path / "s.csv", laser.t[:n], laser.dtheta[:n][:, [1, 0, 2]],
                 laser.dv[:n])
        layout = {"columns": ["t", "gy", "gx", "gz", "ax", "ay", "az"]}
    res, _ = _align(p, tmp_path, "--json", **layout)
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["attitude_t3_deg"][2] == pytest.approx(-90.6, abs=0.1)


def test_a_reference_in_radians_read_as_degrees_is_refused(mems, tmp_path):
    _, ref = mems
    rows = np.column_stack([ref.t, ref.att, ref.v_n, np.degrees(ref.pos[:, :2]),
                            ref.pos[:, 2]])  # attitude left in radians
    p = tmp_path / "ref.csv"
    np.savetxt(p, rows, delimiter=",", fmt="%.12g",
               header="t,pitch,roll,yaw,ve,vn,vu,lat,lon,h", comments="")
    out = tmp_path / "n.h5"
    res = runner.invoke(app, ["navigate", "--imu-file", str(MAT), "--reference", str(p),
                              "--start", "0.11", "-o", str(out)])
    assert_bad_input(res, out, "reference: ", "its attitude looks like radians, read as "
                     "degrees", "check_attitude: false")


def test_a_mat_reference_in_degrees_is_refused(mems, tmp_path):
    _, ref = mems
    avp = np.column_stack([np.degrees(ref.att), ref.v_n, ref.pos, ref.t])
    p = tmp_path / "ref.mat"
    scipy.io.savemat(p, {"avp": avp})
    out = tmp_path / "n.h5"
    res = runner.invoke(app, ["navigate", "--imu-file", str(MAT), "--reference", str(p),
                              "--start", "0.11", "-o", str(out)])
    assert_bad_input(res, out, "it looks like degrees, and psins-mat takes radians")


def _flu(mems, tmp_path):
    imu, ref = mems
    C = rotation_to_rfu("FLU")  # v_rfu = C v_file: the file holds C^T v_rfu
    return _csv(tmp_path / "flu.csv", imu.t, imu.dtheta @ C, imu.dv @ C)


def test_x_forward_axes_declared_y_forward_are_refused_with_a_reference(mems, tmp_path):
    """FLU declared RFU: z is up either way, so the gravity check holds, and the gyros agree
    with the accelerometers; only the vehicle's track shows it."""
    p = _flu(mems, tmp_path)
    out = tmp_path / "n.h5"
    res = runner.invoke(app, ["navigate", "--imu-file", str(p), "--format", "csv",
                              "--reference", str(MAT), "--start", "0.11", "-o", str(out)])
    assert_bad_input(res, out, "the vehicle moves along the body's +x axis, not +y",
                     "the axes look like FLU, declared RFU: give axes: flu")
    res = runner.invoke(app, ["navigate", "--imu-file", str(p), "--format", "csv",
                              "--axes", "FLU", "--reference", str(MAT), "--start", "0.11",
                              "-o", str(out)])
    assert res.exit_code == 0, res.output


def test_x_forward_axes_declared_y_forward_are_refused_with_velocity_aiding(mems, tmp_path):
    imu, ref = mems
    p = _flu(mems, tmp_path)
    vel = tmp_path / "vel.csv"
    np.savetxt(vel, np.column_stack([ref.t, ref.v_n]), delimiter=",", fmt="%.12g",
               header="t,ve,vn,vu", comments="")
    scenario = {"name": "flu", "imu_file": {"path": str(p), "format": "csv"},
                "site": {"lat_deg": float(np.degrees(ref.pos[0, 0])),
                         "lon_deg": float(np.degrees(ref.pos[0, 1])),
                         "height_m": float(ref.pos[0, 2])},
                "align": {"coarse": {"method": "inertial"}, "mode": "conventional",
                          "start_s": 0.11, "t1_s": 10, "t2_s": 99, "t3_s": 99,
                          "aiding": {"source": "file", "path": str(vel),
                                     "format": "velocity-enu"},
                          "stages": [{"t_xy_s": 10, "t_z_s": 50, "xi": 0.707}]}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scenario))
    out = tmp_path / "a.h5"
    res = runner.invoke(app, ["align", str(tmp_path / "s.yaml"), "-o", str(out)])
    assert_bad_input(res, out, "the vehicle moves along the body's +x axis",
                     "align.aiding", "give axes: flu")


def test_the_real_recordings_agree_with_themselves(laser, mems):
    """The numbers the module docstring quotes: both recordings judged, both consistent."""
    rec = laser.meta["recording"]["gyro_check"]
    assert rec["judged"] and rec["rho"] > 0.6 and 0.8 < rec["k"] < 1.25
    rest = rec["at_rest"]
    assert rest["judged"] and abs(rest["ratio_to_earth_rate"] - 1) < 0.05
    assert abs(rest["angle_from_up_deg"] - rest["expected_deg"]) < 1.0
    imu, ref = mems
    rec = imu.meta["recording"]["gyro_check"]
    assert rec["judged"] and rec["rho"] > 0.8 and 0.7 < rec["k"] < 1.3
    found = K.reference_against_gyros("fogavp", ref.t, ref.att, float(ref.pos[0, 0]), imu.t,
                                      imu.dtheta, "psins-mat")
    assert found["judged"] and abs(found["k"] - 1) < 0.1
    track = K.forward_axis("mimu", imu.t, imu.dtheta, imu.dv, ref.t, ref.v_n, np.eye(3),
                           "fogavp")
    assert track["judged"] and track["best"] == "+y"


def _vertical_reference(th, f, h):
    """The carried vertical of ``consistency._vertical`` as a NumPy loop (its first form)."""
    u = f[:max(1, int(round(5.0 / h)))].mean(axis=0)
    u /= np.linalg.norm(u)
    gain = h / K.VERTICAL_TAU_S
    out = np.empty_like(f)
    norms = np.linalg.norm(f, axis=1)
    for k in range(len(f)):
        u = u - np.cross(th[k], u)
        if norms[k] > 0:
            u = u + gain * (f[k] / norms[k] - u)
        u /= np.linalg.norm(u)
        out[k] = u
    return out


def test_the_vertical_kernel_is_the_numpy_loop(mems):
    """The numba kernel of the carried vertical against its NumPy transcription, on the
    rolling MEMS vehicle (with a block of zero specific force); and, as a closed form, a
    body that does not turn under a constant specific force keeps the force's direction."""
    imu, _ = mems
    th, f, h = K._blocks(imu.dtheta, imu.dv, imu.ts, K.TRACK_BLOCK_S)
    f[100] = 0.0
    np.testing.assert_allclose(K._vertical(th, f, h), _vertical_reference(th, f, h),
                               rtol=0, atol=1e-12)
    f_b = np.tile([0.3, -0.2, 9.8], (50, 1))
    U = K._vertical(np.zeros((50, 3)), f_b, 0.1)
    np.testing.assert_allclose(U, np.tile(f_b[0] / np.linalg.norm(f_b[0]), (50, 1)),
                               rtol=0, atol=1e-15)


def test_every_proper_axes_rewriting_of_the_mems_vehicle_declared_rightly_passes(mems):
    """The MEMS vehicle written in each of the 24 proper axes layouts and declared so: the
    gyros, the reference and the track agree with it in every one."""
    from gcalign.io.recorded.axes import describe

    imu, ref = mems
    for C in {describe(P): P for P in K._PERMUTATIONS if np.linalg.det(P) > 0}.values():
        th, dv = imu.dtheta @ C, imu.dv @ C  # the file's axes
        found = K.check_gyros("m", th @ C.T, dv @ C.T, imu.ts, gyro_units="rad",
                              C_rfu_file=C, fmt="csv")
        assert found["judged"]
        K.forward_axis("m", imu.t, th @ C.T, dv @ C.T, ref.t, ref.v_n, C, "fogavp")


def test_x_forward_axes_declared_y_forward_are_refused_with_calibration_velocities(
        mems, tmp_path):
    imu, ref = mems
    p = _flu(mems, tmp_path)
    vel = tmp_path / "vel.csv"
    np.savetxt(vel, np.column_stack([ref.t, ref.v_n]), delimiter=",", fmt="%.12g",
               header="t,ve,vn,vu", comments="")
    scenario = {"name": "flu", "imu_file": {"path": str(p), "format": "csv"},
                "initial": {"att_deg": np.degrees(ref.att[0]).tolist(),
                            "v_enu_mps": ref.v_n[0].tolist(),
                            "lat_deg": float(np.degrees(ref.pos[0, 0])),
                            "lon_deg": float(np.degrees(ref.pos[0, 1])),
                            "height_m": float(ref.pos[0, 2])},
                "calibrate": {"aiding": "file", "measure": "velocity", "start_s": 0.11,
                              "files": {"velocity": {"path": str(vel),
                                                     "format": "velocity-enu"}}}}
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(scenario))
    out = tmp_path / "c.h5"
    res = runner.invoke(app, ["validate", str(tmp_path / "c.yaml")])
    assert_bad_input(res, out, "the vehicle moves along the body's +x axis",
                     "calibrate.files.velocity", "give axes: flu")
