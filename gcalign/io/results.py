"""The HDF5 results file: one schema, written atomically, readable without gcalign.

Layout (README "Results file"): root attributes ``gcalign_version``, ``kind`` (the command),
``command_line``, ``scenario_yaml`` (the scenario text), ``seed``, ``created_utc`` and
``summary_json`` (what ``gcalign show`` prints); groups ``/truth``, ``/imu``, ``/navigate``,
``/align``, ``/northfind``, ``/batch``. Every dataset carries a ``units`` attribute and,
where it applies, a ``frame`` attribute. Arrays are SI, time along axis 0.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import h5py
import numpy as np
import yaml

from gcalign import __version__
from gcalign.errors import ScenarioError
from gcalign.sim.imu import ImuData
from gcalign.sim.motions import Truth

PHI_FRAME = "misalignment, ENU: C_nb,est C_nb,true^T = exp(-[phi x])"
ATT_FRAME = "[pitch, roll, yaw], C_nb = Rz(yaw) Rx(pitch) Ry(roll), ENU, yaw CCW positive"


@contextmanager
def atomic_h5(path: Path) -> Iterator[h5py.File]:
    """Open `path` for writing under a temporary name; rename on success, delete on failure.

    An interrupted or failed run therefore never leaves a truncated file under the final name.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with h5py.File(tmp, "w") as f:
            yield f
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def put(group: h5py.Group, name: str, data, units: str, frame: str | None = None, **attrs):
    """Write one dataset with its units (and frame) attributes."""
    ds = group.create_dataset(name, data=np.asarray(data))
    ds.attrs["units"] = units
    if frame:
        ds.attrs["frame"] = frame
    for k, v in attrs.items():
        ds.attrs[k] = v
    return ds


