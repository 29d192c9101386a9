"""Real-time attitude output of a laser-gyro SINS at external sync pulses (seed 003).

Spec: ``specs/003-realtime-attitude.md`` beside DESIGN.md (it supersedes DESIGN.md's note).
Wang Jin et al. (2021): the sensor data pass a composite digital filter at 5 kHz, the
attitude is solved at 1 kHz, and the attitude latched at a sync pulse lags the pulse by
``Tdelay = T + Δt`` (T the filter's group delay, Δt the pulse's distance from the last
solution instant). A per-axis Kalman tracker on [θ, ω, α] and a three-point least-squares
extrapolation predict the attitude to the pulse time.

Modules
-------
- :mod:`~gcalign.realtime.settings` -- validated settings (SI), the spec's [O] defaults.
- :mod:`~gcalign.realtime.filters` -- FIR order 180 / notch + FIR order 40, group delays,
  streamed filtering (seed §2, eq. 1).
- :mod:`~gcalign.realtime.sensor` -- the gyro channel: increments, noise, dither, counts.
- :mod:`~gcalign.realtime.pulses` -- sync pulses, latch index, Δt (seed §2.2).
- :mod:`~gcalign.realtime.predict` -- tracker (numba), least squares, the seed's
  prediction (reconstructed eq. 13), ``taylor``, ``none``; frequency response (seed §2.3).
- :mod:`~gcalign.realtime.cases` -- turntable motions, the seed's Table 1 cases.
- :mod:`~gcalign.realtime.chain` -- :func:`run_case`: one case end to end.
- :mod:`~gcalign.realtime.table` -- :func:`table1`, :func:`summarise`: our Table 1.

Angles are radians, times seconds, Euler angles ``[pitch, roll, yaw]`` (PSINS order).
"""

from gcalign.realtime.cases import ASYNC_CASE, TABLE1, Case, check_case
from gcalign.realtime.chain import CaseResult, Series, run_case
from gcalign.realtime.filters import FilterChain, alignment_chain, navigation_chain
from gcalign.realtime.predict import TrackerModel, steady_state, swing_residual
from gcalign.realtime.pulses import Pulses, make_pulses
from gcalign.realtime.settings import (
    PREDICTORS,
    FilterSettings,
    PulseSettings,
    SensorSettings,
    Settings,
    TrackerSettings,
    seed_semi_physical,
)
from gcalign.realtime.table import CaseSummary, PredictorStats, summarise, table1

__all__ = [
    "ASYNC_CASE",
    "PREDICTORS",
    "TABLE1",
    "Case",
    "CaseResult",
    "CaseSummary",
    "FilterChain",
    "FilterSettings",
    "PredictorStats",
    "PulseSettings",
    "Pulses",
    "SensorSettings",
    "Series",
    "Settings",
    "TrackerModel",
    "TrackerSettings",
    "alignment_chain",
    "check_case",
    "make_pulses",
    "navigation_chain",
    "run_case",
    "seed_semi_physical",
    "steady_state",
    "summarise",
    "swing_residual",
    "table1",
]
