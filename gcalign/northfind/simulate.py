"""Simulated indexing turntable (seed 001 §3.1): the setup and the dwell means.

:class:`NorthfindSetup` holds and validates the plain parameters of a run (truth, timing,
sensor errors; SI and radians); :func:`simulate_table` draws the dwell means of the gyro
and the two accelerometers (:class:`TableData`), either directly from their exact law or
sample by sample in the numba kernel :func:`gcalign.northfind._kernel.dwell_means`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.nav import earth
from gcalign.northfind.geometry import _ideal_readings, _wrap_2pi, position_angles, table_dcm
from gcalign.schema import stored

__all__ = ["NorthfindSetup", "TableData", "simulate_table"]


def _deg(x: float) -> str:
    return f"{np.degrees(x):.6g} deg"


def _finite(name: str, value: object) -> np.ndarray:
    """`value` as a float array; ValueError naming `name` unless every entry is finite."""
    a = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite, got {a.tolist()}")
    return a


def _per_azimuth(name: str, value: object, m: int) -> np.ndarray:
    """A scalar or (M,) value broadcast to (M,)."""
    a = np.asarray(value, dtype=float)
    if a.ndim > 1 or (a.ndim == 1 and a.size != m):
        raise ValueError(f"{name} must be a scalar or have shape ({m},), got {a.shape}")
    return np.broadcast_to(a, (m,)).copy()


def _is_int(x: object) -> bool:
    """A whole number (3 or 3.0, not True, 3.5 or inf)."""
    return (isinstance(x, (int, float, np.integer, np.floating))
            and not isinstance(x, (bool, np.bool_)) and bool(np.isfinite(x))
            and float(x) == int(x))


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
    lat: float = field(metadata=stored("rad", attr=True))
    positions: int = field(default=24, metadata=stored("1", attr=True))
    dwell_s: float = field(default=60.0, metadata=stored("s", attr=True))
    rate_hz: float = field(default=100.0, metadata=stored("Hz", attr=True))
    tilt: float | np.ndarray = 0.0
    tilt_direction: float | np.ndarray = 0.0
    tilt_direction_ref: str = field(default="north", metadata=stored(None, attr=True))
    repeats: int = field(default=1, metadata=stored("1", attr=True))
    height: float = field(default=0.0, metadata=stored("m", attr=True))
    gyro_bias: float = field(default=0.0, metadata=stored("rad/s", attr=True))
    gyro_arw: float = field(default=0.0, metadata=stored("rad/sqrt(s)", attr=True))
    gyro_scale: float = field(default=0.0, metadata=stored("1", attr=True))
    accel_bias: float | tuple[float, float] | np.ndarray = field(
        default=0.0, metadata=stored("m/s^2", attr=True))
    accel_vrw: float = field(default=0.0, metadata=stored("m/s/sqrt(s)", attr=True))
    index_error: float = field(default=0.0, metadata=stored("rad", attr=True))

    def __post_init__(self) -> None:
        az = _finite("azimuths", np.atleast_1d(np.asarray(self.azimuths, dtype=float)))
        if az.ndim != 1:
            raise ValueError(f"azimuths must have shape (M,), got {az.shape}")
        if az.size == 0:
            raise ValueError("azimuths must hold at least one azimuth (empty sweep), got []")
        m = az.size
        lat = float(_finite("lat", self.lat))
        tilt = _finite("tilt", _per_azimuth("tilt", self.tilt, m))
        tdir = _finite("tilt_direction", _per_azimuth("tilt_direction", self.tilt_direction, m))
        accel_bias = _finite("accel_bias", self.accel_bias)
        numbers = {name: float(_finite(name, getattr(self, name)))
                   for name in ("dwell_s", "rate_hz", "height", "gyro_bias", "gyro_arw",
                                "gyro_scale", "accel_vrw", "index_error")}
        bad_tilt = (tilt < 0.0) | (tilt >= 0.5 * np.pi)
        t_bad = float(tilt[np.argmax(bad_tilt)])
        rules = [
            ("positions", _is_int(self.positions) and self.positions >= 3,
             "be an integer >= 3 (three unknowns R, a, b per sensor)", self.positions),
            ("repeats", _is_int(self.repeats) and self.repeats >= 1, "be an integer >= 1",
             self.repeats),
            ("lat", abs(lat) < 0.5 * np.pi, "satisfy |lat| < pi/2 rad (north is undefined at "
             "the poles)", f"{lat!r} rad ({_deg(lat)})"),
            ("tilt", not np.any(bad_tilt), "satisfy 0 <= tilt < pi/2 rad (0 <= tilt < 90 deg)",
             f"{t_bad!r} rad ({_deg(t_bad)})"),
            ("tilt_direction_ref", self.tilt_direction_ref in ("north", "table"),
             "be 'north' or 'table'", repr(self.tilt_direction_ref)),
            ("accel_bias", accel_bias.shape in ((), (2,)), "be a scalar or shape (2,) [x, y]",
             accel_bias.shape),
            ("gyro_scale", numbers["gyro_scale"] > -1.0, "be > -1", numbers["gyro_scale"]),
        ]
        rules += [(name, numbers[name] > 0.0, "be > 0", getattr(self, name))
                  for name in ("dwell_s", "rate_hz")]
        rules += [(name, numbers[name] >= 0.0, "be >= 0", getattr(self, name))
                  for name in ("gyro_arw", "accel_vrw", "index_error")]
        for name, ok, allowed, got in rules:
            if not ok:
                raise ValueError(f"{name} must {allowed}, got {got}")
        if round(numbers["dwell_s"] * numbers["rate_hz"]) < 1:
            raise ValueError(
                f"dwell_s * rate_hz must give at least one sample per position, got "
                f"dwell_s={self.dwell_s!r} s at rate_hz={self.rate_hz!r} Hz"
            )
        for name, value in (("azimuths", _wrap_2pi(az)), ("lat", lat), ("tilt", tilt),
                            ("tilt_direction", tdir), ("positions", int(self.positions)),
                            ("repeats", int(self.repeats)),
                            ("accel_bias", np.broadcast_to(accel_bias, (2,)).copy()),
                            *numbers.items()):
            object.__setattr__(self, name, value)

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


def simulate_table(
    setup: NorthfindSetup, rng: np.random.Generator, *, samples: bool = False
) -> TableData:
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

    Notes
    -----
    The estimators use only the dwell means. The mean of N independent N(0, σ²) samples is
    exactly N(0, σ²/N), so the default path draws it directly (one number per position
    and sensor instead of N): statistically identical, N times cheaper. ``samples=True``
    draws every sample instead (a numba kernel that consumes the same ``Generator`` stream as
    ``rng.standard_normal((K, n, 3, N))`` would); a test checks that the two agree.
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
        from gcalign.northfind._kernel import dwell_means  # numba: only for this path

        means = dwell_means(rng, flat, bias, sigma, N).reshape(m, r, n, 3)
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
