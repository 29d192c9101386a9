"""The transfer-alignment error model (spec 006): F for observability, the attitude
measurement and its Jacobian for the filter.

``ẋ = F x``: ``φ̇ = −ω_in^n × φ − C_nb ε``, ``δv̇ = f^n × φ + C_nb ∇``, ε, ∇, μ constant
(the filter's per-step ``Φ = I + F T`` of :mod:`gcalign.transfer.filter`).

Attitude measurement, exactly: the slave's true attitude is the master's turned by the
mounting μ on the body side, ``C_s = C_m C(μ) = exp([C_m μ ×]) C_m``, and the mechanised
one is ``C_est = exp(−[φ×]) C_s``, so ``φ_meas = −rotvec(C_est C_mᵀ)
= −rotvec(exp(−[φ×]) exp([a×]))`` with ``a = C_m μ`` (:func:`attitude_measurement`). At
φ = 0 (the filter resets φ̂ after every update) it is ``−a`` exactly, linear in μ through
the master's attitude ``C_m``, and its φ-Jacobian is ``J_l(a)⁻¹ = I − ½[a×] + …`` (the
inverse left Jacobian of SO(3)): ``H(φ rows, φ) = J_l(a)⁻¹``, ``H(φ rows, μ) = −C_m``
(:func:`measurement_matrix`). With ``H(φ, φ) = I`` and the mechanised ``C_nb`` in place of
``C_m`` (PSINS's demo) the μ columns turn with every attitude correction fed back, which
the slave's true axes never do: the filter then learns the roll-axis μ that no data show
(docs/decisions/019). Flexure θ enters as μ does. Rows of H by matching as
:attr:`gcalign.transfer.TransferSettings.rows`.

>>> import numpy as np
>>> H = measurement_matrix(np.eye(3), "velocity")
>>> H.shape, H[:, 3:6].tolist() == np.eye(3).tolist()
((3, 15), True)
"""

from __future__ import annotations

import numpy as np

from gcalign.nav.rotation import quat_mult, quat_to_rotvec, rotvec_to_quat, skew

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


def left_jacobian_inv(a: np.ndarray) -> np.ndarray:
    """``J_l(a)⁻¹`` (3, 3) of SO(3): ``rotvec(exp([u×]) exp([a×])) = a + J_l(a)⁻¹ u + O(u²)``.

    >>> import numpy as np
    >>> np.allclose(left_jacobian_inv(np.zeros(3)), np.eye(3))
    True
    """
    a = np.asarray(a, dtype=float)
    th = float(np.linalg.norm(a))
    A = skew(a)
    if th < 1e-6:  # the series: 1/θ² − (1 + cos θ)/(2θ sin θ) → 1/12
        return np.eye(3) - 0.5 * A + A @ A / 12.0
    c = 1.0 / th ** 2 - (1.0 + np.cos(th)) / (2.0 * th * np.sin(th))
    return np.eye(3) - 0.5 * A + c * (A @ A)


def attitude_measurement(phi: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``−rotvec(exp(−[φ×]) exp([a×]))`` (3,): the measured misalignment of the mechanised
    slave against the master for an attitude error φ and the mounting in n, ``a = C_m μ``."""
    return -quat_to_rotvec(quat_mult(rotvec_to_quat(-np.asarray(phi, dtype=float)),
                                     rotvec_to_quat(a)))


def measurement_matrix(C_m: np.ndarray, matching: str, n: int = 15,
                       mount_n: np.ndarray | None = None) -> np.ndarray:
    """H (m, n): rows of ``[φ_meas; δv]`` that `matching` uses; μ (and θ when n = 21) enter
    the attitude rows as −C_m (the master's attitude), φ as ``J_l(a)⁻¹`` with `mount_n`
    ``a = C_m (μ̂ + θ̂)`` (the identity without it)."""
    H = np.zeros((6, n))
    H[:, :6] = np.eye(6)
    if mount_n is not None:
        H[0:3, 0:3] = left_jacobian_inv(mount_n)
    H[0:3, 12:15] = -C_m
    if n == 21:
        H[0:3, 15:18] = -C_m
    return H[ROWS[matching]]
