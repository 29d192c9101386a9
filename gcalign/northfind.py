r"""Multi-position strapdown gyro north-finding with analytic tilt compensation (seed 001).

A north-finder stands on an indexing turntable. The table turns its platform to ``n``
positions ``θ_i = (i-1)·2π/n`` about the table normal, dwells at each, and averages one
gyro (sensitive axis in the table plane) and two accelerometers (platform x and y). The
harmonics of the readings over one turn give the azimuth of the table's reference axis;
the accelerometer harmonics give the tilt of the table, which leaks the vertical earth
rate into the gyro and must be compensated. This module simulates the table (truth and
sensor errors) and implements the estimators of seed 001 §2, derived again below because
the seed's formulas are garbled. The same derivation, typeset, is in
``docs/northfind_derivation.md``.

Frames and truth
----------------
ENU navigation frame n, unit vectors ``E, N, U``; earth rate
``ω_ie^n = Ω [0, cos L, sin L]`` (Ω = ``earth.OMEGA_IE``, L latitude); specific force at
rest ``f^n = g U`` (g = ``earth.gravity(L, h)``).

Table frame t: ``x_t`` (right), ``y_t`` (reference axis, the north-finder's "forward"),
``z_t`` (table normal, up). ``C_nt`` has the columns ``x_t, y_t, z_t`` resolved in ENU, and
is a PSINS body attitude: ``C_nt = Rz(-ψ) Rx(p) Ry(r)`` (:func:`gcalign.rotation.euler_to_dcm`
with ``att = [p, r, -ψ]``). The truth is given by

* ``ψ`` — the *azimuth* of the table: the azimuth (clockwise from true north) of the
  horizontal projection of ``y_t``; it equals ``-yaw`` of the PSINS Euler angles, and is
  what a north-finder must report (seed: "the angle in the horizontal plane");
* ``ε`` — the tilt: the angle between ``z_t`` and ``U``;
* ``ζ`` — the tilt direction: the azimuth toward which the table surface descends (the
  normal leans toward the low side), either fixed to the earth (``"north"``: a sloping
  base under an instrument set at several azimuths) or fixed to the table (``"table"``:
  measured clockwise from the reference axis, ``ζ = ψ + ζ_rel``; a tilted instrument turned
  as a whole, which is what the seed's figures show).

With ``h = [sin ψ, cos ψ, 0]`` and ``d = [sin ζ, cos ζ, 0]`` (see :func:`table_dcm`)::

    z_t = cos ε U + sin ε d,    y_t ∝ h - tan ε cos(ψ-ζ) U,    x_t = y_t × z_t.

Readings (seed eqs. 4–5)
------------------------
At table angle θ (counter-clockwise about ``z_t``, seed §2.1) the gyro axis is
``s(θ) = -sin θ x_t + cos θ y_t`` (``y_t`` turned by θ), the accelerometer axes are
``cos θ x_t + sin θ y_t`` (x) and ``s(θ)`` (y). Projecting ``ω_ie^n`` and ``g U``::

    ω(θ)   = a cos θ + b sin θ,        a = y_t·ω_ie,  b = -x_t·ω_ie
    f_x(θ) = g (u_x cos θ + u_y sin θ),
    f_y(θ) = g (u_y cos θ - u_x sin θ),  u_x = x_t·U, u_y = y_t·U, u_z = z_t·U = cos ε

so every sensor follows ``y_i = R + a cos θ_i + b sin θ_i + w_i`` (seed eq. 4) with R its
bias; (R, a, b) by least squares (seed eqs. 6–7), :func:`fit_harmonics`. Level table:
``a = Ω cos L cos ψ``, ``b = Ω cos L sin ψ``, so ``ψ = atan2(b, a)`` (seed eq. 8).

Tilt (seed eq. 9)
-----------------
``g u_x = (a_x - b_y)/2`` and ``g u_y = (b_x + a_y)/2`` (both accelerometers, averaged);
``sin ε = √(u_x² + u_y²)``; PSINS pitch and roll of the table ``p = asin u_y``,
``r = atan2(-u_x, u_z)``; tilt direction relative to the reference axis
``ζ - ψ = atan2(-u_x, -u_y u_z)``. See :func:`tilt_from_accel`.

Four azimuth methods (:func:`azimuth_from_harmonics`)
-----------------------------------------------------
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

``none`` — ``ψ = atan2(b, a)`` as if level (seed eq. 8 on tilted data). Closed form of its
error (:func:`none_error`), with ``β = ψ - ζ``::

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

Noise (:func:`predict_azimuth_std`, :func:`azimuth_std_level`)
---------------------------------------------------------------
White noise of density σ_w (ARW, rad/√s) sampled at ``f`` Hz has per-sample standard
deviation ``σ_w √f`` and dwell mean ``σ_m = σ_w √(f/N) ≈ σ_w/√T_dwell`` over N samples.
Least squares gives ``Cov(R, a, b) = σ_m² (AᵀA)⁻¹``, ``= σ_m² diag(1/n, 2/n, 2/n)`` for
equally spaced positions. Level: ``δψ = (a δb - b δa)/(a² + b²)``, so
``σ_ψ = σ_m √(2/n) / (Ω cos L)``. In general the estimator is linearised about the
noise-free harmonics and the coefficient covariances of gyro noise, accelerometer noise
and indexing errors are propagated (indexing error δ_i perturbs each reading by
``δ_i ∂y/∂θ``; level, it gives ``σ_ψ = σ_δ √(3/(2n))`` for n = 3 or n ≥ 5).

Simulation shortcut
-------------------
The estimators use only the dwell means. The mean of N independent N(0, σ²) samples is
exactly N(0, σ²/N), so :func:`simulate_table` draws it directly (one number per position
and sensor instead of N): statistically identical, N times cheaper. ``samples=True``
draws every sample instead (a numba kernel that consumes the same ``Generator`` stream as
``rng.standard_normal((K, n, 3, N))`` would); a test checks that the two agree.

>>> import numpy as np
>>> setup = NorthfindSetup(azimuths=np.radians([30.0, 200.0]), lat=np.radians(40.0),
...                        tilt=np.radians(5.0), tilt_direction=np.radians(120.0))
>>> res = run_northfind(setup, np.random.default_rng(0))
>>> np.degrees(res.estimate("coordinate")[:, 0]).round(9).tolist()
[30.0, 200.0]
>>> float(np.degrees(np.abs(res.error("none")).max()).round(2))
3.41
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from gcalign import earth
from gcalign.rotation import euler_to_dcm, wrap_pi

__all__ = [
    "METHODS",
    "NorthfindEstimate",
    "NorthfindResult",
    "NorthfindSetup",
    "TableData",
    "azimuth_from_harmonics",
    "azimuth_std_level",
    "estimate_northfind",
    "fit_harmonics",
    "naive_error",
    "none_error",
    "pitch_roll_from_tilt",
    "position_angles",
    "predict_azimuth_std",
    "predicted_error",
    "run_northfind",
    "simulate_table",
    "table_dcm",
    "tilt_from_accel",
    "tilt_from_pitch_roll",
]

#: Azimuth methods, in the order of the result arrays.
METHODS: tuple[str, ...] = ("coordinate", "vector", "naive", "none")
_ALL_METHODS = METHODS + ("vector_literal",)
_TWO_PI = 2.0 * np.pi


def _deg(x) -> str:
    return f"{np.degrees(x):.6g} deg"


def _wrap_2pi(a):
    """Wrap angles (rad) to [0, 2π)."""
    return np.mod(a, _TWO_PI)


# --------------------------------------------------------------------------------------
# Setup
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, kw_only=True)
class NorthfindSetup:
    """Plain parameters of a north-finding run, SI units and radians.

    Parameters
    ----------
    azimuths : (M,) float, rad
        True azimuths of the table reference axis (clockwise from true north); a sweep.
        Stored wrapped to [0, 2π).
    lat : float, rad
        Site latitude; ``|lat| < π/2`` (north is undefined at the poles).
    positions : int
        Number n of equally spaced table positions per turn, n >= 3.
    dwell_s : float, s
        Dwell at each position (> 0); ``round(dwell_s * rate_hz)`` samples are averaged.
    rate_hz : float, Hz
        Sampling rate (> 0).
    tilt : float or (M,) float, rad
        Tilt ε of the table normal from the vertical, ``0 <= ε < π/2``.
    tilt_direction : float or (M,) float, rad
        Azimuth ζ toward which the table surface descends; see `tilt_direction_ref`.
    tilt_direction_ref : {"north", "table"}
        ``"north"``: ζ is a true azimuth (tilted base, fixed to the earth). ``"table"``: ζ is
        measured clockwise from the reference axis in the horizontal plane (tilt fixed to
        the instrument, turns with it; the true direction is ``azimuth + ζ``).
    repeats : int
        Independent repeats R per azimuth (>= 1); results have shape (M, R).
    height : float, m
        Site height, for gravity.
    gyro_bias : float, rad/s
        Constant gyro bias (R of seed eq. 4).
    gyro_arw : float, rad/√s
        Gyro white noise (angle random walk), >= 0.
    gyro_scale : float
        Gyro scale-factor error (fraction): reading = (1 + scale) · rate + bias + noise.
    accel_bias : float or (2,) float, m/s²
        Constant bias of the [x, y] accelerometers (scalar: both).
    accel_vrw : float, m/s/√s
        Accelerometer white noise (velocity random walk), >= 0, both accelerometers.
    index_error : float, rad
        1σ of the table indexing error, drawn independently per position and run (truth
        only; the estimator uses the nominal angles), >= 0.
    """

    azimuths: np.ndarray
    lat: float
    positions: int = 24
    dwell_s: float = 60.0
    rate_hz: float = 100.0
    tilt: float | np.ndarray = 0.0
    tilt_direction: float | np.ndarray = 0.0
    tilt_direction_ref: str = "north"
    repeats: int = 1
    height: float = 0.0
    gyro_bias: float = 0.0
    gyro_arw: float = 0.0
    gyro_scale: float = 0.0
    accel_bias: float | tuple[float, float] | np.ndarray = 0.0
    accel_vrw: float = 0.0
    index_error: float = 0.0

    def __post_init__(self) -> None:
        def setf(name, value):
            object.__setattr__(self, name, value)

        az = np.atleast_1d(np.asarray(self.azimuths, dtype=float))
        if az.ndim != 1:
            raise ValueError(f"azimuths must have shape (M,), got {az.shape}")
        if az.size == 0:
            raise ValueError("azimuths must hold at least one azimuth (empty sweep), got []")
        if not np.all(np.isfinite(az)):
            raise ValueError(f"azimuths must be finite, got {az.tolist()}")
        setf("azimuths", _wrap_2pi(az))
        m = az.size

        lat = float(self.lat)
        if not np.isfinite(lat) or abs(lat) >= 0.5 * np.pi:
            raise ValueError(
                f"lat must satisfy |lat| < pi/2 rad (north is undefined at the poles), "
                f"got {lat!r} rad ({_deg(lat)})"
            )
        setf("lat", lat)

        pos = self.positions
        if isinstance(pos, (bool, np.bool_)) or int(pos) != pos or int(pos) < 3:
            raise ValueError(
                f"positions must be an integer >= 3 (three unknowns R, a, b per sensor), "
                f"got {pos!r}"
            )
        setf("positions", int(pos))

        for name in ("dwell_s", "rate_hz"):
            v = float(getattr(self, name))
            if not np.isfinite(v) or v <= 0.0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)!r}")
            setf(name, v)
        if round(self.dwell_s * self.rate_hz) < 1:
            raise ValueError(
                f"dwell_s * rate_hz must give at least one sample per position, got "
                f"dwell_s={self.dwell_s!r} s at rate_hz={self.rate_hz!r} Hz"
            )

        tilt = np.asarray(self.tilt, dtype=float)
        if tilt.ndim > 1 or (tilt.ndim == 1 and tilt.size != m):
            raise ValueError(f"tilt must be a scalar or have shape ({m},), got {tilt.shape}")
        bad = ~np.isfinite(tilt) | (tilt < 0.0) | (tilt >= 0.5 * np.pi)
        if np.any(bad):
            v = float(np.atleast_1d(tilt)[np.argmax(np.atleast_1d(bad))])
            raise ValueError(
                f"tilt must satisfy 0 <= tilt < pi/2 rad (0 <= tilt < 90 deg), "
                f"got {v!r} rad ({_deg(v)})"
            )
        setf("tilt", np.broadcast_to(tilt, (m,)).copy())

        tdir = np.asarray(self.tilt_direction, dtype=float)
        if tdir.ndim > 1 or (tdir.ndim == 1 and tdir.size != m):
            raise ValueError(
                f"tilt_direction must be a scalar or have shape ({m},), got {tdir.shape}"
            )
        if not np.all(np.isfinite(tdir)):
            raise ValueError(f"tilt_direction must be finite, got {tdir.tolist()}")
        setf("tilt_direction", np.broadcast_to(tdir, (m,)).copy())
        if self.tilt_direction_ref not in ("north", "table"):
            raise ValueError(
                f"tilt_direction_ref must be 'north' or 'table', got {self.tilt_direction_ref!r}"
            )

        rep = self.repeats
        if isinstance(rep, (bool, np.bool_)) or int(rep) != rep or int(rep) < 1:
            raise ValueError(f"repeats must be an integer >= 1, got {rep!r}")
        setf("repeats", int(rep))

        for name in ("height", "gyro_bias", "gyro_scale"):
            v = float(getattr(self, name))
            if not np.isfinite(v):
                raise ValueError(f"{name} must be finite, got {getattr(self, name)!r}")
            setf(name, v)
        if self.gyro_scale <= -1.0:
            raise ValueError(f"gyro_scale must be > -1, got {self.gyro_scale!r}")
        for name in ("gyro_arw", "accel_vrw", "index_error"):
            v = float(getattr(self, name))
            if not np.isfinite(v) or v < 0.0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)!r}")
            setf(name, v)
        ab = np.asarray(self.accel_bias, dtype=float)
        if ab.shape not in ((), (2,)) or not np.all(np.isfinite(ab)):
            raise ValueError(
                f"accel_bias must be a finite scalar or shape (2,) [x, y], got {ab.tolist()}"
            )
        setf("accel_bias", np.broadcast_to(ab, (2,)).copy())

    @property
    def theta(self) -> np.ndarray:
        """Nominal table angles θ_i = (i-1)·2π/n (rad), shape (n,)."""
        return position_angles(self.positions)

    @property
    def n_samples(self) -> int:
        """Samples averaged per position, ``round(dwell_s * rate_hz)``."""
        return int(round(self.dwell_s * self.rate_hz))

    @property
    def tilt_direction_north(self) -> np.ndarray:
        """True tilt direction as an azimuth from north (rad, [0, 2π)), shape (M,)."""
        if self.tilt_direction_ref == "table":
            return _wrap_2pi(self.azimuths + self.tilt_direction)
        return _wrap_2pi(self.tilt_direction)

    @property
    def gravity(self) -> float:
        """Normal gravity at the site (m/s²)."""
        return float(earth.gravity(self.lat, self.height))


def position_angles(n: int) -> np.ndarray:
    """Equally spaced table angles ``θ_i = (i-1)·2π/n`` (rad), shape (n,).

    >>> np.degrees(position_angles(4)).tolist()
    [0.0, 90.0, 180.0, 270.0]
    """
    return np.arange(n) * (_TWO_PI / n)


# --------------------------------------------------------------------------------------
# Geometry of the tilted table
# --------------------------------------------------------------------------------------


def table_dcm(azimuth, tilt, tilt_direction):
    """Attitude ``C_nt`` of the table frame (columns x_t, y_t, z_t in ENU).

    Parameters
    ----------
    azimuth : (...) float, rad
        Azimuth ψ of the horizontal projection of the reference axis y_t (clockwise from
        true north).
    tilt : (...) float, rad
        Angle ε between the table normal z_t and Up, ``0 <= ε < π/2``.
    tilt_direction : (...) float, rad
        True azimuth ζ toward which the table surface descends.

    Returns
    -------
    C_nt : (..., 3, 3) float
        ``v_n = C_nt @ v_t``; equals ``euler_to_dcm([p, r, -ψ])`` with
        ``p, r = pitch_roll_from_tilt(ε, ζ - ψ)``.

    Notes
    -----
    ``z_t = cos ε U + sin ε d`` with ``d = [sin ζ, cos ζ, 0]`` (the normal leans toward the
    low side); ``y_t`` is the unit vector in the table plane whose horizontal projection is
    ``h = [sin ψ, cos ψ, 0]``: ``y_t ∝ h - tan ε cos(ψ - ζ) U`` (from ``y_t·z_t = 0``);
    ``x_t = y_t × z_t``.
    """
    psi, eps, zeta = np.broadcast_arrays(
        np.asarray(azimuth, float), np.asarray(tilt, float), np.asarray(tilt_direction, float)
    )
    zero = np.zeros_like(psi)
    up = np.stack([zero, zero, zero + 1.0], -1)
    d = np.stack([np.sin(zeta), np.cos(zeta), zero], -1)
    h = np.stack([np.sin(psi), np.cos(psi), zero], -1)
    z_t = np.cos(eps)[..., None] * up + np.sin(eps)[..., None] * d
    y_t = h - (np.tan(eps) * np.cos(psi - zeta))[..., None] * up
    y_t = y_t / np.linalg.norm(y_t, axis=-1, keepdims=True)
    x_t = np.cross(y_t, z_t)
    return np.stack([x_t, y_t, z_t], -1)


def pitch_roll_from_tilt(tilt, tilt_direction_rel):
    """PSINS pitch and roll of a table tilted by ε toward ζ_rel (relative to its axis).

    Parameters
    ----------
    tilt : (...) float, rad
        Tilt ε, ``0 <= ε < π/2``.
    tilt_direction_rel : (...) float, rad
        Direction of descent, clockwise from the reference axis in the horizontal plane.

    Returns
    -------
    pitch, roll : (...) float, rad
        ``C_nt = Rz(-ψ) Rx(pitch) Ry(roll)``. From ``U`` in table axes
        ``[u_x, u_y, u_z] = [-cos p sin r, sin p, cos p cos r]``,
        ``u_x = sin ε sin β / k``, ``u_y = -tan ε cos β / k``, ``β = -ζ_rel``,
        ``k = √(1 + tan²ε cos²β)``.

    >>> p, r = pitch_roll_from_tilt(np.radians(10.0), 0.0)   # descends along y_t
    >>> np.degrees([p, r]).round(12).tolist()
    [-10.0, 0.0]
    """
    eps = np.asarray(tilt, float)
    beta = -np.asarray(tilt_direction_rel, float)
    t = np.tan(eps)
    k = np.sqrt(1.0 + (t * np.cos(beta)) ** 2)
    ux = np.sin(eps) * np.sin(beta) / k
    uy = -t * np.cos(beta) / k
    uz = np.cos(eps)
    return np.arcsin(np.clip(uy, -1.0, 1.0)), np.arctan2(-ux, uz)


def tilt_from_pitch_roll(pitch, roll):
    """Tilt ε and relative tilt direction ζ_rel from PSINS table pitch and roll.

    Parameters
    ----------
    pitch, roll : (...) float, rad

    Returns
    -------
    tilt : (...) float, rad
        ``acos(cos p cos r)``.
    tilt_direction_rel : (...) float, rad, [0, 2π)
        Direction of descent clockwise from the reference axis (horizontal plane),
        ``atan2(-u_x, -u_y u_z)``; set it with ``tilt_direction_ref="table"``.

    >>> e, z = tilt_from_pitch_roll(0.0, np.radians(3.0))   # right side down
    >>> np.degrees([e, z]).round(12).tolist()
    [3.0, 90.0]
    """
    p, r = np.asarray(pitch, float), np.asarray(roll, float)
    ux, uy, uz = -np.cos(p) * np.sin(r), np.sin(p), np.cos(p) * np.cos(r)
    tilt = np.arctan2(np.hypot(ux, uy), uz)
    return tilt, _wrap_2pi(np.arctan2(-ux, -uy * uz))


# --------------------------------------------------------------------------------------
# Simulation
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TableData:
    """Per-position dwell means of the north-finder's sensors.

    Attributes
    ----------
    theta : (n,) float, rad. Nominal table angles (what the estimator uses).
    theta_true : (M, R, n) float, rad. Actual angles (nominal + indexing error).
    gyro : (M, R, n) float, rad/s. Gyro dwell means.
    accel : (M, R, n, 2) float, m/s². Dwell means of the [x, y] accelerometers.
    C_nt : (M, 3, 3) float. True table attitude per azimuth.
    n_samples : int. Samples averaged per position.
    gravity : float, m/s². Gravity used by the truth.
    """

    theta: np.ndarray
    theta_true: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    C_nt: np.ndarray
    n_samples: int
    gravity: float


def _ideal_readings(C_nt, theta, lat, g):
    """Noise-free gyro and accelerometer readings.

    Parameters
    ----------
    C_nt : (M, 3, 3); theta : (M, R, n) rad; lat : rad; g : m/s².

    Returns
    -------
    (M, R, n, 3) float: [gyro rad/s, accel x m/s², accel y m/s²].
    """
    w_t = np.einsum("mij,i->mj", C_nt, earth.omega_ie_n(lat))  # ω^t = C_nt^T ω_ie^n
    u_t = C_nt[:, 2, :]  # U in table axes = third row of C_nt
    c, s = np.cos(theta), np.sin(theta)
    wx, wy = w_t[:, None, None, 0], w_t[:, None, None, 1]
    ux, uy = u_t[:, None, None, 0], u_t[:, None, None, 1]
    gyro = -wx * s + wy * c  # s(θ)·ω^t, s(θ) = [-sin θ, cos θ, 0]
    fx = g * (ux * c + uy * s)  # [cos θ, sin θ, 0]·g u^t
    fy = g * (-ux * s + uy * c)
    return np.stack([gyro, fx, fy], -1)


@numba.njit(cache=True)
def _dwell_means_kernel(rng, ideal, bias, sigma, n_samples):  # pragma: no cover - numba
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


def simulate_table(setup: NorthfindSetup, rng: np.random.Generator, *, samples: bool = False):
    """Simulate the dwell means of the gyro and accelerometers for every azimuth and repeat.

    Parameters
    ----------
    setup : NorthfindSetup
        Truth, timing and sensor errors (SI).
    rng : numpy.random.Generator
        The only source of randomness. Draw order: indexing errors (M, R, n), then the
        sensor noise.
    samples : bool
        False (default): draw each dwell mean of white noise directly as
        ``N(0, σ_s²/N)`` (σ_s = density·√rate, N samples): the mean of N independent
        normal samples has exactly that law, so this is statistically exact and N times
        cheaper. True: draw every sample (numba kernel, same stream as
        ``rng.standard_normal((M*R, n, 3, N))``) and average; a reference for small cases.

    Returns
    -------
    TableData
        Dwell means, shapes (M, R, n) for the gyro and (M, R, n, 2) for the accelerometers.
    """
    m, r, n, N = setup.azimuths.size, setup.repeats, setup.positions, setup.n_samples
    g = setup.gravity
    C_nt = table_dcm(setup.azimuths, setup.tilt, setup.tilt_direction_north)
    theta = setup.theta
    theta_true = theta + setup.index_error * rng.standard_normal((m, r, n))
    ideal = _ideal_readings(C_nt, theta_true, setup.lat, g)
    ideal[..., 0] *= 1.0 + setup.gyro_scale
    accel_bias = np.asarray(setup.accel_bias, dtype=float)
    bias = np.array([setup.gyro_bias, accel_bias[0], accel_bias[1]])
    sigma = np.array([setup.gyro_arw, setup.accel_vrw, setup.accel_vrw]) * np.sqrt(
        setup.rate_hz
    )  # per-sample standard deviation, rad/s and m/s²
    if samples:
        flat = np.ascontiguousarray(ideal.reshape(m * r, n, 3))
        means = _dwell_means_kernel(rng, flat, bias, sigma, N).reshape(m, r, n, 3)
    else:
        # dwell mean of N white samples ~ N(0, σ_s²/N), drawn directly
        means = ideal + bias + (sigma / np.sqrt(N)) * rng.standard_normal((m, r, n, 3))
    return TableData(
        theta=theta,
        theta_true=theta_true,
        gyro=means[..., 0],
        accel=means[..., 1:],
        C_nt=C_nt,
        n_samples=N,
        gravity=g,
    )


# --------------------------------------------------------------------------------------
# Estimation
# --------------------------------------------------------------------------------------


def _design(theta):
    theta = np.asarray(theta, float)
    return np.stack([np.ones_like(theta), np.cos(theta), np.sin(theta)], -1)


def fit_harmonics(y, theta):
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


def tilt_from_accel(accel_coef, g):
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
    """
    c = np.asarray(accel_coef, float)
    ax, bx, ay, by = c[..., 0, 1], c[..., 0, 2], c[..., 1, 1], c[..., 1, 2]
    return (ax - by) / (2.0 * g), (bx + ay) / (2.0 * g)


