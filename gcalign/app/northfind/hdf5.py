"""The /northfind group of a results file: the setup as attributes, then truth, estimates and
errors per method as :class:`gcalign.northfind.NorthfindResult`'s fields say."""

from __future__ import annotations

import h5py

from gcalign.io.stored import write_fields


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
    g.attrs["samples"] = bool(run.cfg.samples)
    g.attrs["units"] = (
        "lat, tilt, tilt_direction, index_error: rad; dwell_s: s; rate_hz: Hz; "
        "height: m; gyro_bias: rad/s; gyro_arw: rad/sqrt(s); accel_bias: m/s^2 "
        "[x, y]; accel_vrw: m/s/sqrt(s); gravity: m/s^2"
    )
    write_fields(g, res)  # the result as its fields say (NorthfindResult)
