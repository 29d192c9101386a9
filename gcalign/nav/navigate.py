"""Streamed strapdown navigation from an initial state, with errors against the truth.

:func:`navigate` takes arrays of increments; :func:`navigate_blocks` takes them block by
block (a simulation generated on the fly, a long recording), so that memory does not grow
with a run's duration. Each block is integrated by :class:`gcalign.nav.strapdown.Navigator`
(bit-identical for any split into blocks), compared with the truth at every sample
(final and largest errors use every sample) and decimated to every `stride`-th sample.

On a turning IMU (a mechanism) the navigation integrates the sensor frame and reports the
body attitude through the mechanism angles the data carry, ``q_nb = q_ns ⊗ q_bs*``.

>>> import numpy as np
>>> from gcalign.nav.earth import WGS84
>>> from gcalign.nav.strapdown import NavState, Vertical
>>> lat, ts, n = np.radians(45.0), 0.01, 6000          # a still, level IMU, 60 s
>>> w_b, f_b = WGS84.omega_ie_n(lat), np.array([0.0, 0.0, float(WGS84.gravity(lat))])
>>> start = NavState.from_euler(np.zeros(3), np.zeros(3), [lat, 0.0, 0.0])
>>> nav = navigate(np.tile(w_b * ts, (n, 1)), np.tile(f_b * ts, (n, 1)), ts, start,
...                vertical=Vertical("hold"), stride=100)
>>> nav.rows.t.shape, nav.max_horizontal_displacement < 1e-6   # 1 Hz rows, still (m)
((61,), True)
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.errors import InputError
from gcalign.nav import _kernels as K
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import euler_to_quat, quat_conj, quat_mult
from gcalign.nav.rows import NavErrors, NavRows
from gcalign.nav.strapdown import Navigator, NavState, Vertical
from gcalign.schema import stored

__all__ = ["NavErrors", "NavRows", "NavTruth", "Navigation", "navigate", "navigate_blocks",
           "position_error_enu"]

Array = NDArray[np.float64]
BLOCK = 1 << 16  #: increments per block of the array route (bounds the temporaries)
HOLD = Vertical("hold")  #: the default vertical channel: height held at the reference


def position_error_enu(pos: ArrayLike, pos_true: ArrayLike,
                       earth: EarthModel = WGS84) -> Array:
    """ENU metres between two ``[lat, lon, h]`` tracks, (N, 3), radii at the true latitude."""
    pos, pos_true = np.asarray(pos, float), np.asarray(pos_true, float)
    r_m, r_n = earth.radii(pos_true[:, 0])
    h = pos_true[:, 2]
    return np.stack(
        [
            (pos[:, 1] - pos_true[:, 1]) * (r_n + h) * np.cos(pos_true[:, 0]),
            (pos[:, 0] - pos_true[:, 0]) * (r_m + h),
            pos[:, 2] - pos_true[:, 2],
        ],
        -1,
    )


@dataclass(frozen=True)
class NavTruth:
    """The truth at the end of each increment (SI): att (n, 3) rad, v_n (n, 3) m/s ENU,
    pos (n, 3) ``[lat, lon, h]``, and q_nb (n, 4) (default: from att)."""

    att: Array
    v_n: Array
    pos: Array
    q_nb: Array | None = None


class BlockTruth(Protocol):
    """The truth of a block (:class:`NavTruth` or any object with these arrays)."""

    @property
    def att(self) -> Array: ...
    @property
    def q_nb(self) -> Array | None: ...
    @property
    def v_n(self) -> Array: ...
    @property
    def pos(self) -> Array: ...


class ImuBlock(Protocol):
    """Increments k0 .. k0+n-1 of a record ending at times t (n,), their truth if known and
    the mechanism angles q_bs (n, 4) if the IMU turns (e.g. :class:`Increments`)."""

    @property
    def k0(self) -> int: ...
    @property
    def t(self) -> Array: ...
    @property
    def dtheta(self) -> Array: ...
    @property
    def dv(self) -> Array: ...
    @property
    def truth(self) -> BlockTruth | None: ...
    @property
    def q_bs(self) -> Array | None: ...


@dataclass(frozen=True)
class Increments:
    """A block of increments (:class:`ImuBlock`): rows k0 .. k0+n-1 of a record."""

    k0: int
    t: Array
    dtheta: Array
    dv: Array
    truth: NavTruth | None = None
    q_bs: Array | None = None


@dataclass(frozen=True)
class Navigation:
    """A navigation run (SI).

    samples, start_s, duration_s : increments navigated, where (k_start·ts) and for how
        long. final : body state at the end. displacement : (3,) ENU m from the start;
    max_horizontal_displacement : m, over every sample. max_error, final_error,
    max_horizontal_error : against the truth over every sample (None without truth).
    rows : every `stride`-th sample from the start (None when they went to `on_rows`).
    compute_s : integration time; wall_s : the whole call, s.
    """

    samples: int = field(metadata=stored("1", summary=""))
    start_s: float = field(metadata=stored("s", summary="s", label="start"))
    duration_s: float = field(metadata=stored("s", summary="s", label="duration"))
    stride: int
    vertical: Vertical
    final: NavState
    displacement: Array = field(metadata=stored("m", summary="m"))
    max_horizontal_displacement: float = field(metadata=stored("m", summary="m"))
    final_error: NavErrors | None = field(metadata=stored("", summary=""))
    max_error: NavErrors | None = field(metadata=stored("", summary=""))
    max_horizontal_error: float | None = field(metadata=stored("m", summary="m"))
    rows: NavRows | None
    compute_s: float
    wall_s: float


_NONE, _Q_NONE = np.zeros((1, 3)), np.zeros((1, 4))  # error_block's "no truth" rows


def _block_truth(tr: BlockTruth | None, lo: int, hi: int, h_prev: float
                 ) -> tuple[tuple[Array, Array, Array, Array], Array | None, float]:
    """error_block's truth rows lo .. hi-1 (att, q_nb, v_n, pos; placeholders without
    truth), the true height at the start of each step (None without truth) and the height
    the next block starts from."""
    if tr is None:
        return (_NONE, _Q_NONE, _NONE, _NONE), None, h_prev
    h_ref = np.concatenate([[tr.pos[lo - 1, 2] if lo > 0 else h_prev], tr.pos[lo:hi - 1, 2]])
    q = euler_to_quat(tr.att[lo:hi]) if tr.q_nb is None else tr.q_nb[lo:hi]
    c = np.ascontiguousarray
    return (c(tr.att[lo:hi]), c(q), c(tr.v_n[lo:hi]), c(tr.pos[lo:hi])), h_ref, tr.pos[hi - 1, 2]


def _errors(a: Array) -> NavErrors:
    return NavErrors(a[0].copy(), a[1].copy(), a[2].copy(), a[3].copy())


def navigate_blocks(blocks: Iterable[ImuBlock], ts: float, start: NavState, *, k_end: int,
                    k_start: int = 0, earth: EarthModel = WGS84,
                    vertical: Vertical = HOLD, stride: int = 1,
                    q_bs0: ArrayLike | None = None, t0: float = 0.0,
                    on_rows: Callable[[NavRows], None] | None = None,
                    progress: Callable[[float, float, str], None] | None = None,
                    truth_height: bool = True) -> Navigation:
    """Navigate from `start` (the state at sample `k_start`, time ``t0 + k_start·ts``) over
    increments k_start .. k_end-1 of the blocks (in order; blocks outside are skipped).

    The stored rows (every `stride`-th sample from the start) are kept in the result with
    the start row first, or, if `on_rows` is given, handed to it block by block (without
    the start row) and not kept: what bounds the memory of a long run. `q_bs0` (4,): the
    mechanism angles at the start, when the blocks carry q_bs. `progress(done_s, total_s,
    what)` hears of every block. The reference height of ``hold``/``damped`` is the true
    height where the blocks carry truth and `truth_height` is True, else the start height
    (False: the blocks' "truth" is a reference solution, for the errors only).
    """
    if not (np.isfinite(ts) and ts > 0):
        raise InputError("ts", f"must be a finite interval > 0 s, got {ts}")
    if not (isinstance(stride, (int, np.integer)) and stride >= 1):
        raise InputError("stride", f"must be a whole number ≥ 1, got {stride!r}")
    if k_end <= k_start:
        raise InputError("k_end", f"nothing to navigate: start at sample {k_start}, end at "
                         f"{k_end} ({k_start * ts:g} s, {k_end * ts:g} s)")
    E = earth.params()
    pos0 = np.asarray(start.pos, dtype=float)
    h_last = float(pos0[2])
    q_ns0 = start.q_nb if q_bs0 is None else quat_mult(np.asarray(start.q_nb, float),
                                                       np.asarray(q_bs0, float))
    nav = Navigator(NavState(q_ns0, start.v_n, pos0), ts, earth, vertical)
    acc = np.zeros((9, 3))
    last = None
    has_truth = False
    kept: list[NavRows] = []
    compute = 0.0
    t_wall = time.perf_counter()
    for b in blocks:
        lo, hi = max(k_start - b.k0, 0), min(k_end - b.k0, len(b.t))
        if hi <= lo:
            if b.k0 >= k_end:
                break
            continue
        has_truth = b.truth is not None
        truth_rows, h_ref, h_last = _block_truth(b.truth, lo, hi, h_last)
        if not truth_height:
            h_ref = None
        c0 = time.perf_counter()
        states = nav.run(b.dtheta[lo:hi], b.dv[lo:hi], h_ref)
        compute += time.perf_counter() - c0
        q_bs = np.zeros((1, 4)) if b.q_bs is None else np.ascontiguousarray(b.q_bs[lo:hi])
        out = np.empty((len(states) // stride + 1, 21))
        rows = K.error_block(states, q_bs, b.q_bs is not None, *truth_rows, has_truth, E, pos0,
                             b.k0 + lo - k_start, stride, acc, out)
        if rows:
            keep = np.flatnonzero((b.k0 + np.arange(lo, hi) + 1 - k_start) % stride == 0)
            r = out[:rows]
            err = NavErrors(r[:, 9:12], r[:, 12:15], r[:, 15:18], r[:, 18:21]) if has_truth \
                else None
            chunk = NavRows(b.t[lo:hi][keep], r[:, 0:3], r[:, 3:6], r[:, 6:9], err)
            if on_rows is not None:
                on_rows(chunk)
            else:
                kept.append(chunk)
        last = (states[-1], None if b.q_bs is None else b.q_bs[hi - 1])
        if progress is not None:
            progress((b.k0 + hi - k_start) * ts, (k_end - k_start) * ts, "navigating (data s)")
    if last is None:
        raise InputError("blocks", f"hold no increment of samples {k_start} .. {k_end - 1}")
    s_end, qbs_end = last
    q_end = s_end[K.Q] if qbs_end is None else quat_mult(s_end[K.Q][None],
                                                         quat_conj(qbs_end[None]))[0]
    pos_end = s_end[K.P]
    return Navigation(
        samples=k_end - k_start,
        start_s=k_start * ts,
        duration_s=(k_end - k_start) * ts,
        stride=stride,
        vertical=vertical,
        final=NavState(q_end, s_end[K.V].copy(), pos_end.copy()),
        displacement=position_error_enu(pos_end[None], pos0[None], earth)[0],
        max_horizontal_displacement=float(acc[3, 1]),
        max_error=_errors(acc[[0, 1, 2, 4]]) if has_truth else None,
        final_error=_errors(acc[5:9]) if has_truth else None,
        max_horizontal_error=float(acc[3, 0]) if has_truth else None,
        rows=None if on_rows is not None else _joined(start, t0 + k_start * ts, kept,
                                                      has_truth),
        compute_s=compute,
        wall_s=time.perf_counter() - t_wall,
    )


def _joined(start: NavState, t_start: float, chunks: list[NavRows], truth: bool) -> NavRows:
    """The start row (zero errors) and the chunks, as one NavRows."""
    z = np.zeros((1, 3))
    first = NavRows(np.array([t_start]), np.asarray(start.att, float)[None],
                    np.asarray(start.v_n, float)[None], np.asarray(start.pos, float)[None],
                    NavErrors(z, z, z, z) if truth else None)
    parts = [first, *chunks]

    def cat(get: Callable[[NavRows], Array]) -> Array:
        return np.concatenate([get(p) for p in parts])

    err = None
    if truth:
        errs = [p.error for p in parts]
        err = NavErrors(*(np.concatenate([getattr(e, f) for e in errs])
                          for f in ("att", "v_n", "pos", "phi")))
    return NavRows(cat(lambda p: p.t), cat(lambda p: p.att), cat(lambda p: p.v_n),
                   cat(lambda p: p.pos), err)


def _check(name: str, value: ArrayLike, rows: int, width: int) -> Array:
    a = np.asarray(value, dtype=float)
    if a.shape != (rows, width):
        raise InputError(name, f"must have shape ({rows}, {width}), got {a.shape}")
    if not np.isfinite(a).all():
        raise InputError(name, "must be finite (NaN or infinity found)")
    return a


def navigate(dtheta: ArrayLike, dv: ArrayLike, ts: float, start: NavState, *,
             earth: EarthModel = WGS84, vertical: Vertical = HOLD,
             truth: NavTruth | None = None, q_bs: ArrayLike | None = None,
             q_bs0: ArrayLike | None = None, stride: int = 1, t0: float = 0.0) -> Navigation:
    """Strapdown navigation over increments (N, 3) (rad, m/s; body frame, or the sensor
    frame with mechanism angles `q_bs` (N, 4) and `q_bs0` (4,) at the start) from `start`
    at time `t0`; increment k ends at ``t0 + (k+1)·ts``. `truth` (:class:`NavTruth`, n = N)
    gives the errors. Rows every `stride` samples, the start first. See
    :func:`navigate_blocks`."""
    dth = np.asarray(dtheta, dtype=float)
    if dth.ndim != 2 or len(dth) == 0:
        raise InputError("dtheta", f"must have shape (N, 3) with N ≥ 1, got {dth.shape}")
    n = len(dth)
    dth = _check("dtheta", dth, n, 3)
    dvb = _check("dv", dv, n, 3)
    if truth is not None:
        truth = NavTruth(_check("truth.att", truth.att, n, 3),
                         _check("truth.v_n", truth.v_n, n, 3),
                         _check("truth.pos", truth.pos, n, 3),
                         None if truth.q_nb is None else _check("truth.q_nb", truth.q_nb, n, 4))
    qbs = None if q_bs is None else _check("q_bs", q_bs, n, 4)
    if (qbs is None) != (q_bs0 is None):
        raise InputError("q_bs0", "give both q_bs and q_bs0 (a turning IMU), or neither")

    def blocks() -> Iterator[Increments]:
        for k0 in range(0, n, BLOCK):
            sl = slice(k0, k0 + BLOCK)
            tr = None if truth is None else NavTruth(
                truth.att[sl], truth.v_n[sl], truth.pos[sl],
                None if truth.q_nb is None else truth.q_nb[sl])
            t = np.asarray(t0 + np.arange(k0 + 1, k0 + 1 + len(dth[sl])) * ts, float)
            yield Increments(k0, t, dth[sl], dvb[sl], tr, None if qbs is None else qbs[sl])

    return navigate_blocks(blocks(), ts, start, k_end=n, earth=earth, vertical=vertical,
                           stride=stride, q_bs0=q_bs0, t0=t0)
