"""Strapdown navigation of a scenario's data, streamed block by block, with errors against truth.

The data come as a :class:`gcalign.app.data.Stream` (simulated on the fly, or recorded);
each block is integrated by :class:`gcalign.nav.strapdown.Navigator`, compared with the
truth at every sample (final and largest errors use every sample), decimated to the output
rate and appended to the results file, so memory does not grow with a run's duration.

On a turning IMU (a mechanism) the navigation integrates the sensor frame and reports the
body attitude through the mechanism angles the data carry, ``q_nb = q_ns ⊗ q_bs*``.

Where navigation starts (``--init``): the truth (simulated data), the file header (recorded
data), or an alignment results file, whose attitude at T3 is taken at T3's data time.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gcalign.app.data import Stream, scenario_stream
from gcalign.app.registry import Outcome
from gcalign.errors import ScenarioError
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.navigation import NavigationConfig
from gcalign.nav import _kernels as K
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import quat_to_euler
from gcalign.nav.strapdown import Navigator, NavState, Vertical
from gcalign.sim.mechanism import body_attitude


def position_error_enu(pos, pos_true, earth: EarthModel = WGS84):
    """ENU metres between two ``[lat, lon, h]`` tracks, (N, 3), radii at the true latitude."""
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
class Start:
    """Where navigation starts: sample index k (the state is at the end of increment k − 1),
    the body state there, and where it came from."""

    k: int
    state: NavState
    source: str  # "truth" | "header" | "alignment FILE"


def alignment_start(path: Path, stream: Stream) -> Start:
    """The attitude at T3 of an alignment results file, at T3's data time."""
    from gcalign.io import results

    kind, summary, _ = results.read_summary(path)
    if kind != "align":
        raise ScenarioError(f"--init: {path} is a {kind!r} results file; it must come from "
                            "'gcalign align'")
    if summary.get("source") != stream.source:
        raise ScenarioError(f"--init: {path} aligned {summary.get('source')!r}, but this run "
                            f"navigates {stream.source!r}; align the same data")
    t_data = float(summary.get("start_s", 0.0)) + float(summary["t3_s"])
    k = int(round(t_data / stream.ts))
    att = np.radians(summary["attitude_t3_deg"])
    tr = stream.truth_at(k)
    known = tr is not None and tr[0] is not None
    v = tr[1] if known else np.zeros(3)  # type: ignore[index]
    pos = tr[2] if known else stream.site  # type: ignore[index]
    return Start(k, NavState.from_euler(att, v, pos), f"alignment {path} (T3 = {t_data:g} s)")


def vertical_of(cfg: NavigationConfig, sc: Scenario, motion_kind: str | None = None) -> Vertical:
    """The vertical channel: as configured, or ``auto``: hold for bases whose height cannot
    change (static, swing, turntable) and for recorded data (parked or unknown), damped to
    the true height for moving bases and flights."""
    mode = cfg.vertical
    if mode == "auto":
        kind = sc.motion.kind if sc.motion is not None else motion_kind
        mode = "damped" if kind in ("moving", "flight") else "hold"
    return Vertical(mode, cfg.tau_s)


