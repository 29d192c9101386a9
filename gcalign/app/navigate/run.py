"""Strapdown navigation of a scenario's data, streamed block by block, with errors against
the truth (simulated data) or a reference solution (recorded data with ``reference``).

The data come as a :class:`gcalign.app.data.Stream` (simulated on the fly, or recorded);
:func:`gcalign.nav.navigate.navigate_blocks` navigates its blocks (errors at every sample,
rows decimated to the output rate), and the rows are appended to the results file as they
come, so memory does not grow with a run's duration.

Where navigation starts (``--init``): the truth (simulated data); on recorded data the keys
``initial``, else the reference at the start time, else the file's header
(:func:`gcalign.io.recorded.initial_state`); or an alignment results file, whose attitude
at T3 is taken at T3's data time.

A reference is used for the errors only: interpolated to every increment's end time
(attitude on the rotation group), it never enters the navigation (the vertical channel
holds the start height, not the reference's), so a run with and without it navigates the
same numbers.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from gcalign.app.command import Outcome
from gcalign.app.command import stride as output_stride
from gcalign.app.data import DataBlock, Stream, scenario_stream
from gcalign.errors import InputError, ScenarioError
from gcalign.io.recorded.reference import Reference, initial_state, reference_at, reference_gaps
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.navigation import NavigationConfig
from gcalign.nav.navigate import NavErrors, Navigation, NavRows, NavTruth, navigate_blocks
from gcalign.nav.navigate import position_error_enu as position_error_enu  # its old home
from gcalign.nav.rotation import attitude_error, misalignment_q
from gcalign.nav.strapdown import NavState, Vertical
from gcalign.schema import placed, summary_of


@dataclass(frozen=True)
class Start:
    """Where navigation starts: sample index k (the state is at the end of increment k − 1),
    the body state there, and where it came from."""

    k: int
    state: NavState
    source: str  # "truth" | "header" | "keys ..." | "reference ..." | "alignment FILE"


def alignment_start(path: Path, stream: Stream) -> Start:
    """The attitude at T3 of an alignment results file, at T3's data time."""
    from gcalign.app.checked import read_checked

    kind, summary, _ = read_checked(path)
    if kind != "align":
        raise ScenarioError(f"--init: {path} is a {kind!r} results file; it must come from "
                            "'gcalign align'")
    if summary.get("source") != stream.source:
        raise ScenarioError(f"--init: {path} aligned {summary.get('source')!r}, but this run "
                            f"navigates {stream.source!r}; align the same data")
    try:
        t_data = float(summary.get("start_s", 0.0)) + float(summary["t3_s"])
        att = np.radians(np.asarray(summary["attitude_t3_deg"], dtype=float))
    except (KeyError, TypeError, ValueError):
        att = t_data = None
    if t_data is None or att is None or att.shape != (3,) or not (
            np.isfinite(att).all() and math.isfinite(t_data) and t_data >= 0):
        raise ScenarioError(f"--init: {path}: root attribute 'summary_json' must hold a "
                            "finite 't3_s' and 'attitude_t3_deg' (3 numbers)")
    k = int(round(t_data / stream.ts))
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


def reference_window(ref: Reference, stream: Stream, k_start: int, k_end: int) -> tuple:
    """The data times of samples `k_start` and `k_end`; ScenarioError (one line, naming the
    keys that move them) when the reference does not cover them."""
    t_a, t_b = stream.t0 + k_start * stream.ts, stream.t0 + k_end * stream.ts
    lo, hi = float(ref.t[0]), float(ref.t[-1])
    tol = 1e-6 * stream.ts
    if t_a < lo - tol or t_b > hi + tol:
        first = max(lo - stream.t0, 0.0)
        raise ScenarioError(
            f"reference: {ref.record.get('path', 'the reference')} covers {lo:.3f} .. {hi:.3f} s"
            f", navigation needs {t_a:.3f} .. {t_b:.3f} s (data time): start at or after "
            f"navigation.start_s {math.ceil(first / stream.ts) * stream.ts:.6g} s (--start) "
            "and end by the reference's last epoch (navigation.duration_s, --duration)")
    return t_a, t_b


def against_reference(blocks: Iterator[DataBlock], ref: Reference, t_a: float, t_b: float,
                      gaps: tuple = ()) -> Iterator[DataBlock]:
    """The blocks with the reference at their end times as their 'truth' (times outside
    [t_a, t_b], which the navigation skips, take the nearest end); NaN inside the
    reference's `gaps` (:func:`gcalign.io.recorded.reference.reference_gaps`): no error
    there, and none in the maxima."""
    from gcalign.gaps import inside

    for b in blocks:
        if b.t[0] > t_b:
            return
        att, v, pos = reference_at(ref, np.clip(b.t, t_a, t_b), tol=1e-6)
        hole = inside(b.t, gaps)
        if hole.any():
            att, v, pos = att.copy(), v.copy(), pos.copy()
            att[hole] = v[hole] = pos[hole] = np.nan
        yield replace(b, truth=NavTruth(att, v, pos))  # type: ignore[arg-type]


