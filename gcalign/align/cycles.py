"""Fine-alignment passes: conventional, full-cycle and half-cycle modes (seed 000 §3-4, §6).

A *pass* runs the gyrocompass kernel over the stored block [T1, T2] forward or in reverse
(reverse = the data transform of :mod:`gcalign.nav.strapdown`). At each change of direction
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


def run_block(state, block: Block, lo: int, hi: int, reverse: bool, gains, mode, q_out,
              earth: EarthModel = WGS84) -> None:
    """Kernel over increments lo..hi-1 of the block (forward) or hi-1..lo (reverse)."""
    dth, dv, vref = block.dtheta[lo:hi], block.dv[lo:hi], block.vref[lo : hi + 1]
    sign = 1.0
    if reverse:
        dth, dv, vref, sign = -dth[::-1], dv[::-1], -vref[::-1], -1.0
    K.gyrocompass_block(state, np.ascontiguousarray(dth), np.ascontiguousarray(dv),
                        np.ascontiguousarray(vref), block.vref_body, block.ts, sign,
                        earth.params(), gains, mode, q_out)


def run_passes(
    state0: np.ndarray,
    block: Block,
    mode: str,
    passes: int,
    stages: list[Stage],
    azimuth_poles: str,
    level_s: float,
    earth: EarthModel = WGS84,
) -> tuple[np.ndarray, list[PassRecord]]:
    """Run the passes of a mode over the block from the kernel state at its start.

    The first forward pass begins with `level_s` seconds of level-only loops (azimuth free),
    then switches to the compass loop with the loop states carried over.
    Returns the final kernel state (at the end of the block, after the last forward pass)
    and one record per pass.
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
        q_out = np.empty((n + 1, 4))
        if kind == "attitude":
            run_block(state, block, 0, n, reverse, gains, K.ATTITUDE, q_out, earth)
        elif i == 0 and level_s > 0:
            n_level = min(int(round(level_s / block.ts)), n)
            run_block(state, block, 0, n_level, False, gains, K.LEVEL, q_out[: n_level + 1], earth)
            run_block(state, block, n_level, n, False, gains, K.COMPASS, q_out[n_level:], earth)
        else:
            run_block(state, block, 0, n, reverse, gains, K.COMPASS, q_out, earth)
        t = block.t[::-1] if reverse else block.t
        records.append(PassRecord(i, direction, kind, stage_idx[i], gains, t, q_out))
    if direction_prev == "reverse":
        state[K.FLIP] *= -1.0
    return state, records
