"""External sync pulses and the latched attitude's timing (seed 003 §2.2, Fig. 1).

At each pulse edge ``t_p`` the INS latches its current attitude, the solution of the latest
instant ``t_u = kτ ≤ t_p``, and its FPGA measures ``Δt = t_p − t_u`` (0 ≤ Δt < τ). That
attitude was computed from data that lag by T, so it describes the body at ``t_u − T``
(its time of validity) and lags the pulse by ``Tdelay = T + Δt`` (spec 003 §1). Times here
are on the INS clock, which is also the simulation's clock.

>>> import numpy as np
>>> from gcalign.realtime.settings import PulseSettings
>>> p = make_pulses(PulseSettings(mode="async", rate_hz=300.0, offset_s=2.5e-4), 0.01,
...                 1000.0, np.random.default_rng(0))
>>> p.k.tolist(), np.round(p.dt * 1e6, 3).tolist()
([0, 3, 6], [250.0, 583.333, 916.667])
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.realtime.settings import PulseSettings, check_pulses
from gcalign.schema import stored

__all__ = ["Pulses", "latch", "make_pulses"]


@dataclass(frozen=True)
class Pulses:
    """A pulse train and what the INS measures at each edge.

    t : (P,) edge times (s); k : (P,) int, index of the latched solution (``t_u = kτ``);
    dt_true : (P,) ``t − kτ`` (s); dt : (P,) Δt as the FPGA counter measures it (s).
    """

    t: np.ndarray = field(metadata=stored("s", frame="pulse edge times (INS clock)",
                                          compress=True, dims="P", rule="increasing"))
    k: np.ndarray = field(metadata=stored(
        "1", frame="index of the latched solution, t_update = k / solution_hz", compress=True,
        dims="P", whole=True, optional=True))
    dt_true: np.ndarray = field(metadata=stored("s", frame="t - t_update", compress=True,
                                                dims="P", optional=True))
    dt: np.ndarray = field(metadata=stored("s", frame="Δt as the counter measures it",
                                           compress=True, dims="P", optional=True))

    def __len__(self) -> int:
        return len(self.t)

    def select(self, mask: np.ndarray) -> Pulses:
        """The pulses where `mask` (P,) is true."""
        return Pulses(self.t[mask], self.k[mask], self.dt_true[mask], self.dt[mask])


def latch(t: np.ndarray, solution_hz: float, resolution_s: float = 0.0
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Latched solution index k (the latest ``kτ ≤ t``), true Δt and measured Δt (rounded to
    the counter resolution; exact when 0) for edge times `t` (P,) (s)."""
    t = np.asarray(t, dtype=float)
    tau = 1.0 / solution_hz
    # the 1e-9 guards edges that fall on an instant but are computed a hair early
    k = np.floor(t * solution_hz + 1e-9).astype(np.int64)
    dt_true = np.maximum(t - k * tau, 0.0)
    return k, dt_true, _count(dt_true, resolution_s)


def _count(dt: np.ndarray, resolution_s: float) -> np.ndarray:
    """Δt as a counter of `resolution_s` measures it (nearest count); exact when 0."""
    return dt if resolution_s == 0 else np.round(dt / resolution_s) * resolution_s


def make_pulses(p: PulseSettings, duration_s: float, solution_hz: float,
                rng: np.random.Generator) -> Pulses:
    """Pulse edges in [0, duration_s] for the settings `p` (see :class:`PulseSettings`).

    ``solution`` mode: edges at ``kτ + offset`` for every m-th k, ``m = solution_hz /
    rate_hz``. ``async``: a free-running clock with its own phase (random when
    ``offset_s`` is None), rate error and Gaussian jitter; edges sorted.
    """
    check_pulses(p, solution_hz)
    tau = 1.0 / solution_hz
    if p.mode == "solution":
        m = round(solution_hz / p.rate_hz)
        k = np.arange(0, int(np.floor(duration_s * solution_hz + 1e-9)) + 1, m, dtype=np.int64)
        t = k * tau + float(p.offset_s or 0.0)
        k = k[t <= duration_s]
        dt_true = np.full(len(k), float(p.offset_s or 0.0))
        return Pulses(k * tau + dt_true, k, dt_true, _count(dt_true, p.resolution_s))
    period = (1.0 + p.drift_ppm * 1e-6) / p.rate_hz
    offset = rng.uniform(0.0, 1.0 / p.rate_hz) if p.offset_s is None else p.offset_s
    n = int(np.floor((duration_s - offset) / period)) + 1 if offset <= duration_s else 0
    t = offset + np.arange(n) * period
    if p.jitter_s > 0:
        t = np.sort(t + p.jitter_s * rng.standard_normal(n))
    t = t[(t >= 0.0) & (t <= duration_s)]
    k, dt_true, dt = latch(t, solution_hz, p.resolution_s)
    return Pulses(t, k, dt_true, dt)
