"""The seed's observability table (Table 1 analogue) on a trajectory (seed 002 §3–4, spec §4).

Each manoeuvre (segment) is cut into pieces of ``piece_s`` (1 s; the last piece of a
segment may be shorter) with F from the truth at the middle of the piece. Per segment:
the SOM of its pieces, the SVD degree η (states unscaled by default, as the paper), the
rank, the TOM rank, and the null-space condition ``null(O_j) ⊂ null(F_j)`` under which the
two ranks must agree (seed eq. 12). Cumulative: the SOM from the start of the run to the
end of each segment. Beside them, the covariance degree σ_k(0)/σ_k(t) (PSINS ``kfstat``)
from :func:`gcalign.calibrate.filter.covariance_run`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from gcalign.calibrate.data import Span, Trajectory
from gcalign.calibrate.filter import Settings, covariance_run
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.estimation import observability as ob
from gcalign.estimation.degrees import DEGREE as DEGREE
from gcalign.estimation.degrees import ObservabilityTable as ObservabilityTable

SCALINGS = ("none", "p0")


@dataclass(frozen=True)
class Pieces:
    """PWCS pieces of a run: F (J, 21, 21) at the piece midpoints, duration (J,) s,
    segment (J,) index of the segment each piece belongs to."""

    F: np.ndarray
    duration: np.ndarray
    segment: np.ndarray


def pieces(truth: Trajectory, segments: Sequence[Span], piece_s: float = 1.0) -> Pieces:
    """Cut each segment into pieces of `piece_s` and evaluate F at their midpoints."""
    if not (np.isfinite(piece_s) and piece_s > 0):
        raise ScenarioError(f"piece_s: must be a positive number of seconds, got {piece_s!r}")
    t0, t1 = float(truth.t[0]), float(truth.t[-1])
    mids, durs, seg = [], [], []
    for i, sp in enumerate(segments):
        if not (t0 - 1e-9 <= sp.start < sp.end <= t1 + 1e-9):
            raise ScenarioError(f"segments[{i}] ({sp.name!r}): [{sp.start:g}, {sp.end:g}] s "
                                f"is not a non-empty part of the run [{t0:g}, {t1:g}] s")
        edges = np.r_[np.arange(sp.start, sp.end - 1e-9, piece_s), sp.end]
        mids.append(0.5 * (edges[1:] + edges[:-1]))
        durs.append(np.diff(edges))
        seg.append(np.full(len(edges) - 1, i))
    mid = np.concatenate(mids)
    k = np.clip(np.floor((mid - t0) / truth.ts + 1e-9).astype(int), 0, len(truth.f_b) - 1)
    C_nb, f_b, omega_ib_b, v_n, pos = truth.midpoints(k)
    F = ie.error_matrix(C_nb, f_b, omega_ib_b, v_n, pos, earth=truth.earth)
    return Pieces(F=F, duration=np.concatenate(durs), segment=np.concatenate(seg))


@dataclass(frozen=True)
class ObservabilitySettings:
    """Settings of :func:`observability` (see :func:`observability_table` for each)."""

    measure: str = "velocity"
    scaling: str = "p0"  # docs/decisions/013: the unscaled ranks depend on the units
    rtol: float = ob.RANK_RTOL_DEFAULT
    piece_s: float = 1.0
    null_tol: float = 1e-9
    covariance: bool = True


def observability(truth: Trajectory, segments: tuple[Span, ...],
                  settings: ObservabilitySettings | None = None,
                  filter_settings: Settings | None = None) -> ObservabilityTable:
    """The observability table of `truth` cut into `segments` (spec 002 §3–4): the array
    route of ``gcalign observability``. `filter_settings` give P0 (scaling ``p0``) and the
    covariance degree."""
    s = settings or ObservabilitySettings()
    return observability_table(truth, segments, s.measure, s.scaling, s.rtol, s.piece_s,
                               s.null_tol, filter_settings, s.covariance)


def observability_table(truth: Trajectory, segments: tuple[Span, ...], measure: str = "velocity",
                        scaling: str = "p0", rtol: float = ob.RANK_RTOL_DEFAULT,
                        piece_s: float = 1.0, null_tol: float = 1e-9,
                        settings: Settings | None = None,
                        covariance: bool = True) -> ObservabilityTable:
    """The per-segment and cumulative observability table of `truth` (spec 002 §4).

    measure : "velocity" | "position" | "both"; σ_0 is the largest σ of the directly
        measured states (the non-zero columns of H).
    scaling : "p0" (columns scaled by the initial σ of `settings`: ranks and degrees that do
        not depend on the units) or "none" (the paper's literal table).
    rtol : relative rank tolerance (singular values ≤ rtol·σ_max are zero).
    null_tol : the null-space condition holds where the residual is at most this.
    settings : filter settings for P0 (scaling p0) and the covariance degree (its measure
        is replaced by `measure`); default :class:`Settings`.
    """
    if scaling not in SCALINGS:
        raise ScenarioError(f"scaling: got {scaling!r}, allowed: {', '.join(SCALINGS)}")
    if not (0.0 < rtol < 1.0):
        raise ScenarioError(f"rtol: must lie in (0, 1), got {rtol!r}")
    s = replace(settings or Settings(), measure=measure)
    H = ie.measurement_matrix(measure, truth.pos[0], truth.earth)
    measured = np.flatnonzero(np.any(H != 0.0, axis=0))
    scale = (np.sqrt(np.diag(s.covariances(truth.pos[0], truth.earth)[0])) if scaling == "p0"
             else None)
    pc = pieces(truth, segments, piece_s)
    tab = ob.segment_table(pc.F, H, pc.duration, pc.segment, len(segments), measured, scale,
                           rtol)

    cov = cov_seg = None
    if covariance:
        run = covariance_run(truth, s)
        P_end = np.array([run.at(sp.end) for sp in segments])
        P_start = np.array([run.at(sp.start) for sp in segments])
        cov = ob.covariance_degree(run.P[0], P_end)
        cov_seg = np.sqrt(np.diagonal(P_start, axis1=1, axis2=2)
                          / np.diagonal(P_end, axis1=1, axis2=2))
    return ObservabilityTable(
        segments=tuple(sp.name for sp in segments), measure=measure, scaling=scaling, rtol=rtol,
        piece_s=piece_s, eta=tab.eta, sigma_state=tab.sigma_state, rank=tab.rank,
        tom_rank=tab.tom_rank, null_residual=tab.null_residual,
        condition=tab.null_residual <= null_tol, eta_cum=tab.eta_cum, rank_cum=tab.rank_cum,
        tom_rank_cum=tab.tom_rank_cum, cov_degree=cov, cov_degree_segment=cov_seg,
        t0=np.array([sp.start for sp in segments]), t1=np.array([sp.end for sp in segments]),
        margin=tab.margin, margin_cum=tab.margin_cum)