def _start_error(state: NavState, ref: Reference, t: float, earth) -> NavErrors:
    """The errors of the start row against the reference at data time `t`."""
    att, v, pos = (a[0] for a in reference_at(ref, [t], tol=1e-6))
    tr = NavState.from_euler(att, v, pos)
    return NavErrors(attitude_error(state.att, att)[None], (np.asarray(state.v_n) - v)[None],
                     position_error_enu(np.asarray(state.pos)[None], pos[None], earth),
                     misalignment_q(state.q_nb, tr.q_nb)[None])


def navigate_stream(stream: Stream, start: Start, vertical: Vertical, stride: int,
                    duration_s: float | None = None, sink=None, on_rows=None,
                    progress=None, reference: Reference | None = None,
                    ref_gaps: tuple = ()) -> Navigation:
    """Navigate from `start` to the end of the data (or for `duration_s`) by
    :func:`gcalign.nav.navigate.navigate_blocks`, write every `stride`-th row to `sink` (an
    h5py group; the series as the fields of :class:`~gcalign.nav.navigate.NavRows` say) and
    hand it to `on_rows` (called with the dict of arrays appended to the series, block by
    block), and return the core's result. `progress(done_s, total_s, what)`, if given,
    hears of every block (seconds of data navigated). With `reference` (recorded data) the
    errors are against it (see the module docstring)."""
    from gcalign.io.results import Series
    from gcalign.io.stored import series_of

    ts = stream.ts
    k_end = stream.samples if duration_s is None else min(
        stream.samples, start.k + int(round(duration_s / ts)))
    blocks = stream.blocks()
    if reference is not None:
        t_a, t_b = reference_window(reference, stream, start.k, k_end)
        blocks = against_reference(blocks, reference, t_a, t_b, ref_gaps)
    series = None
    texts = SimpleNamespace(against="true" if reference is None else "reference")  # {against}
    if sink is not None:
        t_start = start.k * ts + stream.t0
        error = None if stream.truth0 is None and reference is None else (
            NavErrors(*[np.zeros((1, 3))] * 4) if reference is None
            else _start_error(start.state, reference, t_start, stream.earth))
        row0 = series_of(NavRows(np.array([t_start]), start.state.att[None],
                                 start.state.v_n[None], start.state.pos[None], error), texts)
        series = Series(sink, {name: (a.shape[1] if a.ndim > 1 else None, how.units or "",
                                      how.frame)
                               for name, (a, how) in row0.items()},
                        stride=stride, rate_hz=1.0 / (stride * ts), vertical=vertical.mode)
        if reference is not None:
            sink.attrs["error_source"] = "reference"
        series.append(**{name: a for name, (a, _) in row0.items()})

    def rows_out(rows: NavRows) -> None:  # always given, so the rows are never all held
        data = {name: a for name, (a, _) in series_of(rows, texts).items()}
        if series is not None:
            series.append(**data)
        if on_rows is not None:
            on_rows(data)

    try:
        nav = navigate_blocks(blocks, ts, start.state, k_start=start.k, k_end=k_end,
                              earth=stream.earth, vertical=vertical, stride=stride,
                              q_bs0=stream.q_bs_at(start.k), t0=stream.t0, on_rows=rows_out,
                              progress=progress, truth_height=reference is None)
    except InputError as err:
        raise ScenarioError(f"navigation: {err.message}") from None
    if series is not None:
        series.flush()
    return nav


def run_navigation(sc: Scenario, seed: int | None = None, init: str | Path | None = None,
                   sink=None, on_rows=None, progress=None) -> tuple[dict, Stream]:
    """Navigate a scenario's data; the summary (plain numbers, degrees/m) and the stream.
    `sink`, `on_rows` and `progress` as :func:`navigate_stream`."""
    summary, stream, _ = _run(sc, seed, init, sink, on_rows, progress)
    return summary, stream


