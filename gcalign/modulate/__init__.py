"""Rotation modulation (seed 004, spec ``specs/004-rotation-modulation.md``).

Seed 004 (CN102788598A, Sun Wei et al., 2012) turns the IMU on a three-axis mechanism
through positions A, B, C in 12 steps of 180° and claims that constant gyro and
accelerometer biases then average out completely. As written they do not: the mean of
C_s^b over the cycle is C0·diag(−1, 1, 1)/3 (spec §2, shown by :mod:`.invariants` and the
tests), so the literal scheme behaves like an unrotated INS with one third of each bias.
This package holds the numerical core of ``gcalign modulate``:

- :mod:`gcalign.modulate.schemes` -- schemes as tables of rows (built-in and user) →
  :class:`gcalign.sim.schedule.Schedule`.
- :mod:`gcalign.modulate.terms` -- :class:`ErrorTerms`, the constant sensor errors and noise
  in the sensor frame (SI).
- :mod:`gcalign.modulate.invariants` -- what a schedule does to constant errors, computed from
  the schedule itself: mean C and residual biases, scale-factor and misalignment × rate
  terms, running-integral peaks, Schuler resonance warning.
- :mod:`gcalign.modulate.linear` -- an independent linear (φ-angle) error model of a static
  INS whose IMU turns on the schedule, integrated exactly piece by piece to 72 h.
- :mod:`gcalign.modulate.analysis` -- :func:`analyse_scheme`: the three above for one scheme
  and one IMU (:class:`SchemeAnalysis`), with one cycle of the mechanism.

Frames: n = ENU, s = sensor (IMU) frame; a scheme's schedule is C_s^r with r the body or
the navigation frame at the start (``Scheme.reference``). SI and radians throughout.
"""

from gcalign.modulate.analysis import (
    MechanismCycle,
    SchemeAnalysis,
    analyse_scheme,
    mechanism_cycle,
)
from gcalign.modulate.invariants import InvariantReport, invariant_report
from gcalign.modulate.linear import REPORT_HOURS, LinearErrors, linear_errors
from gcalign.modulate.schemes import (
    BUILTIN_NAMES,
    SEED_DWELL,
    SEED_TURN,
    Row,
    Scheme,
    Turn,
    builtin_rows,
    builtin_scheme,
    row_from_dict,
    rows_from_dicts,
    scheme_from_rows,
)
from gcalign.modulate.terms import SEED004_LAT, ErrorTerms

__all__ = [
    "BUILTIN_NAMES", "REPORT_HOURS", "SEED004_LAT", "SEED_DWELL", "SEED_TURN", "ErrorTerms",
    "InvariantReport", "LinearErrors", "MechanismCycle", "Row", "Scheme", "SchemeAnalysis",
    "Turn", "analyse_scheme", "builtin_rows", "builtin_scheme", "invariant_report",
    "linear_errors", "mechanism_cycle", "row_from_dict", "rows_from_dicts", "scheme_from_rows",
]
