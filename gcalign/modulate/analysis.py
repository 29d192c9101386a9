"""What a scheme does to a given IMU, from its schedule alone (seed 004; spec 004 §2-§5).

:func:`analyse_scheme` is the array route of ``gcalign modulate`` without the navigation:
the invariant report (:func:`gcalign.modulate.invariant_report`), one cycle of the
mechanism (:func:`mechanism_cycle`) and, on a static base, the linear error model
(:func:`gcalign.modulate.linear_errors`), for sensor errors in SI
(:class:`gcalign.modulate.ErrorTerms`). The navigation of the turning IMU against truth is
the other half of the command.

>>> import numpy as np
>>> from gcalign.modulate import ErrorTerms, builtin_scheme
>>> a = analyse_scheme(builtin_scheme("seed-12"), ErrorTerms.seed004(), lat=np.radians(45.0))
>>> (np.round(a.invariants.mean_C * 3, 12) + 0.0).tolist()  # one third of each bias stays
[[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gcalign.modulate.invariants import REF, InvariantReport, invariant_report
from gcalign.modulate.linear import LinearErrors, linear_errors
from gcalign.modulate.schemes import Scheme
from gcalign.modulate.terms import SEED004_LAT, ErrorTerms
from gcalign.nav.earth import SEED004, EarthModel
from gcalign.nav.rotation import euler_to_dcm, quat_to_dcm
from gcalign.schema import stored
from gcalign.sim.schedule import Schedule

__all__ = ["CYCLE_DT_S", "LINEAR_DT_S", "MechanismCycle", "SchemeAnalysis", "analyse_scheme",
           "mechanism_cycle"]

LINEAR_DT_S = 60.0  #: output interval of the linear model, s (the report hours are on it)
CYCLE_DT_S = 0.25  #: sample interval (at most) of the mechanism over one cycle, s


@dataclass(frozen=True)
class MechanismCycle:
    """One cycle of a schedule C(t) = C_s^r (r the scheme's reference frame).

    t : (K,) s, from 0 to just before the period. angle : (K, 3) rad, the angle turned
    about each sensor axis since the start of the cycle (completed steps plus the current
    one). C_diag : (K, 3), the diagonal of C(t) (where each sensor axis points).
    q : (K, 4), C(t) as a quaternion, scalar first.
    """

    t: np.ndarray = field(metadata=stored("s", description="time in the cycle", compress=4,
                                          dims="C", rule="increasing", optional=True))
    angle: np.ndarray = field(metadata=stored(
        "rad", frame="sensor axes x, y, z", compress=4, dims="C 3", optional=True,
        description="angle turned about each sensor axis since the start of the cycle"))
    C_diag: np.ndarray = field(metadata=stored("", frame=REF, compress=4, dims="C 3",
                                               optional=True,
                                               description="diagonal of C_s^r(t)"))
    q: np.ndarray = field(metadata=stored("", frame=REF, compress=4, dims="C 4", rule="unit",
                                          optional=True, description="quaternion of "
                                          "C_s^r(t), scalar first"))


@dataclass(frozen=True)
class SchemeAnalysis:
    """:func:`analyse_scheme` of one scheme: the invariant report, one mechanism cycle and
    the linear error model (None unless a static base's attitude was given)."""

    scheme: Scheme
    invariants: InvariantReport = field(metadata=stored("", optional=True))
    cycle: MechanismCycle = field(metadata=stored("", name="mechanism", optional=True))
    linear: LinearErrors | None


def mechanism_cycle(schedule: Schedule, dt: float = CYCLE_DT_S) -> MechanismCycle:
    """One cycle of `schedule` sampled at most every `dt` s (and at least 2000 times)."""
    T = schedule.period
    n = max(2, int(math.ceil(T / min(dt, T / 2000.0))) + 1)
    t = np.linspace(0.0, T, n)
    t[-1] = np.nextafter(T, 0.0)  # the end of the cycle, not the start of the next
    theta, _, _, step = schedule.angle_rate_accel(t)
    tb = schedule.tables()
    done = np.cumsum([[0.0, 0.0, 0.0]] + [np.asarray(tb["axis"][i]) * st.profile.angle
                                          for i, st in enumerate(schedule.steps)], axis=0)
    angle = done[step] + tb["axis"][step] * theta[:, None]
    q = schedule.quat(t)
    return MechanismCycle(t=t, angle=angle, C_diag=np.einsum("nii->ni", quat_to_dcm(q)), q=q)


def analyse_scheme(scheme: Scheme, errors: ErrorTerms, *, lat: float = SEED004_LAT,
                   earth: EarthModel = SEED004, att0: np.ndarray | None = None,
                   duration: float = 72.0 * 3600.0, dt_out: float = LINEAR_DT_S,
                   name: str = "") -> SchemeAnalysis:
    """The invariants of `scheme` for `errors` at latitude `lat` (rad) of `earth`, one
    mechanism cycle, and with `att0` (the ``[pitch, roll, yaw]`` of a static base, rad)
    the linear error model over `duration` (s) every `dt_out` (s).

    The linear model's C_s^n = C0·S(t): a navigation-referenced schedule starts at its own
    q0 (the body's attitude), so C0 = I; a body-referenced one turns with the body, so
    C0 = C_b^n(att0).
    """
    report = invariant_report(scheme, errors, earth=earth, lat=lat)
    lin = None
    if att0 is not None:
        C0 = np.eye(3) if scheme.reference == "navigation" else euler_to_dcm(att0)
        lin = linear_errors(scheme.schedule, errors, duration=duration, dt_out=dt_out, lat=lat,
                            earth=earth, C0=C0, name=name or scheme.name)
    return SchemeAnalysis(scheme=scheme, invariants=report,
                          cycle=mechanism_cycle(scheme.schedule), linear=lin)
