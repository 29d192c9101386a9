"""Navigation figures: errors against truth (attitude as the misalignment φ, velocity,
position with the horizontal norm), or, for recorded data, the solution and its drift
from the start. Time in s, min or h and attitude in deg, ′ or ″ as the run's size needs."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import ENU, new_figure


def time_axis(t: np.ndarray) -> tuple[np.ndarray, str]:
    """Time from the first sample in s, min or h, whichever reads best."""
    span = float(t[-1] - t[0]) if len(t) else 0.0
    x = t - t[0]
    if span > 3 * 3600:
        return x / 3600.0, "time from the start (h)"
    if span > 20 * 60:
        return x / 60.0, "time from the start (min)"
    return x, "time from the start (s)"


def angle_scale(values_rad: np.ndarray) -> tuple[float, str]:
    """Multiplier from rad and the unit: deg above 1°, arc-minutes above 1′, else ″."""
    peak = float(np.nanmax(np.abs(values_rad))) if values_rad.size else 0.0
    deg = np.degrees(peak)
    if deg >= 1.0:
        return float(np.degrees(1.0)), "deg"
    if deg * 60 >= 1.0:
        return float(np.degrees(1.0) * 60), "arcmin"
    return float(np.degrees(1.0) * 3600), "arcsec"


def navigate_error_figure(t, phi, vel, pos, title: str = "navigation error") -> Figure:
    """Misalignment φ (ENU), velocity and position errors against time; the position panel
    carries the horizontal norm."""
    x, xlabel = time_axis(t)
    scale, unit = angle_scale(phi)
    fig, axes = new_figure(3)
    for j, name in enumerate(ENU):
        axes[0].plot(x, phi[:, j] * scale, label=f"φ {name}")
        axes[1].plot(x, vel[:, j], label=name)
        axes[2].plot(x, pos[:, j], label=name)
    axes[2].plot(x, np.hypot(pos[:, 0], pos[:, 1]), color="black", linewidth=1.2,
                 label="horizontal |·|")
    for ax, lab in zip(axes, (f"misalignment ({unit})", "velocity error (m/s)",
                              "position error (m)"), strict=True):
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize="small", ncols=4)
    axes[-1].set_xlabel(xlabel)
    fig.suptitle(title)
    return fig


def navigate_state_figure(t, att, vel, displacement, title: str = "navigation") -> Figure:
    """Recorded data: pitch and roll, yaw, velocity and the horizontal displacement from the
    start (the drift, if the vehicle stood still) against time."""
    x, xlabel = time_axis(t)
    fig, axes = new_figure(4)
    axes[0].plot(x, np.degrees(att[:, 0]), label="pitch")
    axes[0].plot(x, np.degrees(att[:, 1]), label="roll")
    axes[1].plot(x, np.degrees(np.unwrap(att[:, 2])), label="yaw", color="tab:green")
    for j, name in enumerate(ENU):
        axes[2].plot(x, vel[:, j], label=name)
    axes[3].plot(x, displacement[:, 0], label="east")
    axes[3].plot(x, displacement[:, 1], label="north")
    axes[3].plot(x, np.hypot(displacement[:, 0], displacement[:, 1]), color="black",
                 label="horizontal |·|")
    labels = ("pitch, roll (deg)", "yaw (deg)", "velocity (m/s)", "displacement from\nthe "
              "start (m)")
    for ax, lab in zip(axes, labels, strict=True):
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize="small", ncols=4)
    axes[-1].set_xlabel(xlabel)
    fig.suptitle(title)
    return fig


def figures(f, name: str) -> dict:
    """The figures of a navigate results file."""
    if "navigate" not in f:
        return {}
    g = f["navigate"]
    t = g["t"][()]
    vertical = g.attrs.get("vertical", "")
    vertical = vertical.decode() if isinstance(vertical, bytes) else str(vertical)
    head = f"{name}: vertical channel {vertical}" if vertical else name
    if "error" in g:
        e = g["error"]
        phi = e["phi"][()] if "phi" in e else e["att"][()]
        return {"navigate_error": navigate_error_figure(
            t, phi, e["v_n"][()], e["pos"][()], title=f"{head} — error against truth")}
    from gcalign.app.navigate.run import position_error_enu

    pos = g["pos"][()]
    disp = position_error_enu(pos, np.broadcast_to(pos[0], pos.shape))
    return {"navigate": navigate_state_figure(t, g["att"][()], g["v_n"][()], disp,
                                              title=f"{head} — no truth: drift from the start")}
