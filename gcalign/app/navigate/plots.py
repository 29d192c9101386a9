"""Navigation figures: attitude, velocity and position errors against time."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from gcalign.app.plots import ANGLES, ENU, new_figure


def navigate_error_figure(t: np.ndarray, att: np.ndarray, vel: np.ndarray, pos: np.ndarray,
                          title: str = "navigation error") -> Figure:
    """Attitude (deg), velocity (m/s) and position (m) errors against time."""
    fig, axes = new_figure(3)
    for j, name in enumerate(ANGLES):
        axes[0].plot(t, np.degrees(att[:, j]), label=name)
    for j, name in enumerate(ENU):
        axes[1].plot(t, vel[:, j], label=name)
        axes[2].plot(t, pos[:, j], label=name)
    for ax, lab in zip(axes, ("attitude error (deg)", "velocity error (m/s)",
                              "position error (m)"), strict=True):
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(title)
    return fig


def figures(f, name: str) -> dict[str, Figure]:
    """The figures of a navigate results file (errors need truth)."""
    if "navigate/error" not in f:
        return {}
    e = f["navigate/error"]
    return {"navigate_error": navigate_error_figure(
        f["navigate/t"][()], e["att"][()], e["v_n"][()], e["pos"][()],
        title=f"{name}: free-inertial navigation error")}
