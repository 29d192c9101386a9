"""Simulate a scenario's truth and IMU data; the summary `gcalign simulate` prints."""

from __future__ import annotations

import time

import numpy as np

from gcalign.app.data import RunData, scenario_data
from gcalign.app.registry import Outcome


def simulation_summary(data: RunData, name: str, compute_s: float) -> dict:
    imu = data.imu
    s = {
        "scenario": name,
        "seed": data.seed,
        "samples": len(imu),
        "rate_hz": 1.0 / imu.ts,
        "duration_s": float(len(imu) * imu.ts),
        "compute_s": compute_s,
        "initial_attitude_deg": None,
        "final_attitude_deg": None,
        "final_velocity_mps": None,
        "distance_m": None,
    }
    if data.truth is not None:
        tr = data.truth
        step = np.linalg.norm(np.diff(tr.t)[:, None] * 0.5 * (tr.v_n[1:] + tr.v_n[:-1]), axis=1)
        s.update(
            initial_attitude_deg=np.degrees(tr.att[0]).tolist(),
            final_attitude_deg=np.degrees(tr.att[-1]).tolist(),
            final_velocity_mps=tr.v_n[-1].tolist(),
            distance_m=float(step.sum()),
        )
    return s


def execute(sc, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    """Simulate (or read) the data and summarise; the registry's entry point."""
    from gcalign.io.results import write_imu

    t0 = time.perf_counter()
    data = scenario_data(sc, seed, cache_key)
    summary = simulation_summary(data, sc.name, time.perf_counter() - t0)
    return Outcome(summary, lambda f: write_imu(f, data.imu), data.truth, data.seed)
