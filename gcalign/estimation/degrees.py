"""The seed's observability table as a result (seed 002 §4): degrees, ranks and the
null-space condition per segment and from the start (:mod:`gcalign.calibrate.observability`
computes it). Apart from the computation (and from the filter's package), so that the checks
of a results file read back take its fields without loading the filter's kernels."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.estimation import ins_error as ie
from gcalign.schema import stored

DEGREE = "(segments, 21) in the order of the 'states' attribute"  #: shape of a degree table


@dataclass(frozen=True)
class ObservabilityTable:
    """Degrees of observability per segment and cumulative (S segments, 21 states).

    eta, sigma_state : (S, 21) per-segment SOM degree η = σ_(k)/σ_0 and the state's σ.
    rank, tom_rank : (S,) per-segment SOM and TOM ranks.
    null_residual : (S,) the largest ``‖F_j N_j‖/‖F_j‖`` over the segment's pieces
        (N_j = null(O_j)); condition : (S,) whether it is ≤ null_tol.
    eta_cum, rank_cum, tom_rank_cum : the same from the start of the run to each segment end.
    margin, margin_cum : (S,) the SOM rank's distance from the cut-off, per segment and
        cumulative (:attr:`gcalign.estimation.observability.Degree.margin`).
    cov_degree : (S, 21) σ_k(0)/σ_k(t_end); cov_degree_segment : σ_k(t_start)/σ_k(t_end);
        None without the covariance run.
    t0, t1 : (S,) each segment's start and end, s.
    """

    segments: tuple[str, ...] = field(metadata=stored(None, name="segment_name", dims="Q"))
    measure: str = field(metadata=stored(None, attr=True, summary=""))
    scaling: str = field(metadata=stored(None, attr=True, summary=""))
    rtol: float = field(metadata=stored("1", attr=True, name="rank_rtol", summary="",
                                        label="rank_rtol"))
    piece_s: float = field(metadata=stored("s", attr=True, summary="s", label="piece"))
    eta: np.ndarray = field(metadata=stored(
        "1", shape=DEGREE, description="seed eq. 17 per segment", dims="Q S"))
    sigma_state: np.ndarray = field(metadata=stored("SOM units", shape=DEGREE, dims="Q S",
                                                     optional=True))
    rank: np.ndarray = field(metadata=stored("1", dims="Q", whole=True, optional=True))
    tom_rank: np.ndarray = field(metadata=stored("1", dims="Q", whole=True, optional=True))
    null_residual: np.ndarray = field(metadata=stored("1", dims="Q", optional=True))
    condition: np.ndarray = field(metadata=stored(
        "1", flag=True, description="null(O_j) in null(F_j) for every piece (seed eq. 12)",
        dims="Q", whole=True, optional=True))
    eta_cum: np.ndarray = field(metadata=stored(
        "1", shape=DEGREE, description="from the start of the run", dims="Q S"))
    rank_cum: np.ndarray = field(metadata=stored("1", dims="Q", whole=True, optional=True))
    tom_rank_cum: np.ndarray = field(metadata=stored("1", dims="Q", whole=True, optional=True))
    cov_degree: np.ndarray | None = field(metadata=stored(
        "1", shape=DEGREE, description="sigma(0)/sigma(t_end), PSINS kfstat", dims="Q C",
        optional=True))
    cov_degree_segment: np.ndarray | None = field(metadata=stored(
        "1", shape=DEGREE, description="sigma(t_start)/sigma(t_end)", dims="Q C",
        optional=True))
    t0: np.ndarray | None = field(default=None, metadata=stored("s", dims="Q", rule="increasing"))
    t1: np.ndarray | None = field(default=None, metadata=stored("s", dims="Q", rule="increasing"))
    margin: np.ndarray = field(default_factory=lambda: np.zeros(0))
    margin_cum: np.ndarray = field(default_factory=lambda: np.zeros(0))
    names: tuple[str, ...] = field(default=ie.STATE_NAMES,
                                   metadata=stored(None, attr=True, name="states"))
