"""Numba kernels of the sensor noise: NumPy's normals of a Generator, drawn and applied in one loop.

Numba runs a ``numpy.random.Generator``'s own bit generator and NumPy's ziggurat
(``standard_normal``), so a kernel that draws here takes the same numbers from the stream
as ``rng.standard_normal(shape)`` would, in the same order, and leaves the generator where
that leaves it; the arithmetic is the NumPy expression's, operation by operation, so the
results are the same to the bit (``tests/test_sim_noise.py``). What it saves is the
array of normals and the passes over it: about four times less time for a run's noise.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def noisy_sum(ideal: np.ndarray, bias: np.ndarray, rng: np.random.Generator,
              sigma: np.ndarray) -> np.ndarray:  # pragma: no cover - numba
    """``out = ideal + bias; noise = rng.standard_normal(ideal.shape); noise *= sigma;
    out += noise`` for `ideal` (n, 3), `bias` and `sigma` (3,): a new (n, 3) array."""
    n = ideal.shape[0]
    out = np.empty((n, 3))
    for i in range(n):
        for j in range(3):
            out[i, j] = (ideal[i, j] + bias[j]) + rng.standard_normal() * sigma[j]
    return out


@njit(cache=True)
def add_noise(out: np.ndarray, rng: np.random.Generator,
              sigma: np.ndarray) -> None:  # pragma: no cover - numba
    """``noise = rng.standard_normal(out.shape); noise *= sigma; out += noise`` in place,
    for `out` (n, 3) and `sigma` (3,)."""
    for i in range(out.shape[0]):
        for j in range(3):
            out[i, j] += rng.standard_normal() * sigma[j]


@njit(cache=True)
def normals(rng: np.random.Generator, n: int) -> np.ndarray:  # pragma: no cover - numba
    """``rng.standard_normal(n)``."""
    out = np.empty(n)
    for i in range(n):
        out[i] = rng.standard_normal()
    return out


@njit(cache=True)
def skip_normals(rng: np.random.Generator, n: int) -> float:  # pragma: no cover - numba
    """Advance `rng` as ``rng.standard_normal(n)`` does (the normals' sum is returned so
    that the compiler keeps the draws)."""
    total = 0.0
    for _ in range(n):
        total += rng.standard_normal()
    return total
