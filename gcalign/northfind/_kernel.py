"""Numba kernel of the sample-level north-finder simulation (imported only when used)."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def dwell_means(
    rng: np.random.Generator, ideal: np.ndarray, bias: np.ndarray, sigma: np.ndarray,
    n_samples: int,
) -> np.ndarray:  # pragma: no cover - numba
    """Sample-level dwell means: every sample ``ideal + bias + sigma * w``, then averaged.

    ``ideal`` (K, n, S); draws are consumed in the C order of (K, n, S, n_samples).
    """
    K, n, S = ideal.shape
    out = np.empty_like(ideal)
    for k in range(K):
        for i in range(n):
            for s in range(S):
                acc = 0.0
                for _ in range(n_samples):
                    acc += ideal[k, i, s] + bias[s] + sigma[s] * rng.standard_normal()
                out[k, i, s] = acc / n_samples
    return out
