"""Gyrocompass loop gains by pole placement (seed 000 §2, eqs. 5-9).

A loop is tuned by its damped period ``T_d`` (s) and damping ratio ``ξ``::

    ω_n = 2π / (T_d √(1 − ξ²)),   σ = ξ ω_n,   ω_d = ω_n √(1 − ξ²),   ω_s² = g / R

(``ω_s`` is the Schuler frequency). The gains make the closed-loop characteristic
polynomial of the loop equal to a designed one.

Level loop (3rd order, seed eqs. 5-6), poles ``{−σ, −σ ± jω_d}``::

    s³ + K1 s² + (1 + K2) ω_s² s + g K3  =  (s + σ)((s + σ)² + ω_d²)
    K1 = 3σ,   K2 = (3σ² + ω_d²)/ω_s² − 1,   K3 = (σ³ + σ ω_d²)/g

Azimuth compass loop (4th order, seed eq. 7)::

    s⁴ + (K_U1 + K_U4) s³ + [ω_s² (1 + K_U2) + K_U1 K_U4] s² + ω_s² (1 + K_U2) K_U4 s + g K_U3

with two pole sets:

- ``"double-oscillator"`` (seed method a, eq. 8): ``(s² + 2σs + ω_n²)²``;
  ``K_U1 = K_U4 = 2σ``, ``K_U2 = 2ω_n²/ω_s² − 1``, ``K_U3 = ω_n⁴/g``.
- ``"oscillator-overdamped"`` (seed method b, eq. 9): ``(s + ω_n)² (s² + 2σs + ω_n²)``,
  solved exactly through a cubic in ``K_U4`` (see :func:`azimuth_gains`). The seed's
  printed closed form for b (``K_U1 = 2ω_n, K_U4 = 2σ``, ``K_U2``, ``K_U3`` as in a)
  matches three of the four coefficients but gives ``4σω_n²`` instead of
  ``2ω_n²(ω_n + σ)`` for the ``s¹`` coefficient, i.e. it is short by ``2ω_n³(1 − ξ)``;
  its poles are not the designed ones.

The aliases ``"a"`` and ``"b"`` name the two methods as the seed does.

>>> g, r = 9.8, 6.4e6
>>> gains = level_gains(20.0, 0.707, g, r)
>>> designed = np.poly(designed_poles_level(20.0, 0.707)).real
>>> bool(np.allclose(closed_loop_level(gains, g, r), designed, rtol=1e-12, atol=0.0))
True
>>> az = azimuth_gains(100.0, 0.707, g, r, "oscillator-overdamped")
>>> bool(az.k1 > 0 and az.k2 > -1 and az.k3 > 0 and az.k4 > 0)
True
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

AZIMUTH_METHODS = ("double-oscillator", "oscillator-overdamped")
"""Allowed values of ``method`` in :func:`azimuth_gains` (aliases: ``"a"``, ``"b"``)."""

_METHOD_ALIASES = {"a": "double-oscillator", "b": "oscillator-overdamped"}


@dataclass(frozen=True)
class LevelGains:
    """Gains of a 3rd-order level loop (seed eqs. 1-2, 5-6).

    Attributes
    ----------
    k1 : float, 1/s. Velocity damping ``K1`` (``v̇ = f − K1 δv``).
    k2 : float, dimensionless. Proportional rate gain ``K2`` (``ω_c = δv (1 + K2)/R + …``).
    k3 : float, 1/(m s). Integral rate gain ``K3`` (``… + K3 ∫δv dt``).
    """

    k1: float
    k2: float
    k3: float


@dataclass(frozen=True)
class AzimuthGains:
    """Gains of the 4th-order compass (north + azimuth) loop (seed eqs. 3-4, 7-9).

    Attributes
    ----------
    k1 : float, 1/s. Velocity damping ``K_U1``.
    k2 : float, dimensionless. East-rate gain ``K_U2`` (``ω_cE = −δv_N (1 + K_U2)/R_M``).
    k3 : float, 1/(m s²). Azimuth gain ``K_U3`` (``ω_cU = K_U3/(Ω (s + K_U4)) δv_N``).
    k4 : float, 1/s. Corner frequency ``K_U4`` of the azimuth low-pass filter.
    """

    k1: float
    k2: float
    k3: float
    k4: float


def _check_number(name: str, value: object, allowed: str,
                  ok: Callable[[float], bool]) -> float:
    """Return float(value) or raise ValueError naming the field, the value and the range."""
    try:
        x = float(value)  # type: ignore[arg-type]  # anything float() takes
    except (TypeError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and ok(x)):
        raise ValueError(f"{name} must be {allowed}, got {value!r}")
    return x


def _check_period_damping(t_d: float, xi: float) -> tuple[float, float]:
    t_d = _check_number("t_d (damped period, s)", t_d, "a finite number > 0", lambda x: x > 0)
    xi = _check_number("xi (damping ratio)", xi, "a number with 0 < xi < 1", lambda x: 0 < x < 1)
    return t_d, xi


def _check_earth(g: float, r: float) -> tuple[float, float]:
    g = _check_number("g (gravity, m/s²)", g, "a finite number > 0", lambda x: x > 0)
    r = _check_number("r (earth radius, m)", r, "a finite number > 0", lambda x: x > 0)
    return g, r


def _check_method(method: str) -> str:
    if isinstance(method, str):
        m = _METHOD_ALIASES.get(method, method)
        if m in AZIMUTH_METHODS:
            return m
    allowed = ", ".join(repr(m) for m in AZIMUTH_METHODS + tuple(_METHOD_ALIASES))
    raise ValueError(f"method must be one of {allowed}, got {method!r}")


def loop_frequencies(t_d: float, xi: float) -> tuple[float, float, float]:
    """Natural frequency, decay rate and damped frequency of a loop.

    Parameters
    ----------
    t_d : float, s. Damped oscillation period ``T_d`` (> 0).
    xi : float. Damping ratio ``ξ`` (0 < ξ < 1).

    Returns
    -------
    omega_n, sigma, omega_d : float, rad/s.
        ``ω_n = 2π/(T_d √(1−ξ²))``, ``σ = ξ ω_n``, ``ω_d = ω_n √(1−ξ²) = 2π/T_d``.

    Raises
    ------
    ValueError
        If ``t_d`` or ``xi`` is out of range.
    """
    t_d, xi = _check_period_damping(t_d, xi)
    root = math.sqrt(1.0 - xi * xi)
    omega_n = 2.0 * math.pi / (t_d * root)
    return omega_n, xi * omega_n, omega_n * root


def schuler_rate_sq(g: float, r: float) -> float:
    """Squared Schuler frequency ``ω_s² = g/R`` (rad²/s²) from gravity g (m/s²) and radius R (m)."""
    g, r = _check_earth(g, r)
    return g / r


def level_gains(t_d: float, xi: float, g: float, r: float) -> LevelGains:
    """Level-loop gains placing the poles at ``{−σ, −σ ± jω_d}`` (seed eqs. 5-6).

    Parameters
    ----------
    t_d : float, s. Damped period ``T_xy`` of the level loop (> 0).
    xi : float. Damping ratio (0 < ξ < 1).
    g : float, m/s². Gravity magnitude (> 0).
    r : float, m. Earth radius used by the loop, ``R_N`` (east channel) or ``R_M`` (north).

    Returns
    -------
    LevelGains
        ``K1 = 3σ``, ``K2 = (3σ² + ω_d²)/ω_s² − 1``, ``K3 = (σ³ + σω_d²)/g``.

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range.
    """
    _, sigma, omega_d = loop_frequencies(t_d, xi)
    ws2 = schuler_rate_sq(g, r)
    g = float(g)
    # (s + σ)(s + σ − jω_d)(s + σ + jω_d) = s³ + 3σ s² + (3σ² + ω_d²) s + σ³ + σ ω_d²  (eq. 5)
    # matched with s³ + K1 s² + (1 + K2) ω_s² s + g K3  (eq. 6)
    return LevelGains(
        k1=3.0 * sigma,
        k2=(3.0 * sigma**2 + omega_d**2) / ws2 - 1.0,
        k3=(sigma**3 + sigma * omega_d**2) / g,
    )


def _overdamped_k4_ratio(xi: float) -> float:
    """Unique real root x = K_U4/ω_n of x³ − 2(1+ξ)x² + (2+4ξ)x − 2(1+ξ) = 0 (method b)."""
    a = 2.0 * (1.0 + xi)
    b = 2.0 + 4.0 * xi
    coeffs = np.array([1.0, -a, b, -a])
    roots = np.roots(coeffs)
    # p'(x) > 0 everywhere (see azimuth_gains), so exactly one root is real; np.roots returns
    # it with a round-off imaginary part at most: take the one closest to the real axis.
    x = float(roots[np.argmin(np.abs(roots.imag))].real)
    for _ in range(3):  # Newton polish on the strictly increasing cubic (p' >= 2/3 here)
        p = ((x - a) * x + b) * x - a
        dp = (3.0 * x - 2.0 * a) * x + b
        x -= p / dp
    if not 0.0 < x < a:  # proven in azimuth_gains; guard against a broken root finder
        raise ArithmeticError(f"method b cubic gave K_U4/ω_n = {x!r}, outside (0, {a})")
    return x


def azimuth_gains(t_d: float, xi: float, g: float, r: float, method: str) -> AzimuthGains:
    """Compass-loop gains ``K_U1 … K_U4`` by pole placement (seed eqs. 7-9).

    Parameters
    ----------
    t_d : float, s. Damped period ``T_z`` of the azimuth loop (> 0).
    xi : float. Damping ratio (0 < ξ < 1).
    g : float, m/s². Gravity magnitude (> 0).
    r : float, m. Meridian radius ``R_M`` used by the north channel (> 0).
    method : {"double-oscillator", "oscillator-overdamped"} (aliases "a", "b").
        Designed pole set: ``(s² + 2σs + ω_n²)²`` or ``(s + ω_n)² (s² + 2σs + ω_n²)``.

    Returns
    -------
    AzimuthGains
        All gains positive and ``K_U2 > −1`` (for ``T_d`` shorter than the Schuler period
        ``K_U2`` is itself positive).

    Raises
    ------
    ValueError
        Naming the parameter, its value and what is allowed.

    Notes
    -----
    Write ``P = ω_s²(1 + K_U2)``. The closed loop of eq. 7 factors as
    ``s (s + K_U4)(s² + K_U1 s + P) + g K_U3``. Matching it with a designed polynomial
    ``s⁴ + a3 s³ + a2 s² + a1 s + a0`` gives four equations::

        K_U1 + K_U4 = a3,   P + K_U1 K_U4 = a2,   P K_U4 = a1,   g K_U3 = a0.

    Eliminating ``K_U1 = a3 − K_U4`` and ``P = a1/K_U4`` from the second equation gives the
    cubic in ``K_U4``::

        K_U4³ − a3 K_U4² + a2 K_U4 − a1 = 0,

    i.e. ``−K_U4`` is a non-zero root of ``designed(s) − a0``. Method a has
    ``designed(s) − a0 = s (s + 2σ)(s² + 2σs + 2ω_n²)``: the only real root gives
    ``K_U4 = K_U1 = 2σ``, ``P = 2ω_n²`` (the seed's closed form). Method b has
    ``a3 = 2ω_n(1 + ξ)``, ``a2 = 2ω_n²(1 + 2ξ)``, ``a1 = 2ω_n³(1 + ξ)``, ``a0 = ω_n⁴``;
    with ``x = K_U4/ω_n`` the cubic no longer depends on ``T_d``::

        p(x) = x³ − 2(1+ξ) x² + (2+4ξ) x − 2(1+ξ) = 0.

    Root rule: ``p'(x) = 3x² − 4(1+ξ)x + 2 + 4ξ`` has discriminant
    ``8(2ξ² − 2ξ − 1) < 0`` for 0 ≤ ξ ≤ 1, so ``p`` is strictly increasing and has exactly
    one real root; ``p(0) = −2(1+ξ) < 0`` and ``p(2(1+ξ)) = 2(1+ξ)(1+4ξ) > 0`` put it in
    ``(0, 2(1+ξ))``, hence ``K_U4 > 0``, ``K_U1 = ω_n(2(1+ξ) − x) > 0``,
    ``P = 2ω_n²(1+ξ)/x > 0`` (``K_U2 > −1``) and ``K_U3 = ω_n⁴/g > 0``. The admissible root
    is therefore unique and no tie-break is needed; it is found with ``numpy.roots`` (the
    real eigenvalue of the companion matrix) and polished by Newton steps. For ξ = 0.707,
    ``x ≈ 1.7788``, so ``K_U4 ≈ 1.78 ω_n`` and ``K_U1 ≈ 1.64 ω_n``.
    """
    method = _check_method(method)
    omega_n, sigma, _ = loop_frequencies(t_d, xi)
    ws2 = schuler_rate_sq(g, r)
    g = float(g)
    if method == "double-oscillator":
        # (s² + 2σs + ω_n²)² = s⁴ + 4σ s³ + (4σ² + 2ω_n²) s² + 4σω_n² s + ω_n⁴  (eq. 8)
        k4 = 2.0 * sigma
        k1 = 2.0 * sigma
        p = 2.0 * omega_n**2
    else:
        # (s + ω_n)²(s² + 2σs + ω_n²)  (eq. 9), solved through the cubic of the Notes
        x = _overdamped_k4_ratio(float(xi))
        k4 = omega_n * x
        k1 = omega_n * (2.0 * (1.0 + xi) - x)  # K_U1 = a3 − K_U4
        p = omega_n**2 * 2.0 * (1.0 + xi) / x  # P = a1 / K_U4
    return AzimuthGains(k1=k1, k2=p / ws2 - 1.0, k3=omega_n**4 / g, k4=k4)


def closed_loop_level(gains: LevelGains, g: float, r: float) -> NDArray[np.float64]:
    """Closed-loop characteristic polynomial of the level loop (seed eq. 6).

    Parameters
    ----------
    gains : LevelGains
    g : float, m/s². Gravity magnitude.
    r : float, m. Radius used by the loop.

    Returns
    -------
    (4,) float ndarray
        ``[1, K1, (1 + K2) ω_s², g K3]``, highest power first (``numpy.roots`` order).
    """
    ws2 = schuler_rate_sq(g, r)
    return np.array([1.0, gains.k1, (1.0 + gains.k2) * ws2, float(g) * gains.k3])


def closed_loop_azimuth(gains: AzimuthGains, g: float, r: float) -> NDArray[np.float64]:
    """Closed-loop characteristic polynomial of the compass loop (seed eq. 7).

    Parameters
    ----------
    gains : AzimuthGains
    g : float, m/s². Gravity magnitude.
    r : float, m. Meridian radius used by the loop.

    Returns
    -------
    (5,) float ndarray
        ``[1, K_U1 + K_U4, ω_s²(1 + K_U2) + K_U1 K_U4, ω_s²(1 + K_U2) K_U4, g K_U3]``,
        highest power first.
    """
    ws2 = schuler_rate_sq(g, r)
    p = ws2 * (1.0 + gains.k2)
    return np.array(
        [1.0, gains.k1 + gains.k4, p + gains.k1 * gains.k4, p * gains.k4, float(g) * gains.k3]
    )


def designed_poles_level(t_d: float, xi: float) -> NDArray[np.complex128]:
    """Designed level-loop poles ``[−σ, −σ + jω_d, −σ − jω_d]`` (1/s), shape (3,) complex."""
    _, sigma, omega_d = loop_frequencies(t_d, xi)
    return np.array([-sigma, complex(-sigma, omega_d), complex(-sigma, -omega_d)])


def designed_poles_azimuth(t_d: float, xi: float, method: str) -> NDArray[np.complex128]:
    """Designed compass-loop poles (1/s), shape (4,) complex, double poles listed twice.

    ``"double-oscillator"``: ``−σ ± jω_d`` twice; ``"oscillator-overdamped"``:
    ``−ω_n`` twice and ``−σ ± jω_d``.
    """
    method = _check_method(method)
    omega_n, sigma, omega_d = loop_frequencies(t_d, xi)
    pair = [complex(-sigma, omega_d), complex(-sigma, -omega_d)]
    if method == "double-oscillator":
        return np.array(pair + pair)
    return np.array([complex(-omega_n, 0.0)] * 2 + pair)


def heading_transient(t: ArrayLike, gains: AzimuthGains, g: float,
                      r: float) -> NDArray[np.float64] | float:
    """Heading error of the linear compass loop after an initial heading error, as a
    fraction of it (seed §6.1: "at the first T_z the heading error falls to 4-6 %").

    Parameters
    ----------
    t : float or (N,) array, s. Time since the compass loop started.
    gains : AzimuthGains
    g : float, m/s². Gravity magnitude.
    r : float, m. Meridian radius used by the loop.

    Returns
    -------
    float or (N,) ndarray
        ``φ_U(t)/φ_U(0)`` with the other loop states zero at t = 0.

    Notes
    -----
    Linearised static-base compass channel (seed eqs. 3-4; ENU, ``Ω = ω_ie cos L``)::

        δv̇_N = g φ_E − K_U1 δv_N,    φ̇_E = −(1 + K_U2) δv_N / R − Ω φ_U,
        φ̇_U = ω_cU,                  ω̇_cU = −K_U4 ω_cU + K_U3 δv_N / Ω.

    With ``φ_U(0) = ψ0`` and the rest zero, the Laplace transform gives
    ``δv_N Δ(s) = −g Ω ψ0 (s + K_U4)`` and::

        φ_U(s) / ψ0 = (Δ(s) − g K_U3) / (s Δ(s)) = (s³ + a3 s² + a2 s + a1) / Δ(s),

    ``Δ = s⁴ + a3 s³ + a2 s² + a1 s + a0`` the closed loop of eq. 7 (Ω cancels: the
    response depends only on the poles). Evaluated exactly as ``C exp(A t) B`` in the
    controllable canonical form of that transfer function (double poles need no special
    case). For ξ = 0.707 it is −0.99 % at t = T_z with method a and −0.19 % with method b;
    method a overshoots to −6.2 % at t ≈ 0.70 T_z.
    """
    from scipy.linalg import expm

    a = closed_loop_azimuth(gains, g, r)[1:]  # a3, a2, a1, a0
    A = np.zeros((4, 4))
    A[:3, 1:] = np.eye(3)
    A[3] = -a[::-1]  # z4' = −a0 z1 − a1 z2 − a2 z3 − a3 z4
    C = np.array([a[2], a[1], a[0], 1.0])  # N(s) = a1 + a2 s + a3 s² + s³
    ts = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.array([C @ expm(A * tk)[:, 3] for tk in ts])
    return out if np.ndim(t) else float(out[0])
