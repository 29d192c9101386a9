"""Gyrocompass alignment of a scenario: its data as arrays, :func:`gcalign.align.gyrocompass.align`.

Seed 000. The scenario gives the settings (:func:`settings_of`) and the data (a
:class:`gcalign.app.data.Stream`, simulated on the fly or recorded); :func:`collect` reads
only the samples the alignment needs, the core aligns them, and the result
(:class:`gcalign.align.gyrocompass.Alignment`) becomes the summary and the /align group.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from gcalign.align.gyrocompass import (
    Alignment,
    AlignSettings,
    Timeline,
    TruthRows,
    align,
    timeline,
    truth_samples,
)
from gcalign.app.command import Outcome
from gcalign.app.data import Recording, RunData, Stream, scenario_data, scenario_stream, stream_of
from gcalign.errors import InputError, ScenarioError
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.align import Aiding, AlignConfig
from gcalign.nav.earth import EarthModel
from gcalign.nav.rotation import euler_to_dcm, quat_to_euler
from gcalign.schema import ATT_FRAME, placed, plain, summary_of
from gcalign.units import DPH, DPSH, angle_text

if TYPE_CHECKING:
    import h5py

Progress = Callable[[float, float, str], None]


def settings_of(cfg: AlignConfig, motion_kind: str | None) -> AlignSettings:
    """The core's settings (SI) of a scenario's align section; the motion kind picks the
    default pole set (data simulated earlier carry it along). Not for transfer mode (its
    own filter, :mod:`gcalign.app.align.transfer`)."""
    mode = cfg.mode
    if mode == "transfer":
        raise ValueError("settings_of: transfer mode has no gyrocompass settings")
    c = cfg.coarse
    off = np.radians(c.error_deg if c.method == "given" else c.offset_deg)
    return AlignSettings(
        mode=mode, start_s=cfg.start_s, t1_s=cfg.t1_s, t2_s=cfg.t2_s, t3_s=cfg.t3_s,
        realtime=cfg.realtime, compensation=cfg.compensation, coarse=c.method,
        coarse_offset=(float(off[0]), float(off[1]), float(off[2])),
        azimuth_poles=cfg.poles_for(motion_kind),  # type: ignore[arg-type]
        level_s=cfg.level_phase_s, stages=tuple(cfg.stage_list()), passes=cfg.pass_count)


@dataclass(frozen=True)
class Window:
    """Samples lo .. hi of a run as the core takes them (SI): increments lo .. hi-1, the
    reference velocity at samples lo .. hi, the true attitude at the samples kept (None for
    recorded data without a reference), the true position at T1 (the site without truth)."""

    dtheta: np.ndarray
    dv: np.ndarray
    vref: np.ndarray
    truth: TruthRows | None
    pos_t1: np.ndarray


def _reference(aiding: Aiding, att, v_n, rng: np.random.Generator, body: bool,
               rows: slice, speeds: dict | None = None, k0: int = 0) -> np.ndarray:
    """Reference velocity at `rows` of samples with true attitude att and velocity v_n
    (n, 3): (m, 3) ENU, or for an odometer the forward speed (m,).

    nav: the true ENU velocity plus white noise. odometer: the body-frame forward speed
    plus white noise (seed §1: converted to the navigation frame with the computed attitude
    inside the loop). The noise of successive blocks continues one stream: it is drawn for
    all n samples, whichever rows are kept (NumPy's normals, drawn by
    :func:`gcalign.sim._noise.normals`). `speeds` keeps the true forward speed of the
    block at sample `k0` for the next seed of the same truth.
    """
    from gcalign.sim._noise import normals

    noise = aiding.noise_mps
    if not body:
        return v_n[rows] + noise * normals(rng, v_n.size).reshape(v_n.shape)[rows]
    white = normals(rng, len(att))[rows]
    key = (k0, rows.start, rows.stop)
    speed = None if speeds is None else speeds.get(key)
    if speed is None:
        att, v_n = att[rows], v_n[rows]
        # y of C_bn v_n: column y of C_nb (the terms of euler_to_dcm, summed in einsum's order)
        sp, cp = np.sin(att[:, 0]), np.cos(att[:, 0])
        sy, cy = np.sin(att[:, 2]), np.cos(att[:, 2])
        speed = (-sy * cp) * v_n[:, 0] + (cy * cp) * v_n[:, 1] + sp * v_n[:, 2]
        if speeds is not None:
            speeds[key] = speed
    return speed + noise * white


def collect(stream: Stream, tl: Timeline, aiding: Aiding,
            progress: Progress | None = None, reference=None,
            keep: np.ndarray | None = None, ref_gap: float | None = None,
            shared: dict | None = None) -> Window:
    """One pass over the stream for the samples tl.lo .. tl.hi; the rest of the run is
    never held (nor, simulated, generated). `progress(done_s, total_s, what)` hears of
    every block (the simulation, if it is one, is most of an alignment's time). A
    `reference` (:class:`gcalign.io.recorded.Reference`, recorded data) stands for the
    truth attitude, for the errors only. The truth is kept at the record samples `keep`
    (increasing, within lo .. hi: :func:`gcalign.align.gyrocompass.truth_samples`, all that
    the alignment reads), by default at every sample lo .. hi.

    `shared` (a dict, empty at first) serves the seeds of one simulated variant: what no
    seed changes (the truth rows kept, the position at T1, an odometer's true speed) is
    taken from the first seed's window (read-only), the same numbers without the work.
    """
    source = aiding.source  # simulated aiding on recorded data is refused by Align.check
    has_truth = stream.truth0 is not None
    body = source == "odometer"
    rng = np.random.default_rng([0 if stream.seed is None else stream.seed, 1])
    lo, hi, i1 = tl.lo, tl.hi, tl.i1
    m = hi - lo
    samples = np.arange(lo, hi + 1) if keep is None else np.asarray(keep, np.int64)
    dtheta, dv = np.empty((m, 3)), np.empty((m, 3))
    vref = np.zeros((m + 1, 3))
    if source == "file":  # the file's velocity at the samples lo .. hi
        from gcalign.io.recorded.aiding import velocity_at

        t_samples = stream.t0 + np.arange(lo, hi + 1) * stream.ts
        vref, _ = velocity_at(aiding.read(), t_samples, "align.aiding",
                              max_gap=aiding.max_gap_s)
        source = "none"  # nothing more to take from the truth
    truth_att = np.empty((len(samples), 3)) if has_truth else None
    pos_t1 = stream.site.copy()
    if reference is not None and not has_truth:
        truth_att = _reference_attitude(reference, stream, lo, hi, samples, ref_gap)
    memo = None
    known = False  # the truth rows and the position at T1 are the shared ones
    if shared is not None and stream.truth0 is not None and reference is None:
        # the truth's memory (each seed holds its own view of the cached simulation), kept
        # alive in the memo so that no other array can take its address meanwhile
        held = stream.truth0.att
        token = (held.ctypes.data, lo, hi, i1, len(samples),
                 int(samples[0]) if len(samples) else -1,
                 int(samples[-1]) if len(samples) else -1)
        if shared.get("token") != token:  # another truth: start again
            shared.clear()
            shared.update(token=token, held=held, speeds={})
        memo = shared
        known = "truth_att" in shared
        if known:
            truth_att, pos_t1 = shared["truth_att"], shared["pos_t1"].copy()
    speeds = None if memo is None else memo["speeds"]

    def take(k0: int, att, v_n, pos) -> None:
        """Truth rows of samples k0 .. k0+len-1: reference velocity, attitude, pos at T1."""
        nonlocal pos_t1
        n = len(att)
        a, c = max(lo - k0, 0), min(hi - k0 + 1, n)  # the block's rows of samples lo .. hi
        rows, out = slice(a, max(a, c)), slice(k0 + a - lo, k0 + max(a, c) - lo)
        if source != "none":
            ref = _reference(aiding, att, v_n, rng, body, rows, speeds, k0)
            if body:
                vref[out, 1] = ref  # an odometer measures along the body's y axis only
            else:
                vref[out] = ref
        if known:
            return
        assert truth_att is not None
        kept = slice(*np.searchsorted(samples, [k0, k0 + n]))  # the kept samples here
        truth_att[kept] = att[samples[kept] - k0]
        if k0 <= i1 <= k0 + n - 1:
            pos_t1 = pos[i1 - k0].copy()

    if stream.truth0 is not None:
        tr0 = stream.truth0
        take(0, tr0.att, tr0.v_n, tr0.pos)
    for b in stream.blocks():
        n = len(b.t)
        a, c = max(lo - b.k0, 0), min(hi - b.k0, n)
        if a < c:
            dtheta[b.k0 + a - lo:b.k0 + c - lo] = b.dtheta[a:c]
            dv[b.k0 + a - lo:b.k0 + c - lo] = b.dv[a:c]
        if b.truth is not None:
            take(b.k0 + 1, b.truth.att, b.truth.v_n, b.truth.pos)
        if progress is not None:
            what = "simulating (data s)" if has_truth else "reading (data s)"
            progress(min(b.k0 + n, hi) * stream.ts, hi * stream.ts, what)
        if b.k0 + n >= hi:
            break  # everything needed is in; the rest of the run is never generated
    if memo is not None and not known and truth_att is not None:
        truth_att.flags.writeable = False
        memo.update(truth_att=truth_att, pos_t1=pos_t1.copy())
    truth = None if truth_att is None else TruthRows(samples, truth_att)
    return Window(dtheta, dv, vref, truth, pos_t1)


def _reference_attitude(reference, stream: Stream, lo: int, hi: int,
                        samples: np.ndarray, max_gap: float | None = None) -> np.ndarray:
    """The reference's attitude at record `samples` (slerp); ScenarioError naming
    align.start_s when it does not cover the samples lo .. hi the alignment reads."""
    from gcalign.io.recorded import reference_at

    t_lo, t_hi = stream.t0 + lo * stream.ts, stream.t0 + hi * stream.ts
    lo_t, hi_t = float(reference.t[0]), float(reference.t[-1])
    if t_lo < lo_t - 1e-6 * stream.ts or t_hi > hi_t + 1e-6 * stream.ts:
        raise ScenarioError(
            f"reference: {reference.record.get('path', 'the reference')} covers {lo_t:.3f} .. "
            f"{hi_t:.3f} s, the alignment reads {t_lo:.3f} .. {t_hi:.3f} s (data time): "
            "move align.start_s or shorten align.t2_s / t3_s, or remove the reference")
    _no_gap(reference, t_lo, t_hi, max_gap)
    return reference_at(reference, stream.t0 + samples * stream.ts, tol=1e-6)[0]


def _no_gap(reference, t_lo: float, t_hi: float, max_gap: float | None) -> None:
    """ScenarioError when the reference has a gap longer than `max_gap` (default twice its
    median interval) inside [t_lo, t_hi]: an error against a line drawn across a gap is not
    a measurement."""
    from gcalign.io.recorded.reference import reference_gaps

    inside = [g for g in reference_gaps(reference, max_gap) if g.end > t_lo and g.start < t_hi]
    if inside:
        g = inside[0]
        raise ScenarioError(
            f"reference: {reference.record.get('path', 'the reference')} has no epoch for "
            f"{g.length:.3f} s after {g.start:.3f} s (data time), inside the alignment "
            f"{t_lo:.3f} .. {t_hi:.3f} s: no error against it can be given there (move "
            "align.start_s or shorten align.t2_s / t3_s, or set reference.max_gap_s if the "
            "gap is harmless)")


#: The share of the signal an excursion of the base may reach before the analytic coarse
#: alignment is warned about: 1 % of the horizontal earth rotation over the window (the
#: heading signal) and an equivalent tilt of 1e-4 rad for the specific force (20″).
STILL_SHARE = 0.01
STILL_TILT_RAD = 1e-4


def still_base_warnings(dtheta: np.ndarray, dv: np.ndarray, ts: float, lat: float,
                        earth: EarthModel) -> list[str]:
    """Is the base still enough for the analytic coarse alignment?

    The analytic (static double-vector) method takes the block-averaged angular rate for
    the earth rate and the averaged specific force for gravity; a base that turns or
    accelerates and comes back biases both averages (a swing of a few degrees turns the
    heading by more than 100°). Measure it: the largest excursion of the integrated
    increments about their mean trend (sensor noise only, on a still base), against 1 % of
    the horizontal earth rotation over the window (ω_ie cos L · T) and against the velocity
    a tilt of 1e-4 rad would give (1e-4 · g · T).
    """
    T = len(dtheta) * ts
    k = np.arange(1, len(dtheta) + 1)[:, None]

    def excursion(inc: np.ndarray) -> float:
        wander = np.cumsum(inc, axis=0) - k * inc.mean(axis=0)
        return float(np.max(np.linalg.norm(wander, axis=1))) if len(inc) else 0.0

    turn, limit = excursion(dtheta), STILL_SHARE * earth.omega_ie * math.cos(lat) * T
    if turn > limit:
        return [f"align.coarse.method: 'analytic' assumes a still base, but the base turned "
                f"by up to {angle_text(turn)} about its mean rate during the {T:g} s coarse "
                f"window (1 % of the earth's rotation over it: {angle_text(limit)}); expect "
                "a wrong heading: use 'inertial' on a moving or swinging base"]
    shift, limit = excursion(dv), STILL_TILT_RAD * float(earth.gravity(lat)) * T
    if shift > limit:
        return [f"align.coarse.method: 'analytic' assumes a still base, but its velocity "
                f"changed by up to {shift:.3g} m/s during the {T:g} s coarse window (a tilt "
                f"of 1e-4 rad gives {limit:.3g} m/s); expect wrong tilts: use 'inertial' on a "
                "moving or swinging base"]
    return []


def _at_rest_warnings(sc: Scenario, stream: Stream, tl: Timeline, data: Window) -> list[str]:
    """A recording aligned without aiding is taken to stand still over [0, T2]; say so
    when its reference or its IMU show that it moves (:mod:`gcalign.app.at_rest`)."""
    from gcalign.app.at_rest import evidence

    k = slice(tl.i0 - tl.lo, tl.i2 - tl.lo)
    why = evidence(sc, data.dtheta[k], data.dv[k], stream.ts, stream.site, stream.earth,
                   stream.t0 + tl.i0 * stream.ts, stream.t0 + tl.i2 * stream.ts)
    if why is None:
        return []
    return [f"align.aiding.source: 'none' takes the base to be at rest, but {why}; expect "
            "a wrong heading and tilt: give the vehicle's velocity (align.aiding: {source: "
            "file, path, format})"]


#: The heading is out of reach when the gyrocompass's heading floor (the horizontal gyro
#: drift over the horizontal earth rate) or its noise over the window passes this.
HEADING_REACH_RAD = math.radians(1.0)


def _reach_text(what: str, drift: float, omega_h: float, lat: float) -> str:
    floor = drift / omega_h
    floor_text = (f"a gyrocompass heading floor of ε/(ω_ie cos L) = {math.degrees(floor):.3g}°"
                  if floor < 0.5 else f"{floor:.3g}× the rate it must measure: no heading")
    return (f"the heading is out of reach of these gyros: {what} {drift / DPH:.3g} °/h "
            f"against the horizontal earth rate ω_ie cos L = {omega_h / DPH:.3g} °/h at "
            f"{math.degrees(lat):.1f}°, {floor_text}; the yaw is not a measurement")


def heading_reach_warnings(sc: Scenario, stream: Stream, tl: Timeline, data: Window,
                           reference) -> list[str]:
    """Can the gyros find north at all? A gyrocompass takes the heading from the horizontal
    earth rate Ω = ω_ie cos L; a horizontal gyro drift ε leaves a heading error of ε/Ω
    (rad) whatever the loops do, and white gyro noise N one of about N/(Ω √T) over a
    window of T s. One line with the numbers when either passes 1°:

    * the grade, for simulated data: the scenario's gyro bias, turned into n at the true
      attitude at T1 (its horizontal part), and its ARW;
    * the data, for a recording with a reference attitude: the gyros strapped down from the
      reference's attitude at T1 (with ω_ie and the transport rate of the reference's mean
      velocity) drift from the reference by φ at T2; its horizontal part over T is the
      drift the loops would meet.
    """
    lat, earth, ts = float(stream.site[0]), stream.earth, stream.ts
    omega_h = earth.omega_ie * math.cos(lat)
    T = (tl.i2 - tl.i1) * ts
    if T <= 0 or omega_h <= 0:
        return []
    out = []
    if stream.truth0 is not None and data.truth is not None and sc.imu is not None:
        err = sc.imu.errors().gyro
        C_nb = euler_to_dcm(data.truth.att[int(np.searchsorted(data.truth.samples, tl.i1))
                                           if len(data.truth.samples) else 0])
        eps_n = C_nb @ np.asarray(err.bias, dtype=float)
        drift = float(np.hypot(eps_n[0], eps_n[1]))
        if drift / omega_h > HEADING_REACH_RAD:
            out.append("imu.gyro.bias_dph: " + _reach_text(
                "its bias has a horizontal part of", drift, omega_h, lat))
        arw = float(np.max(err.noise))
        noise = arw / (omega_h * math.sqrt(T))
        if noise > HEADING_REACH_RAD and not out:
            out.append(f"imu.gyro.arw_dprh: the heading is out of reach of these gyros: ARW "
                       f"{arw / DPSH:.3g} °/√h over the {T:.4g} s window against the "
                       f"horizontal earth rate ω_ie cos L = {omega_h / DPH:.3g} °/h leaves a "
                       f"heading noise of about ARW/(ω_ie cos L √T) = "
                       f"{math.degrees(noise):.3g}°; the yaw is not a measurement")
    elif reference is not None and getattr(reference, "att", None) is not None:
        from gcalign.io.recorded import reference_at
        from gcalign.nav.rotation import euler_to_quat, misalignment_q
        from gcalign.nav.strapdown import integrate_attitude

        t_a, t_b = stream.t0 + tl.i1 * ts, stream.t0 + tl.i2 * ts
        try:
            att, v_n, pos = reference_at(reference, np.array([t_a, t_b]), tol=1e-6)
        except ScenarioError:
            return []
        k = slice(tl.i1 - tl.lo, tl.i2 - tl.lo)
        v = 0.5 * (v_n[0] + v_n[1])
        w_in = earth.omega_ie_n(lat) + earth.omega_en_n(lat, float(pos[0, 2]), v)
        q = integrate_attitude(euler_to_quat(att[0]), data.dtheta[k], ts, w_in)[-1]
        phi = misalignment_q(q, euler_to_quat(att[1]))
        drift = float(np.hypot(phi[0], phi[1])) / T
        if drift / omega_h > HEADING_REACH_RAD:
            name = sc.reference.path.name if sc.reference is not None else "the reference"
            out.append(f"reference ({name}): " + _reach_text(
                f"strapped down from the reference's attitude over the {T:.4g} s window, "
                f"the gyros drift from it by {math.degrees(float(np.hypot(phi[0], phi[1]))):.3g}° "
                "horizontally, a horizontal drift of", drift, omega_h, lat))
    return out


def _scenario_error(err: InputError) -> ScenarioError:
    """The core's refusal, naming the scenario field it comes from."""
    names = {"site": "site.lat_deg", "coarse": "align.coarse.method", "passes": "align.stages"}
    return ScenarioError(f"{names.get(err.field, 'align.' + err.field)}: {err.message}")


def run_alignment(sc: Scenario, stream: Stream | RunData,
                  progress: Progress | None = None) -> Alignment:
    """Align a scenario's data (a stream, or the whole run in memory): the core's result
    with the scenario's warnings."""
    if isinstance(stream, RunData):
        stream = stream_of(stream)
    try:
        kw, warnings = alignment_inputs(sc, stream, progress)
        run = align(**kw)
    except InputError as err:
        raise _scenario_error(err) from None
    return replace(run, warnings=tuple(warnings))


def alignment_inputs(sc: Scenario, stream: Stream, progress: Progress | None = None,
                     shared: dict | None = None) -> tuple[dict, list[str]]:
    """The keyword arguments of :func:`gcalign.align.gyrocompass.align` for a scenario's
    data, and the scenario's warnings on them (InputError from the core's checks).
    `shared`: :func:`collect`'s, for the seeds of one variant."""
    cfg = sc.align or AlignConfig()
    kind = sc.motion.kind if sc.motion else (
        stream.header.meta.get("motion_kind") if stream.header is not None else None)
    warnings = []
    if kind == "moving" and cfg.aiding.source == "none":
        warnings.append(
            "a moving base with align.aiding.source 'none': the loops take the "
            "vehicle's accelerations for tilt; expect degrees of error"
        )
    ts = stream.ts
    stride = sc.output.stride(1.0 / ts, stream.samples * ts)  # a recorded file's rate is known here
    settings = settings_of(cfg, kind)
    tl = timeline(settings, ts, stream.samples)
    reference = sc.reference.read() if sc.reference is not None else None
    keep = truth_samples(settings, ts, stream.samples, stride)
    data = collect(stream, tl, cfg.aiding, progress, reference, keep,
                   None if sc.reference is None else sc.reference.max_gap_s, shared)
    if settings.coarse == "analytic":
        k = slice(tl.i0 - tl.lo, tl.i1 - tl.lo)
        warnings += still_base_warnings(data.dtheta[k], data.dv[k], ts, stream.site[0],
                                        stream.earth)
    if cfg.aiding.source == "none" and stream.truth0 is None:  # recorded: at rest?
        warnings += _at_rest_warnings(sc, stream, tl, data)
    warnings += heading_reach_warnings(sc, stream, tl, data, reference)
    kw = dict(dtheta=data.dtheta, dv=data.dv, ts=ts, site=stream.site, settings=settings,
              earth=stream.earth, position_t1=data.pos_t1, vref=data.vref,
              vref_body=cfg.aiding.body, truth_att=data.truth, t0=stream.t0, stride=stride,
              first_sample=tl.lo, samples=stream.samples)
    return kw, warnings


def summaries_of_seeds(sc: Scenario, seeds: list[int],
                       cache_key: str | None) -> list[dict | Exception]:
    """The summary of each seed's run of a simulated scenario, as :func:`execute` would give
    it, the seeds aligned in lockstep (:func:`gcalign.align.lockstep.align_runs`: each
    seed's numbers to the bit those of its own run; ``compute_s`` is the lockstep's time
    per run). A seed whose run fails has its exception in its place. For a batch: the
    noise-free simulation is shared through `cache_key`, and the caller has made the
    preflight (:func:`gcalign.app.preflight.checked_run`'s) for the variant."""
    from gcalign.align.lockstep import align_runs
    from gcalign.io.results import finite_summary

    out: list[dict | Exception] = []
    runs, streams, notes, where = [], [], [], []
    shared: dict = {}  # what the seeds' windows share (collect)
    for seed in seeds:
        try:
            stream = stream_of(scenario_data(sc, seed, cache_key))
            kw, warnings = alignment_inputs(sc, stream, shared=shared)
        except InputError as err:
            out.append(_scenario_error(err))
            continue
        except Exception as err:  # noqa: BLE001 - recorded for this seed, as a run would be
            out.append(err)
            continue
        where.append(len(out))
        out.append(ScenarioError("not aligned"))
        streams.append(stream)
        notes.append(tuple(warnings))
        runs.append(kw)

    def summary(i: int, run: Alignment) -> dict:
        s = alignment_summary(replace(run, warnings=notes[i]), streams[i], sc.name)
        finite_summary(s, "align")
        return s

    for i, res in enumerate(align_runs(runs, summary)):
        out[where[i]] = _scenario_error(res) if isinstance(res, InputError) else res
    return out


def lockstep_ok(sc: Scenario) -> bool:
    """Can a batch align this variant's seeds in lockstep (:func:`summaries_of_seeds`)? A
    simulated gyrocompass alignment (not transfer mode), without a recorded reference."""
    cfg = sc.align or AlignConfig()
    return (sc.imu_file is None and sc.motion is not None and sc.reference is None
            and cfg.mode != "transfer" and cfg.aiding.source != "file")


def alignment_summary(run: Alignment, stream: Stream | RunData, name: str) -> dict:
    """Plain-number summary (degrees, seconds): the JSON contract of `gcalign align --json`;
    the times and notes as the fields of :class:`Alignment` say, the settings, the attitude
    at T1, T2, T3 and the passes placed around them."""
    if isinstance(stream, RunData):
        stream = stream_of(stream)
    s = run.settings
    realtime = s.realtime_conventional
    start, ts = stream.t0, stream.ts  # data time of sample 0

    def aligned_time(t_data: float) -> float:
        return (round((t_data - start) / ts) - run.index_offset) * ts

    spread = run.last_pass_spread()
    last = None if spread is None else {
        "window_s": [aligned_time(spread.t_from), aligned_time(spread.t_to)],
        "rows": spread.rows,
        **{f"{k}_deg": plain(getattr(spread, k), "deg") for k in ("mean", "std", "max")}}
    return placed(summary_of(run), {"t1_s": {
        "scenario": name,
        "seed": stream.seed,
        "source": stream.source,
        "error_source": None if run.truth_t3 is None else (
            "truth" if stream.truth0 is not None else "reference"),
        "mode": s.mode,
        "compensation": "real time" if realtime else s.compensation,
        "azimuth_poles": run.azimuth_poles,
        "stages": [{"stage": i + 1, "t_xy_s": st.t_xy, "t_z_s": st.t_z, "xi": st.xi,
                    "passes": st.passes} for i, st in enumerate(s.stages)]}, "equivalent_s": {
        **summary_of(run.at_times()),  # the attitude at T1, T2, T3 and its errors, in deg
        "last_pass_error": last,
        "passes": [placed(summary_of(r), {"direction": {"pass": r.index + 1}}, {
            "stage": r.stage + 1, "t_end_s": aligned_time(float(r.t[-1])),
            "error_deg": plain(run.pass_end_error(r.index), "deg"),
            "attitude_deg": np.degrees(quat_to_euler(r.q_nb[-1])).tolist()})
            for r in run.passes]},
        "compute_s": {"data_used_s": run.t3 if realtime else run.t2}})


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            progress: Progress | None = None, recording: Recording | None = None) -> Outcome:
    """Simulate (or read) the data, align, summarise; the registry's entry point.
    `recording`: the recorded file as the preflight read it."""
    if sc.align is not None and sc.align.mode == "transfer":  # spec 006: its own room
        from gcalign.app.align import transfer
        return transfer.execute(sc, seed, cache_key, progress, recording)
    if cache_key is not None:  # a batch: the noise-free simulation is shared by the seeds
        stream = stream_of(scenario_data(sc, seed, cache_key))
    else:
        stream = scenario_stream(sc, seed, recording=recording)
    run = run_alignment(sc, stream, progress)
    summary = alignment_summary(run, stream, sc.name)
    against = summary["error_source"] or "truth"
    return Outcome(summary, lambda f: write_alignment(f, run, against), None,
                   stream.seed, run.warnings, result=run)


