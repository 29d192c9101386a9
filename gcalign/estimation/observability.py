"""Observability of piece-wise constant systems (PWCS) by SVD (seed 002 §3, eqs. 8–17; spec §4).

Time is split into pieces j with constant system matrix F_j and duration Δ_j. With m
measurements and n states:

* piece observability matrix (eq. 9): ``O_j = [H; H F_j; …; H F_j^{n−1}]`` (n·m, n);
* total observability matrix, TOM (eq. 10):
  ``Q(r) = [O_1; O_2 e^{F_1Δ_1}; …; O_r e^{F_{r−1}Δ_{r−1}} ⋯ e^{F_1Δ_1}]``;
* stripped observability matrix, SOM (eq. 11): ``Q_s(r) = [O_1; …; O_r]``; if
  ``null(O_j) ⊂ null(F_j)`` for every j then ``rank Q = rank Q_s`` (eq. 12);
* SVD ``Q_s = U S Vᵀ`` (eq. 14): ``x(0) = Σ (u_iᵀY/σ_i) v_i`` (eq. 16). For noise-free
  ``Y = Q_s x₀`` the i-th term is ``(v_iᵀx₀) v_i``, so the state a singular value belongs
  to is ``argmax_k |v_i(k)|``, independent of the data (spec §4 [R]);
* degree (eq. 17): ``η_k = σ_(k)/σ_0`` with σ_0 the singular value of the directly measured
  states (velocity for velocity matching). Several σ for one state: the largest counts;
  none: η = 0. Singular values below the rank tolerance count as 0.

The paper does not scale the states (its small singular values of the last nine states
"come from the states' small magnitudes"); ``scale`` (e.g. the initial σ, PSINS/Yan
style) multiplies the columns, ``Q_s diag(σ₀)``. Degrees depend strongly on both the
scaling and the rank tolerance: always say which were used.

The covariance-based degree σ_k(0)/σ_k(t) (PSINS ``kfstat``) is the cross-check.

>>> import numpy as np
>>> F = np.array([[0.0, 1.0], [0.0, 0.0]])              # position, velocity
>>> d = degree(som([piece_matrix(F, np.array([[1.0, 0.0]]))]), measured=[0])
>>> d.rank, d.eta.round(12).tolist()
(2, [1.0, 1.0])
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from gcalign.schema import stored

RANK_RTOL_DEFAULT = 1e-12
"""Singular values below ``rtol · σ_max`` count as zero (rank and degree)."""


def piece_matrix(F: np.ndarray, H: np.ndarray) -> np.ndarray:
    """``O = [H; H F; …; H F^{n−1}]`` (seed eq. 9), vectorised over leading axes of F.

    F (..., n, n), H (m, n) or one per piece (..., m, n) -> (..., n·m, n).
    """
    F, H = np.asarray(F, dtype=float), np.asarray(H, dtype=float)
    n = F.shape[-1]
    rows = [np.broadcast_to(H, F.shape[:-2] + H.shape[-2:])]
    for _ in range(n - 1):
        rows.append(rows[-1] @ F)
    return np.concatenate(rows, axis=-2)


def expm_stack(A: np.ndarray) -> np.ndarray:
    """Matrix exponentials of a stack (..., n, n) by scaling and squaring a degree-18 Taylor
    series (‖A/2^s‖∞ ≤ 1/2, truncation below 1e-22), on stacked small products only:
    LAPACK's tall or multi-threaded paths collapse when the cores are shared."""
    A = np.asarray(A, dtype=float)
    norm = float(np.abs(A).sum(-1).max()) if A.size else 0.0
    s = max(0, int(np.ceil(np.log2(norm))) + 1) if norm > 0 else 0
    X = A / 2.0**s
    eye = np.broadcast_to(np.eye(A.shape[-1]), A.shape)
    E = eye.copy()
    for k in range(18, 0, -1):  # Horner: I + X/1 (I + X/2 (… (I + X/18)))
        E = eye + (X @ E) / k
    for _ in range(s):
        E = E @ E
    return E