def _uz(ux, uy):
    return np.sqrt(np.clip(1.0 - ux * ux - uy * uy, 0.0, 1.0))


def _azimuth_coordinate(a, b, ux, uy, w_up):
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


def _azimuth_vector(a, b, ux, uy, w_up):
    """Seed eq. (10), corrected: projections of the horizontal earth rate."""
    uz = _uz(ux, uy)
    a1 = a - w_up * uy  # a' = ω_h·y_t   (vertical leakage removed)
    b1 = b + w_up * ux  # b' = -ω_h·x_t
    cos_ta = np.sqrt(1.0 - uy * uy)  # length of the horizontal projection of y_t
    at = a1 / cos_ta  # ã = Ω cos L cos ψ
    bt = (b1 * cos_ta - at * ux * uy) / uz  # Ω cos L sin ψ (x_t,h is skewed by -ux uy)
    return np.arctan2(bt, at)


def _azimuth_vector_literal(a, b, ux, uy, w_up):
    """Seed eq. (10) as printed: b'/cos θ_b over a'/cos θ_a (exact only if ux·uy = 0)."""
    a1, b1 = a - w_up * uy, b + w_up * ux
    return np.arctan2(b1 / np.sqrt(1.0 - ux * ux), a1 / np.sqrt(1.0 - uy * uy))


