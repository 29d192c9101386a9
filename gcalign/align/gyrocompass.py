"""Seed-000 gyrocompass alignment on arrays: coarse on [0, T1], passes on [T1, T2], T2 → T3.

The public face of :mod:`gcalign.align` (DESIGN.md "Gyrocompass fine alignment"):
:func:`align` takes the increments of a recording or a simulation, the sample interval,
the site and :class:`AlignSettings`, and returns an :class:`Alignment` in SI units.

Sample k of a record is the time ``t0 + k·ts`` (sample 0: before the first increment;
increment k ends at sample k + 1). Alignment time t is sample ``round((start_s + t)/ts)``;
:func:`timeline` gives the samples of 0, T1, T2 and T3 and the range the alignment reads,
so that a caller with a long record needs to hold only that window (``first_sample``).

>>> import numpy as np
>>> from gcalign.nav.earth import WGS84
>>> from gcalign.nav.rotation import euler_to_dcm
>>> lat, ts, n = np.radians(45.0), 0.01, 20000          # a still, level IMU, 200 s
>>> C_bn = euler_to_dcm([0.0, 0.0, np.radians(30.0)]).T  # heading 30°
>>> w_b = C_bn @ WGS84.omega_ie_n(lat)
>>> f_b = C_bn @ np.array([0.0, 0.0, float(WGS84.gravity(lat))])
>>> dtheta, dv = np.tile(w_b * ts, (n, 1)), np.tile(f_b * ts, (n, 1))
>>> s = AlignSettings(mode="conventional", t1_s=10, t2_s=200, t3_s=200, level_s=60)
>>> res = align(dtheta, dv, ts, [lat, 0.0, 0.0], s)
>>> bool(np.abs(np.degrees(res.att_t3) - [0.0, 0.0, 30.0]).max() < 1e-3)  # pitch, roll, yaw
True
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.align import coarse as coarse_mod
from gcalign.align import kernel as K
from gcalign.align.compensate import METHODS, compensate
from gcalign.align.cycles import (
    MODES,
    Block,
    PassRecord,
    kept_samples,
    run_passes,
    with_samples,
)
from gcalign.align.gains import AZIMUTH_METHODS
from gcalign.align.result import AlignmentAt, PassRows
from gcalign.align.stages import Stage
from gcalign.errors import InputError
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import (
    attitude_error,
    euler_to_dcm,
    euler_to_quat,
    misalignment,
    misalignment_q,
    quat_to_dcm,
    quat_to_euler,
)
from gcalign.schema import stored

__all__ = ["AlignSettings", "Alignment", "Spread", "Timeline", "TruthRows", "align",
           "timeline", "truth_samples"]

Array = NDArray[np.float64]

COARSE_METHODS = ("analytic", "inertial", "given")
MAX_LAT_DEG = 85.0  #: gyrocompassing needs the horizontal earth rate ω_ie cos L
MEASURED_MAX_S = 600.0  #: data kept after T2 for a 'measured' T3 (the computing latency)
DEFAULT_PASSES = {"conventional": 1, "full-cycle": 5, "half-cycle": 5}


@dataclass(frozen=True)
class AlignSettings:
    """Settings of an alignment (SI: seconds, radians). Field names follow the scenario's
    ``align`` section.

    mode : ``conventional`` (one forward pass), ``full-cycle`` (forward/reverse compass
        passes) or ``half-cycle`` (reverse passes attitude-only).
    start_s : the record time (from sample 0) taken as alignment time 0.
    t1_s, t2_s : end of the coarse window [0, T1]; end of the stored fine block [T1, T2].
    t3_s : when the attitude is wanted (≥ T2), or ``"measured"``: T2 plus the wall time of
        the passes.
    realtime : conventional mode only: run the loop on live data to T3 (True) or stop at T2
        and carry the attitude to T3 by the compensation.
    compensation : T2 → T3: ``none``, ``one-off`` (seed eqs. 14-18) or ``continued``.
    coarse : ``analytic`` (still base), ``inertial`` (swinging or disturbed base) over
        [0, T1], or ``given`` (the `att_t1` argument of :func:`align`, else the truth at T1).
    coarse_offset : (3,) rad added to the coarse attitude (the initial error of a study).
    azimuth_poles : ``oscillator-overdamped`` (method b) or ``double-oscillator`` (a).
    level_s : level-only phase at the start of the first pass (default 3·T_xy of stage 1).
    stages : loop parameters (T_xy, T_z, ξ, passes); the last stage covers the rest.
    passes : passes in all (default 1 in conventional mode, 5 in the cycle modes).
    """

    mode: Literal["conventional", "full-cycle", "half-cycle"] = "full-cycle"
    start_s: float = 0.0
    t1_s: float = 10.0
    t2_s: float = 300.0
    t3_s: float | Literal["measured"] = 330.0
    realtime: bool = True
    compensation: Literal["none", "one-off", "continued"] = "continued"
    coarse: Literal["analytic", "inertial", "given"] = "analytic"
    coarse_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    azimuth_poles: Literal["double-oscillator", "oscillator-overdamped"] = \
        "oscillator-overdamped"
    level_s: float | None = None
    stages: tuple[Stage, ...] = field(default=(Stage(20.0, 100.0, 0.707),))
    passes: int | None = None

    def __post_init__(self) -> None:
        for name, value, allowed in (("mode", self.mode, MODES),
                                     ("compensation", self.compensation, METHODS),
                                     ("coarse", self.coarse, COARSE_METHODS),
                                     ("azimuth_poles", self.azimuth_poles, AZIMUTH_METHODS)):
            if value not in allowed:
                raise InputError(name, f"got {value!r}, allowed: {', '.join(allowed)}")
        times = [("start_s", self.start_s), ("t1_s", self.t1_s), ("t2_s", self.t2_s)]
        if self.t3_s != "measured":
            times.append(("t3_s", self.t3_s))
        for name, t in times:
            if not (isinstance(t, (int, float)) and math.isfinite(t) and t >= 0):
                raise InputError(name, f"must be a finite time ≥ 0 s, got {t!r}")
        if self.t2_s <= self.t1_s:
            raise InputError("t2_s", f"must be greater than t1_s ({self.t1_s} s), got "
                                  f"{self.t2_s}")
        if self.t3_s != "measured" and self.t3_s < self.t2_s:
            raise InputError("t3_s", f"must be at least t2_s ({self.t2_s} s) or "
                                  f"'measured', got {self.t3_s}")
        if self.coarse != "given" and self.t1_s <= 0:
            raise InputError("t1_s", f"coarse method {self.coarse!r} needs data before "
                                  "T1, got 0")
        if not self.stages:
            raise InputError("stages", "give at least one stage")
        n = self.pass_count
        if self.mode == "conventional" and n != 1:
            raise InputError("passes", f"conventional mode runs one pass, got {n}")
        if self.mode != "conventional" and (n < 3 or n % 2 == 0):
            raise InputError("passes", f"mode {self.mode!r} needs an odd number of "
                                  f"passes ≥ 3 (forward, reverse, …, forward), got {n}")
        if not 0 <= self.level_phase_s < self.t2_s - self.t1_s:
            raise InputError("level_s", f"the level phase ({self.level_phase_s} s) must "
                                  f"be shorter than t2_s - t1_s ({self.t2_s - self.t1_s} s)")

    @property
    def pass_count(self) -> int:
        return DEFAULT_PASSES[self.mode] if self.passes is None else self.passes

    @property
    def level_phase_s(self) -> float:
        return 3.0 * self.stages[0].t_xy if self.level_s is None else self.level_s

    @property
    def realtime_conventional(self) -> bool:
        """One forward pass over live data to T3: nothing to compensate."""
        return self.mode == "conventional" and self.realtime


@dataclass(frozen=True)
class Timeline:
    """Sample indices in the record: alignment time 0 (`i0`), T1, T2, T3 (None: measured,
    known after the passes), and the first and last sample the alignment reads."""

    i0: int
    i1: int
    i2: int
    i3: int | None
    lo: int
    hi: int


def timeline(settings: AlignSettings, ts: float, samples: int) -> Timeline:
    """The samples of the alignment times in a record of `samples` increments at interval
    `ts` (s); InputError naming the time that lies past the end of the data."""

    def index(t: float, name: str) -> int:
        k = int(round((settings.start_s + t) / ts))
        if k > samples:
            raise InputError(name, f"{t} s (+ start_s {settings.start_s} s) is past the "
                                  f"end of the data ({samples * ts:.2f} s)")
        return k

    i0, i1, i2 = index(0.0, "start_s"), index(settings.t1_s, "t1_s"), index(settings.t2_s,
                                                                             "t2_s")
    i3: int | None
    if settings.t3_s == "measured":
        realtime = settings.realtime_conventional
        i3 = i2 if realtime else None
        hi = i2 if realtime else min(samples, i2 + int(round(MEASURED_MAX_S / ts)))
    else:
        i3 = hi = index(settings.t3_s, "t3_s")
    return Timeline(i0, i1, i2, i3, i0 if settings.coarse != "given" else i1, hi)


@dataclass(frozen=True)
class TruthRows:
    """The true attitude (rad, ``[pitch, roll, yaw]``) at some samples of a record:
    `samples` (M,) increasing record sample indices, `att` (M, 3) there.

    All that :func:`align` reads of the truth is its rows at :func:`truth_samples`, so a
    caller with a long run keeps those only (at 1 Hz output, 1 % of the samples).
    """

    samples: NDArray[np.int64]
    att: Array

    def at(self, samples: ArrayLike) -> Array:
        """The rows at record `samples`; InputError naming truth_att for one it lacks."""
        want = np.asarray(samples, np.int64)
        i = np.minimum(np.searchsorted(self.samples, want), len(self.samples) - 1)
        missing = self.samples[i] != want if len(self.samples) else np.ones(want.shape, bool)
        if np.any(missing):
            k = int(np.atleast_1d(want)[np.argmax(np.atleast_1d(missing))])
            raise InputError("truth_att", f"has no row at sample {k}; give the rows at "
                             "truth_samples(settings, ts, samples, stride)")
        return self.att[i]


def truth_samples(settings: AlignSettings, ts: float, samples: int,
                  stride: int = 1) -> NDArray[np.int64]:
    """The record samples (increasing) at which :func:`align` reads the truth for a record
    of `samples` increments at interval `ts` and the passes' `stride`: every sample the
    passes keep, T1, T2 and T3 (with a 'measured' T3, every sample from T2 to the end of the
    data it may take). Read-only; the same array for the same arguments (a batch's runs of
    a variant, the caller that collects the truth and align() itself)."""
    return _truth_samples(settings, float(ts), int(samples), int(stride))


@lru_cache(maxsize=16)
def _truth_samples(settings: AlignSettings, ts: float, samples: int,
                   stride: int) -> NDArray[np.int64]:
    tl = timeline(settings, ts, samples)
    end = tl.i3 if settings.realtime_conventional and tl.i3 is not None else tl.i2
    kept = tl.i1 + kept_samples(end - tl.i1, settings.mode, settings.pass_count,
                                settings.level_phase_s, ts, stride)
    if tl.i3 is None:  # every sample T3 may fall on
        k = np.union1d(kept, np.arange(tl.i2, tl.hi + 1)).astype(np.int64)
    else:
        k = with_samples(kept, [tl.i1, tl.i2, tl.i3])
    k.flags.writeable = False
    return k


@dataclass(frozen=True)
class Spread:
    """The error over the second half of the last pass: mean, std (ddof 0), max |·| per
    angle (rad), over `rows` stored rows between record times `t_from` and `t_to` (s)."""

    mean: Array
    std: Array
    max: Array
    t_from: float
    t_to: float
    rows: int


@dataclass(frozen=True)
class Alignment:
    """What an alignment produced (SI). Truth-dependent values are None without truth.

    t1, t2, t3 : alignment times of T1, T2, T3 actually used (whole samples), s.
    t3_source : ``configured`` or ``measured``.
    coarse_att : (3,) attitude at T1 the passes start from, rad.
    passes : one :class:`gcalign.align.cycles.PassRecord` per pass (record times and
        samples, attitude `q_nb` every `stride` samples and at both ends, in processing
        order).
    truth : the true attitude at the samples the alignment read it (:class:`TruthRows`),
        or None.
    att_t2, att_t3 : (3,) attitude at T2 and T3; truth_t2, truth_t3 : the truth there.
    compute_s : wall time of the passes, s. equivalent_s : data length the passes
        amount to (coarse window + passes × fine block), s.
    index_offset : record sample of alignment time 0.
    warnings : the caller's notes on its inputs (this module adds none).
    """

    settings: AlignSettings
    t1: float = field(metadata=stored("s", summary="s"))
    t2: float = field(metadata=stored("s", summary="s"))
    t3: float = field(metadata=stored("s", summary="s"))
    t3_source: str = field(metadata=stored(None, summary=""))
    coarse_att: Array
    passes: list[PassRecord]
    truth: TruthRows | None
    att_t2: Array
    att_t3: Array
    truth_t2: Array | None
    truth_t3: Array | None
    equivalent_s: float = field(metadata=stored("s", summary="s", label="equivalent"))
    compute_s: float = field(metadata=stored("s", summary="s", label="compute"))
    index_offset: int
    warnings: tuple[str, ...] = field(default=(), metadata=stored(None, summary=""))

    @property
    def azimuth_poles(self) -> str:
        return self.settings.azimuth_poles

    @property
    def error_t2(self) -> Array | None:
        """Euler-angle error at T2 (rad), yaw wrapped."""
        return None if self.truth_t2 is None else attitude_error(self.att_t2, self.truth_t2)

    @property
    def error_t3(self) -> Array | None:
        return None if self.truth_t3 is None else attitude_error(self.att_t3, self.truth_t3)

    @property
    def phi_t2(self) -> Array | None:
        """Misalignment φ at T2 (rad, ENU): C_nb,est C_nb,true^T = exp(−[φ×])."""
        return None if self.truth_t2 is None else _phi(self.att_t2, self.truth_t2)

    @property
    def phi_t3(self) -> Array | None:
        return None if self.truth_t3 is None else _phi(self.att_t3, self.truth_t3)

    @cached_property
    def pass_truth(self) -> list[Array] | None:
        """The true attitude (n, 3) at each pass's stored rows, or None."""
        if self.truth is None:
            return None
        return [self.truth.at(r.samples) for r in self.passes]

    @cached_property
    def pass_att(self) -> list[Array]:
        """Euler angles (n, 3) rad along each pass (its stored rows)."""
        return [quat_to_euler(r.q_nb) for r in self.passes]

    def pass_error_rows(self, i: int, rows: slice = slice(None)) -> Array | None:
        """Euler-angle error (rad; est − true, roll and yaw wrapped) at `rows` of pass i's
        stored rows, or None without truth: computed by the error kernel on those rows
        alone, each against the truth at its sample (a batch's summary needs the second
        half of the last pass and the end of each, not the 5 × 29001 rows of a §5.3 run)."""
        if self.truth is None:
            return None
        done = self.__dict__.get("pass_errors")
        if done is not None:
            return done[i][rows]
        r = self.passes[i]
        q, k = r.q_nb[rows], r.samples[rows]
        out = np.empty((len(k), 3))
        found = K.attitude_errors(q, k, self.truth.samples, self.truth.att, out)
        if found < len(k):
            self.truth.at(k[found])  # raises, naming the sample
        return out

    @cached_property
    def pass_errors(self) -> list[Array | None]:
        """Euler-angle error (n, 3) rad along each pass (est − true, roll and yaw wrapped);
        computed when first asked for."""
        return [self.pass_error_rows(i) for i in range(len(self.passes))]

    @cached_property
    def pass_phi(self) -> list[Array | None]:
        """Misalignment φ (n, 3) rad, ENU, along each pass."""
        if self.pass_truth is None:
            return [None] * len(self.passes)
        return [misalignment_q(r.q_nb, euler_to_quat(tr))
                for r, tr in zip(self.passes, self.pass_truth, strict=True)]

    def pass_end_error(self, i: int) -> Array | None:
        """Euler-angle error at the end of pass i (rad)."""
        err = self.pass_error_rows(i, slice(-1, None))
        return None if err is None else err[0].copy()

    def pass_rows(self) -> list[PassRows]:
        """Every pass at its stored rows as the results file keeps it."""
        return [PassRows(r.index, r.direction, r.kind, r.stage + 1, r.t, att, r.gains, err, phi)
                for r, att, err, phi in zip(self.passes, self.pass_att, self.pass_errors,
                                            self.pass_phi, strict=True)]

    def at_times(self) -> AlignmentAt:
        """The attitude at T1, T2 and T3 (the truth, errors and misalignment there) as the
        results file keeps it and the summary gives it."""
        return AlignmentAt(self.coarse_att, self.att_t2, self.truth_t2, self.error_t2,
                           self.att_t3, self.truth_t3, self.error_t3, self.phi_t2,
                           self.phi_t3, self.compute_s, self.equivalent_s)

    @property
    def pass_end_errors(self) -> list[Array | None]:
        """Euler-angle error at the end of every pass (rad)."""
        return [self.pass_end_error(i) for i in range(len(self.passes))]

    def last_pass_spread(self) -> Spread | None:
        """The error's spread over the second half of the last pass (where a pass has
        settled; the first half of a conventional run's only pass holds the coarse
        transient); None without truth."""
        r = self.passes[-1]
        h = len(r.t) // 2
        err = self.pass_error_rows(len(self.passes) - 1, slice(h, None))
        if err is None:
            return None
        mean, std, peak = K.column_spread(err)
        return Spread(mean, std, peak, float(min(r.t[h], r.t[-1])), float(max(r.t[h], r.t[-1])),
                      len(err))