def r_factor(A: np.ndarray) -> np.ndarray:
    """Triangular factor R (≤ n, n) of a tall A (rows, n), ``A = Q R``: the singular values
    and right singular vectors of A. Reduced pairwise by batches of (2n × n) QRs (TSQR)
    so that no LAPACK call sees more than 2n rows."""
    A = np.asarray(A, dtype=float)
    n = A.shape[1]
    while A.shape[0] > 2 * n:
        k = -(-A.shape[0] // (2 * n))
        blocks = np.zeros((k * 2 * n, n))
        blocks[: A.shape[0]] = A
        A = np.asarray(np.linalg.qr(blocks.reshape(k, 2 * n, n), mode="r")).reshape(k * n, n)
    return np.asarray(np.linalg.qr(A, mode="r")) if A.shape[0] > n else A


def som(O_pieces: Iterable[np.ndarray]) -> np.ndarray:
    """Stripped observability matrix ``[O_1; …; O_r]`` (seed eq. 11)."""
    return np.concatenate(list(O_pieces), axis=0)


def tom(O_pieces: Sequence[np.ndarray], F_pieces: Sequence[np.ndarray] | np.ndarray,
        durations: ArrayLike) -> np.ndarray:
    """Total observability matrix ``[O_1; O_2 e^{F_1Δ_1}; …]`` (seed eq. 10)."""
    n = F_pieces[0].shape[-1]
    Phi = expm_stack(np.asarray(F_pieces) * np.asarray(durations, dtype=float)[:, None, None])
    M = np.eye(n)
    out = []
    for O, P in zip(O_pieces, Phi, strict=True):
        out.append(O @ M)
        M = P @ M
    return np.concatenate(out, axis=0)


def null_space_residual(O: np.ndarray, F: np.ndarray,
                        rtol: float = RANK_RTOL_DEFAULT) -> Any:  # float or (...,)
    """``‖F N‖_F / ‖F‖_F`` with N an orthonormal basis of null(O): zero exactly when
    null(O) ⊂ null(F) (the condition of seed eq. 12). Vectorised over leading axes of O
    (..., rows, n) and F (..., n, n); a float for a single piece."""
    O, F = np.asarray(O, dtype=float), np.asarray(F, dtype=float)
    n = O.shape[-1]
    _, s, Vt = np.linalg.svd(O, full_matrices=True)
    s_full = np.zeros(O.shape[:-2] + (n,))
    s_full[..., : s.shape[-1]] = s
    null = s_full <= rtol * np.maximum(s_full[..., :1], np.finfo(float).tiny)  # (..., n)
    FV = F @ np.swapaxes(Vt, -1, -2)  # columns F v_i
    num = np.sqrt(np.sum(np.where(null[..., None, :], FV, 0.0) ** 2, axis=(-2, -1)))
    den = np.sqrt(np.sum(F**2, axis=(-2, -1)))
    out = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return float(out) if out.ndim == 0 else out


@dataclass(frozen=True)
class Degree:
    """SVD of an observability matrix and the seed's degree of observability (eq. 17).

    sigma : (n,) singular values, descending (zero-padded when rows < n).
    V : (n, n) right singular vectors as columns.
    owner : (n,) state index each singular value belongs to (argmax |v_i|).
    sigma_state : (n,) the largest singular value belonging to each state (0 if none or
        below the rank tolerance).
    eta : (n,) ``σ_state / σ_0``; sigma_0 : the measured states' largest σ_state.
    rank : numerical rank (σ > rtol · σ_max).
    """

    sigma: np.ndarray
    V: np.ndarray
    owner: np.ndarray
    sigma_state: np.ndarray
    eta: np.ndarray
    sigma_0: float
    rank: int
    rtol: float

    @property
    def margin(self) -> float:
        """How far the rank is from the cut-off ``c = rtol·σ_max``: the smaller of
        ``σ_rank / c`` (the last singular value kept) and ``c / σ_rank+1`` (the first one
        dropped); the factor by which the tolerance may change before the rank does (inf
        for full rank with nothing near the cut-off from below)."""
        cut = self.rtol * float(self.sigma[0])
        if cut <= 0:
            return math.inf
        above = float(self.sigma[self.rank - 1]) / cut if self.rank > 0 else math.inf
        below = (cut / float(self.sigma[self.rank])
                 if self.rank < len(self.sigma) and self.sigma[self.rank] > 0 else math.inf)
        return min(above, below)


def degree(Q: np.ndarray, measured: Iterable[int], scale: ArrayLike | None = None,
           rtol: float = RANK_RTOL_DEFAULT) -> Degree:
    """Degree of observability of every state from the (stripped) observability matrix Q.

    Parameters
    ----------
    Q : (rows, n) observability matrix (SOM or TOM).
    measured : indices of the directly measured states (σ_0 is their largest σ_state).
    scale : (n,) or None. Column scaling (``Q diag(scale)``), e.g. the initial σ; None is
        the paper's unscaled analysis.
    rtol : singular values ≤ ``rtol · σ_max`` are zero.
    """
    Q = np.asarray(Q, dtype=float)
    n = Q.shape[1]
    if scale is not None:
        Q = Q * np.asarray(scale, dtype=float)
    # A tall Q has the singular values and right vectors of its triangular factor.
    if Q.shape[0] > 2 * n:
        Q = r_factor(Q)
    _, s, Vt = np.linalg.svd(Q, full_matrices=True)
    sigma = np.zeros(n)
    sigma[: len(s)] = s
    V = Vt.T
    cut = rtol * sigma[0]
    kept = np.where(sigma > cut, sigma, 0.0)
    owner = np.argmax(np.abs(V), axis=0)
    sigma_state = np.zeros(n)
    np.maximum.at(sigma_state, owner, kept)
    sigma_0 = float(np.max(sigma_state[list(measured)]))
    eta = sigma_state / sigma_0 if sigma_0 > 0 else np.zeros(n)
    return Degree(sigma=sigma, V=V, owner=owner, sigma_state=sigma_state, eta=eta,
                  sigma_0=sigma_0, rank=int(np.sum(sigma > cut)), rtol=rtol)


def column_separation(Q: np.ndarray) -> np.ndarray:
    """Per state k, ``‖(I − Π_k) Q e_k‖ / ‖Q e_k‖`` with Π_k the projection on the span of
    the other columns of Q (rows, n): 1 when the state acts unlike any combination of the
    others, 0 when it is one (unobservable: a null vector of Q has its component), and 0
    for a zero column. Association-free (no singular value is assigned to a state) and
    unchanged by any scaling of the columns, so by the units and P0; the SVD degree's
    companion when two states trade places under a scaling. (n,)

    >>> Q = np.array([[1.0, 2.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])  # x1 = 2·x0 alike
    >>> column_separation(Q).round(12).tolist()
    [0.0, 0.0, 1.0]
    """
    Q = np.asarray(Q, dtype=float)
    n = Q.shape[1]
    if Q.shape[0] > 2 * n:
        Q = r_factor(Q)  # the same column geometry (QᵀQ = RᵀR) in n rows
    out = np.zeros(n)
    for k in range(n):
        q = Q[:, k]
        norm = float(np.linalg.norm(q))
        if norm == 0.0:
            continue
        others = np.delete(Q, k, axis=1)
        coef, *_ = np.linalg.lstsq(others, q, rcond=None)
        out[k] = float(np.linalg.norm(q - others @ coef)) / norm
    return out


#: the shape of a table's degrees (``{row}``: what a row is, said by the result that holds it)
_SHAPE = "({row}s, states) in the order of the 'states' attribute"


@dataclass(frozen=True)
class SegmentTable:
    """SOM/TOM degrees of a run cut into S segments of PWCS pieces (n states).

    eta, sigma_state : (S, n) per-segment SOM degree and the state's singular value.
    rank, tom_rank : (S,) per-segment SOM and TOM (from the segment's first piece) ranks.
    null_residual : (S,) the largest piece residual of seed eq. (12) in the segment.
    eta_cum, rank_cum, tom_rank_cum : from the start of the run to each segment's end.
    margin, margin_cum : (S,) the SOM ranks' distance from the cut-off.
    R_som_cum, R_tom_cum : (n, n) triangular factors of the whole run's SOM and TOM, scaled
        by `scale` (their singular values and right vectors; :func:`column_separation`).
    """

    eta: np.ndarray = field(metadata=stored("1", shape=_SHAPE, description="seed eq. 17 per "
                                                                       "{row}"))
    sigma_state: np.ndarray = field(metadata=stored("SOM units", shape=_SHAPE))
    rank: np.ndarray = field(metadata=stored("1"))
    tom_rank: np.ndarray = field(metadata=stored("1"))
    null_residual: np.ndarray = field(metadata=stored("1"))
    eta_cum: np.ndarray = field(metadata=stored("1", shape=_SHAPE,
                                                description="from the start of the run"))
    rank_cum: np.ndarray = field(metadata=stored("1"))
    tom_rank_cum: np.ndarray = field(metadata=stored("1"))
    margin: np.ndarray
    margin_cum: np.ndarray
    R_som_cum: np.ndarray
    R_tom_cum: np.ndarray


def _stack_r(R: np.ndarray | None, rows: np.ndarray) -> np.ndarray:  # (≤ n, n)
    """Triangular factor of ``[R; rows]``: the SVD of a stack only needs it."""
    return r_factor(rows if R is None else np.vstack([R, rows]))


def segment_table(F: np.ndarray, H: np.ndarray, duration: np.ndarray, segment: np.ndarray,
                  n_segments: int, measured: Iterable[int], scale: ArrayLike | None = None,
                  rtol: float = RANK_RTOL_DEFAULT) -> SegmentTable:
    """Per segment and cumulative SOM/TOM degrees and ranks of PWCS pieces (seed eqs.
    9–17): F (J, n, n) per piece, H (m, n) or (J, m, n), duration (J,) s, segment (J,) the
    segment index of each piece (non-decreasing, 0 … n_segments − 1); `measured`, `scale`
    and `rtol` as :func:`degree`."""
    F, measured = np.asarray(F, dtype=float), list(measured)
    n = F.shape[-1]
    sc = np.ones(n) if scale is None else np.asarray(scale, dtype=float)
    # O_j = Q_j R_j: every stack of O_j (SOM) or O_j M (TOM) has the singular values and
    # right vectors of the same stack of R_j, half the rows
    O = piece_matrix(F, H)
    Rp = np.asarray(np.linalg.qr(O, mode="r"))
    Phi = expm_stack(F * np.asarray(duration, dtype=float)[:, None, None])
    # condition of seed eq. (12), in the coordinates the ranks are taken in (x = diag(sc) y)
    resid_piece = null_space_residual(Rp * sc, F * sc / sc[:, None], rtol)

    eta, sig = np.zeros((n_segments, n)), np.zeros((n_segments, n))
    eta_c = np.zeros((n_segments, n))
    rank, tom_rank, rank_c, tom_c = (np.zeros(n_segments, int) for _ in range(4))
    resid, margin, margin_c = (np.zeros(n_segments) for _ in range(3))
    R_cum: np.ndarray | None = None
    R_tom_cum: np.ndarray | None = None
    M_cum = np.eye(n)
    for i in range(n_segments):
        js = np.flatnonzero(segment == i)
        R_seg = _stack_r(None, som(Rp[js]))
        d = degree(R_seg, measured, scale, rtol)
        eta[i], sig[i], rank[i], margin[i] = d.eta, d.sigma_state, d.rank, d.margin
        # TOM of the segment alone (from its first piece) and from the start of the run
        M = np.eye(n)
        rows, rows_cum = [], []
        for j in js:
            rows.append(Rp[j] @ M)
            rows_cum.append(Rp[j] @ M_cum)
            M, M_cum = Phi[j] @ M, Phi[j] @ M_cum
        tom_rank[i] = degree(_stack_r(None, np.vstack(rows)), measured, scale, rtol).rank
        R_tom_cum = _stack_r(R_tom_cum, np.vstack(rows_cum))
        tom_c[i] = degree(R_tom_cum, measured, scale, rtol).rank
        R_cum = _stack_r(R_cum, R_seg)
        dc = degree(R_cum, measured, scale, rtol)
        eta_c[i], rank_c[i], margin_c[i] = dc.eta, dc.rank, dc.margin
        resid[i] = resid_piece[js].max()
    assert R_cum is not None and R_tom_cum is not None
    return SegmentTable(eta=eta, sigma_state=sig, rank=rank, tom_rank=tom_rank,
                        null_residual=resid, eta_cum=eta_c, rank_cum=rank_c,
                        tom_rank_cum=tom_c, margin=margin, margin_cum=margin_c,
                        R_som_cum=R_cum * sc, R_tom_cum=R_tom_cum * sc)


def covariance_degree(P0: np.ndarray, P: np.ndarray) -> np.ndarray:
    """PSINS ``kfstat`` degree ``σ_k(0)/σ_k(t)`` per state (≥ 1 for constant states), (n,)
    or (..., n) for a stack of covariances P (..., n, n)."""
    s0 = np.sqrt(np.diagonal(P0, axis1=-2, axis2=-1))
    return s0 / np.sqrt(np.diagonal(P, axis1=-2, axis2=-1))


def separation(Q: np.ndarray, k: int, j: int) -> float:
    """How far state k's column of Q is from state j's: ``‖(I − Π_j) Q e_k‖ / ‖Q e_j‖``
    with Π_j the projection on ``Q e_j`` (0 when the two states act alike, in the unit of
    state j per unit of state k). Association-free and independent of the state scaling
    of any other state; e.g. k = δKg_x, j = ε_x gives the effective change of ω_x over the
    pieces in rad/s."""
    a, b = Q[:, k], Q[:, j]
    bb = float(b @ b)
    if bb == 0.0:
        return float("inf") if np.any(a) else 0.0
    return float(np.linalg.norm(a - (a @ b) / bb * b) / np.sqrt(bb))