def azimuth_from_harmonics(a, b, ux, uy, lat, method: str = "coordinate"):
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


def estimate_northfind(gyro, accel, theta, lat, g, methods=METHODS) -> NorthfindEstimate:
    """Harmonic fits, tilt and azimuth by each method.

    Parameters
    ----------
    gyro : (..., n) float, rad/s
        Gyro dwell means.
    accel : (..., n, 2) float, m/s²
        Dwell means of the [x, y] accelerometers.
    theta : (n,) float, rad
        Nominal table angles.
    lat : float, rad
        Latitude.
    g : float, m/s²
        Gravity magnitude used to scale the accelerometer harmonics.
    methods : sequence of str
        Subset of :data:`METHODS` (and ``"vector_literal"``).

    Returns
    -------
    NorthfindEstimate
    """
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
    )


# --------------------------------------------------------------------------------------
# Closed forms and predictions
# --------------------------------------------------------------------------------------


def _tilt_error(azimuth, tilt, tilt_direction, tan_lat):
    psi = np.asarray(azimuth, float)
    eps = np.asarray(tilt, float)
    zeta = np.asarray(tilt_direction, float)
    beta = psi - zeta
    se, ce = np.sin(eps), np.cos(eps)
    y = np.sin(psi) - se * np.sin(beta) * (se * np.cos(zeta) + tan_lat * ce)
    x = ce * np.cos(psi) - tan_lat * se * np.cos(beta)
    return wrap_pi(np.arctan2(y, x) - psi)