def _phi(att_est: Array, att_true: Array) -> Array:
    return misalignment(euler_to_dcm(att_est), euler_to_dcm(att_true))


def _warm_up() -> None:
    """Load the compiled kernel (numba cache) before the computation is timed."""
    state = K.new_state(np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3), np.array([0.7, 0.0, 0.0]))
    K.gyrocompass_block(state, np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((2, 3)), False,
                        0.01, 1.0, WGS84.params(), np.zeros(K.GAINS_SIZE), K.ATTITUDE,
                        np.empty((2, 4)))


def _array(name: str, value: ArrayLike, shape: tuple[int, ...]) -> Array:
    """`value` as a float array of `shape` (-1: any length) with finite entries."""
    a = np.asarray(value, dtype=float)
    if a.ndim != len(shape) or any(s not in (-1, n) for s, n in zip(shape, a.shape,
                                                                     strict=True)):
        want = "(" + ", ".join("N" if s == -1 else str(s) for s in shape) + ")"
        raise InputError(name, f"must have shape {want}, got {a.shape}")
    # NaN and ±inf show in the extremes: two reductions, no temporary of the array's size
    if a.size and not (math.isfinite(a.min()) and math.isfinite(a.max())):
        raise InputError(name, "must be finite (NaN or infinity found)")
    return a


