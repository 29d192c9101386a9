"""Observability of a transfer-alignment run (spec 006, "What the data support") by the
method of ``gcalign observability`` (seed 002 §3–4: piece-wise constant systems, SOM/TOM,
SVD degree), with the transfer filter's own F and H.

Pieces: the run's master epochs grouped into pieces of ``piece_s``; a piece's F is the
continuous model of the filter's per-step Φ (:func:`gcalign.transfer.model.error_matrix`,
``Φ = I + F T``) with the slave attitude C_nb and ω_in^n of the filter at the piece's middle
epoch and the mean specific force of the piece's steps; its H is the matching's rows of
``[I₆ 0]`` with ``H(φ rows, μ) = −C_m``, the master's attitude at the same epoch, and
``H(φ rows, φ) = J_l(C_m μ̂)⁻¹`` (the filter's own Jacobian,
:func:`gcalign.transfer.model.measurement_matrix`). Windows of ``window_s`` take the
place of a flight's manoeuvres: per window and cumulative, the SOM degree η = σ_(k)/σ_0
(seed eq. 17, σ_0 the largest of the directly measured states: φ for attitude matching, δv
for velocity matching; columns scaled by P0 by default, docs/decisions/013), the SOM and TOM
ranks and the null-space condition of seed eq. (12).

Beside them, per state: the separation of its column of the whole run's TOM from the span of
the other states' (:func:`gcalign.estimation.observability.column_separation`: 0 when it is
a combination of them, independent of P0 and units), and the covariance degree σ(0)/σ(t) of
the filter's own run (PSINS ``kfstat``).

What the model's structure says (the tests hold the command to it):

* velocity matching: μ enters neither F nor the velocity rows of H, so its columns of every
  O_j are zero (η = 0, separation 0) and, with P0 diagonal, its covariance never changes:
  σ(μ) = σ0 exactly;
* attitude matching on a vehicle that rolls about its body y axis only (heading and pitch
  constant), the slave turned from the body by μ: with C_nb = C_b(t) C(μ), the forward axis
  d = C_b(t) e_y constant and the roll axis in slave axes u = C(μ)ᵀ e_y (e_y but for μ
  itself), ``x = (φ = d, μ = u)`` gives ``H x = d − C_b(t) e_y = 0`` on every piece and
  ``F x = (−ω_in × d, f^n × d, 0, …)``, whose attitude rows vanish without the earth and
  transport rate ω_in (7e-5 rad/s): μ along the roll axis, mostly μ_y, is told from a
  constant attitude error about the forward axis only through ω_in, while μ_x, μ_z (columns
  −C_m e_x, −C_m e_z that turn with the roll) are observed; δv and ∇ reach neither H's
  attitude rows nor φ (zero columns). The filter's H takes μ through the master's attitude,
  which turns only as the vehicle does, and its model learns nothing of the combination
  (with the slave's mechanised C_nb, corrected at every update, it learnt what no data
  show: docs/decisions/019);
* attitude + velocity matching: φ along d is a tilt, which the velocity sees through
  ``f^n × φ`` (f^n ≈ g up, d horizontal): every μ is observable.

The flexure θ, ω (21 states) are a stationary Markov process driven by noise: a
deterministic analysis of the initial state cannot rate them (the fast mode β_z = 10 s⁻¹
puts its block of F^20 at 2e22 and swamps the SVD), so the PWCS covers the 15
constant-error states and the flexure rows carry the covariance degree only
(docs/decisions/014).

>>> from gcalign.transfer.filter import NAMES_15
>>> PWCS_STATES == NAMES_15
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.estimation import observability as ob
from gcalign.nav.rotation import quat_to_dcm
from gcalign.schema import stored
from gcalign.transfer.filter import NAMES_15, TransferResult
from gcalign.transfer.model import error_matrix, measurement_matrix

SCALINGS = ("none", "p0")
PWCS_STATES = NAMES_15  #: the states of the PWCS analysis (the flexure left out)
#: the shape of a table over the filter's states (its ``shape`` attribute)
COVARIANCE = "(windows, states) in the order of the 'covariance_states' attribute"
_MEASURED = {"attitude+velocity": [0, 1, 2, 3, 4, 5], "velocity": [3, 4, 5],
             "attitude": [0, 1, 2]}


@dataclass(frozen=True)
class TransferObservability:
    """The observability table of one run (S windows; 15 PWCS states, n filter states).

    matching, scaling, rtol, piece_s, window_s : how it was computed.
    names : (n,) the filter's states; pwcs : (15,) those of the PWCS analysis.
    t0, t1 : (S,) window bounds, s from the start of the run.
    table : :class:`gcalign.estimation.observability.SegmentTable` of the 15 states.
    condition : (S,) the null-space condition of seed eq. (12) holds (residual ≤ null_tol).
    separation : (15,) of the whole run's TOM.
    sigma0 : (n,) P0 σ; sigma_end : (S, n) σ at each window's last epoch.
    cov_degree : (S, n) σ0/σ(t1); cov_degree_segment : (S, n) σ(t0)/σ(t1).
    singular_values : (15,) of the whole run's TOM (scaled as the table), descending.
    unobservable : (15,) bool, the states whose TOM column is zero (no measurement, no path
        to one: exactly unobservable).
    weakest : (15,) unit vector, the right singular vector of the smallest singular value
        of the TOM of the other states (in the scaled coordinates: units of P0 σ with
        scaling p0), zero on the unobservable ones; weakest_ratio its σ_min/σ_max: the
        combination of states the run tells apart worst.
    pieces : J, the number of PWCS pieces.
    """

    row: ClassVar[str] = "window"  #: what a row of the table is (its stored texts)
    matching: str = field(metadata=stored(None, attr=True, name="measure", summary="",
                                          label="measure"))
    scaling: str = field(metadata=stored(None, attr=True, summary=""))
    rtol: float = field(metadata=stored("1", attr=True, name="rank_rtol", summary="",
                                        label="rank_rtol"))
    piece_s: float = field(metadata=stored("s", attr=True, summary="s", label="piece"))
    window_s: float = field(metadata=stored("s", attr=True, summary="s", label="window"))
    names: tuple[str, ...] = field(metadata=stored(None, attr=True, name="covariance_states"))
    pwcs: tuple[str, ...] = field(metadata=stored(None, attr=True, name="states"))
    t0: np.ndarray = field(metadata=stored("s", description="window start, from the start of "
                                               "the run"))
    t1: np.ndarray = field(metadata=stored("s"))
    table: ob.SegmentTable = field(metadata=stored("", inline=True))
    condition: np.ndarray = field(metadata=stored(
        "1", flag=True, description="null(O_j) in null(F_j) for every piece (seed eq. 12)"))
    separation: np.ndarray = field(metadata=stored(
        "1", description="of each state's TOM column from the span of the others (whole run)"))
    sigma0: np.ndarray = field(metadata=stored("SI", description="P0 sigma, "
                                                     "'covariance_states' order"))
    sigma_end: np.ndarray
    cov_degree: np.ndarray = field(metadata=stored(
        "1", shape=COVARIANCE, description="sigma(0)/sigma(t_end), PSINS kfstat"))
    cov_degree_segment: np.ndarray = field(metadata=stored(
        "1", shape=COVARIANCE, description="sigma(t_start)/sigma(t_end)"))
    singular_values: np.ndarray = field(metadata=stored("1", description="whole run's TOM"))
    unobservable: np.ndarray
    weakest: np.ndarray = field(metadata=stored(
        "1", description="right singular vector of the smallest singular value, scaled "
        "coordinates"))
    weakest_ratio: float
    pieces: int
    #: the windows by their bounds (``0–10 s``), in the file as ``segment_name``
    windows: tuple[str, ...] = field(init=False, metadata=stored(None, name="segment_name"))

    def __post_init__(self) -> None:
        object.__setattr__(self, "windows", tuple(
            f"{a:.0f}–{b:.0f} s" for a, b in zip(self.t0, self.t1, strict=True)))


@dataclass(frozen=True)
class Pieces:
    """PWCS pieces of a run: F (J, 15, 15), H (J, m, 15), duration (J,) s, start (J,) s from
    the run's start, middle (J,) the epoch index F and H come from, last (J,) the index of
    the piece's last epoch."""

    F: np.ndarray
    H: np.ndarray
    duration: np.ndarray
    start: np.ndarray
    middle: np.ndarray
    last: np.ndarray


