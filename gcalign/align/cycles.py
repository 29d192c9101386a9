"""Fine-alignment passes: conventional, full-cycle and half-cycle modes (seed 000 §3-4, §6).

A *pass* runs the gyrocompass kernel over the stored block [T1, T2] forward or in reverse
(reverse = the data transform of :mod:`gcalign.nav.strapdown`, applied by the kernel as it
reads the block backwards). At each change of direction
the loop states that are velocities or rates change sign with the data; the attitude is
kept. Full-cycle alternates forward/reverse compass passes; half-cycle alternates forward
compass passes with reverse attitude-only passes; conventional is one forward pass.
Loop parameters come in *stages* (seed §6.1): each stage covers a number of passes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from gcalign.align import kernel as K
from gcalign.align.gains import azimuth_gains, level_gains
from gcalign.align.stages import Stage, stage_of_passes
from gcalign.choices import ALIGN_MODES
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.schema import stored

MODES = ALIGN_MODES


@dataclass(frozen=True)
class Block:
    """The data a sequence of passes runs on, in forward time order (SI).

    first : the record sample of the block's start (block sample k is record sample
        first + k, at record time ``t0 + (first + k)·ts``: no array of times is held).
    dtheta, dv : (N, 3) increments; vref : (N+1, 3) reference velocity at the samples, in
    ENU or, if `vref_body`, the body frame (odometer).
    """

    first: int
    t0: float
    dtheta: np.ndarray
    dv: np.ndarray
    vref: np.ndarray
    vref_body: bool
    ts: float

    def times(self, idx: np.ndarray) -> np.ndarray:
        """Record times of block samples `idx`: the float of the record sample times ts
        plus t0, in that order (the values of ``np.arange(a, b + 1.0) * ts + t0``)."""
        t = (self.first + np.asarray(idx, np.int64)).astype(float)
        t *= self.ts
        t += self.t0
        return t

    @property
    def t(self) -> np.ndarray:
        """(N+1,) record times of the block's samples."""
        return self.times(np.arange(len(self.dtheta) + 1))


@dataclass(frozen=True)
class PassRecord:
    """One pass: its direction, kind ("compass" or "attitude"), stage, gains, and the
    attitude at the samples it kept (processing order; a reverse pass's `t` decreases):
    record times `t`, q_nb, and the record samples there. Its direction and kind are
    summarised as they are (:func:`gcalign.schema.summary_of`)."""

    index: int
    direction: str = field(metadata=stored(None, summary=""))
    kind: str = field(metadata=stored(None, summary=""))
    stage: int
    gains: np.ndarray
    t: np.ndarray
    q_nb: np.ndarray
    samples: np.ndarray


def pass_plan(mode: str, passes: int) -> list[tuple[str, str]]:
    """``(direction, kind)`` of each pass. Full-cycle: F R F …; half-cycle: F(compass)
    R(attitude) F …; conventional: one forward compass pass."""
    if mode == "conventional":
        return [("forward", "compass")]
    plan = []
    for i in range(passes):
        if i % 2 == 0:
            plan.append(("forward", "compass"))
        else:
            plan.append(("reverse", "compass" if mode == "full-cycle" else "attitude"))
    return plan


def loop_gains(stage: Stage, lat: float, h: float, azimuth_poles: str,
               earth: EarthModel = WGS84) -> np.ndarray:
    """Gains vector of the kernel for a stage at the site (east loop with R_N, north with R_M)."""
    r_m, r_n = earth.radii(lat)
    g = float(earth.gravity(lat, h))
    east = level_gains(stage.t_xy, stage.xi, g, r_n + h)
    north = level_gains(stage.t_xy, stage.xi, g, r_m + h)
    az = azimuth_gains(stage.t_z, stage.xi, g, r_m + h, azimuth_poles)
    return np.array(
        [east.k1, east.k2, east.k3, north.k1, north.k2, north.k3, az.k1, az.k2, az.k3, az.k4]
    )


def run_block(state: np.ndarray, block: Block, lo: int, hi: int, reverse: bool,
              gains: np.ndarray, mode: int, q_out: np.ndarray,
              earth: EarthModel = WGS84) -> None:
    """Kernel over increments lo..hi-1 of the block (forward) or hi-1..lo (reverse), the
    attitude after every step into `q_out` ((hi - lo + 1, 4), row 0 the start)."""
    idx = np.empty(hi - lo + 1, np.int64)
    _range(state, block, lo, hi, reverse, gains, mode, 1, idx, q_out, earth)


def _range(state: np.ndarray, block: Block, lo: int, hi: int, reverse: bool,
           gains: np.ndarray, mode: int, stride: int, idx: np.ndarray, q: np.ndarray,
           earth: EarthModel) -> int:
    """:func:`gcalign.align.kernel.gyrocompass_range` on the block: a reverse pass reads it
    backwards with the signs of the data transform applied as it reads (no copy)."""
    sign = -1.0 if reverse else 1.0
    return K.gyrocompass_range(
        state, np.ascontiguousarray(block.dtheta), np.ascontiguousarray(block.dv),
        np.ascontiguousarray(block.vref), block.vref_body, block.ts, int(lo), int(hi),
        reverse, sign, sign, earth.params(), gains, int(mode), int(stride), idx, q)


#: Steps per kernel call of a pass. Each call starts its loops' control rates afresh from
#: the state (with the radii at its first sample; within a call they carry the radii of the
#: step before), so the call boundaries are part of the results, which are kept to the bit.
CHUNK = 1 << 16