def _coarse_attitude(settings: AlignSettings, dtheta: Array, dv: Array, ts: float,
                     site: Array, earth: EarthModel, given: Array | None) -> Array:
    """Attitude at T1 (rad): `given` or the analytic / inertial result over the coarse
    window (`dtheta`, `dv`), plus ``coarse_offset``."""
    offset = np.asarray(settings.coarse_offset, float)
    if settings.coarse == "given":
        assert given is not None
        return given + offset
    try:
        if settings.coarse == "analytic":
            return coarse_mod.analytic_coarse(dtheta, dv, ts, site[0], earth) + offset
        return coarse_mod.inertial_frame_coarse(dtheta, dv, ts, site[0], site[1], site[2],
                                                earth=earth) + offset
    except ValueError as err:  # too short a window
        raise InputError("t1_s", f"the coarse window [0, {len(dtheta) * ts:g}] s does "
                              f"not fit method {settings.coarse!r}: {err}") from None


def _site(site: ArrayLike) -> Array:
    pos = _array("site", site, (3,))
    if abs(pos[0]) > math.radians(MAX_LAT_DEG):
        raise InputError("site", f"gyrocompassing needs |latitude| < {MAX_LAT_DEG:g}°, got "
                         f"{math.degrees(pos[0]):.4f}° (the horizontal earth rate vanishes)")
    return pos


