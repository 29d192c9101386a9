"""Gauss–Legendre quadrature over one cycle of a schedule, piece by piece (private).

Integrands here are smooth within a piece (C(t) = C_before·R_u(θ(t)) with θ a polynomial
or a sine of t) and may jump only at piece boundaries, so Gauss–Legendre on each piece
converges geometrically. Turning pieces are cut into sub-intervals over which the angle
changes by at most 45° (and that last at most `max_len`); 12 nodes on such a sub-interval
integrate cos θ(t) to round-off (the error term is below (π/4)^24/24! ≈ 1e-26).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gcalign.sim.schedule import SINE, Schedule

N_NODES = 12
MAX_SPAN = math.pi / 4  # rad of turn per sub-interval


@dataclass(frozen=True)
class Pieces:
    """The pieces of one cycle: start (s, cycle time), duration (s), whether the frame is at
    rest on it (C constant), and a bound on the angle it turns through (rad)."""

    t0: np.ndarray
    duration: np.ndarray
    constant: np.ndarray
    span: np.ndarray


def pieces(schedule: Schedule) -> Pieces:
    tb = schedule.tables()
    t0 = np.asarray(tb["t0"], dtype=float)
    dur = np.diff(np.append(t0, schedule.period))
    c = np.abs(tb["coef"])
    sine = tb["kind"] == SINE
    span = np.where(sine, c[:, 0] * c[:, 1] * dur,
                    c[:, 0] * dur + 0.5 * c[:, 1] * dur**2 + c[:, 2] * dur**3 / 6.0)
    constant = ~sine & np.all(tb["coef"] == 0.0, axis=1)
    return Pieces(t0, dur, constant, span)


@dataclass(frozen=True)
class CycleGrid:
    """Sub-intervals [a, b] of one cycle (shape (M,)), the piece each lies in, whether the
    frame rests on it, and Gauss–Legendre nodes ``t`` and weights ``w`` (M, n)."""

    a: np.ndarray
    b: np.ndarray
    piece: np.ndarray
    constant: np.ndarray
    t: np.ndarray
    w: np.ndarray

    def integrals(self, values: np.ndarray) -> np.ndarray:
        """∫ f over each sub-interval from ``values = f(t.ravel())`` of shape (M·n, ...)."""
        v = values.reshape(self.t.shape + values.shape[1:])
        return np.einsum("mn,mn...->m...", self.w, v)


def split_count(span: float, duration: float, max_len: float | None,
                max_span: float = MAX_SPAN) -> int:
    """Sub-intervals for a piece turning through `span` rad in `duration` s."""
    k = max(1, math.ceil(span / max_span - 1e-12))
    if max_len is not None:
        k = max(k, math.ceil(duration / max_len - 1e-12))
    return k


def gauss_legendre(a: np.ndarray, b: np.ndarray,
                   n: int = N_NODES) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights on each interval [a_m, b_m], shapes (M, n)."""
    x, w = np.polynomial.legendre.leggauss(n)
    h = 0.5 * (b - a)[:, None]
    return h * x + 0.5 * (a + b)[:, None], h * w


def cycle_grid(schedule: Schedule, n: int = N_NODES, max_len: float | None = 60.0,
               split_constant: bool = False, max_span: float = MAX_SPAN) -> CycleGrid:
    """The quadrature grid of one cycle. Turning pieces are split by angle (`max_span`,
    rad) and `max_len` (s); resting pieces are one sub-interval unless `split_constant`
    (for integrands that vary in time on them, such as e^{-iωt})."""
    p = pieces(schedule)
    a, b, idx, const = [], [], [], []
    for j in range(len(p.t0)):
        if p.duration[j] <= 0:
            continue
        if p.constant[j] and not split_constant:
            k = 1
        else:
            k = split_count(float(p.span[j]), float(p.duration[j]), max_len, max_span)
        e = p.t0[j] + p.duration[j] * np.arange(k + 1) / k
        a.append(e[:-1])
        b.append(e[1:])
        idx.append(np.full(k, j))
        const.append(np.full(k, bool(p.constant[j])))
    aa, bb = np.concatenate(a), np.concatenate(b)
    t, w = gauss_legendre(aa, bb, n)
    return CycleGrid(aa, bb, np.concatenate(idx), np.concatenate(const), t, w)
