"""One north-finding run (seed 001 §3): simulate the table, estimate, compare.

:func:`run_northfind` simulates the turntable for every azimuth and repeat of a
:class:`~gcalign.northfind.simulate.NorthfindSetup`, estimates the azimuth by each method,
and returns the errors against the truth beside the closed-form predictions
(:class:`NorthfindResult`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from gcalign.northfind.estimate import METHODS, estimate_northfind
from gcalign.northfind.simulate import NorthfindSetup, simulate_table
from gcalign.northfind.theory import predict_azimuth_std, predicted_error
from gcalign.schema import ATT_FRAME, stored

__all__ = ["NorthfindResult", "run_northfind"]

AZIMUTH = "clockwise from true north, [0, 2pi)"  #: the frame of an azimuth
DESCENT = "azimuth of descent, " + AZIMUTH  #: the frame of a tilt's direction
RM = "(repeats, azimuths)"  #: the shape of a method's estimates as stored


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

    methods: tuple[str, ...] = field(metadata=stored(None, attr=True))
    azimuth_true: np.ndarray = field(metadata=stored("rad", frame=AZIMUTH, dims="M"))
    tilt_true: np.ndarray = field(metadata=stored(
        "rad", frame="table normal from the vertical", dims="M", optional=True))
    tilt_direction_true: np.ndarray = field(metadata=stored(
        "rad", frame=DESCENT, dims="M", optional=True, summary="deg360"))
    azimuth_error: np.ndarray = field(metadata=stored(
        "rad", frame="estimate - true, wrapped to [-pi, pi)", shape=RM, axes=(1, 0),
        per="methods", name="error", dims="R M | M", summary="deg", label="errors"))
    azimuth_est: np.ndarray = field(metadata=stored(
        "rad", frame=AZIMUTH, shape=RM, axes=(1, 0), per="methods", name="estimate",
        dims="R M | M", optional=True, summary="deg360", label="estimates"))
    azimuth_std_pred: np.ndarray = field(metadata=stored(
        "rad", frame="linearised 1-sigma prediction", per="methods", name="std_pred",
        dims="M", optional=True, finite=False, summary="deg", label="std_pred"))
    error_pred: np.ndarray = field(metadata=stored(
        "rad", frame="noise-free closed form (NaN: none)", per="methods", dims="M",
        optional=True, finite=False, summary="deg"))
    tilt_est: np.ndarray = field(metadata=stored("rad", shape=RM, axes=(1, 0), dims="R M",
                                                 optional=True, summary="deg"))
    tilt_direction_est: np.ndarray = field(metadata=stored(
        "rad", frame=DESCENT, shape=RM, axes=(1, 0), dims="R M", optional=True,
        summary="deg360"))
    pitch_est: np.ndarray = field(metadata=stored(
        "rad", frame=ATT_FRAME, shape=RM, axes=(1, 0), dims="R M", optional=True))
    roll_est: np.ndarray = field(metadata=stored(
        "rad", frame=ATT_FRAME, shape=RM, axes=(1, 0), dims="R M", optional=True))
    gyro_coef: np.ndarray = field(metadata=stored(
        "rad/s", shape="(repeats, azimuths, [R, a, b])", axes=(1, 0, 2), dims="R M 3",
        optional=True))
    accel_coef: np.ndarray = field(metadata=stored(
        "m/s^2", shape="(repeats, azimuths, [x, y], [R, a, b])", axes=(1, 0, 2, 3),
        dims="R M 2 3", optional=True))
    gyro_residual: np.ndarray
    accel_residual: np.ndarray
    theta: np.ndarray = field(metadata=stored(
        "rad", frame="table angles, counter-clockwise about the table normal", dims="P",
        optional=True))

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
    methods: Sequence[str] = METHODS,
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
    est = estimate_northfind(data.gyro, data.accel, data.theta, setup.lat, data.gravity, methods,
                             azimuth_true=setup.azimuths[:, None])
    methods = est.methods
    assert est.azimuth_error is not None  # the truth was given
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
        azimuth_error=est.azimuth_error,
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