def _window(settings: AlignSettings, ts: float, n: int, first: int,
            samples: int | None) -> Timeline:
    """The timeline of a record of `samples` increments, of which the arrays hold `n` from
    sample `first`; they must cover what the alignment reads."""
    total = first + n if samples is None else samples
    if not 0 <= first <= total - n:
        raise InputError("first_sample", f"{first} with {n} increments does not fit a record "
                         f"of {total}")
    tl = timeline(settings, ts, total)
    if tl.lo < first or tl.hi > first + n:
        raise InputError("dtheta", f"covers samples {first} .. {first + n}; the alignment "
                         f"reads {tl.lo} .. {tl.hi}")
    return tl


def _given(settings: AlignSettings, att_t1: ArrayLike | None, truth: TruthRows | None,
           i1: int) -> Array | None:
    """The attitude at T1 of coarse method 'given' (`att_t1`, else the truth at sample i1)."""
    if settings.coarse != "given":
        return None
    if att_t1 is not None:
        return _array("att_t1", att_t1, (3,))
    if truth is None:
        raise InputError("coarse", "'given' needs att_t1 or truth_att; use 'analytic' or "
                         "'inertial' for recorded data")
    return truth.at(i1)


def _truth(truth_att: ArrayLike | TruthRows | None, settings: AlignSettings, ts: float,
           tl_samples: int, stride: int, lo: int, n: int) -> TruthRows | None:
    """The truth as :class:`TruthRows`: given so, checked; an (N+1, 3) array of every
    sample of the arrays, its rows at :func:`truth_samples` (all the alignment reads)."""
    if truth_att is None:
        return None
    if isinstance(truth_att, TruthRows):
        need = truth_samples(settings, ts, tl_samples, stride)
        if truth_att.samples is need and isinstance(truth_att.att, np.ndarray) \
                and truth_att.att.shape == (len(need), 3) and truth_att.att.dtype == float:
            _array("truth_att", truth_att.att, (len(need), 3))  # finite
            return truth_att  # the rows of truth_samples itself (a collecting caller's)
        k = np.asarray(truth_att.samples)
        if k.ndim != 1 or k.dtype.kind not in "iu" or np.any(np.diff(k) <= 0):
            raise InputError("truth_att", "samples must be increasing whole sample numbers")
        rows = TruthRows(k.astype(np.int64), _array("truth_att", truth_att.att, (len(k), 3)))
        if np.array_equal(rows.samples, need):
            return rows
        return TruthRows(need, rows.at(need))  # InputError for a row it lacks
    full = _array("truth_att", truth_att, (n + 1, 3))
    k = truth_samples(settings, ts, tl_samples, stride)
    return TruthRows(k, full[k - lo])