def write_alignment(f: h5py.File, run: Alignment, error_source: str = "truth") -> None:
    """``/align``: the settings and times as attributes, every pass (``pass_NN``, NN from 01)
    and the attitude at T1, T2 and T3 (``result``) as their fields say
    (:mod:`gcalign.align.result`); the true attitude at the stored samples under ``/truth``
    (t, att), or the reference's under ``/reference`` (`error_source` "reference")."""
    from gcalign.io.results import put
    from gcalign.io.stored import write_fields

    if run.pass_truth is not None:
        # every stored sample once, in time order (a later pass's row of a time kept, as a
        # mapping from time to row would); not a Python loop over the 10^5 rows
        t_all = np.concatenate([rec.t for rec in run.passes])
        att_all = np.concatenate(run.pass_truth)
        t, last = np.unique(t_all[::-1], return_index=True)
        tg = f.create_group(error_source)
        put(tg, "t", t, "s", description="the samples the passes stored (output rate)")
        put(tg, "att", att_all[::-1][last], "rad", ATT_FRAME)
    g = f.create_group("align")
    g.attrs.update(error_source=error_source, mode=run.settings.mode,
                   azimuth_poles=run.azimuth_poles, t1_s=run.t1, t2_s=run.t2, t3_s=run.t3)
    for p in run.pass_rows():
        write_fields(g.create_group(f"pass_{p.index + 1:02d}"), p)
    write_fields(g.create_group("result"), run.at_times())