def none_error(azimuth, tilt, tilt_direction, lat):
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

    >>> e = none_error(0.0, np.radians(1.0), np.radians(90.0), np.radians(40.0))
    >>> round(float(np.degrees(e) * 60.0), 2)   # arc-minutes
    50.34
    """
    return _tilt_error(azimuth, tilt, tilt_direction, np.tan(lat))


def naive_error(azimuth, tilt, tilt_direction):
    """Azimuth error of the ``naive`` method (seed eq. 11) with an exact tilt estimate.

    Same parameters as :func:`none_error` (no latitude dependence). Returns (...) rad:
    the :func:`none_error` formula with ``tan L = 0``,
    ``atan2(sin ψ - sin²ε sin(ψ-ζ) cos ζ, cos ε cos ψ) - ψ``; for a tilt along a table
    axis its maximum over ψ is ``asin(tan²(ε/2)) ≈ ε²/4``.
    """
    return _tilt_error(azimuth, tilt, tilt_direction, 0.0)


def predicted_error(setup: NorthfindSetup, methods=METHODS) -> np.ndarray:
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


def azimuth_std_level(gyro_arw, dwell_s, rate_hz, positions, lat):
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
    return sigma_m * np.sqrt(2.0 / positions) / (earth.OMEGA_IE * np.cos(lat))


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


# --------------------------------------------------------------------------------------
# Top level
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class NorthfindResult:
    """Result of :func:`run_northfind` (plain NumPy arrays; radians and SI).

    Attributes
    ----------
    methods : tuple of str. Order of the method axis P.
    azimuth_true : (M,) rad, [0, 2π).
    tilt_true : (M,) rad.
    tilt_direction_true : (M,) rad. True azimuth of descent.
    azimuth_est : (P, M, R) rad, [0, 2π).
    azimuth_error : (P, M, R) rad, ``est - true`` wrapped to [-π, π).
    error_pred : (P, M) rad. Tilt-induced error from the closed forms
        (:func:`predicted_error`).
    azimuth_std_pred : (P, M) rad. :func:`predict_azimuth_std`.
    tilt_est : (M, R) rad.
    tilt_direction_est : (M, R) rad. True azimuth of descent (uses the coordinate azimuth).
    pitch_est, roll_est : (M, R) rad. PSINS Euler angles of the table.
    gyro_coef : (M, R, 3) rad/s. ``[R, a, b]``.
    accel_coef : (M, R, 2, 3) m/s².
    gyro_residual : (M, R, n) rad/s.
    accel_residual : (M, R, n, 2) m/s².
    theta : (n,) rad. Nominal table angles.
    """

    methods: tuple[str, ...]
    azimuth_true: np.ndarray
    tilt_true: np.ndarray
    tilt_direction_true: np.ndarray
    azimuth_est: np.ndarray
    azimuth_error: np.ndarray
    error_pred: np.ndarray
    azimuth_std_pred: np.ndarray
    tilt_est: np.ndarray
    tilt_direction_est: np.ndarray
    pitch_est: np.ndarray
    roll_est: np.ndarray
    gyro_coef: np.ndarray
    accel_coef: np.ndarray
    gyro_residual: np.ndarray
    accel_residual: np.ndarray
    theta: np.ndarray

    def _index(self, method: str) -> int:
        if method not in self.methods:
            raise ValueError(f"method must be one of {self.methods}, got {method!r}")
        return self.methods.index(method)

    def estimate(self, method: str) -> np.ndarray:
        """Azimuth estimates (M, R) of `method`, rad."""
        return self.azimuth_est[self._index(method)]

    def error(self, method: str) -> np.ndarray:
        """Azimuth errors (M, R) of `method`, rad."""
        return self.azimuth_error[self._index(method)]

    def error_mean(self) -> np.ndarray:
        """Mean error over repeats, (P, M) rad (the seed's "bias")."""
        return self.azimuth_error.mean(-1)

    def error_std(self) -> np.ndarray:
        """Standard deviation over repeats (ddof = 1; NaN if R = 1), (P, M) rad."""
        r = self.azimuth_error.shape[-1]
        if r < 2:
            return np.full(self.azimuth_error.shape[:-1], np.nan)
        return self.azimuth_error.std(-1, ddof=1)


def run_northfind(
    setup: NorthfindSetup,
    rng: np.random.Generator,
    *,
    methods=METHODS,
    samples: bool = False,
) -> NorthfindResult:
    """Simulate a multi-position north-finder and estimate the azimuth by each method.

    Parameters
    ----------
    setup : NorthfindSetup
        Scenario (validated on construction).
    rng : numpy.random.Generator
        Source of all randomness (indexing errors, sensor noise).
    methods : sequence of str
        Methods to run, default :data:`METHODS`.
    samples : bool
        Simulate every sample instead of drawing the dwell means (see
        :func:`simulate_table`).

    Returns
    -------
    NorthfindResult
    """
    data = simulate_table(setup, rng, samples=samples)
    est = estimate_northfind(data.gyro, data.accel, data.theta, setup.lat, data.gravity, methods)
    methods = est.methods
    err = wrap_pi(est.azimuth - setup.azimuths[None, :, None])
    std_pred = np.stack(
        [
            predict_azimuth_std(setup, m) if m in METHODS else np.full(setup.azimuths.size, np.nan)
            for m in methods
        ]
    )
    return NorthfindResult(
        methods=methods,
        azimuth_true=setup.azimuths.copy(),
        tilt_true=np.array(setup.tilt, dtype=float),
        tilt_direction_true=setup.tilt_direction_north,
        azimuth_est=est.azimuth,
        azimuth_error=err,
        error_pred=predicted_error(setup, methods),
        azimuth_std_pred=std_pred,
        tilt_est=est.tilt,
        tilt_direction_est=est.tilt_direction,
        pitch_est=est.pitch,
        roll_est=est.roll,
        gyro_coef=est.gyro_coef,
        accel_coef=est.accel_coef,
        gyro_residual=est.gyro_residual,
        accel_residual=est.accel_residual,
        theta=data.theta,
    )