def pieces(result: TransferResult, piece_s: float = 1.0, matching: str | None = None
           ) -> Pieces:
    """Group the run's epochs into pieces of `piece_s` (by the middle of each epoch's
    interval; at least one epoch each, so a `piece_s` below the master interval gives one
    piece per epoch) and build their F and H (module docstring). `matching` defaults to
    the run's."""
    if not (np.isfinite(piece_s) and piece_s > 0):
        raise ScenarioError(f"piece_s: must be a positive number of seconds, got {piece_s!r}")
    matching = matching or result.settings.matching
    r = result
    end = r.t - r.t0
    mid_time = end - 0.5 * r.dt
    index = np.floor(mid_time / piece_s + 1e-9).astype(int)
    first = np.flatnonzero(np.r_[True, index[1:] != index[:-1]])
    last = np.r_[first[1:] - 1, len(index) - 1]
    middle = (first + last) // 2
    dur = np.add.reduceat(r.dt, first)
    f_n = np.add.reduceat(r.f_n * r.dt[:, None], first, axis=0) / dur[:, None]
    F = np.array([error_matrix(r.C_nb[m], f, r.omega_in_n[m])
                  for m, f in zip(middle, f_n, strict=True)])
    # the filter's own H: μ through the master's attitude, φ through J_l(C_m μ̂)⁻¹ (velocity
    # matching, whose reference may have no attitude, uses no attitude rows)
    H = []
    for m in middle:
        if np.all(np.isfinite(r.q_master[m])):
            C_m = quat_to_dcm(r.q_master[m])
            mount = r.x[m, 12:15] + (r.x[m, 15:18] if r.x.shape[1] == 21 else 0.0)
            H.append(measurement_matrix(C_m, matching, mount_n=C_m @ mount))
        else:
            H.append(measurement_matrix(r.C_nb[m], matching))
    start = np.maximum(end[first] - r.dt[first], 0.0)  # the first is 0 (not −1e-17)
    return Pieces(F=F, H=np.array(H), duration=dur, start=start, middle=middle, last=last)