def _passes(settings: AlignSettings, state0: Array, tl: Timeline,
            block: Callable[[int, int], Block], t0: float, ts: float, earth: EarthModel,
            stride: int) -> tuple[list[PassRecord], Array, Array, int, float]:
    """The passes and the attitude at T2 and T3: (records, q2, q3, i3, compute_s).

    Real-time conventional: one forward pass over live data to T3, no latency to
    compensate ('measured' then means T3 = T2). Otherwise the passes run over the stored
    block [T1, T2] and the compensation carries the attitude on to T3.
    """
    realtime = settings.realtime_conventional
    end = tl.i3 if realtime and tl.i3 is not None else tl.i2
    _warm_up()
    t_start = time.perf_counter()
    state_end, records = run_passes(
        state0, block(tl.i1, end), settings.mode, settings.pass_count, list(settings.stages),
        settings.azimuth_poles, settings.level_phase_s, earth, stride)
    compute = time.perf_counter() - t_start
    if realtime:
        rec = records[0]
        q2 = rec.q_nb[np.searchsorted(rec.t, t0 + tl.i2 * ts - 1e-9 * ts)]
        return records, q2, state_end[K.ATT].copy(), end, compute
    i3 = tl.i2 + math.ceil(compute / ts) if tl.i3 is None else tl.i3
    if i3 > tl.hi:
        raise InputError("t3_s", "'measured' latency runs past the end of the data")
    q3 = compensate(settings.compensation, state_end, block(tl.i2, i3), earth)
    return records, state_end[K.ATT].copy(), q3, i3, compute


