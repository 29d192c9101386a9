"""Many calibration runs of one variant in lockstep: the seeds of a Monte Carlo batch.

:func:`calibrate_runs` runs the calibration filter on several runs' data and returns each
run's :class:`~gcalign.calibrate.CalibrationResult`, equal to the bit to what
:func:`gcalign.calibrate.calibrate` gives on the same data, settings and generator
(``tests/test_calibrate_lockstep.py``). Runs that share the filter's schedule, settings,
reference and earth model (the seeds of a simulated variant: their truth is one
trajectory, only their sensor errors, initial errors and noise differ) step through the
filter epochs together in one numba kernel (:mod:`gcalign.calibrate._kernel`: state arrays
(L, 21), P (L, 21, 21), one loop over the epochs, each run's step the single run's); the
others (measured fixes, a lever arm, sensor processes, Van Loan, the smoother) run one by
one through the filter's general loop.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gcalign.calibrate.data import FlightData
from gcalign.calibrate.filter import (
    CalibrationResult,
    Settings,
    _finish,
    _kernel_epochs,
    _loop,
    _Plan,
    _plan,
    kernel_route,
)

__all__ = ["LANES", "calibrate_runs"]

#: runs stepped together at most (their P per epoch, kept for the NEES, is 2 MB a run on
#: the seed's 590 s flight)
LANES = 16

Run = tuple[FlightData, Settings, np.random.Generator | None]


def calibrate_runs(runs: Sequence[Run]) -> list[CalibrationResult | Exception]:
    """``calibrate(data, settings, rng)`` of every run, as a list in the order of `runs`;
    a run that fails (a bad input, a covariance that is not positive definite) has its
    exception in its place. The generators draw the runs' measurement noise, each its own
    (as each run alone would)."""
    out: list[CalibrationResult | Exception] = []
    groups: list[list[tuple[int, _Plan]]] = []
    for i, (data, settings, rng) in enumerate(runs):
        out.append(ValueError("not run"))
        try:
            plan = _plan(data, settings, rng)
        except Exception as err:  # noqa: BLE001 - this run's failure, the others go on
            out[i] = err
            continue
        if not kernel_route(plan):
            out[i] = _alone(plan)
            continue
        for g in groups:
            if len(g) < LANES and _shares(g[0][1], plan):
                g.append((i, plan))
                break
        else:
            groups.append([(i, plan)])
    for g in groups:
        for (i, plan), ep in zip(g, _kernel_epochs([p for _, p in g]), strict=True):
            out[i] = ep if isinstance(ep, Exception) else _finish(plan, ep)
    return out


def _alone(plan: _Plan) -> CalibrationResult | Exception:
    try:
        return _finish(plan, _loop(plan, None))
    except Exception as err:  # noqa: BLE001 - as calibrate_runs
        return err


def _shares(a: _Plan, b: _Plan) -> bool:
    """Can two runs step together: the same epochs, what the kernel takes of the settings
    (measurement, components, feedback, Q, R), earth model, reference and truth kept?"""
    da, db = a.data, b.data
    sa, sb = a.s, b.s
    return (sa.measure == sb.measure and sa.components == sb.components
            and sa.feedback == sb.feedback and a.S == b.S and len(a.stops) == len(b.stops)
            and da.ts == db.ts and (a.truth is None) == (b.truth is None)
            and np.array_equal(a.Qc, b.Qc) and np.array_equal(a.R_fixed, b.R_fixed)
            and np.array_equal(da.earth.params(), db.earth.params())
            and _same(da.ref_v_n, db.ref_v_n) and _same(da.ref_pos, db.ref_pos))


def _same(x: np.ndarray | None, y: np.ndarray | None) -> bool:
    return x is y or (x is not None and y is not None and np.array_equal(x, y))
