"""Simulate a scenario's truth and IMU data, streamed; the summary `gcalign simulate` prints.

Series are stored at the output rate (``output.rate_hz``; every sample for runs up to an
hour by default). At full rate ``/imu`` holds the increments themselves; decimated, it
holds their exact sums over each output interval (attribute ``summed_from_ts``), which are
fine for plots and statistics but not for navigation (coning and sculling are lost).
"""

from __future__ import annotations

import time

import numpy as np

from gcalign.app.command import Outcome
from gcalign.app.data import scenario_stream
from gcalign.io.scenario import Scenario

BODY = "body: x right, y forward, z up"
SENSOR = "sensor frame s (turned by the mechanism; C_s^b in q_bs)"


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            sink=None, progress=None) -> Outcome:
    """Simulate block by block; with `sink` (an open results file) write /truth and /imu.
    `progress(done_s, total_s, what)`, if given, hears of every block."""
    from gcalign.io.results import ATT_FRAME, Series

    t_start = time.perf_counter()
    stream = scenario_stream(sc, seed)
    ts = stream.ts
    stride = sc.output.stride(1.0 / ts, stream.samples * ts)
    frame = SENSOR if stream.has_mechanism else BODY
    truth = imu = None
    tr0 = stream.truth0
    if sink is not None and tr0 is not None:
        truth = Series(sink.create_group("truth"), {
            "t": (None, "s", None), "att": (3, "rad", ATT_FRAME), "v_n": (3, "m/s", "ENU"),
            "pos": (3, "rad, rad, m", "[latitude, longitude, height]"),
            "segment": (None, "", "index of the motion segment")}, stride=stride)
        truth.append(t=[0.0], att=tr0.att, v_n=tr0.v_n, pos=tr0.pos, segment=[0])
    if sink is not None:
        spec = {"t": (None, "s", None), "dtheta": (3, "rad", frame), "dv": (3, "m/s", frame)}
        if stream.has_mechanism:
            spec["q_bs"] = (4, "", "mechanism angles: quaternion of C_s^b at t")
        imu = Series(sink.create_group("imu"), spec, ts=ts * stride, source=stream.source,
                     site=stream.site)
        if stride > 1:
            imu.group.attrs["summed_from_ts"] = ts
        if stream.has_mechanism:
            imu.group.attrs["q_bs0"] = stream.q_bs_at(0)
    distance = 0.0
    v_prev = np.zeros(3) if tr0 is None else tr0.v_n[0]
    h0 = 0.0 if tr0 is None else float(tr0.pos[0, 2])
    h_range = (h0, h0)
    last = None
    carry = {"dtheta": np.zeros(3), "dv": np.zeros(3)}
    for b in stream.blocks():
        tr = b.truth
        if tr is not None:
            v_mid = 0.5 * (np.vstack([v_prev[None], tr.v_n[:-1]]) + tr.v_n)
            distance += float(np.sqrt(np.einsum("ij,ij->i", v_mid, v_mid)).sum() * ts)
            v_prev = tr.v_n[-1]
            h_range = (min(h_range[0], float(tr.pos[:, 2].min())),
                       max(h_range[1], float(tr.pos[:, 2].max())))
        # rows kept: the samples k (1-based over the run) with k % stride == 0
        keep = np.arange((-(b.k0 + 1)) % stride, len(b.t), stride)
        if truth is not None and tr is not None:
            truth.append(t=b.t[keep], att=tr.att[keep], v_n=tr.v_n[keep], pos=tr.pos[keep],
                         segment=tr.segment[keep])
        if imu is not None:
            if stride == 1:
                rows = {"dtheta": b.dtheta, "dv": b.dv}
            else:  # sums over each output interval, the remainder carried to the next block
                rows = {}
                starts = np.r_[0, keep + 1]
                for name, inc in (("dtheta", b.dtheta), ("dv", b.dv)):
                    sums = np.add.reduceat(inc, starts[starts < len(inc)], axis=0)
                    sums[0] += carry[name]
                    if starts[-1] < len(inc):  # samples after the last kept one
                        carry[name] = sums[-1]
                        sums = sums[:-1]
                    else:
                        carry[name] = np.zeros(3)
                    rows[name] = sums
            extra = {} if b.q_bs is None else {"q_bs": b.q_bs[keep]}
            imu.append(t=b.t[keep], **rows, **extra)
        last = b
        if progress is not None:
            progress((b.k0 + len(b.t)) * ts, stream.samples * ts, "simulating (data s)")
    for series in (truth, imu):
        if series is not None:
            series.flush()
    end = None if last is None else last.truth
    moved: dict = dict.fromkeys(("initial_attitude_deg", "final_attitude_deg",
                                 "final_velocity_mps", "distance_m", "height_range_m",
                                 "final_displacement_m"))  # none without a truth
    if tr0 is not None and end is not None:
        from gcalign.nav.navigate import position_error_enu

        d = position_error_enu(end.pos[-1:], tr0.pos[:1], stream.earth)[0]
        moved = {"initial_attitude_deg": np.degrees(tr0.att[0]).tolist(),
                 "final_attitude_deg": np.degrees(end.att[-1]).tolist(),
                 "final_velocity_mps": end.v_n[-1].tolist(), "distance_m": distance,
                 "height_range_m": list(h_range), "final_displacement_m": d.tolist()}
    summary: dict = {
        "scenario": sc.name,
        "seed": stream.seed,
        "earth": stream.earth.name,
        "samples": stream.samples,
        "rate_hz": 1.0 / ts,
        "duration_s": float(stream.samples * ts),
        "output_rate_hz": 1.0 / (stride * ts),
        "mechanism": stream.has_mechanism,
        "compute_s": time.perf_counter() - t_start,
        **moved,
    }
    return Outcome(summary, lambda f: None, None, stream.seed)
