"""The observability table of a scenario's flight (seed 002 §3–4, Table 1 analogue).

The truth and ideal increments of the motion (once per batch variant), at the calibration's
navigation rate; each manoeuvre cut into PWCS pieces; per segment and cumulative SOM
degrees η = σ_(k)/σ_0 (states scaled by their initial σ by default; ``scaling: none`` is the
paper's literal, unit-dependent table), ranks with their margin from the cut-off, TOM
ranks, the null-space condition of seed eq. (12), and the covariance degree σ(0)/σ(t)
(PSINS kfstat).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from gcalign.app.command import Outcome
from gcalign.calibrate import (
    ObservabilitySettings,
    ObservabilityTable,
    Span,
    Trajectory,
    motion_spans,
    observability,
    sampled_truth,
    trajectory,
)
from gcalign.calibrate.filter import warm_up
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.calibrate import CalibrateConfig, ObservabilityConfig
from gcalign.schema import plain, summary_of

if TYPE_CHECKING:
    import h5py


def flight_truth(sc: Scenario,
                 cache_key: str | None = None) -> tuple[Trajectory, tuple[Span, ...]]:
    """The scenario's truth at the navigation rate (:class:`gcalign.calibrate.Trajectory`)
    and its manoeuvres."""
    from gcalign.app.data import cached_noise_free, noise_free

    if sc.motion is None:
        raise ScenarioError("motion: missing; the observability table needs a simulated "
                            "motion (its truth)")
    cfg = sc.calibrate or CalibrateConfig()
    n = cfg.subsamples(sc.imu.rate_hz)
    raw = cached_noise_free(sc, cache_key) if cache_key is not None else noise_free(sc)
    tr = raw.truth
    assert tr is not None
    traj = trajectory(tr.t, tr.att, tr.v_n, tr.pos, raw.imu.dtheta, raw.imu.dv,
                      sc.earth_model, n)
    return traj, motion_spans(sc.motion.to_motion(), float(traj.t[-1]))


def run_table(sc: Scenario, cache_key: str | None = None, progress: Any = None
              ) -> tuple[ObservabilityTable, Trajectory, tuple[Span, ...], float]:
    """``(table, trajectory, spans, compute_s)``: the table's own time, without the
    simulation. `progress(done, total, what)` hears of the two stages."""
    cfg = sc.observability or ObservabilityConfig()
    cfg.check(sc)
    if progress is not None:
        progress(0, 1, "simulating the flight")
    traj, spans = flight_truth(sc, cache_key)
    if progress is not None:
        progress(0, 1, "PWCS + SVD table")
    cal = sc.calibrate or CalibrateConfig()
    settings = cal.settings(traj.pos[0], traj.earth)
    warm_up()
    t0 = time.perf_counter()
    options = ObservabilitySettings(cfg.measure, cfg.scaling, cfg.rank_rtol, cfg.piece_s,
                                    cfg.null_tol, cfg.covariance)
    tab = observability(traj, spans, options, settings)
    if progress is not None:
        progress(1, 1, "PWCS + SVD table")
    return tab, traj, spans, time.perf_counter() - t0


def per_state(names: Sequence[str], values: np.ndarray) -> dict:
    return {n: float(v) for n, v in zip(names, values, strict=True)}


def table_rows(tab: ObservabilityTable, spans: Sequence[Span], condition: np.ndarray,
               states: Sequence[str], cov: tuple | None = None) -> tuple[list, list]:
    """The JSON's ``segments`` and ``cumulative`` rows of `tab` over `spans`: the SOM's
    degrees named by `states`, whether seed eq. 12 holds (`condition`) and, with `cov`
    (names, per segment, cumulative), the covariance's degrees."""
    segs, cum = [], []
    for i, sp in enumerate(spans):
        segs.append({**summary_of(sp), "rank": int(tab.rank[i]),
                     "rank_margin": plain(tab.margin[i]), "tom_rank": int(tab.tom_rank[i]),
                     "null_residual": float(tab.null_residual[i]),
                     "condition": bool(condition[i]), "degree": per_state(states, tab.eta[i])})
        cum.append({**summary_of(replace(sp, start=spans[0].start)),
                    "rank": int(tab.rank_cum[i]), "rank_margin": plain(tab.margin_cum[i]),
                    "tom_rank": int(tab.tom_rank_cum[i]),
                    "degree": per_state(states, tab.eta_cum[i])})
        if cov is not None:
            segs[-1]["covariance_degree"] = per_state(cov[0], cov[1][i])
            cum[-1]["covariance_degree"] = per_state(cov[0], cov[2][i])
    return segs, cum


def summary(sc: Scenario, tab: ObservabilityTable, spans: tuple[Span, ...],
            compute_s: float) -> dict:
    """Plain numbers: the JSON contract of ``gcalign observability``."""
    names = ie.STATE_NAMES
    segs, cum = table_rows(tab, spans, tab.condition, names, None if tab.cov_degree is None
                           or tab.cov_degree_segment is None
                           else (names, tab.cov_degree_segment, tab.cov_degree))
    return {
        "scenario": sc.name,
        **summary_of(tab),  # how the table was made
        "states": list(ie.STATE_NAMES),
        "segments": segs,
        "cumulative": cum,
        "rank_final": int(tab.rank_cum[-1]),
        "degree_final": [float(v) for v in tab.eta_cum[-1]],
        "compute_s": compute_s,
    }


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            progress: Any = None) -> Outcome:
    """The table of the scenario's flight (a transfer alignment's is
    :func:`gcalign.app.observability.transfer.execute`); no randomness: the seed only names
    the run."""
    tab, traj, spans, compute_s = run_table(sc, cache_key, progress)
    truth = sampled_truth(traj, spans)
    return Outcome(summary(sc, tab, spans, compute_s),
                   lambda f: write_observability(f, tab, truth, spans), truth, None, result=tab)


def write_observability(f: h5py.File, tab: ObservabilityTable, truth: Any,
                        spans: tuple[Span, ...]) -> None:
    """/observability: the table as its fields say (:class:`ObservabilityTable`); the
    segments of /truth."""
    from gcalign.io.results import write_segments
    from gcalign.io.stored import write_fields

    write_segments(f, truth, spans)
    write_fields(f.create_group("observability"), tab)
