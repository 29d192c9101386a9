"""The simulator checked against itself by a second route: its ideal increments
integrated by :mod:`.strapdown` from the true start must follow the closed-form truth."""

from __future__ import annotations

import numpy as np

from benchmarks.vehicle import earth, strapdown
from benchmarks.vehicle.dataset import Dataset


def strapdown_errors(ds: Dataset, samples: int | None = None) -> dict:
    """Largest |strapdown − truth| over the first `samples` IMU samples (all by default):
    position and velocity (NED m, m/s), attitude (the small angle between the two body
    frames, rad), each per axis, and the series themselves (``series``)."""
    n = len(ds.t) if samples is None else min(samples, len(ds.t))
    tr = ds.truth
    C_en = earth.C_en(tr.lat[:n], tr.lon[:n])
    C_eb = C_en @ tr.C_nb[:n]
    v_e = np.einsum("kij,kj->ki", C_en, tr.v_ned[:n])
    r_e = earth.to_ecef(tr.lat[:n], tr.lon[:n], tr.h[:n])
    # row k's increments end at stamp k: the strapdown starts at stamp 0 and uses rows 1..
    C, V, R = strapdown.navigate(C_eb[0], v_e[0], r_e[0], ds.ideal_dtheta[1:n],
                                 ds.ideal_dv[1:n], ds.dt)
    dr = np.einsum("kji,kj->ki", C_en, R - r_e)
    dv = np.einsum("kji,kj->ki", C_en, V - v_e)
    E = np.swapaxes(C, 1, 2) @ C_eb
    att = 0.5 * np.column_stack([E[:, 2, 1] - E[:, 1, 2], E[:, 0, 2] - E[:, 2, 0],
                                 E[:, 1, 0] - E[:, 0, 1]])
    return {"pos_ned_m": np.abs(dr).max(0).tolist(), "vel_ned_mps": np.abs(dv).max(0).tolist(),
            "att_rad": np.abs(att).max(0).tolist(), "series": (dr, dv, att)}
