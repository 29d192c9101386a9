"""Many alignments of one variant in lockstep: the seeds of a Monte Carlo batch.

:func:`align_runs` aligns several runs that share everything but their data (settings,
timeline, sample interval, site model, stride: the seeds of one variant of a sweep) and
hands each run's :class:`gcalign.align.gyrocompass.Alignment` to a callback. Each run's
numbers are those of :func:`gcalign.align.gyrocompass.align` on its own data, to the bit
(``tests/test_align_lockstep.py``): the coarse alignment and the checks are the same
functions, and the passes and the continued T2 → T3 compensation run
:func:`gcalign.align.kernel.gyrocompass_range_lanes`, which steps
:data:`~gcalign.align.kernel.LANES` runs side by side with the single kernel's operations,
vectorised over the runs (about three times the single kernel's speed a step).

What the lockstep keeps of the passes is what a run's summary reads: the end of every pass
and the second half of the last one (:meth:`Alignment.last_pass_spread`). The other rows
of the records' ``q_nb`` are NaN, and the records are valid only inside the callback (one
buffer serves the runs in turn): a caller that wants whole passes aligns alone.
Runs that cannot share the lockstep (a 'measured' T3, which depends on the computing
time, or real-time conventional mode) are aligned one by one, as are runs whose inputs the
checks refuse (their InputError is their result).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import numpy as np

from gcalign.align import kernel as K
from gcalign.align.compensate import compensate
from gcalign.align.cycles import (
    Block,
    PassRecord,
    calls,
    level_samples,
    loop_gains,
    pass_plan,
    pass_segments,
)
from gcalign.align.gyrocompass import Alignment, _finish, _passes, _prepare, _Prepared
from gcalign.align.stages import stage_of_passes

__all__ = ["align_runs"]

R = TypeVar("R")


def align_runs(runs: Sequence[dict[str, Any]],
               each: Callable[[int, Alignment], R]) -> list[R | Exception]:
    """Align every run (the keyword arguments of :func:`gcalign.align.gyrocompass.align`
    each) and return ``each(i, alignment)`` for run i, or the InputError that refused it.

    Runs that share settings, timeline, interval, earth model, record start, stride and
    reference frame go through the passes in lockstep, :data:`gcalign.align.kernel.LANES`
    at a time; ``each`` is called in the order of `runs`.
    """
    from gcalign.errors import InputError

    out: list[R | Exception] = [InputError("runs", "not aligned")] * len(runs)
    preps: list[tuple[int, _Prepared]] = []
    for i, kw in enumerate(runs):
        try:
            preps.append((i, _prepare_kw(kw)))
        except InputError as err:
            out[i] = err
    groups: dict[tuple, list[tuple[int, _Prepared]]] = {}
    for i, p in preps:
        if _shares(p):
            groups.setdefault(_key(p), []).append((i, p))
        else:
            records, q2, q3, i3, compute = _passes(p.settings, p.state0, p.tl, p.block, p.t0,
                                                   p.ts, p.earth, p.stride)
            out[i] = each(i, _finish(p, records, q2, q3, i3, compute))
    for members in groups.values():
        for g in range(0, len(members), K.LANES):
            _lockstep(members[g:g + K.LANES], each, out)
    return out


def _prepare_kw(kw: dict[str, Any]) -> _Prepared:
    from gcalign.align.gyrocompass import AlignSettings
    from gcalign.nav.earth import WGS84

    return _prepare(kw["dtheta"], kw["dv"], kw["ts"], kw["site"],
                    kw.get("settings", AlignSettings()), kw.get("earth", WGS84),
                    kw.get("att_t1"), kw.get("position_t1"), kw.get("vref"),
                    kw.get("vref_body", False), kw.get("truth_att"), kw.get("t0", 0.0),
                    kw.get("stride", 1), kw.get("first_sample", 0), kw.get("samples"))


def _shares(p: _Prepared) -> bool:
    """Can this run share a lockstep (its T3 known before the passes, passes on a stored
    block followed by the compensation)?"""
    return p.tl.i3 is not None and not p.settings.realtime_conventional


def _key(p: _Prepared) -> tuple:
    return (p.settings, p.tl, p.ts, p.t0, p.stride, p.vref_body,
            tuple(p.earth.params().tolist()))


def _pack(blocks: list[Block], lanes: int) -> np.ndarray:
    """The blocks' data as :func:`gcalign.align.kernel.gyrocompass_range_lanes` reads it,
    (N+1, DATA_ROWS·lanes); lanes past the blocks repeat the first (their results unused)."""
    n = len(blocks[0].dtheta)
    pick = [blocks[s if s < len(blocks) else 0] for s in range(lanes)]
    data = _buffer((n + 1, K.DATA_ROWS * lanes))
    K.pack_lanes(tuple(np.ascontiguousarray(b.dtheta) for b in pick),
                 tuple(np.ascontiguousarray(b.dv) for b in pick),
                 tuple(np.ascontiguousarray(b.vref) for b in pick), data)
    return data


_BUFFERS: dict[tuple[int, int], np.ndarray] = {}


def _buffer(shape: tuple[int, int]) -> np.ndarray:
    """A scratch array of `shape`, kept for the next group (a fresh one of tens of
    megabytes costs a page fault every 4 kB at its first writing): one per shape, the
    passes' block and the compensation's being of different lengths."""
    if shape not in _BUFFERS:
        if len(_BUFFERS) >= 4:
            _BUFFERS.clear()
        _BUFFERS[shape] = np.empty(shape)
    return _BUFFERS[shape]


def _rows(lo: int, hi: int, reverse: bool, stride: int) -> np.ndarray:
    """The block samples :func:`gcalign.align.kernel.gyrocompass_range` keeps over a range,
    in processing order: both ends and the multiples of `stride` between them."""
    inner = np.arange((lo // stride + 1) * stride, hi, stride, dtype=np.int64)
    if hi == lo:
        return np.array([lo], np.int64)
    if reverse:
        return np.concatenate([[hi], inner[::-1], [lo]]).astype(np.int64)
    return np.concatenate([[lo], inner, [hi]]).astype(np.int64)


def _lockstep(members: list[tuple[int, _Prepared]], each: Callable[[int, Alignment], R],
              out: list) -> None:
    """The passes and the compensation of up to LANES runs that share a key, then each."""
    p0 = members[0][1]
    s, tl, earth, stride = p0.settings, p0.tl, p0.earth, p0.stride
    lanes = K.LANES
    used = len(members)
    E = earth.params()
    blocks = [p.block(tl.i1, tl.i2) for _, p in members]
    first = blocks[0]
    n = len(first.dtheta)
    t_start = time.perf_counter()
    data = _pack(blocks, lanes)
    states = np.array([members[min(k, used - 1)][1].state0 for k in range(lanes)])
    stage_idx = stage_of_passes(list(s.stages), s.pass_count)
    lat, h = p0.state0[K.POS][0], p0.state0[K.POS][2]
    gains_by_stage = [loop_gains(st, lat, h, s.azimuth_poles, earth) for st in s.stages]
    level_n = level_samples(s.level_phase_s, first.ts, n)
    plan = pass_plan(s.mode, s.pass_count)
    kept: list[tuple[np.ndarray, np.ndarray, int]] = []  # per pass: samples, q, first row
    direction_prev = "forward"
    for i, (direction, kind) in enumerate(plan):
        reverse = direction == "reverse"
        sign = -1.0 if reverse else 1.0
        if direction != direction_prev:
            states[:, K.FLIP] *= -1.0
        direction_prev = direction
        gains = gains_by_stage[stage_idx[i]]
        parts = [(a, b, mode) for lo, hi, mode in pass_segments(i, kind, n, level_n)
                 for a, b in calls(lo, hi, reverse)]
        idx = np.concatenate([_rows(a, b, reverse, stride)[(1 if c else 0):]
                              for c, (a, b, _) in enumerate(parts)])
        # the rows the summary reads: the second half of the last pass, the end of others
        want = len(idx) // 2 if i == len(plan) - 1 else len(idx) - 1
        q = np.empty((len(idx) - want, 4, lanes))
        row = 0  # the pass's row at the start of the call
        for a, b, mode in parts:
            size = K.stored_rows(a, b, stride)
            start = max(want - row, 0)  # the call's first row to keep
            w = max(row - want, 0)  # where it goes in q
            if start < size:
                ix = np.empty(size - start, np.int64)
                got = K.gyrocompass_range_lanes(
                    states, data, first.vref_body, first.ts, int(a), int(b), reverse, sign,
                    sign, E, gains, int(mode), int(stride), int(start), ix,
                    q[w:w + size - start])
            else:
                ix = np.empty(0, np.int64)
                got = K.gyrocompass_range_lanes(
                    states, data, first.vref_body, first.ts, int(a), int(b), reverse, sign,
                    sign, E, gains, int(mode), int(stride), int(size), ix, q[:0])
            assert got == size
            row += size - 1
        kept.append((idx, q, want))
    if direction_prev == "reverse":
        states[:, K.FLIP] *= -1.0
    q3s = _compensate(members, states, lanes, E)
    compute = (time.perf_counter() - t_start) / used
    times = [first.times(idx) for idx, _, _ in kept]
    full = [np.full((len(idx), 4), np.nan) for idx, _, _ in kept]
    for k, (i, p) in enumerate(members):
        records = []
        for j, ((idx, q, want), t, buf) in enumerate(zip(kept, times, full, strict=True)):
            buf[want:] = q[:, :, k]
            direction, kind = plan[j]
            records.append(PassRecord(j, direction, kind, stage_idx[j],
                                      gains_by_stage[stage_idx[j]], t, buf,
                                      first.first + idx))
        q2 = states[k, K.ATT].copy()
        out[i] = each(i, _finish(p, records, q2, q3s[k], tl.i3, compute))  # type: ignore[arg-type]


def _compensate(members: list[tuple[int, _Prepared]], states: np.ndarray, lanes: int,
                E: np.ndarray) -> list[np.ndarray]:
    """q_nb at T3 of each run from its state at T2 (``continued``: the attitude-only
    update in lockstep; the other methods run by run, as :func:`compensate` does)."""
    p0 = members[0][1]
    tl, method = p0.tl, p0.settings.compensation
    assert tl.i3 is not None
    if method != "continued" or tl.i3 == tl.i2:
        return [compensate(method, states[k], p.block(tl.i2, tl.i3), p.earth)
                for k, (_, p) in enumerate(members)]
    after = [p.block(tl.i2, tl.i3) for _, p in members]
    m = len(after[0].dtheta)
    data = _pack(after, lanes)
    st = states.copy()
    size = K.stored_rows(0, m, 1)
    ix, q = np.empty(1, np.int64), np.empty((1, 4, lanes))
    K.gyrocompass_range_lanes(st, data, after[0].vref_body, after[0].ts, 0, m, False, 1.0,
                              1.0, E, np.zeros(K.GAINS_SIZE), K.ATTITUDE, 1, size - 1, ix, q)
    return [q[0, :, k].copy() for k in range(len(members))]
