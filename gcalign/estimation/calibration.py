"""The calibration filter's result (:func:`gcalign.calibrate.calibrate`) and its RTS-smoothed
estimates, as the results file keeps them (each field says how: :mod:`gcalign.schema`).
Apart from the filter, so that the checks of a results file read back take its fields
without loading the filter's kernels."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gcalign.estimation import ins_error as ie
from gcalign.schema import ATT_FRAME, stored

#: the shape of a state series (its ``shape`` attribute in the results file)
STATE_SHAPE = "(epochs, 21) in the order of the 'states' attribute, SI units of 'state_units'"
LLH = "[latitude, longitude, height]"  #: the frame of a position


@dataclass(frozen=True)
class Spans:
    """The named stretches of a flight (its segments): name, t0, t1 (G,), s."""

    name: tuple[str, ...] = field(metadata=stored(None, dims="G"))
    t0: np.ndarray = field(metadata=stored("s", dims="G", rule="increasing"))
    t1: np.ndarray = field(metadata=stored("s", dims="G", rule="increasing"))

    @classmethod
    def of(cls, spans: Any) -> Spans:
        """From spans with a name, start and end each."""
        return cls(tuple(s.name for s in spans), np.array([s.start for s in spans]),
                   np.array([s.end for s in spans]))


@dataclass(frozen=True)
class Errors:
    """A solution's errors at its epochs t (D,): att (Euler differences), v_n, pos (ENU m),
    (D, 3); what : what they are the errors of."""

    what: str = field(metadata=stored(None, attr=True, name="description"))
    t: np.ndarray = field(metadata=stored("s", dims="D", rule="increasing", optional=True))
    att: np.ndarray = field(metadata=stored(
        "rad", description="Euler differences, roll and yaw wrapped: pitch, roll, yaw",
        dims="D 3", optional=True))
    v_n: np.ndarray = field(metadata=stored("m/s", frame="ENU", dims="D 3", optional=True))
    pos: np.ndarray = field(metadata=stored("m", frame="ENU", dims="D 3", optional=True))


@dataclass(frozen=True)
class Smoothed:
    """RTS-smoothed estimates at the filter epochs: estimate and sigma (K+1, 21), as in
    :class:`CalibrationResult` (IMU part: the sensor parameters, navigation part: the error
    of the INS solution before the update at that epoch); att, v_n, pos (K+1, 3) the
    smoothed navigation solution (that INS solution less its smoothed error)."""

    estimate: np.ndarray = field(metadata=stored("SI", shape=STATE_SHAPE, dims="K S",
                                                 optional=True))
    sigma: np.ndarray = field(metadata=stored("SI", shape=STATE_SHAPE, dims="K S",
                                              optional=True))
    att: np.ndarray = field(metadata=stored("rad", frame=ATT_FRAME, dims="K 3", optional=True,
                                            description="the smoothed solution"))
    v_n: np.ndarray = field(metadata=stored("m/s", frame="ENU", dims="K 3", optional=True))
    pos: np.ndarray = field(metadata=stored("rad, rad, m", frame=LLH, dims="K 3",
                                            optional=True))


@dataclass(frozen=True)
class CalibrationResult:
    """A calibration run at the filter epochs ``t`` (K+1,), t[0] the start (no update).

    estimate, sigma : (K+1, 21). IMU part (states 9–20): the estimated sensor parameters
        ε, ∇, δKg, δKa of ``ω̃ = (I + diag δKg) ω + ε`` after the update at t (feed-forward:
        the filter state). Navigation part: the estimated error of the INS solution at t
        before the correction. σ: posterior standard deviation of the filter state.
    truth : (K+1, 21) the same quantities from the truth (None for recorded data).
    nees : (K+1,) NEES of the filter state against the truth (None without truth).
    innovation, standardized : (U, m) z − H x⁻ and its whitened form (~ N(0, 1)) at the
        U epochs with a measurement (``updated``; every epoch but the first on the seed's
        schedule). nis : (U,) normalised innovation squared (~ χ²_m). sigma_z : (U, m) the
        measurement σ used (R = diag σ²: the fix's own, or the settings').
    att, v_n, pos : (K+1, 3) the corrected INS solution at the epochs.
    measure_names : names of the m measurement components.
    index : (K+1,) the navigation sample of each epoch (into the data's t).
    updated : (K+1,) whether a measurement updated the filter at the epoch (in an outage
        the filter only predicts, every filter period).
    fixes_unused : fixes outside the run, or a second one within one navigation step.
    """

    t: np.ndarray = field(metadata=stored(
        "s", description="filter epochs (t[0]: the start, no update)", dims="K",
        rule="increasing"))
    estimate: np.ndarray = field(metadata=stored(
        "SI", shape=STATE_SHAPE, dims="K S", description="sensor errors: the parameters in "
        "force after the update; navigation errors: the estimated error of the INS before the "
        "correction"))
    sigma: np.ndarray = field(metadata=stored("SI", shape=STATE_SHAPE, dims="K S",
                                              description="posterior 1-sigma"))
    truth: np.ndarray | None = field(metadata=stored("SI", shape=STATE_SHAPE, dims="K S",
                                                     optional=True))
    nees: np.ndarray | None = field(metadata=stored(
        "1", description="chi-square, 21 degrees of freedom", dims="K", optional=True))
    innovation: np.ndarray = field(metadata=stored(
        "{measure_units}", names="{measure_names}", description="z - H x-, z = INS - reference",
        dims="U m", optional=True))
    standardized: np.ndarray = field(metadata=stored(
        "1", description="L^-1 innovation, S = L L^T", dims="U m"))
    nis: np.ndarray = field(metadata=stored("1", description="chi-square, {dof} dof", dims="U"))
    att: np.ndarray = field(metadata=stored("rad", frame=ATT_FRAME, dims="K 3"))
    v_n: np.ndarray = field(metadata=stored("m/s", frame="ENU", dims="K 3", optional=True))
    pos: np.ndarray = field(metadata=stored("rad, rad, m", frame=LLH, dims="K 3",
                                            optional=True))
    measure_names: tuple[str, ...] = field(metadata=stored(None, attr=True))
    settings: Any  # the filter's Settings (gcalign.calibrate.filter: not imported here)
    smoothed: Smoothed | None = field(default=None, metadata=stored("", optional=True))
    names: tuple[str, ...] = field(default=ie.STATE_NAMES)
    index: np.ndarray | None = None
    updated: np.ndarray | None = field(default=None, metadata=stored(
        "1", flag=True, dims="K", whole=True, optional=True,
        description="1: a measurement updated the filter at the epoch, 0: predict only"))
    sigma_z: np.ndarray | None = field(default=None, metadata=stored(
        "{measure_units}", names="{measure_names}", dims="U m", optional=True,
        description="the measurement sigma of each update (R = diag sigma^2)"))
    fixes_unused: int = 0

    @property
    def measure_units(self) -> str:
        """The units of the measurement: m/s (velocity), m (position), or per component."""
        return {"velocity": "m/s", "position": "m"}.get(self.settings.measure,
                                                         "m/s, m/s, m, m")

    @property
    def dof(self) -> int:
        """The measurement's components (m), the NIS's degrees of freedom."""
        return int(self.standardized.shape[1])

    @property
    def update_t(self) -> np.ndarray:
        """(U,) the epochs with a measurement."""
        return self.t[1:] if self.updated is None else self.t[self.updated]

    @property
    def error(self) -> np.ndarray | None:
        """estimate − truth (K+1, 21), or None without truth."""
        return None if self.truth is None else self.estimate - self.truth