def align(dtheta: ArrayLike, dv: ArrayLike, ts: float, site: ArrayLike,
          settings: AlignSettings = AlignSettings(), *, earth: EarthModel = WGS84,
          att_t1: ArrayLike | None = None, position_t1: ArrayLike | None = None,
          vref: ArrayLike | None = None, vref_body: bool = False,
          truth_att: ArrayLike | TruthRows | None = None, t0: float = 0.0, stride: int = 1,
          first_sample: int = 0, samples: int | None = None) -> Alignment:
    """Coarse alignment, the passes of the mode and the T2 → T3 compensation (seed 000).

    Parameters
    ----------
    dtheta, dv : (N, 3) gyro and velocity increments (rad, m/s), body frame (x right,
        y forward, z up); row j is increment ``first_sample + j`` of the record.
    ts : sample interval, s.
    site : (3,) ``[lat, lon, h]`` (rad, rad, m) of the start; the coarse alignment's.
    settings : :class:`AlignSettings`.
    earth : earth model.
    att_t1 : (3,) attitude at T1 (rad) for coarse ``given`` (default: `truth_att` at T1).
    position_t1 : (3,) position at T1 (default `site`); the loops carry it along `vref`.
    vref, vref_body : (N+1, 3) reference velocity at the samples (m/s; ENU, or body frame
        if `vref_body`: an odometer); default zero (a static or swinging base).
    truth_att : the true attitude (rad), for the errors: (N+1, 3) at the samples, or a
        :class:`TruthRows` with (at least) the rows at :func:`truth_samples`.
    t0 : record time of sample 0, s (the pass records' `t` are record times).
    stride : the passes keep their attitude every `stride` samples (and at their ends).
    first_sample, samples : where the arrays sit in a longer record of `samples`
        increments (default: they are the whole record); they must cover
        :func:`timeline`'s ``lo`` .. ``hi``.

    Returns
    -------
    Alignment. InputError (a ValueError) names the argument or setting it refuses.
    """
    prep = _prepare(dtheta, dv, ts, site, settings, earth, att_t1, position_t1, vref,
                    vref_body, truth_att, t0, stride, first_sample, samples)
    records, q2, q3, i3, compute = _passes(settings, prep.state0, prep.tl, prep.block, t0,
                                           prep.ts, earth, prep.stride)
    return _finish(prep, records, q2, q3, i3, compute)


