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

from dataclasses import dataclass

import numpy as np

from gcalign.align import kernel as K
from gcalign.align.gains import azimuth_gains, level_gains
from gcalign.align.stages import Stage, stage_of_passes
from gcalign.nav.earth import WGS84, EarthModel

MODES = ("conventional", "full-cycle", "half-cycle")


@dataclass(frozen=True)
class Block:
    """The data a sequence of passes runs on, in forward time order (SI).

    t : (N+1,) sample times, t[0] the start of the block.
    dtheta, dv : (N, 3) increments; vref : (N+1, 3) reference velocity at the sample times,
    in ENU or, if `vref_body`, the body frame (odometer).
    """

    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    vref: np.ndarray
    vref_body: bool
    ts: float


@dataclass(frozen=True)
class PassRecord:
    """One pass: its direction, kind ("compass" or "attitude"), stage, gains, and the
    attitude after every step (processing order; a reverse pass's `t` decreases)."""

    index: int
    direction: str
    kind: str
    stage: int
    gains: np.ndarray
    t: np.ndarray
    q_nb: np.ndarray


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


def run_stored(state: np.ndarray, block: Block, lo: int, hi: int, reverse: bool,
               gains: np.ndarray, mode: int, stride: int,
               earth: EarthModel = WGS84) -> tuple[np.ndarray, np.ndarray]:
    """:func:`run_block` in calls of :data:`CHUNK` steps, keeping only the attitude at the
    block samples that are multiples of `stride` from the block's start, at both ends of
    the range and at the end of each call (only those rows are written).

    Returns (block sample indices in processing order, q_nb there (m, 4)).
    """
    idx: list[np.ndarray] = []
    qs: list[np.ndarray] = []
    order = range(hi, lo, -CHUNK) if reverse else range(lo, hi, CHUNK)
    for a in order if hi > lo else [lo]:
        c_lo, c_hi = (max(a - CHUNK, lo), a) if reverse else (a, min(a + CHUNK, hi))
        m = K.stored_rows(c_lo, c_hi, stride)
        i, q = np.empty(m, np.int64), np.empty((m, 4))
        rows = _range(state, block, c_lo, c_hi, reverse, gains, mode, stride, i, q, earth)
        assert rows == m
        start = 1 if idx else 0  # a call's first row is the previous call's last
        idx.append(i[start:])
        qs.append(q[start:])
    return np.concatenate(idx), np.concatenate(qs)


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
    records = []
    direction_prev = "forward"
    for i, (direction, kind) in enumerate(pass_plan(mode, passes)):
        reverse = direction == "reverse"
        if direction != direction_prev:
            state[K.FLIP] *= -1.0
        direction_prev = direction
        gains = gains_by_stage[stage_idx[i]]
        if kind == "attitude":
            idx, q = run_stored(state, block, 0, n, reverse, gains, K.ATTITUDE, stride, earth)
        elif i == 0 and level_s > 0:
            n_level = min(int(round(level_s / block.ts)), n)
            i_a, q_a = run_stored(state, block, 0, n_level, False, gains, K.LEVEL, stride, earth)
            i_b, q_b = run_stored(state, block, n_level, n, False, gains, K.COMPASS, stride,
                                  earth)
            idx, q = np.concatenate([i_a, i_b[1:]]), np.concatenate([q_a, q_b[1:]])
        else:
            idx, q = run_stored(state, block, 0, n, reverse, gains, K.COMPASS, stride, earth)
        t = block.t[idx]
        records.append(PassRecord(i, direction, kind, stage_idx[i], gains, t, q))
    if direction_prev == "reverse":
        state[K.FLIP] *= -1.0
    return state, records
