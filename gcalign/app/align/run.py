"""Gyrocompass alignment of a scenario: coarse on [0, T1], passes on [T1, T2], T2 → T3.

Seed 000; DESIGN.md "Gyrocompass fine alignment". Returns an :class:`AlignRun` of plain
arrays; the CLI writes and prints it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gcalign.align import coarse as coarse_mod
from gcalign.align import kernel as K
from gcalign.align.compensate import compensate
from gcalign.align.cycles import Block, PassRecord, run_passes
from gcalign.app.data import RunData, scenario_data
from gcalign.app.registry import Outcome
from gcalign.errors import ScenarioError
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.align import AlignConfig
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import (
    attitude_error,
    euler_to_dcm,
    euler_to_quat,
    misalignment,
    quat_to_dcm,
    quat_to_euler,
)


@dataclass(frozen=True)
class AlignRun:
    """Everything an alignment produced (SI). Truth-dependent fields are None without truth."""

    cfg: AlignConfig
    azimuth_poles: str
    t1: float
    t2: float
    t3: float
    coarse_att: np.ndarray
    passes: list[PassRecord]
    pass_truth: list[np.ndarray] | None  # true attitude along each pass (rad), if known
    att_t2: np.ndarray
    att_t3: np.ndarray
    truth_t2: np.ndarray | None
    truth_t3: np.ndarray | None
    compute_s: float
    equivalent_s: float
    index_offset: int  # data sample index of alignment time 0
    t3_source: str  # "configured" or "measured"
    warnings: tuple[str, ...] = ()

    @property
    def error_t2(self):
        return None if self.truth_t2 is None else attitude_error(self.att_t2, self.truth_t2)

    @property
    def error_t3(self):
        return None if self.truth_t3 is None else attitude_error(self.att_t3, self.truth_t3)

    @cached_property
    def pass_errors(self) -> list[np.ndarray | None]:
        """Euler-angle error (n+1, 3) rad along each pass; computed when first asked for
        (a batch needs only the end of each pass)."""
        if self.pass_truth is None:
            return [None] * len(self.passes)
        return [
            attitude_error(quat_to_euler(r.q_nb), tr)
            for r, tr in zip(self.passes, self.pass_truth, strict=True)
        ]

    @cached_property
    def pass_phi(self) -> list[np.ndarray | None]:
        """Misalignment φ (n+1, 3) rad, ENU, along each pass."""
        if self.pass_truth is None:
            return [None] * len(self.passes)
        return [
            misalignment(quat_to_dcm(r.q_nb), euler_to_dcm(tr))
            for r, tr in zip(self.passes, self.pass_truth, strict=True)
        ]

    def pass_end_error(self, i: int) -> np.ndarray | None:
        """Euler-angle error at the end of pass i (rad)."""
        if self.pass_truth is None:
            return None
        return attitude_error(quat_to_euler(self.passes[i].q_nb[-1]), self.pass_truth[i][-1])

    @property
    def phi_t2(self):
        """Misalignment φ at T2 (rad, ENU): C_nb,est C_nb,true^T = exp(−[φ×])."""
        return None if self.truth_t2 is None else _phi(self.att_t2, self.truth_t2)

    @property
    def phi_t3(self):
        return None if self.truth_t3 is None else _phi(self.att_t3, self.truth_t3)


def _phi(att_est, att_true):
    return misalignment(euler_to_dcm(att_est), euler_to_dcm(att_true))


def _index(data: RunData, cfg: AlignConfig, t: float, field: str) -> int:
    """Data sample index of alignment time t (s); ScenarioError if outside the data."""
    ts = data.imu.ts
    k = int(round((cfg.start_s + t) / ts))
    end = len(data.imu) * ts
    if k > len(data.imu):
        raise ScenarioError(
            f"align.{field}: {t} s (+ start_s {cfg.start_s} s) is past the end of the data "
            f"({end:.2f} s); lengthen motion.duration_s or choose an earlier time"
        )
    return k


def reference_velocity(data: RunData, cfg: AlignConfig, rng: np.random.Generator):
    """Reference velocity at every sample, (N+1, 3), and whether it is in the body frame.

    none: zero (static or swing base). nav: the true ENU velocity plus white noise.
    odometer: the body-frame forward speed plus white noise (seed §1: converted to the
    navigation frame with the computed attitude inside the loop).
    """
    n = len(data.imu) + 1
    source, noise = cfg.aiding.source, cfg.aiding.noise_mps
    if source == "none":
        return np.zeros((n, 3)), False
    if data.truth is None:
        raise ScenarioError(
            f"align.aiding.source: {source!r} needs a simulated motion (truth); "
            "recorded data supports 'none'"
        )
    v_n = data.truth.v_n
    if source == "nav":
        return v_n + noise * rng.standard_normal(v_n.shape), False
    v_b = np.einsum("kji,kj->ki", euler_to_dcm(data.truth.att), v_n)
    speed = v_b[:, 1] + noise * rng.standard_normal(n)
    return np.stack([np.zeros(n), speed, np.zeros(n)], -1), True


def coarse_attitude(data: RunData, cfg: AlignConfig, i0: int, i1: int):
    """Attitude at T1 from the coarse method, plus the configured offset (rad)."""
    c = cfg.coarse
    offset = np.radians(c.offset_deg)
    if c.method == "given":
        if data.truth is None:
            raise ScenarioError(
                "align.coarse.method: 'given' needs truth; use 'analytic' or "
                "'inertial' for recorded data"
            )
        return data.truth.att[i1] + np.radians(c.error_deg) + offset
    lo = i1 - int(round(c.duration_s / data.imu.ts)) if c.duration_s else i0
    dth, dv, ts, site = data.imu.dtheta[lo:i1], data.imu.dv[lo:i1], data.imu.ts, data.site
    try:
        if c.method == "analytic":
            return coarse_mod.analytic_coarse(dth, dv, ts, site[0], data.earth) + offset
        return coarse_mod.inertial_frame_coarse(dth, dv, ts, site[0], site[1], site[2],
                                                earth=data.earth) + offset
    except ValueError as err:  # too short a window
        raise ScenarioError(
            f"align.coarse.duration_s: the coarse window [{(lo - i0) * ts:g}, "
            f"{(i1 - i0) * ts:g}] s does not fit method {c.method!r}: {err}"
        ) from None


def _block(data: RunData, vref, body: bool, lo: int, hi: int) -> Block:
    imu = data.imu
    t = (imu.t[0] - imu.ts) + np.arange(lo, hi + 1) * imu.ts
    return Block(
        t=t,
        dtheta=imu.dtheta[lo:hi],
        dv=imu.dv[lo:hi],
        vref=vref[lo : hi + 1],
        vref_body=body,
        ts=imu.ts,
    )


def warm_up() -> None:
    """Load the compiled kernel (numba cache) before the computation is timed."""
    state = K.new_state(np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3), np.array([0.7, 0.0, 0.0]))
    K.gyrocompass_block(state, np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((2, 3)), False,
                        0.01, 1.0, WGS84.params(), np.zeros(K.GAINS_SIZE), K.ATTITUDE,
                        np.empty((2, 4)))


def run_alignment(sc: Scenario, data: RunData) -> AlignRun:
    """Coarse alignment, the passes of the mode, and the T2 → T3 compensation."""
    cfg = sc.align or AlignConfig()
    warm_up()
    if abs(data.site[0]) > math.radians(85.0):
        raise ScenarioError(
            f"site.lat_deg: gyrocompassing needs |latitude| < 85°, got "
            f"{math.degrees(data.site[0]):.4f}° (the horizontal earth rate vanishes)"
        )
    # The motion kind picks the default pole set; data simulated earlier carry it along.
    kind = sc.motion.kind if sc.motion else data.imu.meta.get("motion_kind")
    poles = cfg.poles_for(kind)
    warnings = []
    if kind == "moving" and cfg.aiding.source == "none":
        warnings.append(
            "a moving base with align.aiding.source 'none': the loops take the "
            "vehicle's accelerations for tilt; expect degrees of error"
        )
    ts = data.imu.ts
    i0 = _index(data, cfg, 0.0, "start_s")
    i1 = _index(data, cfg, cfg.t1_s, "t1_s")
    i2 = _index(data, cfg, cfg.t2_s, "t2_s")
    rng = np.random.default_rng([0 if data.seed is None else data.seed, 1])
    vref, body = reference_velocity(data, cfg, rng)
    att1 = coarse_attitude(data, cfg, i0, i1)
    q1 = euler_to_quat(att1)
    v1 = quat_to_dcm(q1) @ vref[i1] if body else vref[i1]
    pos1 = data.truth.pos[i1] if data.truth is not None else data.site
    state0 = K.new_state(q1, v1, pos1)

    # Real-time conventional: one forward pass over live data to T3, no latency to
    # compensate ('measured' then means T3 = T2). Otherwise the passes run over the stored
    # block [T1, T2] and the compensation carries the attitude on to T3.
    realtime = cfg.mode == "conventional" and cfg.realtime
    if realtime:
        i3 = i2 if cfg.t3_s == "measured" else _index(data, cfg, cfg.t3_s, "t3_s")
    t_start = time.perf_counter()
    state_end, records = run_passes(
        state0,
        _block(data, vref, body, i1, i3 if realtime else i2),
        cfg.mode,
        cfg.pass_count,
        [s.to_stage() for s in cfg.stages],
        poles,
        cfg.level_phase_s,
        data.earth,
    )
    compute = time.perf_counter() - t_start
    if realtime:
        q2, q3 = records[0].q_nb[i2 - i1], state_end[K.ATT].copy()
        equivalent = (i3 - i0) * ts
    else:
        if cfg.t3_s == "measured":
            i3 = i2 + math.ceil(compute / ts)
            if i3 > len(data.imu):
                raise ScenarioError("align.t3_s: 'measured' latency runs past the end of the data")
        else:
            i3 = _index(data, cfg, cfg.t3_s, "t3_s")
        q2 = state_end[K.ATT].copy()
        q3 = compensate(cfg.compensation, state_end, _block(data, vref, body, i2, i3), data.earth)
        equivalent = (i1 - i0) * ts + cfg.pass_count * (i2 - i1) * ts

    truth = data.truth
    start = data.imu.t[0] - ts  # data time of sample 0
    pass_truth = (
        None
        if truth is None
        else [truth.att[np.rint((rec.t - start) / ts).astype(int)] for rec in records]
    )
    return AlignRun(
        cfg=cfg,
        azimuth_poles=poles,
        t1=(i1 - i0) * ts,  # the sample times actually used
        t2=(i2 - i0) * ts,
        t3=(i3 - i0) * ts,
        coarse_att=att1,
        passes=records,
        pass_truth=pass_truth,
        att_t2=quat_to_euler(q2),
        att_t3=quat_to_euler(q3),
        truth_t2=None if truth is None else truth.att[i2],
        truth_t3=None if truth is None else truth.att[i3],
        compute_s=compute,
        equivalent_s=equivalent,
        index_offset=i0,
        t3_source="measured" if cfg.t3_s == "measured" else "configured",
        warnings=tuple(warnings),
    )


def _deg(x):
    return None if x is None else np.degrees(x).tolist()


def alignment_summary(run: AlignRun, data: RunData, name: str) -> dict:
    """Plain-number summary (degrees, seconds): the JSON contract of `gcalign align --json`."""
    cfg = run.cfg
    realtime = cfg.mode == "conventional" and cfg.realtime
    start = data.imu.t[0] - data.imu.ts  # data time of sample 0

    def aligned_time(t_data: float) -> float:
        return (round((t_data - start) / data.imu.ts) - run.index_offset) * data.imu.ts

    return {
        "scenario": name,
        "seed": data.seed,
        "source": data.imu.source,
        "mode": cfg.mode,
        "compensation": "real time" if realtime else cfg.compensation,
        "azimuth_poles": run.azimuth_poles,
        "stages": [s.model_dump() for s in cfg.stages],
        "t1_s": run.t1,
        "t2_s": run.t2,
        "t3_s": run.t3,
        "t3_source": run.t3_source,
        "coarse_attitude_deg": _deg(run.coarse_att),
        "attitude_t2_deg": _deg(run.att_t2),
        "truth_t2_deg": _deg(run.truth_t2),
        "error_t2_deg": _deg(run.error_t2),
        "attitude_t3_deg": _deg(run.att_t3),
        "truth_t3_deg": _deg(run.truth_t3),
        "error_t3_deg": _deg(run.error_t3),
        "misalignment_t2_deg": _deg(run.phi_t2),
        "misalignment_t3_deg": _deg(run.phi_t3),
        "passes": [
            {
                "index": r.index,
                "direction": r.direction,
                "kind": r.kind,
                "stage": r.stage,
                "t_end_s": aligned_time(float(r.t[-1])),
                "error_deg": _deg(run.pass_end_error(r.index)),
                "attitude_deg": np.degrees(quat_to_euler(r.q_nb[-1])).tolist(),
            }
            for r in run.passes
        ],
        "equivalent_s": run.equivalent_s,
        "data_used_s": run.t3 if realtime else run.t2,
        "compute_s": run.compute_s,
        "warnings": list(run.warnings),
    }


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    """Simulate (or read) the data, align, summarise; the registry's entry point."""
    from gcalign.app.align.hdf5 import write_alignment

    data = scenario_data(sc, seed, cache_key)
    run = run_alignment(sc, data)
    return Outcome(alignment_summary(run, data, sc.name), lambda f: write_alignment(f, run),
                   data.truth, data.seed, run.warnings)
