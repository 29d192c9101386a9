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
- :mod:`~gcalign.realtime.sensor` -- the gyro triad: noise, dither, counts.
- :mod:`~gcalign.realtime.pulses` -- sync pulses, latch index, Δt (seed §2.2).
- :mod:`~gcalign.realtime.predict` -- tracker (numba), least squares, the seed's
  prediction (reconstructed eq. 13), ``taylor``, ``none``; frequency response (seed §2.3).
- :mod:`~gcalign.realtime.cases` -- turntable motions, the seed's Table 1 cases.
- :mod:`~gcalign.realtime.chain` -- :func:`run_case`: one case end to end on the core
  (ideal increments, sensor, filter, attitude-only strapdown with coning correction).
- :mod:`~gcalign.realtime.table` -- :func:`run_realtime` (:class:`RealtimeResult`): every
  case and its row of our Table 1 (:func:`table1`, :func:`summarise`).

Angles are radians, times seconds, Euler angles ``[pitch, roll, yaw]`` (PSINS order).

The names below are loaded on first use (PEP 562), so that the scenario layer can read
:mod:`~gcalign.realtime.settings` and :mod:`~gcalign.realtime.cases` without importing
scipy or numba (``gcalign validate`` and ``show`` must stay light).
"""

from __future__ import annotations

import importlib
from typing import Any

_WHERE = {
    "ASYNC_CASE": "cases", "TABLE1": "cases", "Case": "cases", "check_case": "cases",
    "accel_case": "cases", "rate_case": "cases", "swing_case": "cases",
    "table1_cases": "cases", "async_case": "cases",
    "CaseResult": "chain", "Series": "chain", "run_case": "chain", "SITE": "chain",
    "FilterChain": "filters", "alignment_chain": "filters", "navigation_chain": "filters",
    "TrackerModel": "predict", "steady_state": "predict", "swing_residual": "predict",
    "Pulses": "pulses", "make_pulses": "pulses",
    "PREDICTORS": "settings", "FilterSettings": "settings", "PulseSettings": "settings",
    "SensorSettings": "settings", "Settings": "settings", "TrackerSettings": "settings",
    "seed_semi_physical": "settings",
    "CaseSummary": "table", "PredictorStats": "table", "RealtimeResult": "table",
    "run_realtime": "table", "summarise": "table", "table1": "table",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    try:
        module = _WHERE[name]
    except KeyError:
        raise AttributeError(f"module 'gcalign.realtime' has no attribute {name!r}") from None
    return getattr(importlib.import_module(f"gcalign.realtime.{module}"), name)


def __dir__() -> list[str]:
    return __all__
