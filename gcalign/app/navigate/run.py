"""Free inertial navigation from the initial state, with errors against truth."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from gcalign.app.data import RunData, scenario_data
from gcalign.app.registry import Outcome
from gcalign.errors import ScenarioError
from gcalign.nav import earth
from gcalign.nav.rotation import attitude_error
from gcalign.nav.strapdown import NavSolution, NavState, navigate


@dataclass(frozen=True)
class NavRun:
    """A free-navigation run. Errors are None without truth.

    att_error (N+1, 3) rad as Euler differences; vel_error (N+1, 3) m/s ENU;
    pos_error (N+1, 3) m ENU (east, north, up).
    """

    solution: NavSolution
    att_error: np.ndarray | None
    vel_error: np.ndarray | None
    pos_error: np.ndarray | None
    compute_s: float


def position_error_enu(pos, pos_true):
    """ENU metres between two ``[lat, lon, h]`` tracks, (N, 3), radii at the true latitude."""
    r_m, r_n = earth.radii(pos_true[:, 0])
    h = pos_true[:, 2]
    return np.stack(
        [
            (pos[:, 1] - pos_true[:, 1]) * (r_n + h) * np.cos(pos_true[:, 0]),
            (pos[:, 0] - pos_true[:, 0]) * (r_m + h),
            pos[:, 2] - pos_true[:, 2],
        ],
        -1,
    )


def initial_state(data: RunData) -> NavState:
    """The true initial state, or the one in the IMU file's header for recorded data."""
    if data.truth is not None:
        tr = data.truth
        return NavState.from_euler(tr.att[0], tr.v_n[0], tr.pos[0])
    if data.imu.att0 is None:
        raise ScenarioError(
            f"imu_file: {data.imu.source} gives no initial attitude and there is no truth"
        )
    v0 = data.imu.v0_n if data.imu.v0_n is not None else np.zeros(3)
    return NavState.from_euler(data.imu.att0, v0, data.site)


def run_navigation(data: RunData) -> NavRun:
    imu = data.imu
    start = initial_state(data)
    t0 = time.perf_counter()
    sol = navigate(imu.t, imu.dtheta, imu.dv, imu.ts, start)
    compute = time.perf_counter() - t0
    if data.truth is None:
        return NavRun(sol, None, None, None, compute)
    tr = data.truth
    return NavRun(
        solution=sol,
        att_error=attitude_error(sol.att, tr.att),
        vel_error=sol.v_n - tr.v_n,
        pos_error=position_error_enu(sol.pos, tr.pos),
        compute_s=compute,
    )


def navigation_summary(run: NavRun, data: RunData, name: str) -> dict:
    """Plain-number summary (degrees, m/s, m) for tables, JSON and the results file."""
    sol = run.solution
    out = {
        "scenario": name,
        "source": data.imu.source,
        "samples": len(data.imu),
        "duration_s": float(sol.t[-1] - sol.t[0]),
        "compute_s": run.compute_s,
        "final_state": {
            "attitude_deg": np.degrees(sol.att[-1]).tolist(),
            "velocity_mps": sol.v_n[-1].tolist(),
            "position_deg_m": [*np.degrees(sol.pos[-1, :2]).tolist(), float(sol.pos[-1, 2])],
        },
        "final_error": None,
        "max_error": None,
    }
    if run.att_error is not None:
        errors = {
            "attitude_deg": np.degrees(run.att_error),
            "velocity_mps": run.vel_error,
            "position_m": run.pos_error,
        }
        out["final_error"] = {k: v[-1].tolist() for k, v in errors.items()}
        out["max_error"] = {k: np.abs(v).max(axis=0).tolist() for k, v in errors.items()}
    return out


def execute(sc, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    """Simulate (or read) the data, navigate, summarise; the registry's entry point."""
    from gcalign.app.navigate.hdf5 import write_navigation

    data = scenario_data(sc, seed, cache_key)
    run = run_navigation(data)
    return Outcome(navigation_summary(run, data, sc.name), lambda f: write_navigation(f, run),
                   data.truth, data.seed)
