"""The /northfind group of a results file: truth, estimates and errors per method."""

from __future__ import annotations

import h5py
import numpy as np

from gcalign.io.results import ATT_FRAME, put


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
