"""Navigation figures: errors against truth or a reference solution, labelled which
(attitude as the misalignment φ, velocity, position with the horizontal norm), or, for
recorded data without a reference, the solution and its drift from the start. Time in s,
min or h and attitude in deg, ′ or ″ as the run's size needs; legends beside the panels."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import (
    ENU,
    _s,
    angle_scale,
    finish,
    new_figure,
    plot_series,
    time_axis,
)


def navigate_error_figure(t, phi, vel, pos, title: str = "navigation error") -> Figure:
    """Misalignment φ (ENU), velocity and position errors against time; the position panel
    carries the horizontal norm."""
    x, xlabel = time_axis(t)
    scale, unit = angle_scale(phi)
    fig, axes = new_figure(3, width=10.0)
    for j, name in enumerate(ENU):
        plot_series(axes[0], x, phi[:, j] * scale, f"φ {name}")
        plot_series(axes[1], x, vel[:, j], name)
        plot_series(axes[2], x, pos[:, j], name)
    plot_series(axes[2], x, np.hypot(pos[:, 0], pos[:, 1]), "horizontal |·|", color="black",
                linewidth=1.2)
    return finish(fig, axes, xlabel, title, (f"misalignment ({unit})", "velocity error (m/s)",
                                             "position error (m)"))


def navigate_state_figure(t, att, vel, displacement, title: str = "navigation") -> Figure:
    """Recorded data: pitch and roll, yaw, velocity and the horizontal displacement from the
    start (the drift, if the vehicle stood still) against time."""
    x, xlabel = time_axis(t)
    fig, axes = new_figure(4, width=10.0)
    plot_series(axes[0], x, np.degrees(att[:, 0]), "pitch")
    plot_series(axes[0], x, np.degrees(att[:, 1]), "roll")
    plot_series(axes[1], x, np.degrees(np.unwrap(att[:, 2])), "yaw", color="tab:green")
    for j, name in enumerate(ENU):
        plot_series(axes[2], x, vel[:, j], name)
    plot_series(axes[3], x, displacement[:, 0], "east")
    plot_series(axes[3], x, displacement[:, 1], "north")
    plot_series(axes[3], x, np.hypot(displacement[:, 0], displacement[:, 1]), "horizontal |·|",
                color="black")
    return finish(fig, axes, xlabel, title, ("pitch, roll (deg)", "yaw (deg)",
                                             "velocity (m/s)", "displacement from\nthe start (m)"))


def figures(f, name: str) -> dict:
    """The figures of a navigate results file, its rows read back
    (:class:`~gcalign.nav.navigate.NavRows`)."""
    from gcalign.io.stored import read_fields
    from gcalign.nav.navigate import NavRows, position_error_enu

    if "navigate" not in f:
        return {}
    g = f["navigate"]
    rows = read_fields(g, NavRows)
    vertical = _s(g.attrs.get("vertical", ""))
    head = f"{name}: vertical channel {vertical}" if vertical else name
    if (e := rows.error) is not None:
        against = _s(g.attrs.get("error_source", "truth"))
        return {"navigate_error": navigate_error_figure(
            rows.t, e.att if e.phi is None else e.phi, e.v_n, e.pos,
            title=f"{head} — error against {against}")}
    disp = position_error_enu(rows.pos, np.broadcast_to(rows.pos[0], rows.pos.shape))
    return {"navigate": navigate_state_figure(rows.t, rows.att, rows.v_n, disp,
                                              title=f"{head} — no truth: drift from the start")}
