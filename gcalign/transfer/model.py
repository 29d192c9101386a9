"""The transfer-alignment error model in continuous time (spec 006), for observability.

``ẋ = F x``: ``φ̇ = −ω_in^n × φ − C_nb ε``, ``δv̇ = f^n × φ + C_nb ∇``, ε, ∇, μ constant
(the filter's per-step ``Φ = I + F T`` of :mod:`gcalign.transfer.filter`); measurement
``z = H x`` with ``H = [I₆ 0]`` and ``H(φ rows, μ) = −C_nb`` (flexure omitted: a piece-wise
constant analysis of constant states). Rows of H by matching as
:attr:`gcalign.transfer.TransferSettings.rows`.

>>> import numpy as np
>>> H = measurement_matrix(np.eye(3), "velocity")
>>> H.shape, H[:, 3:6].tolist() == np.eye(3).tolist()
((3, 15), True)
"""

from __future__ import annotations

import numpy as np

from gcalign.nav.rotation import skew

ROWS = {"attitude+velocity": slice(0, 6), "velocity": slice(3, 6), "attitude": slice(0, 3)}


def error_matrix(C_nb: np.ndarray, f_n: np.ndarray, omega_in_n: np.ndarray) -> np.ndarray:
    """F (15, 15) at one instant: slave attitude C_nb (3, 3), specific force f^n (3,) m/s²,
    ω_in^n (3,) rad/s."""
    F = np.zeros((15, 15))
    F[0:3, 0:3] = -skew(omega_in_n)
    F[0:3, 6:9] = -C_nb
    F[3:6, 0:3] = skew(f_n)
    F[3:6, 9:12] = C_nb
    return F


def measurement_matrix(C_nb: np.ndarray, matching: str, n: int = 15) -> np.ndarray:
    """H (m, n): rows of ``[φ_meas; δv]`` that `matching` uses; μ (and θ when n = 21) enter
    the attitude rows as −C_nb."""
    H = np.zeros((6, n))
    H[:, :6] = np.eye(6)
    H[0:3, 12:15] = -C_nb
    if n == 21:
        H[0:3, 15:18] = -C_nb
    return H[ROWS[matching]]