def navigate_stream(stream: Stream, start: Start, vertical: Vertical, stride: int,
                    duration_s: float | None = None, sink=None) -> dict:
    """Navigate from `start` to the end of the data (or for `duration_s`), compare with the
    truth at every sample (:func:`gcalign.nav._kernels.error_block`), write every
    `stride`-th row to `sink` (an h5py group), and return the plain-number pieces of the
    summary (SI, radians)."""
    from gcalign.io.results import ATT_FRAME, PHI_FRAME, Series

    ts, earth = stream.ts, stream.earth
    E = earth.params()
    k_end = stream.samples if duration_s is None else min(
        stream.samples, start.k + int(round(duration_s / ts)))
    if k_end <= start.k:
        raise ScenarioError(f"navigation: nothing to navigate: start at sample {start.k} of "
                            f"{stream.samples} ({start.k * ts:g} s of {stream.samples * ts:g} s)")
    has_truth = stream.truth0 is not None
    series = None
    if sink is not None:
        spec = {"t": (None, "s", None), "att": (3, "rad", ATT_FRAME), "v_n": (3, "m/s", "ENU"),
                "pos": (3, "rad, rad, m", "[latitude, longitude, height]")}
        if has_truth:
            spec |= {"error/att": (3, "rad", "Euler differences est - true, roll and yaw "
                                              "wrapped"),
                     "error/v_n": (3, "m/s", "ENU"),
                     "error/pos": (3, "m", "ENU (east, north, up)"),
                     "error/phi": (3, "rad", PHI_FRAME)}
        series = Series(sink, spec, stride=stride, rate_hz=1.0 / (stride * ts),
                        vertical=vertical.mode)
        row0 = {"t": [start.k * ts + stream.t0], "att": [start.state.att],
                "v_n": [start.state.v_n], "pos": [start.state.pos]}
        if has_truth:
            row0 |= {f"error/{n}": np.zeros((1, 3)) for n in ("att", "v_n", "pos", "phi")}
        series.append(**row0)
    state = start.state
    pos0 = np.asarray(state.pos, dtype=float)
    h_last = float(pos0[2])
    q_bs0 = stream.q_bs_at(start.k)
    q_ns0 = state.q_nb if q_bs0 is None else _qmul(state.q_nb, q_bs0)
    nav = Navigator(NavState(q_ns0, state.v_n, pos0), ts, earth, vertical)
    acc = np.zeros((9, 3))
    none, q_none = np.zeros((1, 3)), np.zeros((1, 4))
    last = None
    compute = 0.0
    t0 = time.perf_counter()
    for b in stream.blocks():
        lo, hi = max(start.k - b.k0, 0), min(k_end - b.k0, len(b.t))
        if hi <= lo:
            if b.k0 >= k_end:
                break
            continue
        tr = b.truth
        h_ref = None
        if tr is not None:  # the true height at the start of each step
            prev = tr.pos[lo - 1, 2] if lo > 0 else h_last
            h_ref = np.concatenate([[prev], tr.pos[lo:hi - 1, 2]])
            h_last = tr.pos[hi - 1, 2]
        c0 = time.perf_counter()
        states = nav.run(b.dtheta[lo:hi], b.dv[lo:hi], h_ref)
        compute += time.perf_counter() - c0
        q_bs = np.zeros((1, 4)) if b.q_bs is None else np.ascontiguousarray(b.q_bs[lo:hi])
        out = np.empty((len(states) // stride + 1, 21))
        rows = K.error_block(states, q_bs, b.q_bs is not None,
                             none if tr is None else np.ascontiguousarray(tr.att[lo:hi]),
                             q_none if tr is None else np.ascontiguousarray(tr.q_nb[lo:hi]),
                             none if tr is None else np.ascontiguousarray(tr.v_n[lo:hi]),
                             none if tr is None else np.ascontiguousarray(tr.pos[lo:hi]),
                             tr is not None, E, pos0, b.k0 + lo - start.k, stride, acc, out)
        if series is not None and rows:
            keep = np.flatnonzero((b.k0 + np.arange(lo, hi) + 1 - start.k) % stride == 0)
            r = out[:rows]
            data = {"t": b.t[lo:hi][keep], "att": r[:, 0:3], "v_n": r[:, 3:6],
                    "pos": r[:, 6:9]}
            if has_truth:
                data |= {"error/att": r[:, 9:12], "error/v_n": r[:, 12:15],
                         "error/pos": r[:, 15:18], "error/phi": r[:, 18:21]}
            series.append(**data)
        last = (states[-1], None if b.q_bs is None else b.q_bs[hi - 1])
    if series is not None:
        series.flush()
    assert last is not None
    s_end, qbs_end = last
    q_end = s_end[K.Q] if qbs_end is None else body_attitude(s_end[K.Q][None], qbs_end[None])[0]
    pos_end = s_end[K.P]
    return {
        "samples": k_end - start.k,
        "duration_s": (k_end - start.k) * ts,
        "start_s": start.k * ts,
        "final_state": (quat_to_euler(q_end), s_end[K.V].copy(), pos_end.copy()),
        "displacement": position_error_enu(pos_end[None], pos0[None], earth)[0],
        "max_horizontal_displacement": float(acc[3, 1]),
        "peak": acc[[0, 1, 2, 4]] if has_truth else None,
        "final_error": acc[5:9] if has_truth else None,
        "max_horizontal_error": float(acc[3, 0]) if has_truth else None,
        "compute_s": compute,
        "wall_s": time.perf_counter() - t0,
    }


def _qmul(a, b):
    from gcalign.nav.rotation import quat_mult

    return quat_mult(np.asarray(a, float), np.asarray(b, float))


def run_navigation(sc: Scenario, seed: int | None = None, init: str | Path | None = None,
                   sink=None) -> tuple[dict, Stream]:
    """Navigate a scenario's data; the summary (plain numbers, degrees/m) and the stream."""
    cfg = sc.navigation or NavigationConfig()
    stream = scenario_stream(sc, seed)
    kind = None if stream.header is None else stream.header.meta.get("motion_kind")
    vertical = vertical_of(cfg, sc, kind)
    stride = _stride(sc, stream)

    if init is not None and init not in ("truth", "header"):
        if cfg.start_s:
            raise ScenarioError(f"navigation.start_s: {cfg.start_s:g} s cannot matter with "
                                f"--init {init} (it starts at the alignment's T3); remove one")
        start = alignment_start(Path(init), stream)
    else:
        k = int(round(cfg.start_s / stream.ts))
        if k >= stream.samples:
            raise ScenarioError(f"navigation.start_s: {cfg.start_s:g} s is past the end of the "
                                f"data ({stream.samples * stream.ts:g} s)")
        source = init or ("truth" if stream.truth0 is not None else "header")
        tr = stream.truth_at(k) if source == "truth" else None
        if source == "truth":
            if tr is None or tr[0] is None:
                raise ScenarioError("--init: truth: recorded data have no truth; use 'header' "
                                    "or an alignment results file")
            state = NavState.from_euler(tr[0], tr[1], tr[2])
        else:
            hd = stream.header
            if hd is None or hd.att0 is None:
                raise ScenarioError(f"--init: header: {stream.source} gives no initial "
                                    "attitude; use an alignment results file")
            if k:
                raise ScenarioError("navigation.start_s: the file header's state is at the "
                                    "first sample; start_s must be 0 with --init header")
            v0 = hd.v0_n if hd.v0_n is not None else np.zeros(3)
            state = NavState.from_euler(hd.att0, v0, stream.site)
        start = Start(k, state, source)
    part = navigate_stream(stream, start, vertical, stride, cfg.duration_s, sink)
    return _summary(sc, stream, start, vertical, stride, part), stream


def _stride(sc: Scenario, stream: Stream) -> int:
    try:
        return sc.output.stride(1.0 / stream.ts, stream.samples * stream.ts)
    except ValueError as err:
        raise ScenarioError(str(err)) from None


def _summary(sc: Scenario, stream: Stream, start: Start, vertical: Vertical, stride: int,
             part: dict) -> dict:
    att, v, pos = part["final_state"]
    out = {
        "scenario": sc.name,
        "source": stream.source,
        "seed": stream.seed,
        "earth": stream.earth.name,
        "samples": part["samples"],
        "start_s": part["start_s"],
        "duration_s": part["duration_s"],
        "init": start.source,
        "vertical": vertical.mode,
        "vertical_tau_s": vertical.tau if vertical.mode == "damped" else None,
        "mechanism": stream.has_mechanism,
        "output_rate_hz": 1.0 / (stride * stream.ts),
        "compute_s": part["compute_s"],
        "final_state": {
            "attitude_deg": np.degrees(att).tolist(),
            "velocity_mps": v.tolist(),
            "position_deg_m": [*np.degrees(pos[:2]).tolist(), float(pos[2])],
        },
        "displacement_m": part["displacement"].tolist(),
        "max_horizontal_displacement_m": part["max_horizontal_displacement"],
        "final_error": None,
        "max_error": None,
        "max_horizontal_error_m": None,
    }
    if part["peak"] is not None:
        scale = np.array([[math.degrees(1.0)], [1.0], [1.0], [math.degrees(1.0)]])
        names = ("attitude_deg", "velocity_mps", "position_m", "misalignment_deg")
        out["final_error"] = dict(zip(names, (part["final_error"] * scale).tolist(), strict=True))
        out["max_error"] = dict(zip(names, (part["peak"] * scale).tolist(), strict=True))
        out["max_horizontal_error_m"] = part["max_horizontal_error"]
    return out


def execute(sc, seed: int | None = None, cache_key: str | None = None, sink=None,
            init: str | Path | None = None) -> Outcome:
    """Navigate (streamed); the registry's entry point. With `sink` (an open results file)
    the decimated series go into its /navigate group as they are computed."""
    group = None if sink is None else sink.create_group("navigate")
    summary, stream = run_navigation(sc, seed, init, group)
    return Outcome(summary, lambda f: None, None, stream.seed)
