"""The /navigate group of a results file: the solution and its errors against truth."""

from __future__ import annotations

import h5py

from gcalign.io.results import ATT_FRAME, put


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
