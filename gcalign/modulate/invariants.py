r"""What a rotation schedule does to constant sensor errors, from the schedule itself
(spec 004 §2, §3, §6: the invariant report).

With the sensor frame s turning in the reference frame r (body or navigation) as
``C(t) = C_s^r(t)`` and rate ``ω(t)`` (rad/s, sensor frame), a constant sensor-frame error
enters the reference frame as follows (open loop: no earth rate, no navigation loops):

* gyro bias ε and accelerometer bias ∇: ``C(t) ε``, ``C(t) ∇``. Over a cycle they leave the
  residual biases ``C̄ ε`` and ``C̄ ∇`` with ``C̄ = (1/T) ∫_cycle C dt``; what remains
  oscillates, and displaces the attitude by ``∫_0^t (C − C̄) ε dt``.
* scale factor and misalignment × mechanism rate, ``(diag δk + M) ω``: the rate tensor
  ``W[:, i, j](t) = ∫_0^t C e_i ω_j dt`` (rad) gives the open-loop attitude term
  ``m(t) = Σ_ij (diag δk + M)_ij W[:, i, j](t)`` — the gyro-only attitude relative to the
  mechanism is ``−m`` to first order. For a turn about a sensor axis u, ``C u`` is constant
  (``R_u(θ) u = u``), so the scale-factor term of a step is exactly ``δk_u Δθ C_before u``:
  the net over the seed's 12 steps is ``Σ ±π δk_u C_before u = 0`` (its ccw and cw halves
  cancel), and within the cycle it reaches 2π·δk on each axis.

* asymmetric scale factor × mechanism rate, ``δk_asym ⊙ |ω|``: the sense of a turn does not
  change its sign, so the ccw and cw halves of a scheme add instead of cancelling. Per
  cycle it leaves ``asym_net = A δk_asym`` with ``A[:, j] = ∫_cycle C e_j |ω_j| dt`` (rad):
  for a turn about u, π·C_before u per 180° whatever its sense. Divided by the period it is
  a residual drift, like C̄ ε.

A term that returns to zero every cycle still has a cycle mean (``*_offset``): the
computed attitude is off by −m(t), on average by −m̄, a standing tilt and heading error
that the navigation loops see as if it were an initial attitude error (it starts the
Schuler and earth-rate oscillations). For the seed's scheme m̄ = π δk (−1, 1, 1)
(6.5″ per 10 ppm); a scheme whose second half repeats the first with every turn reversed
(``single-4``, ``four-position-24``) has m̄ = 0.

The literal seed-12 scheme (spec §2): over any symmetric turn profile ``∫cos θ dt = 0`` and
the sine terms cancel in pairs, so ``∫_cycle C dt = 4(Ts + Tz)·diag(−1, 1, 1)`` exactly,
``C̄ = diag(−1, 1, 1)/3`` — at each of the three equally weighted positions every sensor
axis lies along ± one reference axis, so each diagonal entry of the mean is a sum of three
±1: odd, never zero. The seed's claim that all constant drifts are "completely modulated"
does not hold.

Schuler resonance (spec §3): a bias modulated at ω_m drives the Schuler loop, attenuated
only by ``ω_s² / |ω_m² − ω_s²|``; so does every other error the mechanism modulates — the
scale-factor and misalignment × rate terms m(t) repeat with the cycle too, and a net of 0
per cycle does not keep their harmonics out of the loop, nor their cycle mean (the
``*_offset`` below) out of the navigation. We warn when a harmonic k of C(t) with amplitude above
1 % has its period ``T/k`` within ±20 % of the Schuler period (k = 1: the cycle period
itself; dual-16 with the seed's timing: 83.2 min against 84.46 min).

Integrals are Gauss–Legendre on the schedule's pieces (:mod:`._quadrature`), exact to
round-off for these profiles; peaks are taken at every piece end and every 5.6° of turn
(exact for turns about sensor axes, where each term is monotonic or, for ∫C dt, linear in
the turning column; within a few 1e-5 otherwise).

>>> from gcalign.modulate.schemes import builtin_scheme
>>> r = invariant_report(builtin_scheme("seed-12"))
>>> (np.round(3 * r.mean_C, 12) + 0.0).tolist()
[[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from gcalign.modulate._quadrature import CycleGrid, cycle_grid
from gcalign.modulate.schemes import Scheme
from gcalign.modulate.terms import SEED004_LAT, ErrorTerms
from gcalign.nav.earth import SEED004, EarthModel
from gcalign.schema import stored
from gcalign.sim.schedule import Schedule

SCHULER_BAND = 0.2  # warn when a harmonic's period is within ±20 % of Schuler's
HARMONIC_FLOOR = 0.01  # ... and its amplitude per unit bias exceeds 1 %
PEAK_SPAN = math.pi / 32  # rad of turn between the samples where peaks are taken


@dataclass(frozen=True)
class Harmonic:
    """Harmonic k of C(t) near the Schuler frequency: period T/k (s), amplitude (largest
    column of 2|c_k|, per unit bias), attenuation ω_s²/|ω_k² − ω_s²| (> 1: amplified)."""

    k: int
    period: float
    amplitude: float
    attenuation: float


#: the frame of the stored invariants
REF = "reference frame of the scheme (body or navigation), sensor axes in columns"
#: how an error term over the cycle (rad per sensor axis) is stored and summarised
_TERM = stored("rad", frame=REF, summary="arcsec", dims="3", optional=True)


@dataclass(frozen=True)
class InvariantReport:
    """The invariant report of one scheme (SI; vectors resolved in the reference frame).

    Attributes
    ----------
    scheme, reference : name and ``"body"`` | ``"navigation"``.
    period : cycle period T, s.
    integral_C : (3, 3) s, ∫_cycle C dt.  mean_C : (3, 3), C̄ = integral_C / T.
    rate_tensor : (3, 3, 3) rad, ``W[:, i, j] = ∫_cycle C e_i ω_j dt``.
    peak_integral_C : (3,) s, per sensor axis j: max over the cycle of |∫_0^t C e_j dt|.
    errors : the :class:`ErrorTerms` the vectors below are for.
    residual_gyro_bias : (3,) rad/s, C̄ ε.  residual_accel_bias : (3,) m/s², C̄ ∇.
    gyro_bias_excursion : (3,) rad, per axis max |∫_0^t (C − C̄) ε dt| over the cycle.
    gyro_bias_offset : (3,) rad, the cycle mean of ∫_0^t (C − C̄) ε dt.
    scale_factor_net, scale_factor_peak, scale_factor_offset : (3,) rad, the scale-factor
        term m(T), per axis max |m(t)|, and the cycle mean of m(t).
    misalignment_net, misalignment_peak, misalignment_offset : (3,) rad, the same for the
        misalignment term.
    abs_rate_integral : (3, 3) rad, ``A[:, j] = ∫_cycle C e_j |ω_j| dt``.
    asym_net : (3,) rad, ``A δk_asym``: the asymmetric scale-factor term over a cycle
        (``asym_net / period`` acts as a residual gyro drift).
    schuler_period : s, 2π/ω_s at the site.
    harmonics : the harmonics of C(t) within ±20 % of the Schuler period (any amplitude).
    warnings : human-readable warnings (Schuler resonance).
    t : (K,) s, times in the cycle where the running values below are given.
    running_C : (K, 3, 3) s, ∫_0^t C dt.  running_rate : (K, 3, 3, 3) rad, W(t).
    """

    scheme: str
    reference: str
    period: float = field(metadata=stored("s", attr=True, name="period_s"))
    integral_C: np.ndarray = field(metadata=stored("s", frame=REF, dims="3 3", optional=True))
    mean_C: np.ndarray = field(metadata=stored("", frame=REF, dims="3 3", optional=True))
    rate_tensor: np.ndarray = field(metadata=stored("rad", frame=REF, dims="3 3 3", optional=True))
    peak_integral_C: np.ndarray = field(
        metadata=stored("s", frame=REF, summary="s", dims="3", optional=True))
    errors: ErrorTerms
    residual_gyro_bias: np.ndarray = field(
        metadata=stored("rad/s", frame=REF, dims="3", optional=True))
    residual_accel_bias: np.ndarray = field(
        metadata=stored("m/s^2", frame=REF, dims="3", optional=True))
    gyro_bias_excursion: np.ndarray = field(metadata=_TERM)
    gyro_bias_offset: np.ndarray = field(
        metadata=stored("rad", frame=REF, dims="3", optional=True))
    scale_factor_net: np.ndarray = field(metadata=_TERM)
    scale_factor_peak: np.ndarray = field(metadata=_TERM)
    scale_factor_offset: np.ndarray = field(metadata=_TERM)
    misalignment_net: np.ndarray = field(metadata=_TERM)
    misalignment_peak: np.ndarray = field(metadata=_TERM)
    misalignment_offset: np.ndarray = field(metadata=_TERM)
    abs_rate_integral: np.ndarray = field(
        metadata=stored("rad", frame=REF, dims="3 3", optional=True))
    asym_net: np.ndarray = field(metadata=stored("rad", frame=REF, dims="3", optional=True))
    schuler_period: float = field(metadata=stored("s", attr=True, name="schuler_period_s"))
    harmonics: tuple[Harmonic, ...]
    warnings: tuple[str, ...]
    t: np.ndarray
    running_C: np.ndarray
    running_rate: np.ndarray

    @property
    def schuler_warning(self) -> bool:
        """True when a modulation harmonic sits within ±20 % of the Schuler period."""
        return bool(self.warnings)


@dataclass(frozen=True)
class Running:
    """Running integrals over one cycle at the quadrature grid's sub-interval ends.

    t : (K,) s (0 first, T last). C : (K, 3, 3) s, ∫_0^t C ds. W : (K, 3, 3, 3) rad, the
    rate tensor W(t). mean_C : (3, 3) s and mean_W : (3, 3, 3) rad, their cycle means
    (1/T)∫_0^T (·)(t) dt = (1/T)∫_0^T (T − s) (integrand)(s) ds (by parts, exact).
    """

    t: np.ndarray
    C: np.ndarray
    W: np.ndarray
    mean_C: np.ndarray
    mean_W: np.ndarray


def running_integrals(schedule: Schedule, grid: CycleGrid | None = None) -> Running:
    """:class:`Running` of `schedule` (Gauss–Legendre on `grid`; by default the cycle grid
    with sub-intervals of ≤ 360°/64 of turn, where the peaks are sampled)."""
    g = grid if grid is not None else cycle_grid(schedule, max_span=PEAK_SPAN)
    tt = g.t.ravel()
    T = schedule.period
    C = schedule.dcm(tt)
    CW = np.einsum("nai,nj->naij", C, schedule.rate(tt))
    dC, dW = g.integrals(C), g.integrals(CW)
    lever = (T - tt) / T
    zero = np.zeros((1,) + dC.shape[1:]), np.zeros((1,) + dW.shape[1:])
    return Running(np.append(0.0, g.b), np.concatenate([zero[0], np.cumsum(dC, 0)]),
                   np.concatenate([zero[1], np.cumsum(dW, 0)]),
                   g.integrals(C * lever[:, None, None]).sum(0),
                   g.integrals(CW * lever[:, None, None, None]).sum(0))


def modulation_harmonic(schedule: Schedule, k: int) -> np.ndarray:
    """c_k = (1/T) ∫_cycle C(t) e^{−i 2π k t/T} dt, complex (3, 3)."""
    T = schedule.period
    g = cycle_grid(schedule, max_len=min(60.0, T / (8.0 * max(k, 1))), split_constant=True)
    tt = g.t.ravel()
    e = np.exp(-2j * math.pi * k * tt / T)
    return g.integrals(schedule.dcm(tt) * e[:, None, None]).sum(0) / T


def schuler_harmonics(schedule: Schedule, omega_s: float) -> tuple[Harmonic, ...]:
    """The harmonics k ≥ 1 of C(t) whose period T/k is within ±20 % of 2π/ω_s."""
    T, Ts = schedule.period, 2.0 * math.pi / omega_s
    lo = max(1, math.ceil(T / ((1.0 + SCHULER_BAND) * Ts)))
    hi = math.floor(T / ((1.0 - SCHULER_BAND) * Ts))
    out = []
    for k in range(lo, hi + 1):
        c = modulation_harmonic(schedule, k)
        amp = 2.0 * float(np.linalg.norm(c, axis=0).max())
        w = 2.0 * math.pi * k / T
        gap = abs(w * w - omega_s**2)
        out.append(Harmonic(k, T / k, amp, omega_s**2 / gap if gap > 0 else math.inf))
    return tuple(out)


def invariant_report(scheme: Scheme | Schedule, errors: ErrorTerms | None = None, *,
                     earth: EarthModel = SEED004, lat: float = SEED004_LAT,
                     name: str = "", reference: str = "body") -> InvariantReport:
    """The invariant report of `scheme` (a :class:`Scheme`, or a bare :class:`Schedule` with
    `name` and `reference`) for `errors` (default: the seed's biases, spec §4, with δk = 10
    ppm on every axis and no misalignment), at latitude `lat` (rad) of `earth`."""
    if isinstance(scheme, Scheme):
        schedule, name, reference = scheme.schedule, scheme.name, scheme.reference
    else:
        schedule = scheme
    if errors is None:
        errors = ErrorTerms.seed004(gyro_scale=np.full(3, 10e-6))
    T = schedule.period
    run = running_integrals(schedule)
    t, run_C, run_W = run.t, run.C, run.W
    integral_C, W = run_C[-1], run_W[-1]
    mean_C = integral_C / T
    eps = errors.gyro_bias
    excursion = np.abs(run_C @ eps - np.outer(t, mean_C @ eps)).max(0)
    K = np.diag(errors.gyro_scale)
    M = errors.gyro_misalignment
    m_sf = np.einsum("kaij,ij->ka", run_W, K)
    m_mis = np.einsum("kaij,ij->ka", run_W, M)
    # cycle mean of ∫_0^t (C − C̄) ε ds: (1/T)∫(T − s) C ds ε − (T/2) C̄ ε
    offset = run.mean_C @ eps - 0.5 * T * (mean_C @ eps)
    g = cycle_grid(schedule, max_span=PEAK_SPAN)
    tt = g.t.ravel()
    A = g.integrals(schedule.dcm(tt) * np.abs(schedule.rate(tt))[:, None, :]).sum(0)
    omega_s = earth.schuler_rate(lat)
    harmonics = schuler_harmonics(schedule, omega_s)
    warnings = tuple(
        f"modulation period {h.period / 60:.1f} min (cycle/{h.k}) is within ±20 % of the "
        f"Schuler period {2 * math.pi / omega_s / 60:.2f} min: every error the mechanism "
        f"modulates (biases, and the scale-factor and misalignment × rate terms, which "
        f"repeat with the cycle) is attenuated only ×{h.attenuation:.3g} (bias amplitude "
        f"{h.amplitude:.3g} per unit bias)"
        for h in harmonics if h.amplitude > HARMONIC_FLOOR)
    return InvariantReport(
        scheme=name, reference=reference, period=T, integral_C=integral_C, mean_C=mean_C,
        rate_tensor=W, peak_integral_C=np.linalg.norm(run_C, axis=1).max(0), errors=errors,
        residual_gyro_bias=mean_C @ eps, residual_accel_bias=mean_C @ errors.accel_bias,
        gyro_bias_excursion=excursion, gyro_bias_offset=offset, scale_factor_net=m_sf[-1],
        scale_factor_peak=np.abs(m_sf).max(0),
        scale_factor_offset=np.einsum("aij,ij->a", run.mean_W, K), misalignment_net=m_mis[-1],
        misalignment_peak=np.abs(m_mis).max(0),
        misalignment_offset=np.einsum("aij,ij->a", run.mean_W, M),
        abs_rate_integral=A, asym_net=A @ errors.gyro_asym,
        schuler_period=2 * math.pi / omega_s,
        harmonics=harmonics, warnings=warnings, t=t, running_C=run_C, running_rate=run_W)