def _run(sc: Scenario, seed: int | None, init: str | Path | None, sink, on_rows,
         progress, recording=None) -> tuple[dict, Stream, Navigation]:
    """:func:`run_navigation` with the core's result (`recording`: the recorded file as the
    preflight read it)."""
    cfg = sc.navigation or NavigationConfig()
    stream = scenario_stream(sc, seed, recording=recording)
    ref = sc.reference.read() if sc.reference is not None else None
    kind = None if stream.header is None else stream.header.meta.get("motion_kind")
    vertical = vertical_of(cfg, sc, kind)
    stride = output_stride(sc, stream)

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
            state, source = _recorded_start(sc, stream, k, ref, init == "header")
        start = Start(k, state, source)
    gaps = () if ref is None or sc.reference is None else reference_gaps(
        ref, sc.reference.max_gap_s)
    nav = navigate_stream(stream, start, vertical, stride, cfg.duration_s, sink, on_rows,
                          progress, ref, gaps)
    return _summary(sc, stream, start, vertical, stride, nav), stream, nav


def _recorded_start(sc: Scenario, stream: Stream, k: int, ref: Reference | None,
                    header_only: bool) -> tuple[NavState, str]:
    """The state at sample k of recorded data and where it came from: the keys
    ``initial``, else the reference at that time (its position too), else the file's
    header (at the first sample only); `header_only` (``--init header``) takes the header."""
    hd = stream.header
    header_att = None if hd is None else hd.att0
    if header_att is not None and k:
        if header_only or (sc.initial is None and ref is None):
            raise ScenarioError("navigation.start_s: the file header's state is at the "
                                "first sample; start_s must be 0 with --init header")
        header_att = None
    t = stream.t0 + k * stream.ts
    keys = {} if header_only or sc.initial is None else {
        "att_deg": sc.initial.att_deg, "v_enu_mps": sc.initial.v_enu_mps}
    if ref is not None and not header_only:
        reference_window(ref, stream, k, k)  # the start inside the reference (one line)
    att, v, source = initial_state(
        stream.source, t, reference=None if header_only else ref, header_att=header_att,
        header_v=None if hd is None else hd.v0_n, **keys)
    pos = stream.site
    if ref is not None and not header_only:  # the reference knows where the start is
        pos = reference_at(ref, [t], tol=1e-6)[2][0]
        if not source.startswith("reference"):
            source += f"; position: the reference at {t:g} s"
    return NavState.from_euler(att, v, pos), source


def _summary(sc: Scenario, stream: Stream, start: Start, vertical: Vertical, stride: int,
             nav: Navigation) -> dict:
    """Plain numbers (degrees, m): the JSON contract of ``gcalign navigate``; the run's
    figures as the fields of :class:`~gcalign.nav.navigate.Navigation` say, the scenario's
    settings and the final state placed around them."""
    out = placed(summary_of(nav), {"samples": {
        "scenario": sc.name, "source": stream.source, "seed": stream.seed,
        "earth": stream.earth.name}, "displacement_m": {
        "init": start.source,
        "error_source": None if nav.max_error is None else (
            "reference" if sc.reference is not None else "truth"),
        "reference": None if sc.reference is None else {
            "path": str(sc.reference.path), "format": sc.reference.format},
        "vertical": vertical.mode,
        "vertical_tau_s": vertical.tau if vertical.mode == "damped" else None,
        "mechanism": stream.has_mechanism,
        "output_rate_hz": 1.0 / (stride * stream.ts),
        "compute_s": nav.compute_s,
        "final_state": {
            "attitude_deg": np.degrees(nav.final.att).tolist(),
            "velocity_mps": nav.final.v_n.tolist(),
            "position_deg_m": [*np.degrees(nav.final.pos[:2]).tolist(),
                               float(nav.final.pos[2])]}}})
    if nav.final_error is not None and not np.isfinite(nav.final_error.stack()).all():
        out["final_error"] = None  # the run ends in a reference gap
    return out


def execute(sc, seed: int | None = None, cache_key: str | None = None, sink=None,
            init: str | Path | None = None, progress=None, recording=None) -> Outcome:
    """Navigate (streamed); the registry's entry point. With `sink` (an open results file)
    the decimated series go into its /navigate group as they are computed."""
    group = None if sink is None else sink.create_group("navigate")
    summary, stream, nav = _run(sc, seed, init, group, None, progress, recording)
    warnings = duration_warnings(sc, summary, stream.ts)
    return Outcome(summary, lambda f: None, None, stream.seed, warnings, result=nav)


def duration_warnings(sc: Scenario, summary: dict, ts: float) -> tuple[str, ...]:
    """A requested ``navigation.duration_s`` the data cannot give: said, not cut quietly."""
    asked = (sc.navigation or NavigationConfig()).duration_s
    ran = summary["duration_s"]
    if asked is None or asked <= ran + ts / 2:
        return ()
    return (f"navigation.duration_s: {asked:g} s runs past the end of the data: ran {ran:g} s "
            f"(from {summary['start_s']:g} s)",)