def write_header(f: h5py.File, kind: str, scenario_yaml: str, seed: int | None, summary: dict):
    f.attrs["gcalign_version"] = __version__
    f.attrs["kind"] = kind
    f.attrs["command_line"] = " ".join(["gcalign", *sys.argv[1:]])
    f.attrs["scenario_yaml"] = scenario_yaml
    f.attrs["seed"] = -1 if seed is None else int(seed)
    f.attrs["created_utc"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
    f.attrs["summary_json"] = json.dumps(summary)


def write_truth(f: h5py.File, truth: Truth):
    g = f.create_group("truth")
    put(g, "t", truth.t, "s")
    put(g, "att", truth.att, "rad", ATT_FRAME)
    put(g, "v_n", truth.v_n, "m/s", "ENU")
    put(g, "pos", truth.pos, "rad, rad, m", "[latitude, longitude, height], WGS-84")


def write_imu(f: h5py.File, imu: ImuData):
    g = f.create_group("imu")
    g.attrs["ts"] = imu.ts
    g.attrs["source"] = imu.source
    put(g, "t", imu.t, "s", description="end time of each increment")
    put(g, "dtheta", imu.dtheta, "rad", "body: x right, y forward, z up")
    put(g, "dv", imu.dv, "m/s", "body: x right, y forward, z up")
    for name in ("site", "att0", "v0_n"):
        value = getattr(imu, name)
        if value is not None:
            g.attrs[name] = value


def open_results(path: Path) -> h5py.File:
    """Open a gcalign results file for reading; ScenarioError if it is missing or not ours."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: file not found")
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise ScenarioError(f"{path}: not an HDF5 file (expected a gcalign results file)") from None
    if "gcalign_version" not in f.attrs:
        f.close()
        raise ScenarioError(
            f"{path}: an HDF5 file, but not a gcalign results file (no 'gcalign_version' attribute)"
        )
    return f


def read_summary(path: Path) -> tuple[str, dict, dict]:
    """``(kind, summary, root attributes)`` of a results file."""
    with open_results(path) as f:
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
    return str(attrs["kind"]), json.loads(attrs["summary_json"]), attrs


def read_truth(path: Path) -> Truth | None:
    with open_results(path) as f:
        if "truth" not in f:
            return None
        g = f["truth"]
        return Truth(t=g["t"][()], att=g["att"][()], v_n=g["v_n"][()], pos=g["pos"][()])


def read_imu(path: Path) -> ImuData:
    """The IMU block stored by ``gcalign simulate`` (so the same data feeds several runs)."""
    with open_results(path) as f:
        if "imu" not in f:
            raise ScenarioError(f"{path}: holds no /imu group (write one with 'gcalign simulate')")
        g = f["imu"]
        extra: dict = {k: np.asarray(g.attrs[k]) for k in ("site", "att0", "v0_n") if k in g.attrs}
        scenario = yaml.safe_load(str(f.attrs.get("scenario_yaml", ""))) or {}
        motion = scenario.get("motion") if isinstance(scenario, dict) else None
        kind = motion.get("kind") if isinstance(motion, dict) else None
        return ImuData(
            t=g["t"][()],
            dtheta=g["dtheta"][()],
            dv=g["dv"][()],
            ts=float(g.attrs["ts"]),
            source=str(path),
            meta={"motion_kind": kind} if kind else {},
            **extra,
        )


def read_scenario_yaml(path: Path) -> str:
    with open_results(path) as f:
        return str(f.attrs["scenario_yaml"])


def write_navigation(f: h5py.File, run) -> None:
    """/navigate: the free-navigation solution and, with truth, its errors."""
    g = f.create_group("navigate")
    sol = run.solution
    put(g, "t", sol.t, "s")
    put(g, "att", sol.att, "rad", ATT_FRAME)
    put(g, "v_n", sol.v_n, "m/s", "ENU")
    put(g, "pos", sol.pos, "rad, rad, m", "[latitude, longitude, height]")
    if run.att_error is not None:
        e = g.create_group("error")
        put(e, "att", run.att_error, "rad", "Euler differences est - true, yaw wrapped")
        put(e, "v_n", run.vel_error, "m/s", "ENU")
        put(e, "pos", run.pos_error, "m", "ENU (east, north, up)")


GAIN_NAMES = "K_E1, K_E2, K_E3, K_N1, K_N2, K_N3, K_U1, K_U2, K_U3, K_U4"


def write_alignment(f: h5py.File, run) -> None:
    """/align/pass_NN (attitude and error per pass), /align/result, /align/gains."""
    from gcalign.nav.rotation import quat_to_euler

    g = f.create_group("align")
    g.attrs["mode"] = run.cfg.mode
    g.attrs["azimuth_poles"] = run.azimuth_poles
    g.attrs["t1_s"], g.attrs["t2_s"], g.attrs["t3_s"] = run.t1, run.t2, run.t3
    for rec, err, phi in zip(run.passes, run.pass_errors, run.pass_phi, strict=True):
        p = g.create_group(f"pass_{rec.index:02d}")
        p.attrs["direction"], p.attrs["kind"], p.attrs["stage"] = rec.direction, rec.kind, rec.stage
        put(p, "t", rec.t, "s",
            description="data time, processing order (decreasing in a reverse pass)")
        put(p, "att", quat_to_euler(rec.q_nb), "rad", ATT_FRAME)
        put(p, "gains", rec.gains, "SI", names=GAIN_NAMES)
        if err is not None:
            put(p, "error", err, "rad", "Euler differences est - true, yaw wrapped")
            put(p, "phi", phi, "rad", PHI_FRAME)
    r = g.create_group("result")
    put(r, "coarse_att", run.coarse_att, "rad", ATT_FRAME)
    put(r, "att_t2", run.att_t2, "rad", ATT_FRAME)
    put(r, "att_t3", run.att_t3, "rad", ATT_FRAME)
    if run.truth_t2 is not None:
        put(r, "truth_t2", run.truth_t2, "rad", ATT_FRAME)
        put(r, "truth_t3", run.truth_t3, "rad", ATT_FRAME)
        put(r, "error_t2", run.error_t2, "rad", "Euler differences est - true, yaw wrapped")
        put(r, "error_t3", run.error_t3, "rad", "Euler differences est - true, yaw wrapped")
        put(r, "phi_t2", run.phi_t2, "rad", PHI_FRAME)
        put(r, "phi_t3", run.phi_t3, "rad", PHI_FRAME)
    r.attrs["compute_s"] = run.compute_s
    r.attrs["equivalent_s"] = run.equivalent_s


def write_northfind(f: h5py.File, run) -> None:
    """/northfind: truth, per-method estimates and errors (R repeats × M azimuths), the tilt
    estimates and the setup as attributes (SI, radians)."""
    s, res = run.setup, run.result
    g = f.create_group("northfind")
    for name in (
        "positions",
        "dwell_s",
        "rate_hz",
        "lat",
        "height",
        "tilt_direction_ref",
        "repeats",
        "gyro_bias",
        "gyro_arw",
        "gyro_scale",
        "accel_bias",
        "accel_vrw",
        "index_error",
        "n_samples",
        "gravity",
    ):
        g.attrs[name] = getattr(s, name)
    g.attrs["tilt"] = float(s.tilt[0])
    g.attrs["tilt_direction"] = float(s.tilt_direction[0])
    g.attrs["methods"] = ",".join(res.methods)
    g.attrs["samples"] = bool(run.cfg.samples)
    g.attrs["units"] = (
        "lat, tilt, tilt_direction, index_error: rad; dwell_s: s; rate_hz: Hz; "
        "height: m; gyro_bias: rad/s; gyro_arw: rad/sqrt(s); accel_bias: m/s^2 "
        "[x, y]; accel_vrw: m/s/sqrt(s); gravity: m/s^2"
    )
    az = "clockwise from true north, [0, 2pi)"
    put(g, "azimuth_true", res.azimuth_true, "rad", az)
    put(g, "theta", res.theta, "rad", "table angles, counter-clockwise about the table normal")
    put(g, "tilt_true", res.tilt_true, "rad", "table normal from the vertical")
    put(g, "tilt_direction_true", res.tilt_direction_true, "rad", "azimuth of descent, " + az)
    rm = "(repeats, azimuths)"
    put(g, "tilt_est", res.tilt_est.T, "rad", shape=rm)
    put(
        g,
        "tilt_direction_est",
        res.tilt_direction_est.T,
        "rad",
        "azimuth of descent, " + az,
        shape=rm,
    )
    put(g, "pitch_est", res.pitch_est.T, "rad", ATT_FRAME, shape=rm)
    put(g, "roll_est", res.roll_est.T, "rad", ATT_FRAME, shape=rm)
    put(
        g,
        "gyro_coef",
        np.swapaxes(res.gyro_coef, 0, 1),
        "rad/s",
        shape="(repeats, azimuths, [R, a, b])",
    )
    put(
        g,
        "accel_coef",
        np.swapaxes(res.accel_coef, 0, 1),
        "m/s^2",
        shape="(repeats, azimuths, [x, y], [R, a, b])",
    )
    for i, name in enumerate(res.methods):
        m = g.create_group(name)
        put(m, "estimate", res.azimuth_est[i].T, "rad", az, shape=rm)
        put(
            m,
            "error",
            res.azimuth_error[i].T,
            "rad",
            "estimate - true, wrapped to [-pi, pi)",
            shape=rm,
        )
        put(m, "error_pred", res.error_pred[i], "rad", "noise-free closed form (NaN: none)")
        put(m, "std_pred", res.azimuth_std_pred[i], "rad", "linearised 1-sigma prediction")
