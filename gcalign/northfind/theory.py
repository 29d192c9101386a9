"""Closed forms of the north-finder's errors (seed 001 §1, §3.1).

The deterministic tilt-induced azimuth error of the uncompensated (``none``) and ``naive``
methods (:func:`none_error`, :func:`naive_error`, :func:`predicted_error`), and the azimuth
standard deviation predicted from sensor noise and indexing errors by linearised least
squares (:func:`azimuth_std_level`, :func:`predict_azimuth_std`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gcalign.nav import earth
from gcalign.nav.rotation import wrap_pi
from gcalign.northfind.estimate import (
    METHODS,
    _design,
    azimuth_from_harmonics,
    tilt_from_accel,
)
from gcalign.northfind.geometry import Values, _ideal_readings, table_dcm
from gcalign.northfind.simulate import NorthfindSetup

__all__ = [
    "azimuth_std_level",
    "naive_error",
    "none_error",
    "predict_azimuth_std",
    "predicted_error",
]


def _tilt_error(
    azimuth: Values, tilt: Values, tilt_direction: Values, tan_lat: Values
) -> np.ndarray:
    psi = np.asarray(azimuth, float)
    eps = np.asarray(tilt, float)
    zeta = np.asarray(tilt_direction, float)
    beta = psi - zeta
    se, ce = np.sin(eps), np.cos(eps)
    y = np.sin(psi) - se * np.sin(beta) * (se * np.cos(zeta) + tan_lat * ce)
    x = ce * np.cos(psi) - tan_lat * se * np.cos(beta)
    return wrap_pi(np.arctan2(y, x) - psi)


def none_error(
    azimuth: Values, tilt: Values, tilt_direction: Values, lat: Values
) -> np.ndarray:
    """Exact azimuth error of the uncompensated (``none``) method on a tilted table.

    Parameters
    ----------
    azimuth : (...) float, rad
        True azimuth ψ.
    tilt : (...) float, rad
        Tilt ε.
    tilt_direction : (...) float, rad
        True azimuth ζ of descent (add ψ to a table-relative direction first).
    lat : (...) float, rad
        Latitude L.

    Returns
    -------
    (...) float, rad, wrapped to [-π, π)
        ``atan2(sin ψ - sin ε sin(ψ-ζ)(sin ε cos ζ + tan L cos ε),
        cos ε cos ψ - tan L sin ε cos(ψ-ζ)) - ψ``; first order
        ``atan2(tan L sin ε sin ζ, 1 - tan L sin ε cos ζ)``, at most
        ``asin(tan L sin ε)`` (≈ 50.3′ per degree of tilt at L = 40°). Independent of the
        gyro bias and scale factor.

    Notes
    -----
    Seed eq. 8 applied to a tilted table, ``ψ = atan2(b, a)``; with ``β = ψ - ζ``::

        ψ_none = atan2(sin ψ - sin ε sin β (sin ε cos ζ + tan L cos ε),
                       cos ε cos ψ - tan L sin ε cos β)

    (from ``x_t = [tan ε sin ε cos β sin β, cos ε + tan ε sin ε cos² β, sin ε sin β]/k``,
    ``y_t = [1, 0, -tan ε cos β]/k`` in the basis ``h, h×U, U``, ``k = √(1 + tan²ε cos²β)``).
    To first order in ε the error is ``atan2(tan L sin ε sin ζ, 1 - tan L sin ε cos ζ)``: the
    vertical rate leaks as a fixed horizontal vector ``Ω sin L sin ε`` toward ζ; at most
    ``asin(tan L sin ε)`` — 50.3′ per degree of tilt at L = 40°, 8.4° at 10° (seed §1, §3.1).
    The second-order part (the ``naive`` error) brings the maximum at 10° to 8.55° (tilt along
    a table axis) … 8.99° (diagonal). With ``tan L → 0`` the formula gives the ``naive``
    error.

    >>> e = none_error(0.0, np.radians(1.0), np.radians(90.0), np.radians(40.0))
    >>> round(float(np.degrees(e) * 60.0), 2)   # arc-minutes
    50.34
    """
    return _tilt_error(azimuth, tilt, tilt_direction, np.tan(lat))


def naive_error(azimuth: Values, tilt: Values, tilt_direction: Values) -> np.ndarray:
    """Azimuth error of the ``naive`` method (seed eq. 11) with an exact tilt estimate.

    Same parameters as :func:`none_error` (no latitude dependence). Returns (...) rad:
    the :func:`none_error` formula with ``tan L = 0``,
    ``atan2(sin ψ - sin²ε sin(ψ-ζ) cos ζ, cos ε cos ψ) - ψ``; for a tilt along a table
    axis its maximum over ψ is ``asin(tan²(ε/2)) ≈ ε²/4``.
    """
    return _tilt_error(azimuth, tilt, tilt_direction, 0.0)


def predicted_error(setup: NorthfindSetup, methods: Sequence[str] = METHODS) -> np.ndarray:
    """Deterministic tilt-induced error of each method for an error-free instrument.

    Returns
    -------
    (P, M) float, rad
        :func:`none_error` for ``none``, :func:`naive_error` for ``naive``, 0 for
        ``coordinate`` and ``vector``; NaN for ``vector_literal``.
    """
    args = (setup.azimuths, setup.tilt, setup.tilt_direction_north)
    out = []
    for m in methods:
        if m == "none":
            out.append(none_error(*args, setup.lat))
        elif m == "naive":
            out.append(naive_error(*args))
        elif m in ("coordinate", "vector"):
            out.append(np.zeros(setup.azimuths.size))
        else:
            out.append(np.full(setup.azimuths.size, np.nan))
    return np.stack(out)


def azimuth_std_level(
    gyro_arw: float, dwell_s: float, rate_hz: float, positions: int, lat: float
) -> float:
    """Azimuth standard deviation from gyro white noise, level table, equally spaced.

    Parameters
    ----------
    gyro_arw : float, rad/√s
    dwell_s : float, s
    rate_hz : float, Hz
    positions : int
    lat : float, rad

    Returns
    -------
    float, rad
        ``σ_m √(2/n) / (Ω cos L)`` with ``σ_m = ARW √(rate/N)``, ``N = round(dwell·rate)``
        (≈ ARW/√dwell): ``Var(â) = Var(b̂) = 2σ_m²/n`` and
        ``δψ = (a δb - b δa)/(a² + b²)`` with ``a² + b² = (Ω cos L)²``.
    """
    n_samples = round(dwell_s * rate_hz)
    sigma_m = gyro_arw * np.sqrt(rate_hz / n_samples)
    return float(sigma_m * np.sqrt(2.0 / positions) / (earth.OMEGA_IE * np.cos(lat)))


def predict_azimuth_std(setup: NorthfindSetup, method: str = "coordinate") -> np.ndarray:
    """Linearised least-squares prediction of the azimuth standard deviation.

    The estimator ``ψ = F(a, b, ux, uy)`` is linearised (central differences) about the
    noise-free harmonics of the setup, and the covariances of the fitted coefficients are
    propagated: gyro noise ``σ_m² P`` with ``P = (AᵀA)⁻¹[1:, 1:]``; accelerometer noise
    ``Var(ux) = Var(uy) = σ_am² (P_aa + P_bb)/(4g²)``, uncorrelated; indexing errors
    ``δ(coef) = A⁺ diag(∂y/∂θ_i) δ`` for all three sensors. Constant biases do not enter
    (absorbed by R). Level and gyro noise only, this is :func:`azimuth_std_level`.

    Parameters
    ----------
    setup : NorthfindSetup
    method : str
        One of :data:`METHODS`.

    Returns
    -------
    (M,) float, rad

    Notes
    -----
    White noise of density σ_w (ARW, rad/√s) sampled at ``f`` Hz has per-sample standard
    deviation ``σ_w √f`` and dwell mean ``σ_m = σ_w √(f/N) ≈ σ_w/√T_dwell`` over N samples.
    Least squares gives ``Cov(R, a, b) = σ_m² (AᵀA)⁻¹``, ``= σ_m² diag(1/n, 2/n, 2/n)`` for
    equally spaced positions. Level: ``δψ = (a δb - b δa)/(a² + b²)``, so
    ``σ_ψ = σ_m √(2/n) / (Ω cos L)``. In general the estimator is linearised about the
    noise-free harmonics and the coefficient covariances of gyro noise, accelerometer noise
    and indexing errors are propagated (indexing error δ_i perturbs each reading by
    ``δ_i ∂y/∂θ``; level, it gives ``σ_ψ = σ_δ √(3/(2n))`` for n = 3 or n ≥ 5).
    """
    theta = setup.theta
    A = _design(theta)
    Ainv = np.linalg.pinv(A)  # (3, n)
    P = Ainv @ Ainv.T
    g = setup.gravity
    C_nt = table_dcm(setup.azimuths, setup.tilt, setup.tilt_direction_north)
    ideal = _ideal_readings(C_nt, theta[None, None, :], setup.lat, g)[:, 0]  # (M, n, 3)
    ideal[..., 0] *= 1.0 + setup.gyro_scale
    coef = np.einsum("kn,mns->msk", Ainv, ideal)  # (M, 3 sensors, [R, a, b])
    ux, uy = tilt_from_accel(coef[:, 1:], g)
    x0 = np.stack([coef[:, 0, 1], coef[:, 0, 2], ux, uy], -1)  # (M, 4)
    scale = np.array([earth.OMEGA_IE, earth.OMEGA_IE, 1.0, 1.0])
    J = np.empty_like(x0)
    for j in range(4):
        h = 1e-6 * scale[j]
        xp, xm = x0.copy(), x0.copy()
        xp[:, j] += h
        xm[:, j] -= h
        fp = azimuth_from_harmonics(xp[:, 0], xp[:, 1], xp[:, 2], xp[:, 3], setup.lat, method)
        fm = azimuth_from_harmonics(xm[:, 0], xm[:, 1], xm[:, 2], xm[:, 3], setup.lat, method)
        J[:, j] = wrap_pi(fp - fm) / (2.0 * h)
    n_s = setup.n_samples
    sig_g = setup.gyro_arw * np.sqrt(setup.rate_hz / n_s)
    sig_a = setup.accel_vrw * np.sqrt(setup.rate_hz / n_s)
    Jab = J[:, :2]
    var = sig_g**2 * np.einsum("mi,ij,mj->m", Jab, P[1:, 1:], Jab)
    var += sig_a**2 * (P[1, 1] + P[2, 2]) / (4.0 * g * g) * (J[:, 2] ** 2 + J[:, 3] ** 2)
    if setup.index_error > 0.0:
        c, s = np.cos(theta), np.sin(theta)
        dy = -coef[:, :, 1, None] * s + coef[:, :, 2, None] * c  # ∂y/∂θ at θ_i, (M, 3, n)
        Ga = Ainv[1] * dy[:, 0]  # δa per unit δ_i, (M, n)
        Gb = Ainv[2] * dy[:, 0]
        Gux = (Ainv[1] * dy[:, 1] - Ainv[2] * dy[:, 2]) / (2.0 * g)
        Guy = (Ainv[2] * dy[:, 1] + Ainv[1] * dy[:, 2]) / (2.0 * g)
        row = J[:, 0, None] * Ga + J[:, 1, None] * Gb + J[:, 2, None] * Gux + J[:, 3, None] * Guy
        var += setup.index_error**2 * np.sum(row * row, -1)
    return np.sqrt(var)
