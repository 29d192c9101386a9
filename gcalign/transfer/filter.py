"""Transfer alignment of a slave IMU against a master INS on a moving vehicle (spec 006).

The model is PSINS's demo ``test_align_transfer_fog_mems`` written in our conventions (ENU,
body RFU, ``att = [pitch, roll, yaw]``, ``C_nb,est ≈ (I − [φ×]) C_nb``); each step below
names the line of the demo it follows.

Slave mechanisation, at the IMU rate T, from the master's attitude and velocity at the first
master epoch (demo ``qnbs = a2qua(fogavp(1,1:3)); vns = fogavp(1,4:6)``):

* increments corrected by the biases fed back so far, ``Δθ − ε̂ T``, ``Δv − ∇̂ T`` (demo
  ``imuavp(k,1:6) − ebdb'·ts``); one-sample ``cnscl``: ``Δv_b = Δv + ½ Δθ × Δv``;
* ``Δv^n = C_nb Δv_b``, ``v += Δv^n + g_cc T`` with ``g_cc = g^n − (2ω_ie^n + ω_en^n) × v_m``
  (PSINS ``eth.gcc``; the earth terms come from the master at its latest epoch, as
  ``eth = earth(posm, vnm)`` in the demo);
* ``q_nb ← q_nb ⊗ q(Δθ − C_nbᵀ ω_in^n T)`` (demo ``qupdt``).

Error state (spec 006 "States"): φ (3), δv (3), ε (3), ∇ (3), μ (3) and, with flexure, θ (3)
and ω = θ̇ (3). Per IMU step (spec 006; demo ``kf.Phikk_1``), with C_nb the slave attitude at
the start of the step::

    Φ(φ,φ) = I − [ω_in^n T ×]   Φ(φ,ε) = −C_nb T   Φ(δv,φ) = [Δv^n ×]   Φ(δv,∇) = C_nb T

and μ constant. Flexure per axis is PSINS's second-order Markov ``markov2``:
``θ̈ + 2β θ̇ + β² θ = w``, ``E[w w] = 4β³σ² δ`` (so that var θ = σ² in steady state), its
Φ and Q_d exact by Van Loan (:func:`gcalign.estimation.kalman.van_loan`). Process noise of
φ and δv: ``ARW² T``, ``VRW² T`` (PSINS ``Qk = Qt·ts``).

Measurement at every master epoch (demo ``kfupdate(kf, [qq2phi(qnbs,qnbm); vns−vnm])``)::

    z = [φ_meas; v_slave − v_master − C_nb (ω_ib^b × l)],   φ_meas = qq2phi(q_slave, q_master)

``qq2phi`` is our :func:`gcalign.nav.rotation.misalignment_q`: the slave's true attitude is
``q_master ⊗ q(μ + θ)`` (the data's ``qnb_mems = qnb_fog ∘ rv2q(mu0)``), so to first order
``φ_meas = φ − C_m (μ + θ)``. We take it exactly about the estimate
(:func:`gcalign.transfer.model.attitude_measurement`, ``h = −rotvec(exp(−[φ̂×]) exp([a×]))``,
``a = C_m (μ̂ + θ̂)``) with ``H(φ rows, φ) = J_l(a)⁻¹`` and ``H(φ rows, μ) = H(φ rows, θ)
= −C_m``, C_m the master's attitude; the demo's ``−C_nb`` of the mechanised slave turns
with every attitude correction and made the filter learn the roll-axis mounting that no
data show (docs/decisions/019). The lever arm l (body frame, m, from the master to the
slave) is zero in the demo. The update is the Joseph form of
:func:`gcalign.estimation.kalman.update` (the demo's ``kfupdate``); bias feedback after
every update (``ebdb += x(ε,∇); x(ε,∇) = 0``); φ̂ reset into the filter's attitude after
every update (the demo's commented ``qnbs = qdelphi(qnbs, xk(1:3))``) with the covariance
carried, ``P ← G P Gᵀ``, ``G(φ,φ) = I + ½[φ̂×]``. With attitude feedback off the slave's
own solution runs free beside the filter's and φ̂, δv̂ are reported as its corrections
(decision 019: the estimates do not depend on the switch).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from gcalign.choices import MATCHINGS
from gcalign.errors import ScenarioError
from gcalign.estimation.kalman import update, van_loan
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import (
    euler_to_quat,
    misalignment_q,
    quat_conj,
    quat_mult,
    quat_to_dcm,
    quat_to_euler,
    quat_to_rotvec,
    rotvec_to_quat,
    skew,
)
from gcalign.schema import ATT_FRAME, stored
from gcalign.transfer.model import attitude_measurement, measurement_matrix
from gcalign.units import ARCMIN, DEG, DPH, DPSH, G0, UG, UGPSHZ

GRAVITY_MODELS = ("normal", "constant")

NAMES_15 = ("phiE", "phiN", "phiU", "dvE", "dvN", "dvU", "ebx", "eby", "ebz",
            "dbx", "dby", "dbz", "mux", "muy", "muz")
NAMES_FLEXURE = ("thx", "thy", "thz", "wx", "wy", "wz")
#: SI unit of each state's estimate and σ, in the order of the names
UNITS_15 = ("rad",) * 3 + ("m/s",) * 3 + ("rad/s",) * 3 + ("m/s^2",) * 3 + ("rad",) * 3
UNITS_FLEXURE = ("rad",) * 3 + ("rad/s",) * 3
PHI, DV, EB, DB, MU, TH, OM = (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12),
                               slice(12, 15), slice(15, 18), slice(18, 21))
BIASES = slice(6, 12)

#: spec 006 / the demo's P0: φ 10°, δv 10 m/s, ε 500 °/h, ∇ 1000 µg, μ 1°, θ 0.1°, ω 10 °/s
P0_SIGMA_DEFAULT = ((10 * DEG,) * 3 + (10.0,) * 3 + (500 * DPH,) * 3 + (1000 * UG,) * 3
                    + (1 * DEG,) * 3 + (0.1 * DEG,) * 3 + (10 * DEG,) * 3)
#: R = diag(10′ ×3, 0.1 m/s ×3)²
R_SIGMA_DEFAULT = (10 * ARCMIN,) * 3 + (0.1,) * 3
#: the demo's markov2 parameters: σ = (0.6, −1.0, 0.7)′ (the sign is PSINS's; σ² is used)
FLEXURE_SIGMA_DEFAULT = (0.6 * ARCMIN, -1.0 * ARCMIN, 0.7 * ARCMIN)
FLEXURE_BETA_DEFAULT = (0.5, 0.4, 10.0)


@dataclass(frozen=True)
class MasterSeries:
    """The master INS solution (SI): t (K,) s increasing; att (K, 3) rad [pitch, roll, yaw];
    v_n (K, 3) m/s ENU; pos (K, 3) [lat rad, lon rad, h m]. att may be None (a reference
    without attitude: velocity matching only)."""

    t: np.ndarray
    att: np.ndarray | None
    v_n: np.ndarray
    pos: np.ndarray


@dataclass(frozen=True)
class TransferSettings:
    """Filter settings (SI); the defaults are PSINS's demo (spec 006).

    matching : "attitude+velocity" | "velocity" | "attitude" (rows of z used).
    flexure : add θ, ω (21 states; the demo does).
    bias_feedback : feed ε̂, ∇̂ into the compensation after every update (the demo).
    attitude_feedback : correct the slave's own attitude by φ̂ after every update (demo:
        off). The filter linearises about its corrected attitude either way (decision 019);
        off keeps the slave's solution free and reports φ̂, δv̂ as its corrections.
    lever_arm_b : (3,) m, slave position relative to the master, body frame.
    p0_sigma : (21,) initial σ (the first 15 without flexure).
    r_sigma : (6,) measurement σ, rad ×3 then m/s ×3.
    arw, vrw : rad/√s, m/s/√s (spec 006: 0.1 °/√h, 10 µg/√Hz).
    flexure_beta : (3,) 1/s; flexure_sigma : (3,) rad (markov2).
    gravity : "normal" (the earth model's normal gravity with height) or "constant" (g0).
    earth : the earth model (WGS-84).
    """

    matching: str = "attitude+velocity"
    flexure: bool = True
    bias_feedback: bool = True
    attitude_feedback: bool = False
    lever_arm_b: tuple[float, float, float] = (0.0, 0.0, 0.0)
    p0_sigma: tuple[float, ...] = P0_SIGMA_DEFAULT
    r_sigma: tuple[float, ...] = R_SIGMA_DEFAULT
    arw: float = 0.1 * DPSH
    vrw: float = 10.0 * UGPSHZ
    flexure_beta: tuple[float, float, float] = FLEXURE_BETA_DEFAULT
    flexure_sigma: tuple[float, float, float] = FLEXURE_SIGMA_DEFAULT
    gravity: str = "normal"
    earth: EarthModel = field(default=WGS84)

    def __post_init__(self) -> None:
        if self.matching not in MATCHINGS:
            raise ScenarioError(f"matching: {self.matching!r} is not one of {MATCHINGS}")
        if self.gravity not in GRAVITY_MODELS:
            raise ScenarioError(f"gravity: {self.gravity!r} is not one of {GRAVITY_MODELS}")
        if len(self.p0_sigma) not in (15, 21) or (self.flexure and len(self.p0_sigma) != 21):
            raise ScenarioError(f"p0_sigma: needs 21 values with flexure, 15 or 21 without, "
                                f"got {len(self.p0_sigma)}")
        if len(self.r_sigma) != 6:
            raise ScenarioError(f"r_sigma: needs 6 values, got {len(self.r_sigma)}")

    @property
    def names(self) -> tuple[str, ...]:
        return NAMES_15 + (NAMES_FLEXURE if self.flexure else ())

    @property
    def units(self) -> tuple[str, ...]:
        """SI unit of each state (:attr:`names`' order)."""
        return UNITS_15 + (UNITS_FLEXURE if self.flexure else ())

    @property
    def n(self) -> int:
        return 21 if self.flexure else 15

    @property
    def rows(self) -> np.ndarray:
        """Indices of z = [φ_meas; δv] that the matching uses."""
        return {"attitude+velocity": np.arange(6), "velocity": np.arange(3, 6),
                "attitude": np.arange(3)}[self.matching]


#: the ``description`` of a series of states in the results file
STATE_SERIES = "(epochs, states) in the order of the 'states' attribute, units 'state_units'"


@dataclass(frozen=True)
class TransferResult:
    """Per master epoch after its update (SI).

    t (K,) s; x (K, n) estimates, the biases being the totals fed back plus what is left
    in the state; sigma (K, n) √diag P; P (K, n, n) the covariance; sigma0 (n,) the P0 σ;
    names (n,); bias_fed (K, 6) the ε, ∇ fed back so far; nis (K,) and its degrees of
    freedom m; q_slave (K, 4) and att_slave (K, 3) the slave attitude corrected by φ̂;
    v_slave (K, 3); q_master (K, 4) the master at the measurement epochs;
    attitude_error (K, 3) rad, the corrected slave against master ∘ (μ̂ + θ̂); t0 the
    start of the run (s). The filter's own error model at each epoch, for its
    observability (:mod:`gcalign.transfer.observability`): C_nb (K, 3, 3) the slave
    attitude of H (and of the last step's Φ), f_n (K, 3) m/s² the mean specific force of
    the steps since the previous epoch (their Φ(δv,φ) = [f^n T ×]), omega_in_n (K, 3)
    rad/s the ω_in^n of those steps, dt (K,) s their length.
    """

    t: np.ndarray = field(metadata=stored("s", dims="K", rule="increasing"))
    x: np.ndarray = field(metadata=stored("SI", name="estimate", description=STATE_SERIES,
                                          dims="K S"))
    sigma: np.ndarray = field(metadata=stored("SI", description=STATE_SERIES, dims="K S"))
    P: np.ndarray
    sigma0: np.ndarray = field(metadata=stored("SI", dims="S", optional=True))
    names: tuple[str, ...] = field(metadata=stored(None, attr=True, name="states"))
    bias_fed: np.ndarray = field(metadata=stored(
        "rad/s, m/s^2", description="ε (3), ∇ (3) fed back into the compensation so far",
        dims="K 6", optional=True))
    nis: np.ndarray
    m: int
    q_slave: np.ndarray
    att_slave: np.ndarray = field(metadata=stored(
        "rad", name="att", frame=ATT_FRAME,
        description="slave attitude corrected by the φ estimate", dims="K 3", optional=True))
    v_slave: np.ndarray = field(metadata=stored("m/s", name="v_n", frame="ENU", dims="K 3",
                                                optional=True))
    q_master: np.ndarray
    attitude_error: np.ndarray = field(metadata=stored(
        "rad", frame="ENU", description="corrected slave against master ∘ (μ + θ estimates), "
        "misalignment φ", dims="K 3", optional=True))
    t0: float
    settings: TransferSettings
    C_nb: np.ndarray
    f_n: np.ndarray
    omega_in_n: np.ndarray
    dt: np.ndarray

    def index(self, name: str) -> int:
        return self.names.index(name)

    def final(self) -> dict[str, tuple[float, float]]:
        """``{name: (estimate, sigma)}`` at the last epoch (SI)."""
        return {n: (float(self.x[-1, i]), float(self.sigma[-1, i]))
                for i, n in enumerate(self.names)}

    def attitude_error_summary(self, last_s: float = 10.0) -> dict[str, np.ndarray]:
        """The corrected slave against master ∘ μ̂: the final error and the RMS over the
        last `last_s` seconds, per axis of φ (E, N, U), rad."""
        w = self.t >= self.t[-1] - last_s
        return {"final": self.attitude_error[-1],
                "rms_last": np.sqrt(np.mean(self.attitude_error[w] ** 2, axis=0))}

    def health_warnings(self, label: str = "") -> list[str]:
        """Does the filter agree with its data (:mod:`gcalign.estimation.health`, the checks
        of in-flight calibration)? One line if the mean NIS lies outside the 95 % band of a
        mean of as many χ²_m, one per state whose σ grows past 10× its P0 σ; `label` heads
        each line. Needs no truth: it holds on recorded data."""
        from gcalign.estimation.health import nis_warnings, sigma_growth_warnings

        return (nis_warnings(self.nis, self.m, label)
                + sigma_growth_warnings(self.sigma0, self.sigma, self.names,
                                        self.settings.units, label))

    def convergence_s(self) -> dict[str, float]:
        """Per state, the first time (s from the start) after which the estimate stays
        within 2σ of its final value, σ the final one."""
        return convergence_times(self.t - self.t0, self.x, self.sigma, self.names)


def convergence_times(t: np.ndarray, x: np.ndarray, sigma: np.ndarray,
                      names: Sequence[str]) -> dict[str, float]:
    """First time after which ``|x_k − x_final| ≤ 2 σ_final`` for every later k, per state.

    Against the final σ, not the running one: a state whose σ starts wide (500 °/h) and
    shrinks while the estimate moves into place never leaves a band of its running 2σ,
    which would put it at the first epoch.

    >>> import numpy as np
    >>> t = np.arange(5.0)
    >>> x = np.array([[9.0], [5.0], [1.5], [1.0], [1.0]])
    >>> convergence_times(t, x, np.array([[100.0], [50.0], [1.0], [0.5], [0.5]]), ["a"])
    {'a': 2.0}
    """
    out = {}
    for i, n in enumerate(names):
        outside = np.nonzero(np.abs(x[:, i] - x[-1, i]) > 2.0 * sigma[-1, i])[0]
        out[n] = float(t[0] if len(outside) == 0 else t[min(outside[-1] + 1, len(t) - 1)])
    return out


def markov2_block(beta: ArrayLike, sigma: ArrayLike,
                  dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Φ, Q_d (6, 6) of θ (3), ω (3) over `dt`: per axis ``θ̇ = ω``,
    ``ω̇ = −β² θ − 2β ω + w``, ``E[w w] = 4β³σ²`` (PSINS markov2; var θ → σ²)."""
    b, s = np.asarray(beta, dtype=float), np.asarray(sigma, dtype=float)
    F = np.zeros((6, 6))
    F[:3, 3:] = np.eye(3)
    F[3:, :3] = -np.diag(b * b)
    F[3:, 3:] = -np.diag(2.0 * b)
    G = np.zeros((6, 3))
    G[3:, :] = np.eye(3)
    return van_loan(F, G, np.diag(4.0 * b ** 3 * s * s), dt)


def _slerp_master(master: MasterSeries, t: np.ndarray
                  ) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """The master at times `t` (inside its span): v, pos linear, attitude along the
    rotation between the bracketing epochs. Returns (q_nb (N, 4) or None, v_n, pos)."""
    tm = np.asarray(master.t, dtype=float)
    j = np.clip(np.searchsorted(tm, t, side="right") - 1, 0, len(tm) - 2)
    a = np.clip((t - tm[j]) / (tm[j + 1] - tm[j]), 0.0, 1.0)[:, None]
    v = master.v_n[j] * (1 - a) + master.v_n[j + 1] * a
    pos = master.pos[j] * (1 - a) + master.pos[j + 1] * a
    if master.att is None:
        return None, v, pos
    q = euler_to_quat(master.att)
    dq = quat_mult(quat_conj(q[j]), q[j + 1])  # body-side rotation from epoch j to j+1
    return quat_mult(q[j], rotvec_to_quat(quat_to_rotvec(dq) * a)), v, pos


def measurement_epochs(t_imu: np.ndarray, master: MasterSeries
                       ) -> tuple[int, np.ndarray, np.ndarray]:
    """Start sample and measurement samples: the slave starts at the first master epoch
    inside the IMU run (at the IMU sample nearest to it); a measurement is taken at the
    IMU sample nearest to each later master epoch, the master interpolated to it."""
    tm = np.asarray(master.t, dtype=float)
    ts = float(np.median(np.diff(t_imu)))
    dtm = float(np.median(np.diff(tm))) if len(tm) > 1 else np.inf
    if len(tm) > 1 and not np.all(np.diff(tm) > 0):
        raise ScenarioError("reference: its times must increase strictly")
    if len(tm) < 2 or tm[-1] < t_imu[0] or tm[0] > t_imu[-1]:
        raise ScenarioError(f"reference: no overlap with the IMU run: the reference covers "
                            f"{tm[0]:.3f}–{tm[-1]:.3f} s, the IMU {t_imu[0]:.3f}–"
                            f"{t_imu[-1]:.3f} s")
    slack = dtm + ts
    if tm[0] > t_imu[0] + slack or tm[-1] < t_imu[-1] - slack:
        raise ScenarioError(f"reference: does not cover the IMU run: the reference covers "
                            f"{tm[0]:.3f}–{tm[-1]:.3f} s, the IMU {t_imu[0]:.3f}–"
                            f"{t_imu[-1]:.3f} s (allowed: one reference interval, "
                            f"{dtm:.3f} s, at either end)")
    k_of = np.clip(np.searchsorted(t_imu, tm - 0.5 * ts), 0, len(t_imu) - 1)
    inside = (tm >= t_imu[0] - 0.5 * ts) & (tm <= t_imu[-1] + 0.5 * ts)
    k_of = k_of[inside]
    if len(k_of) < 2:
        raise ScenarioError(f"reference: {len(k_of)} epoch(s) inside the IMU run "
                            f"{t_imu[0]:.3f}–{t_imu[-1]:.3f} s; at least 2 are needed (a start "
                            "and a measurement)")
    k0 = int(k_of[0])
    k_meas = np.unique(k_of[k_of > k0])
    t_meas = np.clip(t_imu[k_meas], tm[0], tm[-1])
    return k0, k_meas, t_meas


def transfer_align(dtheta: np.ndarray, dv: np.ndarray, t: np.ndarray, master: MasterSeries,
                   settings: TransferSettings | None = None,
                   att0: np.ndarray | None = None) -> TransferResult:
    """Align and calibrate a slave IMU against a master INS (spec 006; PSINS demo
    ``test_align_transfer_fog_mems``).

    Parameters
    ----------
    dtheta, dv : (N, 3) slave increments, rad and m/s, body RFU; sample k covers
        ``(t[k−1], t[k]]``.
    t : (N,) s, uniform.
    master : the master solution (:class:`MasterSeries`); must cover the IMU run to within
        one of its intervals at either end.
    settings : :class:`TransferSettings`, the demo's by default.
    att0 : (3,) rad, the slave's initial ``[pitch, roll, yaw]`` (its own coarse alignment);
        by default the master's at the start, as the demo (then the initial φ is −C_nb μ,
        fully correlated with μ, which P0 does not say).
    """
    from gcalign.transfer import _kernel  # numba, loaded only by a run (validate checks)

    s = settings or TransferSettings()
    dtheta, dv, t = (np.asarray(a, dtype=float) for a in (dtheta, dv, t))
    if s.matching != "velocity" and master.att is None:
        raise ScenarioError(f"matching: {s.matching!r} needs the reference's attitude; this "
                            "reference has none (allowed: 'velocity')")
    ts = float(np.median(np.diff(t)))
    k0, k_meas, t_meas = measurement_epochs(t, master)
    qm_meas, vm_meas, pm_meas = _slerp_master(master, t_meas)
    qm0, vm0, pm0 = _slerp_master(master, t[k0:k0 + 1])
    earth, n, rows = s.earth, s.n, s.rows
    lever = np.asarray(s.lever_arm_b, dtype=float)

    # PSINS eth = earth(pos, vn): ω_in^n and g_cc
    def earth_terms(pos: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w_ie = earth.omega_ie_n(pos[0])
        w_in = w_ie + earth.omega_en_n(pos[0], pos[2], v)
        g = earth.gravity(pos[0], pos[2]) if s.gravity == "normal" else G0
        return w_in, np.array([0.0, 0.0, -g]) - np.cross(w_ie + w_in, v)

    # the slave starts from the master (the demo: a2qua(fogavp(1,1:3)), fogavp(1,4:6));
    # without a master attitude (velocity matching), from level and north-pointing
    if att0 is not None:
        q_s = euler_to_quat(np.asarray(att0, dtype=float))
    else:
        q_s = qm0[0].copy() if qm0 is not None else np.array([1.0, 0.0, 0.0, 0.0])
    v_s = vm0[0].copy()
    w_in, g_cc = earth_terms(pm0[0], vm0[0])

    x = np.zeros(n)
    P = np.diag(np.asarray(s.p0_sigma[:n], dtype=float) ** 2)
    Qd = np.zeros((n, n))
    Qd[PHI, PHI] = np.eye(3) * s.arw ** 2 * ts  # PSINS Qk = Qt·ts
    Qd[DV, DV] = np.eye(3) * s.vrw ** 2 * ts
    Phi = np.eye(n)
    if s.flexure:
        Phi[15:, 15:], Qd[15:, 15:] = markov2_block(s.flexure_beta, s.flexure_sigma, ts)
    R = np.diag(np.asarray(s.r_sigma, dtype=float)[rows] ** 2)
    fed = np.zeros(6)

    K = len(k_meas)
    out_x, out_P = np.zeros((K, n)), np.zeros((K, n, n))
    out_fed, out_nis = np.zeros((K, 6)), np.zeros(K)
    out_q, out_v, out_err = np.zeros((K, 4)), np.zeros((K, 3)), np.zeros((K, 3))
    out_C, out_f, out_w, out_dt = np.zeros((K, 3, 3)), np.zeros((K, 3)), np.zeros((K, 3)), \
        np.zeros(K)
    C_nb, dv_n = np.zeros((3, 3)), np.zeros(3)
    # without attitude feedback the slave's own solution runs free beside the filter's
    # corrected one (decision 019): the filter linearises about its best attitude always
    q_free, v_free = q_s.copy(), v_s.copy()
    k_prev = k0 + 1
    for j, k in enumerate(k_meas):
        # mechanisation and prediction over the IMU samples up to this epoch (the kernel)
        if not s.attitude_feedback:
            _kernel.mechanise(q_free, v_free, dtheta, dv, k_prev, k + 1, fed, w_in, g_cc, ts)
        _kernel.propagate(q_s, v_s, x, P, dtheta, dv, k_prev, k + 1, fed, w_in, g_cc, ts,
                          Phi, Qd, C_nb, dv_n)
        out_dt[j] = (k + 1 - k_prev) * ts
        out_C[j], out_f[j], out_w[j] = C_nb, dv_n / out_dt[j], w_in
        k_prev = k + 1
        w_in, g_cc = earth_terms(pm_meas[j], vm_meas[j])
        omega_ib_b = dtheta[k] / ts - fed[:3]
        v_lever = C_nb @ np.cross(omega_ib_b, lever)
        z_v = v_s - vm_meas[j] - v_lever
        if qm_meas is not None:
            # the exact attitude measurement about the estimate, linear in μ through the
            # master's attitude (model.attitude_measurement; decision 019)
            C_m = quat_to_dcm(qm_meas[j])
            mount_n = C_m @ (x[MU] + (x[TH] if s.flexure else 0.0))
            H = measurement_matrix(C_m, "attitude+velocity", n, mount_n)
            h_phi = attitude_measurement(x[PHI], mount_n)
            # z − h(x̂) + H x̂: the update's innovation is then z − h(x̂)
            z = np.concatenate([misalignment_q(q_s, qm_meas[j]) - h_phi + H[0:3] @ x, z_v])
        else:
            H = measurement_matrix(C_nb, "attitude+velocity", n)
            z = np.concatenate([np.zeros(3), z_v])
        u = update(x, P, z[rows], H[rows], R)
        x, P = u.x, u.P
        if s.bias_feedback:  # demo: ebdb = ebdb + kf.xk(7:12); kf.xk(7:12) = 0
            fed = fed + x[BIASES]
            x[BIASES] = 0.0
        # attitude reset (the demo's commented qnbs = qdelphi(qnbs, xk(1:3))), with the
        # covariance carried to the new error: exp([φ'×]) = exp([φ×]) exp(−[φ̂×]) gives
        # φ' = e + ½ φ̂ × e to first order in e = φ − φ̂, so P ← G P Gᵀ, G(φ,φ) = I + ½[φ̂×]
        phi_hat = x[PHI].copy()
        q_s[:] = quat_mult(rotvec_to_quat(phi_hat), q_s)
        x[PHI] = 0.0
        G = np.eye(3) + 0.5 * skew(phi_hat)
        P[PHI, :] = G @ P[PHI, :]
        P[:, PHI] = P[:, PHI] @ G.T
        P = 0.5 * (P + P.T)
        q_corr = q_s.copy()
        rel = x[MU] + (x[TH] if s.flexure else 0.0)
        if qm_meas is not None:
            out_err[j] = misalignment_q(q_corr, quat_mult(qm_meas[j], rotvec_to_quat(rel)))
        else:
            out_err[j] = np.nan
        out_x[j] = x
        out_x[j, BIASES] += fed
        out_v[j] = v_s
        if not s.attitude_feedback:
            # the estimates as corrections of the free solution: C_nb = exp([φ̂×]) C_free,
            # δv̂ = v_free − v (v the filter's velocity, δv̂ its error about it)
            out_x[j, PHI] = quat_to_rotvec(quat_mult(q_corr, quat_conj(q_free)))
            out_x[j, DV] += v_free - v_s
            out_v[j] = v_free
        out_P[j] = P
        out_fed[j], out_nis[j], out_q[j] = fed, u.nis, q_corr
    return TransferResult(
        t=t_meas, x=out_x, sigma=np.sqrt(np.diagonal(out_P, axis1=1, axis2=2)), P=out_P,
        sigma0=np.asarray(s.p0_sigma[:n], dtype=float),
        names=s.names, bias_fed=out_fed, nis=out_nis, m=len(rows), q_slave=out_q,
        att_slave=quat_to_euler(out_q), v_slave=out_v,
        q_master=qm_meas if qm_meas is not None else np.full((K, 4), np.nan),
        attitude_error=out_err, t0=float(t[k0]), settings=s, C_nb=out_C, f_n=out_f,
        omega_in_n=out_w, dt=out_dt)


def attitude_error_vs(result: TransferResult, mu: np.ndarray) -> np.ndarray:
    """The corrected slave against master ∘ `mu` (3,) rad (e.g. a stored misalignment such
    as PSINS's ``mu0``): φ per epoch (K, 3), rad (the demo's ``res`` row, corrected by φ̂)."""
    return misalignment_q(result.q_slave,
                          quat_mult(result.q_master, rotvec_to_quat(np.asarray(mu, float))))
