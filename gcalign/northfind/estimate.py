"""North-finding estimators (seed 001 §2): harmonics, tilt, and azimuth by each method.

From the dwell means of the gyro and the two accelerometers: :func:`fit_harmonics` (least
squares of ``y_i = R + a cos θ_i + b sin θ_i``, seed eqs. 4–7), :func:`tilt_from_accel`
(the up vector in table axes, seed eq. 9), :func:`azimuth_from_harmonics` (the methods of
:data:`METHODS`: ``coordinate`` seed eqs. 1–3, ``vector`` eq. 10 corrected, ``naive``
eq. 11, ``none`` eq. 8; and ``vector_literal``), and :func:`estimate_northfind`, which
chains them over arrays of any leading shape.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gcalign.choices import AZIMUTH_METHODS, AZIMUTH_METHODS_ALL
from gcalign.nav import earth
from gcalign.nav.rotation import euler_to_dcm, wrap_pi
from gcalign.northfind.geometry import Values, _uz, _wrap_2pi

__all__ = [
    "METHODS",
    "NorthfindEstimate",
    "azimuth_from_harmonics",
    "estimate_northfind",
    "fit_harmonics",
    "tilt_from_accel",
]

#: Azimuth methods, in the order of the result arrays.
METHODS: tuple[str, ...] = AZIMUTH_METHODS
_ALL_METHODS = AZIMUTH_METHODS_ALL


def _design(theta: Values) -> np.ndarray:
    theta = np.asarray(theta, float)
    return np.stack([np.ones_like(theta), np.cos(theta), np.sin(theta)], -1)


def fit_harmonics(y: Values, theta: Values) -> tuple[np.ndarray, np.ndarray]:
    """Least squares of ``y_i = R + a cos θ_i + b sin θ_i`` (seed eqs. 4–7).

    Parameters
    ----------
    y : (..., n) float
        Dwell means of one sensor (any unit).
    theta : (n,) float, rad
        Table angles used by the estimator (nominal), n >= 3, not all equal modulo π in a
        way that makes the design rank-deficient.

    Returns
    -------
    coef : (..., 3) float
        ``[R, a, b]`` in the unit of `y`: ``X̂ = (AᵀA)⁻¹ Aᵀ Y`` computed with the
        pseudo-inverse (SVD, as ``lstsq``), valid for any θ_i; for equally spaced θ_i it
        reduces to ``R = mean(y)``, ``a = (2/n) Σ y cos θ``, ``b = (2/n) Σ y sin θ``.
    residual : (..., n) float
        ``y - A X̂``.

    >>> from gcalign.northfind.geometry import position_angles
    >>> th = position_angles(8)
    >>> fit_harmonics(1.0 + 2.0 * np.cos(th) - 3.0 * np.sin(th), th)[0].round(12).tolist()
    [1.0, 2.0, -3.0]
    """
    A = _design(theta)
    if A.shape[0] < 3 or np.linalg.matrix_rank(A) < 3:
        raise ValueError(
            f"theta must give a rank-3 design (>= 3 distinct angles), got {np.shape(theta)}"
        )
    y = np.asarray(y, float)
    coef = y @ np.linalg.pinv(A).T
    return coef, y - coef @ A.T


def tilt_from_accel(accel_coef: Values, g: float) -> tuple[np.ndarray, np.ndarray]:
    """Up vector in table axes from the accelerometer harmonics (seed eq. 9).

    Parameters
    ----------
    accel_coef : (..., 2, 3) float, m/s²
        ``[R, a, b]`` of the x and y accelerometers.
    g : float, m/s²
        Gravity magnitude.

    Returns
    -------
    ux, uy : (...) float
        ``x_t·U = (a_x - b_y)/(2g)`` and ``y_t·U = (b_x + a_y)/(2g)`` (both
        accelerometers averaged); the tilt is ``asin √(ux² + uy²)``.

    Notes
    -----
    Seed eq. 9: ``g u_x = (a_x - b_y)/2`` and ``g u_y = (b_x + a_y)/2`` (both
    accelerometers, averaged); ``sin ε = √(u_x² + u_y²)``; PSINS pitch and roll of the table
    ``p = asin u_y``, ``r = atan2(-u_x, u_z)``; tilt direction relative to the reference
    axis ``ζ - ψ = atan2(-u_x, -u_y u_z)`` (the last three in :func:`estimate_northfind`).
    """
    c = np.asarray(accel_coef, float)
    ax, bx, ay, by = c[..., 0, 1], c[..., 0, 2], c[..., 1, 1], c[..., 1, 2]
    return (ax - by) / (2.0 * g), (bx + ay) / (2.0 * g)


def _azimuth_coordinate(
    a: np.ndarray, b: np.ndarray, ux: np.ndarray, uy: np.ndarray, w_up: Values
) -> np.ndarray:
    """Seed eqs. (1)–(3): level-frame earth rate by the Euler-matrix route."""
    uz = _uz(ux, uy)
    p = np.arcsin(np.clip(uy, -1.0, 1.0))
    r = np.arctan2(-ux, uz)
    M = euler_to_dcm(np.stack([p, r, np.zeros_like(p)], -1))  # Rx(p) Ry(r): ω^l = M ω^t
    wx, wy = -b, a  # ω^t_x = -b, ω^t_y = a (gyro harmonics)
    # third row: Ω sin L = M20 ω^t_x + M21 ω^t_y + M22 ω^t_z  ->  unmeasured ω^t_z
    wz = (w_up - M[..., 2, 0] * wx - M[..., 2, 1] * wy) / M[..., 2, 2]
    wlx = M[..., 0, 0] * wx + M[..., 0, 1] * wy + M[..., 0, 2] * wz
    wly = M[..., 1, 0] * wx + M[..., 1, 1] * wy + M[..., 1, 2] * wz
    return np.arctan2(-wlx, wly)  # ω^l = Ω[-cos L sin ψ, cos L cos ψ, sin L]


def _azimuth_vector(
    a: np.ndarray, b: np.ndarray, ux: np.ndarray, uy: np.ndarray, w_up: Values
) -> np.ndarray:
    """Seed eq. (10), corrected: projections of the horizontal earth rate."""
    uz = _uz(ux, uy)
    a1 = a - w_up * uy  # a' = ω_h·y_t   (vertical leakage removed)
    b1 = b + w_up * ux  # b' = -ω_h·x_t
    cos_ta = np.sqrt(1.0 - uy * uy)  # length of the horizontal projection of y_t
    at = a1 / cos_ta  # ã = Ω cos L cos ψ
    bt = (b1 * cos_ta - at * ux * uy) / uz  # Ω cos L sin ψ (x_t,h is skewed by -ux uy)
    return np.arctan2(bt, at)


def _azimuth_vector_literal(
    a: np.ndarray, b: np.ndarray, ux: np.ndarray, uy: np.ndarray, w_up: Values
) -> np.ndarray:
    """Seed eq. (10) as printed: b'/cos θ_b over a'/cos θ_a (exact only if ux·uy = 0)."""
    a1, b1 = a - w_up * uy, b + w_up * ux
    return np.arctan2(b1 / np.sqrt(1.0 - ux * ux), a1 / np.sqrt(1.0 - uy * uy))


def azimuth_from_harmonics(
    a: Values,
    b: Values,
    ux: Values,
    uy: Values,
    lat: Values,
    method: str = "coordinate",
) -> np.ndarray:
    """Azimuth of the reference axis from gyro harmonics and the estimated tilt.

    Parameters
    ----------
    a, b : (...) float, rad/s
        Gyro harmonics (cos θ and sin θ coefficients of seed eq. 4).
    ux, uy : (...) float
        Up vector in table axes, from :func:`tilt_from_accel`. Ignored by ``none``.
    lat : float or (...) float, rad
        Latitude (the vertical earth rate Ω sin L is known, not measured).
    method : {"coordinate", "vector", "naive", "none", "vector_literal"}
        ``coordinate`` seed eq. (3): ``ψ = atan2(b cos p + a sin p sin r - Ω sin L sin r,
        cos r (a - Ω sin L sin p))`` via the matrix ``Rx(p) Ry(r)``.
        ``vector`` seed eq. (10) corrected: ``ψ = atan2((b' cos θ_a - ã ux uy)/uz, ã)``,
        ``a' = a - Ω sin L uy``, ``b' = b + Ω sin L ux``, ``cos θ_a = √(1-uy²)``,
        ``ã = a'/cos θ_a``. ``naive`` seed eq. (11): ``atan2(b', a')``.
        ``none``: ``atan2(b, a)``. ``vector_literal``: eq. (10) as printed, kept only to
        show its O(ε²) error for tilt off the table axes.

    Returns
    -------
    (...) float, rad, [0, 2π)
        Azimuth clockwise from true north.

    Notes
    -----
    ``coordinate`` — seed eqs. (1)–(3). With the level frame l (``ψ`` only),
    ``ω^l = Ω [-cos L sin ψ, cos L cos ψ, sin L]`` and ``ω^l = M ω^t``, ``M = Rx(p) Ry(r)``.
    The gyro gives ``ω^t_x = -b`` and ``ω^t_y = a``; the unmeasured ``ω^t_z`` follows from the
    third row and the *known* vertical rate ``ω^l_z = Ω sin L``; rows 1–2 then give
    ``ψ = atan2(-ω^l_x, ω^l_y)``. In closed form (identical to seed eq. 3 with θ→p, γ→r,
    Ω_x = n b/2, Ω_y = n a/2)::

        ψ = atan2(b cos p + a sin p sin r - Ω sin L sin r,  cos r (a - Ω sin L sin p)).

    ``vector`` — seed eq. (10), corrected. Split ``ω_ie = ω_h + Ω sin L U`` (ω_h horizontal,
    north, magnitude Ω cos L). Removing the vertical part from the harmonics gives the
    projections of ω_h on the tilted axes: ``a' = a - Ω sin L u_y = ω_h·y_t`` and
    ``b' = b + Ω sin L u_x = -ω_h·x_t``. The horizontal projection of ``y_t`` has length
    ``cos θ_a = √(1 - u_y²)`` and azimuth ψ, so ``ã = a'/cos θ_a = Ω cos L cos ψ`` exactly.
    The horizontal projection of ``x_t`` is *not* perpendicular to it: in the horizontal basis
    ``e1`` (along the projection of ``y_t``), ``e2`` (to its right),
    ``x_t,h = (-u_x u_y e1 + u_z e2)/cos θ_a``, hence ``b' = Ω cos L (u_z sin ψ + u_x u_y cos ψ)
    / cos θ_a`` and::

        ψ = atan2((b' cos θ_a - ã u_x u_y) / u_z,  ã).

    The seed prints ``atan2(b'/cos θ_b, a'/cos θ_a)`` with ``cos θ_b = √(1 - u_x²)``; that is
    the formula above when ``u_x u_y = 0`` (tilt along a table axis, as in the seed's
    simulation) but errs by O(ε²) otherwise (0.88° at 10° of tilt toward a table diagonal).
    Method ``vector_literal`` (not in :data:`METHODS`) keeps the printed form to show it.
    After derivation ``coordinate`` and ``vector`` are the *same function* of (a, b, u_x, u_y)
    (expand ``sin p = u_y``, ``cos p sin r = -u_x``, ``cos p cos r = u_z``); they are computed
    along the two routes (Euler-matrix elimination vs. vector projection) as a cross-check.

    ``naive`` — seed eq. (11): ``ψ = atan2(b', a')``: leakage removed but no projection to the
    horizontal; its error is the angle measured in the tilted plane instead of the horizontal
    one, ``asin(tan²(ε/2)) ≈ ε²/4`` at most for a tilt along a table axis (4.4 % of ε at 10°).

    ``none`` — ``ψ = atan2(b, a)`` as if level (seed eq. 8 on tilted data); the closed form
    of its error is :func:`~gcalign.northfind.theory.none_error`.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    ux, uy = np.asarray(ux, float), np.asarray(uy, float)
    w_up = earth.OMEGA_IE * np.sin(lat)
    if method == "coordinate":
        psi = _azimuth_coordinate(a, b, ux, uy, w_up)
    elif method == "vector":
        psi = _azimuth_vector(a, b, ux, uy, w_up)
    elif method == "naive":
        psi = np.arctan2(b + w_up * ux, a - w_up * uy)
    elif method == "none":
        psi = np.arctan2(b, a)
        psi = np.broadcast_to(psi, np.broadcast_shapes(psi.shape, ux.shape, uy.shape))
    elif method == "vector_literal":
        psi = _azimuth_vector_literal(a, b, ux, uy, w_up)
    else:
        raise ValueError(f"method must be one of {_ALL_METHODS}, got {method!r}")
    return _wrap_2pi(psi)


@dataclass(frozen=True, eq=False)
class NorthfindEstimate:
    """Estimates from one set of dwell means (leading shape ``S``, e.g. (M, R)).

    Attributes
    ----------
    methods : tuple of str. Order of the first axis of `azimuth`.
    azimuth : (P, *S) float, rad, [0, 2π). Azimuth per method.
    tilt : (*S) float, rad. ``asin √(ux² + uy²)``.
    tilt_direction : (*S) float, rad, [0, 2π). True azimuth of descent, using the
        ``coordinate`` azimuth: ``ψ̂ + atan2(-ux, -uy uz)`` (meaningless, = ψ̂, at zero tilt).
    pitch, roll : (*S) float, rad. PSINS Euler angles of the table.
    ux, uy : (*S) float. Up vector in table axes.
    gyro_coef : (*S, 3) float, rad/s. ``[R, a, b]`` of the gyro.
    accel_coef : (*S, 2, 3) float, m/s². ``[R, a, b]`` of the x and y accelerometers.
    gyro_residual : (*S, n) float, rad/s. Least-squares residuals of the gyro.
    accel_residual : (*S, n, 2) float, m/s². Residuals of the accelerometers.
    azimuth_error : (P, *S) float, rad, or None. ``azimuth - truth`` wrapped to [-π, π),
        when the truth was given.
    """

    methods: tuple[str, ...]
    azimuth: np.ndarray
    tilt: np.ndarray
    tilt_direction: np.ndarray
    pitch: np.ndarray
    roll: np.ndarray
    ux: np.ndarray
    uy: np.ndarray
    gyro_coef: np.ndarray
    accel_coef: np.ndarray
    gyro_residual: np.ndarray
    accel_residual: np.ndarray
    azimuth_error: np.ndarray | None = None


def estimate_northfind(
    gyro: np.ndarray,
    accel: np.ndarray,
    theta: np.ndarray,
    lat: float,
    g: float,
    methods: Sequence[str] = METHODS,
    *,
    azimuth_true: Values | None = None,
) -> NorthfindEstimate:
    """Harmonic fits, tilt and azimuth by each method, from the dwell means of one turn.

    The array route of north-finding: a recorded north-finder gives these means directly
    (:func:`gcalign.northfind.run_northfind` simulates them first).

    Parameters
    ----------
    gyro : (..., n) float, rad/s
        Gyro dwell means (leading shape ``S``, e.g. (M, R) azimuths × repeats).
    accel : (..., n, 2) float, m/s²
        Dwell means of the [x, y] accelerometers, the same leading shape.
    theta : (n,) float, rad
        Nominal table angles, n >= 3.
    lat : float, rad
        Latitude, ``|lat| < π/2``.
    g : float, m/s²
        Gravity magnitude used to scale the accelerometer harmonics (> 0).
    methods : sequence of str
        Subset of :data:`METHODS` (and ``"vector_literal"``).
    azimuth_true : float or array broadcastable to ``S``, rad, optional
        The truth; gives :attr:`NorthfindEstimate.azimuth_error`.

    Returns
    -------
    NorthfindEstimate

    Raises
    ------
    ValueError
        An input of the wrong shape, not finite, or out of range (names the argument).

    >>> from gcalign.northfind.geometry import position_angles
    >>> th, lat, g = position_angles(4), np.radians(40.0), 9.8
    >>> w = 7.2921151467e-5 * np.cos(lat)  # level table, reference axis at azimuth 30°
    >>> gyro = w * np.cos(th - np.radians(30.0))  # a = w cos ψ, b = w sin ψ
    >>> est = estimate_northfind(gyro, np.zeros((4, 2)), th, lat, g, ["none"],
    ...                          azimuth_true=np.radians(29.0))
    >>> np.degrees([est.azimuth[0], est.azimuth_error[0]]).round(9).tolist()
    [30.0, 1.0]
    """
    gyro, accel, theta = _check_means(gyro, accel, theta)
    if not (np.isfinite(lat) and abs(lat) < 0.5 * np.pi):
        raise ValueError(f"lat must satisfy |lat| < pi/2 rad (north is undefined at the "
                         f"poles), got {lat!r}")
    if not (np.isfinite(g) and g > 0.0):
        raise ValueError(f"g must be a finite gravity > 0 m/s², got {g!r}")
    methods = tuple(methods)
    for name in methods:
        if name not in _ALL_METHODS:
            raise ValueError(f"methods must be drawn from {_ALL_METHODS}, got {name!r}")
    gyro_coef, gyro_res = fit_harmonics(gyro, theta)
    acc = np.moveaxis(np.asarray(accel, float), -1, -2)  # (..., 2, n)
    accel_coef, accel_res = fit_harmonics(acc, theta)
    ux, uy = tilt_from_accel(accel_coef, g)
    uz = _uz(ux, uy)
    a, b = gyro_coef[..., 1], gyro_coef[..., 2]
    az = np.stack([azimuth_from_harmonics(a, b, ux, uy, lat, m) for m in methods])
    psi_c = (
        az[methods.index("coordinate")]
        if "coordinate" in methods
        else azimuth_from_harmonics(a, b, ux, uy, lat, "coordinate")
    )
    error = None
    if azimuth_true is not None:
        truth = np.asarray(azimuth_true, dtype=float)
        if not np.all(np.isfinite(truth)):
            raise ValueError(f"azimuth_true must be finite, got {truth.tolist()}")
        try:
            error = wrap_pi(az - np.broadcast_to(truth, gyro.shape[:-1]))
        except ValueError:
            raise ValueError(f"azimuth_true must broadcast to the leading shape "
                             f"{gyro.shape[:-1]} of gyro, got {truth.shape}") from None
    return NorthfindEstimate(
        methods=methods,
        azimuth=az,
        tilt=np.arctan2(np.hypot(ux, uy), uz),
        tilt_direction=_wrap_2pi(psi_c + np.arctan2(-ux, -uy * uz)),
        pitch=np.arcsin(np.clip(uy, -1.0, 1.0)),
        roll=np.arctan2(-ux, uz),
        ux=ux,
        uy=uy,
        gyro_coef=gyro_coef,
        accel_coef=accel_coef,
        gyro_residual=gyro_res,
        accel_residual=np.moveaxis(accel_res, -2, -1),
        azimuth_error=error,
    )


def _check_means(
    gyro: np.ndarray, accel: np.ndarray, theta: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The dwell means and angles as float arrays of matching shapes, all finite."""
    out = []
    for name, value in (("gyro", gyro), ("accel", accel), ("theta", theta)):
        a = np.asarray(value, dtype=float)
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite, got a non-finite entry")
        out.append(a)
    gyro, accel, theta = out
    if theta.ndim != 1 or theta.size < 3:
        raise ValueError(f"theta must have shape (n,) with n >= 3 positions, got {theta.shape}")
    n = theta.size
    if gyro.shape[-1:] != (n,):
        raise ValueError(f"gyro must have shape (..., {n}) (one mean per position), "
                         f"got {gyro.shape}")
    if accel.shape != (*gyro.shape, 2):
        raise ValueError(f"accel must have shape {(*gyro.shape, 2)} (gyro's, then [x, y]), "
                         f"got {accel.shape}")
    return gyro, accel, theta
