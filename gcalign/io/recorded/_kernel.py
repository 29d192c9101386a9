"""Numba kernel of the consistency checks (imported only where it runs)."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def carried_vertical(th: np.ndarray, f: np.ndarray, u0: np.ndarray,
                     gain: float) -> np.ndarray:  # pragma: no cover - numba
    """The up direction in the body frame at each block (n, 3), from `u0` (3,): carried
    through the block rotations `th` (n, 3) rad and pulled toward the specific force `f`
    (n, 3) by `gain` per block (:func:`gcalign.io.recorded.consistency._vertical`)."""
    out = np.empty_like(f)
    x, y, z = u0[0], u0[1], u0[2]
    for k in range(f.shape[0]):
        # u ← u − θ × u: a vector fixed in the navigation frame, seen from the turned body
        a, b, c = th[k, 0], th[k, 1], th[k, 2]
        x, y, z = x - (b * z - c * y), y - (c * x - a * z), z - (a * y - b * x)
        norm_f = math.sqrt(f[k, 0] ** 2 + f[k, 1] ** 2 + f[k, 2] ** 2)
        if norm_f > 0:  # u ← u + gain (f/|f| − u)
            x += gain * (f[k, 0] / norm_f - x)
            y += gain * (f[k, 1] / norm_f - y)
            z += gain * (f[k, 2] / norm_f - z)
        norm = math.sqrt(x * x + y * y + z * z)
        x, y, z = x / norm, y / norm, z / norm
        out[k, 0], out[k, 1], out[k, 2] = x, y, z
    return out