@dataclass(frozen=True)
class _Prepared:
    """An alignment's inputs, checked, up to the passes: its settings and timeline, the
    truth rows, the coarse attitude at T1, the loop state there and its data by range."""

    settings: AlignSettings
    ts: float
    t0: float
    stride: int
    earth: EarthModel
    vref_body: bool
    tl: Timeline
    truth: TruthRows | None
    att1: Array
    state0: Array
    block: Callable[[int, int], Block]


def _prepare(dtheta: ArrayLike, dv: ArrayLike, ts: float, site: ArrayLike,
             settings: AlignSettings, earth: EarthModel, att_t1: ArrayLike | None,
             position_t1: ArrayLike | None, vref: ArrayLike | None, vref_body: bool,
             truth_att: ArrayLike | TruthRows | None, t0: float, stride: int,
             first_sample: int, samples: int | None) -> _Prepared:
    """:func:`align`'s checks, truth, coarse alignment and initial loop state."""
    ts = float(ts)
    if not (math.isfinite(ts) and ts > 0):
        raise InputError("ts", f"must be a finite interval > 0 s, got {ts}")
    if not (isinstance(stride, (int, np.integer)) and stride >= 1):
        raise InputError("stride", f"must be a whole number ≥ 1, got {stride!r}")
    dth = _array("dtheta", dtheta, (-1, 3))
    n = len(dth)
    dvb = _array("dv", dv, (n, 3))
    pos0 = _site(site)
    ref = np.zeros((n + 1, 3)) if vref is None else _array("vref", vref, (n + 1, 3))
    lo = first_sample
    tl = _window(settings, ts, n, lo, samples)
    truth = _truth(truth_att, settings, ts, lo + n if samples is None else samples, int(stride),
                   lo, n)
    i0, i1 = tl.i0, tl.i1
    given = _given(settings, att_t1, truth, i1)
    pos1 = pos0.copy() if position_t1 is None else _array("position_t1", position_t1, (3,))
    att1 = _coarse_attitude(settings, dth[i0 - lo:i1 - lo], dvb[i0 - lo:i1 - lo], ts, pos0,
                            earth, given)
    q1 = euler_to_quat(att1)
    v1 = quat_to_dcm(q1) @ ref[i1 - lo] if vref_body else ref[i1 - lo]

    def block(a: int, b: int) -> Block:
        """Increments a .. b-1 and the reference at samples a .. b, as the passes take them
        (block sample k is record sample a + k)."""
        i, j = a - lo, b - lo
        return Block(a, t0, dth[i:j], dvb[i:j], ref[i:j + 1], vref_body, ts)

    return _Prepared(settings, ts, t0, int(stride), earth, vref_body, tl, truth, att1,
                     K.new_state(q1, v1, pos1), block)


def _finish(prep: _Prepared, records: list[PassRecord], q2: Array, q3: Array, i3: int,
            compute: float) -> Alignment:
    """The :class:`Alignment` of prepared inputs, their passes and the attitude at T2, T3."""
    settings, tl, truth, ts = prep.settings, prep.tl, prep.truth, prep.ts
    i0, i1, i2 = tl.i0, tl.i1, tl.i2
    if settings.realtime_conventional:
        equivalent = (i3 - i0) * ts
    else:
        equivalent = (i1 - i0) * ts + settings.pass_count * (i2 - i1) * ts
    return Alignment(
        settings=settings,
        t1=(i1 - i0) * ts,  # the sample times actually used
        t2=(i2 - i0) * ts,
        t3=(i3 - i0) * ts,
        t3_source="measured" if settings.t3_s == "measured" else "configured",
        coarse_att=prep.att1,
        passes=records,
        truth=truth,
        att_t2=quat_to_euler(q2),
        att_t3=quat_to_euler(q3),
        truth_t2=None if truth is None else truth.at(i2),
        truth_t3=None if truth is None else truth.at(i3),
        compute_s=compute,
        equivalent_s=equivalent,
        index_offset=i0,
    )