def transfer_observability(result: TransferResult, piece_s: float = 1.0,
                           window_s: float = 10.0, scaling: str = "p0",
                           rtol: float = ob.RANK_RTOL_DEFAULT,
                           null_tol: float = 1e-9) -> TransferObservability:
    """The observability table of a transfer-alignment run (module docstring), for the
    run's own matching (its covariance is the filter's, so one run per matching).

    Parameters
    ----------
    result : the run (:func:`gcalign.transfer.transfer_align`).
    piece_s : PWCS piece length, s; window_s : window length, s (the table's rows).
    scaling : "p0" (columns × the P0 σ) or "none" (the states' SI units).
    rtol : relative rank tolerance; null_tol : bound of the eq. (12) residual.
    """
    if scaling not in SCALINGS:
        raise ScenarioError(f"scaling: got {scaling!r}, allowed: {', '.join(SCALINGS)}")
    if not (0.0 < rtol < 1.0):
        raise ScenarioError(f"rtol: must lie in (0, 1), got {rtol!r}")
    if not (np.isfinite(window_s) and window_s > 0):
        raise ScenarioError(f"window_s: must be a positive number of seconds, got "
                            f"{window_s!r}")
    r, n_p = result, len(PWCS_STATES)
    pc = pieces(r, piece_s)
    win = np.floor((pc.start + 0.5 * pc.duration) / window_s + 1e-9).astype(int)
    _, segment = np.unique(win, return_inverse=True)  # windows without a piece dropped
    S = int(segment.max()) + 1
    scale = r.sigma0[:n_p] if scaling == "p0" else None
    tab = ob.segment_table(pc.F, pc.H, pc.duration, segment, S,
                           _MEASURED[r.settings.matching], scale, rtol)
    first = np.array([np.flatnonzero(segment == i)[0] for i in range(S)])
    final = np.array([np.flatnonzero(segment == i)[-1] for i in range(S)])
    t0, t1 = pc.start[first], pc.start[final] + pc.duration[final]
    k_end = pc.last[final]
    sigma_end = r.sigma[k_end]
    sigma_start = np.vstack([r.sigma0[None, :], sigma_end[:-1]])
    R = tab.R_tom_cum  # scaled like the degrees
    s_all = np.linalg.svd(R, compute_uv=False)
    zero = ~np.any(R != 0.0, axis=0)
    weakest, ratio = np.zeros(n_p), 0.0
    if not zero.all():
        _, s_obs, Vt = np.linalg.svd(R[:, ~zero])
        weakest[~zero] = Vt[-1] * np.sign(Vt[-1][np.argmax(np.abs(Vt[-1]))])
        ratio = float(s_obs[-1] / s_obs[0]) if len(s_obs) == int((~zero).sum()) else 0.0
    return TransferObservability(
        matching=r.settings.matching, scaling=scaling, rtol=rtol, piece_s=piece_s,
        window_s=window_s, names=r.names, pwcs=PWCS_STATES, t0=t0, t1=t1, table=tab,
        condition=tab.null_residual <= null_tol,
        separation=ob.column_separation(tab.R_tom_cum), sigma0=r.sigma0,
        sigma_end=sigma_end, cov_degree=r.sigma0 / sigma_end,
        cov_degree_segment=sigma_start / sigma_end, singular_values=s_all,
        unobservable=zero, weakest=weakest, weakest_ratio=ratio, pieces=len(pc.duration))