def calls(lo: int, hi: int, reverse: bool) -> list[tuple[int, int]]:
    """The kernel calls (c_lo, c_hi) of a range, in processing order: :data:`CHUNK` steps
    each from the range's start (its end for a reverse pass); one call for an empty range."""
    if hi <= lo:
        return [(lo, lo)]
    if reverse:
        return [(max(a - CHUNK, lo), a) for a in range(hi, lo, -CHUNK)]
    return [(a, min(a + CHUNK, hi)) for a in range(lo, hi, CHUNK)]


def run_stored(state: np.ndarray, block: Block, lo: int, hi: int, reverse: bool,
               gains: np.ndarray, mode: int, stride: int,
               earth: EarthModel = WGS84) -> tuple[np.ndarray, np.ndarray]:
    """:func:`run_block` in :func:`calls`, keeping only the attitude at the block samples
    that are multiples of `stride` from the block's start, at both ends of the range and at
    the end of each call (only those rows are written, each once, into arrays of their
    size: a call's first row is the previous call's last).

    Returns (block sample indices in processing order, q_nb there (m, 4)).
    """
    return _run_segments(state, block, [(lo, hi, mode)], reverse, gains, stride, earth)


def _run_segments(state: np.ndarray, block: Block, segments: list[tuple[int, int, int]],
                  reverse: bool, gains: np.ndarray, stride: int,
                  earth: EarthModel) -> tuple[np.ndarray, np.ndarray]:
    """:func:`run_stored` over consecutive ranges (lo, hi, mode) of one pass, in
    processing order, into one set of rows (each range starts where the last ended)."""
    parts = [(a, b, mode) for lo, hi, mode in segments for a, b in calls(lo, hi, reverse)]
    sizes = [K.stored_rows(a, b, stride) for a, b, _ in parts]
    m = sum(sizes) - (len(parts) - 1)
    idx, q = np.empty(m, np.int64), np.empty((m, 4))
    row = 0
    for (a, b, mode), size in zip(parts, sizes, strict=True):
        rows = _range(state, block, a, b, reverse, gains, mode, stride, idx[row:row + size],
                      q[row:row + size], earth)
        assert rows == size
        row += size - 1
    return idx, q


def pass_segments(i: int, kind: str, n: int, level_n: int | None) -> list[tuple[int, int, int]]:
    """The ranges (lo, hi, kernel mode) of pass `i` over a block of `n` increments: the
    first pass starts with `level_n` samples of level-only loops (None: no level phase)."""
    if kind == "attitude":
        return [(0, n, K.ATTITUDE)]
    if i == 0 and level_n is not None:
        return [(0, level_n, K.LEVEL), (level_n, n, K.COMPASS)]
    return [(0, n, K.COMPASS)]


def level_samples(level_s: float, ts: float, n: int) -> int | None:
    """Samples of the level-only phase at the start of the first pass (at most the block);
    None for none."""
    return min(int(round(level_s / ts)), n) if level_s > 0 else None


def kept_samples(n: int, mode: str, passes: int, level_s: float, ts: float,
                 stride: int) -> np.ndarray:
    """Every block sample (of a block of `n` increments) at which :func:`run_passes` keeps
    the attitude, increasing: the multiples of `stride` and the ends of every kernel call
    (the ends of the block and of the level phase among them)."""
    level_n = level_samples(level_s, ts, n)
    ends = []
    for i, (direction, kind) in enumerate(pass_plan(mode, passes)):
        for lo, hi, _ in pass_segments(i, kind, n, level_n):
            for a, b in calls(lo, hi, direction == "reverse"):
                ends += [a, b]
    return with_samples(np.arange(0, n + 1, stride, dtype=np.int64), ends)


def with_samples(a: np.ndarray, extra: ArrayLike) -> np.ndarray:
    """The increasing sample numbers `a` with the few samples `extra` merged in (each once;
    what ``np.union1d`` gives, without sorting or hashing the long array)."""
    extra = np.unique(np.asarray(extra, np.int64))
    pos = np.searchsorted(a, extra)
    present = a[np.minimum(pos, len(a) - 1)] == extra if len(a) else np.zeros(len(extra), bool)
    return np.insert(a, pos[~present], extra[~present])


def run_passes(
    state0: np.ndarray,
    block: Block,
    mode: str,
    passes: int,
    stages: list[Stage],
    azimuth_poles: str,
    level_s: float,
    earth: EarthModel = WGS84,
    stride: int = 1,
) -> tuple[np.ndarray, list[PassRecord]]:
    """Run the passes of a mode over the block from the kernel state at its start.

    The first forward pass begins with `level_s` seconds of level-only loops (azimuth free),
    then switches to the compass loop with the loop states carried over.
    Returns the final kernel state (at the end of the block, after the last forward pass)
    and one record per pass, its attitude kept every `stride` samples (and at its ends).
    """
    state = state0.copy()
    n = len(block.dtheta)
    stage_idx = stage_of_passes(stages, passes)
    lat, h = state[K.POS][0], state[K.POS][2]
    gains_by_stage = [loop_gains(st, lat, h, azimuth_poles, earth) for st in stages]
    level_n = level_samples(level_s, block.ts, n)
    records = []
    direction_prev = "forward"
    for i, (direction, kind) in enumerate(pass_plan(mode, passes)):
        reverse = direction == "reverse"
        if direction != direction_prev:
            state[K.FLIP] *= -1.0
        direction_prev = direction
        gains = gains_by_stage[stage_idx[i]]
        segments = pass_segments(i, kind, n, level_n)
        idx, q = _run_segments(state, block, segments, reverse, gains, stride, earth)
        records.append(PassRecord(i, direction, kind, stage_idx[i], gains, block.times(idx),
                                  q, block.first + idx))
    if direction_prev == "reverse":
        state[K.FLIP] *= -1.0
    return state, records
