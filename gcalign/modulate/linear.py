r"""Linear error model of a static INS whose IMU turns on a schedule (spec 004 §5).

The reference the nonlinear navigation is checked against, and what reproduces the spec's
§5 table and closed forms (a)–(c). φ-angle model in ENU (PSINS), static base (v = 0),
height held, zero initial errors; state ``x = [φ_E, φ_N, φ_U, δv_E, δv_N, δL, δλ]`` (rad,
m/s, rad). With ω_ie^n = Ω [0, cos L, sin L] = [0, Ω_N, Ω_U], f^n = [0, 0, g]:

.. code-block:: text

    φ̇   = −ω_ie^n × φ + δω_in^n − C(t) δω^s        δω_in^n = [−δv_N/R_M,
                                                               δv_E/R_N − Ω_U δL,
                                                               δv_E tan L/R_N + Ω_N δL]
    δv̇_E = −g φ_N + 2 Ω_U δv_N + (C(t) ∇)_E
    δv̇_N =  g φ_E − 2 Ω_U δv_E + (C(t) ∇)_N
    δL̇  = δv_N / R_M,      δλ̇ = δv_E / (R_N cos L)

with ``C(t) = C_s^n(t) = C0 · S(t)`` (S the scheme's schedule, C0 = I: body = ENU, spec
§4), the sensed rate ``ω^s = ω_m(t) + Cᵀ ω_ie^n`` (ω_m the mechanism rate) and specific
force ``f^s = Cᵀ [0, 0, g]``, and the sensor-frame errors (:class:`ErrorTerms`)

.. code-block:: text

    δω^s = ε + (diag δk + M) ω^s + δk_asym ⊙ |ω^s| + w                (w: density arw)
    δf^s = ∇ + (diag δk_a + M_a) f^s + δk_a,asym ⊙ |f^s| + ω̇_m × r + ω_m × (ω_m × r) + w_a

(r the lever arm of the accelerometers from the rotation centre, w_a of density vrw): the
same terms the simulation puts into the increments.

The system matrix F is constant (static base); only the forcing turns with the IMU. So
each interval between knots (piece ends and output times) is integrated exactly:
``x(b) = e^{F h} x(a) + ∫_a^b e^{F(b−s)} u(s) ds``, with e^{F τ} from the modes of F.
Where the IMU rests u is constant and the integral is ``∫_0^h e^{F s} ds · u``; on a turn
the convolution is Gauss–Legendre on sub-intervals of ≤ 45° (:mod:`._quadrature`), exact
to round-off. Piece maps repeat every cycle and are computed once, so 72 h cost a few
thousand 7×7 matrix–vector products.

Noise: ARW and VRW are the same on every axis, so ``C(t) w`` has the law of w whatever
the mechanism does — the noise enters independently of the scheme, with the Van Loan
covariance ``Q_d(h)`` of ``blockdiag(arw² I₃, vrw² I₂, 0, 0)``. The covariance P(t) is
propagated alongside; sample paths (``rng``, ``n_paths``) add ``L z`` per interval, with
L Lᵀ = Q_d (eigen-decomposition: Q_d is only semi-definite) and z ~ N(0, I).

Outputs: north ``R_M δL``, east ``R_N cos L δλ`` and horizontal error (m), φ (rad).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from gcalign.modulate._quadrature import gauss_legendre, pieces, split_count
from gcalign.modulate.schemes import Scheme
from gcalign.modulate.terms import SEED004_LAT, ErrorTerms
from gcalign.nav.earth import SEED004, EarthModel
from gcalign.schema import stored
from gcalign.sim.schedule import Schedule
from gcalign.units import HOUR

REPORT_HOURS = (1.0, 4.0, 12.0, 24.0, 72.0)
STATES = ("phi_E", "phi_N", "phi_U", "dv_E", "dv_N", "dL", "dlambda")
PHI, DV, DL, DLON = slice(0, 3), slice(3, 5), 5, 6
_TOL = 1e-6  # s: knots closer than this are one knot


def error_matrix(lat: float, earth: EarthModel = SEED004) -> np.ndarray:
    """F (7, 7) of the static, height-held φ-angle model (module docstring) at `lat` (rad)."""
    r_m, r_n = earth.radii(lat)
    g = float(earth.gravity(lat))
    om_n, om_u = earth.omega_ie * math.cos(lat), earth.omega_ie * math.sin(lat)
    F = np.zeros((7, 7))
    # φ̇ = −ω_ie^n × φ + δω_in^n
    F[0, 1], F[0, 2], F[0, 4] = om_u, -om_n, -1.0 / r_m
    F[1, 0], F[1, 3], F[1, 5] = -om_u, 1.0 / r_n, -om_u
    F[2, 0], F[2, 3], F[2, 5] = om_n, math.tan(lat) / r_n, om_n
    # δv̇ = f^n × φ − 2 ω_ie^n × δv (horizontal)
    F[3, 1], F[3, 4] = -g, 2.0 * om_u
    F[4, 0], F[4, 3] = g, -2.0 * om_u
    F[5, 4] = 1.0 / r_m
    F[6, 3] = 1.0 / (r_n * math.cos(lat))
    return F


@dataclass(frozen=True)
class LinearSeries:
    """What the results file keeps of :class:`LinearErrors` (its ``linear`` group): the
    output times and the errors there (SI); the noise's RMS horizontal error with noise."""

    t: np.ndarray = field(metadata=stored("s", dims="L", rule="increasing", optional=True))
    north: np.ndarray = field(metadata=stored("m", dims="L", optional=True))
    east: np.ndarray = field(metadata=stored("m", dims="L", optional=True))
    horizontal: np.ndarray = field(metadata=stored("m", dims="L", optional=True))
    phi: np.ndarray = field(metadata=stored("rad", frame="ENU", dims="L 3", optional=True))
    sigma_horizontal: np.ndarray | None = field(default=None, metadata=stored(
        "m", description="RMS horizontal error from noise", dims="L", optional=True))


@dataclass(frozen=True)
class LinearErrors:
    """Errors of the linear model (SI).

    Attributes
    ----------
    scheme : name of the scheme.
    t : (N,) s, output times (the report hours are among them).
    x : (N, 7) deterministic state (response to the constant errors), order :data:`STATES`.
    P : (N, 7, 7) covariance of the noise response, or None without noise.
    paths : (n_paths, N, 7) sample states (deterministic part included), or None.
    lat : rad.  r_m, r_n : radii of curvature, m.
    """

    scheme: str
    t: np.ndarray
    x: np.ndarray
    P: np.ndarray | None
    paths: np.ndarray | None
    lat: float
    r_m: float
    r_n: float

    def _ne(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.r_m * x[..., DL], self.r_n * math.cos(self.lat) * x[..., DLON]

    @property
    def north(self) -> np.ndarray:
        """North position error R_M δL (N,), m."""
        return self._ne(self.x)[0]

    @property
    def east(self) -> np.ndarray:
        """East position error R_N cos L δλ (N,), m."""
        return self._ne(self.x)[1]

    @property
    def horizontal(self) -> np.ndarray:
        """Horizontal position error (N,), m."""
        return np.hypot(*self._ne(self.x))

    @property
    def phi(self) -> np.ndarray:
        """Attitude error φ (N, 3), rad, ENU."""
        return self.x[:, PHI]

    @property
    def velocity(self) -> np.ndarray:
        """Horizontal velocity error [δv_E, δv_N] (N, 2), m/s."""
        return self.x[:, DV]

    @property
    def sigma_north(self) -> np.ndarray:
        """1σ of the north error from noise (N,), m (zeros without noise)."""
        return self.r_m * np.sqrt(self._var(DL))

    @property
    def sigma_east(self) -> np.ndarray:
        """1σ of the east error from noise (N,), m."""
        return self.r_n * math.cos(self.lat) * np.sqrt(self._var(DLON))

    @property
    def sigma_horizontal(self) -> np.ndarray:
        """RMS horizontal error from noise, √(σ_N² + σ_E²) (N,), m."""
        return np.hypot(self.sigma_north, self.sigma_east)

    def series(self) -> LinearSeries:
        """The series the results file keeps."""
        return LinearSeries(self.t, self.north, self.east, self.horizontal, self.phi,
                            None if self.P is None else self.sigma_horizontal)

    def _var(self, i: int) -> np.ndarray:
        return np.zeros(len(self.t)) if self.P is None else np.maximum(self.P[:, i, i], 0.0)

    def index(self, hours: float) -> int:
        """Index of the output at `hours` (h); it must be an output time."""
        k = int(np.argmin(np.abs(self.t - hours * HOUR)))
        if abs(self.t[k] - hours * HOUR) > _TOL:
            raise ValueError(f"{hours} h is not an output time")
        return k

    def at(self, hours: float | Sequence[float] = REPORT_HOURS,
           quantity: str = "horizontal") -> np.ndarray:
        """`quantity` (a property name) at each of `hours`."""
        v = getattr(self, quantity)
        return np.array([v[self.index(h)] for h in np.atleast_1d(hours)])


class _Modes:
    """e^{F τ} and ∫_0^τ e^{F s} ds from the eigen-decomposition of F, for many τ at once.

    F is diagonalisable (eigenvalues 0, ±iΩ and the Foucault-split Schuler pair
    ±i(ω_s ± Ω_U), all distinct); it is decomposed in scaled states (velocities divided by
    R ω_s) where every entry is O(ω_s), so the eigenvectors are well conditioned
    (cond ≈ 4.5) and the result agrees with ``scipy.linalg.expm`` to ~1e-13 of its largest
    entry (a test keeps it so).
    """

    def __init__(self, F: np.ndarray, scale: np.ndarray):
        lam, V = np.linalg.eig(F * scale[:, None] / scale[None, :])
        self.lam = lam
        self.left = V / scale[:, None]  # D⁻¹ V
        self.right = np.linalg.inv(V) * scale[None, :]  # V⁻¹ D

    def _mat(self, diag: np.ndarray) -> np.ndarray:
        return np.real(np.einsum("ik,...k,kj->...ij", self.left, diag, self.right))

    def exp(self, tau: float | np.ndarray) -> np.ndarray:
        """e^{F τ}, shape (..., 7, 7)."""
        return self._mat(np.exp(np.multiply.outer(tau, self.lam)))

    def gamma(self, h: float | np.ndarray) -> np.ndarray:
        """∫_0^h e^{F s} ds = V diag(h φ1(λ h)) V⁻¹ with φ1(z) = (e^z − 1)/z."""
        z = np.multiply.outer(h, self.lam)
        small = np.abs(z) < 1e-8
        phi1 = np.where(small, 1.0 + 0.5 * z, np.expm1(z) / np.where(small, 1.0, z))
        return self._mat(np.multiply.outer(h, np.ones_like(self.lam)) * phi1)

    def convolve(self, tau: np.ndarray, weights: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Σ_m weights_m e^{F τ_m} u_m (7,), τ (m,), u (m, 7)."""
        c = np.exp(np.multiply.outer(tau, self.lam)) * (u @ self.right.T) * weights[:, None]
        return np.real(self.left @ c.sum(0))


class _Propagator:
    """Interval maps ``x(b) = Φ x(a) + w`` of the model for one schedule and error set."""

    def __init__(self, F: np.ndarray, schedule: Schedule, C0: np.ndarray, errors: ErrorTerms,
                 vel_scale: float, omega_ie_n: np.ndarray, f_n: np.ndarray):
        self.F, self.schedule, self.C0, self.errors = F, schedule, C0, errors
        self.omega_ie_n, self.f_n = omega_ie_n, f_n
        self.p = pieces(schedule)
        scale = np.ones(F.shape[0])
        scale[DV] = 1.0 / vel_scale
        self.modes = _Modes(F, scale)
        self._phi: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self._full: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._rest: dict[int, np.ndarray] = {}
        self._q: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        n = F.shape[0]
        self.Qc = np.zeros((n, n))
        self.Qc[PHI, PHI] = errors.arw**2 * np.eye(3)
        self.Qc[DV, DV] = errors.vrw**2 * np.eye(2)

    def forcing(self, tt: np.ndarray) -> np.ndarray:
        """u(t) (n, 7) at cycle times `tt` (n,)."""
        C = self.C0 @ self.schedule.dcm(tt)
        e = self.errors
        w_m = self.schedule.rate(tt)
        w_s = w_m + np.einsum("nji,j->ni", C, self.omega_ie_n)  # what the gyros sense
        d_omega = e.gyro_bias + w_s @ e.gyro_matrix.T + e.gyro_asym * np.abs(w_s)
        f_s = np.einsum("nji,j->ni", C, self.f_n)
        d_f = e.accel_bias + f_s @ e.accel_matrix.T + e.accel_asym * np.abs(f_s)
        if np.any(e.lever != 0):  # ω̇ × r + ω × (ω × r), mechanism rate
            a_m = self.schedule.angular_accel(tt)
            d_f = d_f + np.cross(a_m, e.lever) + np.cross(w_m, np.cross(w_m, e.lever))
        u = np.zeros((len(tt), 7))
        u[:, PHI] = -np.einsum("nij,nj->ni", C, d_omega)
        u[:, DV] = np.einsum("nij,nj->ni", C, d_f)[:, :2]
        return u

    def phi_gamma(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """e^{F h} and ∫_0^h e^{F s} ds (cached by h)."""
        key = round(h, 9)
        if key not in self._phi:
            self._phi[key] = (self.modes.exp(h), self.modes.gamma(h))
        return self._phi[key]

    def interval(self, j: int, ta: float, tb: float) -> tuple[np.ndarray, np.ndarray]:
        """Φ and w over [ta, tb] (s, local time in piece j)."""
        full = abs(ta) < _TOL and abs(tb - self.p.duration[j]) < _TOL
        if full and j in self._full:
            return self._full[j]
        h = tb - ta
        t0 = self.p.t0[j]
        Phi, Gam = self.phi_gamma(h)
        if self.p.constant[j]:
            if j not in self._rest:
                self._rest[j] = self.forcing(np.array([t0 + 0.5 * self.p.duration[j]]))[0]
            w = Gam @ self._rest[j]
        else:
            k = split_count(float(self.p.span[j]) * h / float(self.p.duration[j]), h, 60.0)
            e = ta + h * np.arange(k + 1) / k
            s, wt = gauss_legendre(e[:-1], e[1:])
            s, wt = s.ravel(), wt.ravel()
            w = self.modes.convolve(tb - s, wt, self.forcing(t0 + s))  # ∫ e^{F(b−s)} u ds
        if full:
            self._full[j] = (Phi, w)
        return Phi, w

    def q_d(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """Van Loan noise covariance Q_d over h and a square root L (L Lᵀ = Q_d)."""
        key = round(h, 9)
        if key not in self._q:
            from gcalign.estimation.kalman import van_loan  # scipy: only with noise

            Q = van_loan(self.F, np.eye(self.F.shape[0]), self.Qc, h)[1]
            self._q[key] = (Q, _sqrt_psd(Q))
        return self._q[key]


def _knots(schedule: Schedule, t_out: np.ndarray, duration: float) -> np.ndarray:
    T = schedule.period
    t0 = pieces(schedule).t0
    n = math.ceil(duration / T) + 1
    b = (np.arange(n)[:, None] * T + t0[None, :]).ravel()
    k = np.sort(np.concatenate([b[b < duration], t_out, [0.0, duration]]))
    keep = np.concatenate([[True], np.diff(k) > _TOL])
    return k[keep]


def _sqrt_psd(Q: np.ndarray) -> np.ndarray:
    lam, V = np.linalg.eigh(0.5 * (Q + Q.T))
    return V * np.sqrt(np.clip(lam, 0.0, None))


def linear_errors(scheme: Scheme | Schedule, errors: ErrorTerms, *,
                  duration: float = 72.0 * HOUR, dt_out: float = 60.0,
                  t_out: np.ndarray | None = None, lat: float = SEED004_LAT,
                  earth: EarthModel = SEED004, C0: np.ndarray | None = None,
                  rng: np.random.Generator | None = None, n_paths: int = 0,
                  name: str = "") -> LinearErrors:
    """Integrate the linear error model (module docstring) for `scheme` and `errors`.

    Parameters
    ----------
    scheme : a :class:`Scheme` or a bare :class:`Schedule` (a cycle that returns the IMU to
        its start).
    errors : sensor-frame errors and noise densities.
    duration : s (72 h by default). dt_out : s between outputs, or `t_out` (s) directly;
        the report hours (1, 4, 12, 24, 72 h) within `duration` are always included.
    lat : rad; `earth` : the earth model (seed 004's by default, height 0).
    C0 : (3, 3) C_s^n at the start (identity: body = ENU, spec §4).
    rng, n_paths : sample paths of the noise response (needs noise densities in `errors`).

    Returns
    -------
    LinearErrors
    """
    schedule = scheme.schedule if isinstance(scheme, Scheme) else scheme
    name = scheme.name if isinstance(scheme, Scheme) else name
    if not duration > 0:
        raise ValueError(f"duration must be > 0 s, got {duration}")
    if n_paths and rng is None:
        raise ValueError("n_paths > 0 needs an rng (numpy.random.Generator)")
    if t_out is None:
        if not dt_out > 0:
            raise ValueError(f"dt_out must be > 0 s, got {dt_out}")
        t_out = np.arange(0.0, duration + _TOL, dt_out)
    hours = np.array([h * HOUR for h in REPORT_HOURS if h * HOUR <= duration + _TOL])
    t_out = np.unique(np.concatenate([np.asarray(t_out, dtype=float), hours, [0.0]]))
    t_out = t_out[(t_out >= 0) & (t_out <= duration + _TOL)]
    F = error_matrix(lat, earth)
    r_m, r_n = earth.radii(lat)
    vel_scale = float(np.sqrt(r_m * r_n)) * earth.schuler_rate(lat)  # R ω_s, m/s per rad
    omega_ie_n = earth.omega_ie * np.array([0.0, math.cos(lat), math.sin(lat)])
    f_n = np.array([0.0, 0.0, float(earth.gravity(lat))])
    prop = _Propagator(F, schedule, np.eye(3) if C0 is None else np.asarray(C0, float), errors,
                       vel_scale, omega_ie_n, f_n)
    knots = _knots(schedule, t_out, float(t_out[-1]))
    out_k = np.searchsorted(knots, t_out - _TOL)  # knot of each output time
    is_out = np.full(len(knots), -1)
    is_out[out_k] = np.arange(len(t_out))
    noisy = errors.arw > 0 or errors.vrw > 0
    T, t0 = schedule.period, prop.p.t0

    X = np.zeros((len(t_out), 7))
    Ps = np.zeros((len(t_out), 7, 7)) if noisy else None
    paths = np.zeros((n_paths, len(t_out), 7)) if n_paths else None
    x = np.zeros((7, 1 + n_paths))
    P = np.zeros((7, 7))
    for i in range(len(knots) - 1):
        a, b = knots[i], knots[i + 1]
        k = math.floor(0.5 * (a + b) / T)
        j = int(np.searchsorted(t0, 0.5 * (a + b) - k * T, side="right")) - 1
        Phi, w = prop.interval(j, a - k * T - t0[j], b - k * T - t0[j])
        x = Phi @ x + w[:, None]
        if noisy:
            Q, L = prop.q_d(b - a)
            P = Phi @ P @ Phi.T + Q
            if n_paths:
                assert rng is not None  # checked above
                x[:, 1:] += L @ rng.standard_normal((7, n_paths))
        m = is_out[i + 1]
        if m >= 0:
            X[m] = x[:, 0]
            if Ps is not None:
                Ps[m] = P
            if paths is not None:
                paths[:, m] = x[:, 1:].T
    return LinearErrors(name, t_out, X, Ps, paths, float(lat), float(r_m), float(r_n))


def gyro_increment_response(scheme: Scheme | Schedule, dtheta: np.ndarray, ts: float, *,
                            lat: float = SEED004_LAT, earth: EarthModel = SEED004,
                            C0: np.ndarray | None = None, window: float = 10.0,
                            block: int = 1 << 17) -> tuple[np.ndarray, np.ndarray]:
    """The model's response to given sensor-frame gyro error increments, one path.

    ``dtheta`` (n, 3) rad: the error of each increment (say the noise a simulation drew),
    sample k over ``[k ts, (k+1) ts]``. Each enters φ as the impulse ``−C(t_k) dθ_k``
    (C = C0 · S at the sample's middle); impulses are summed over windows of `window` s
    (a whole number of samples) and applied at the window's middle, which is exact to
    O((ω_s · window/2)²) of the response. Returns the times (0, window, 2·window, …) and
    the states there, (m,), (m, 7) (order :data:`STATES`).
    """
    from scipy.linalg import expm

    schedule = scheme.schedule if isinstance(scheme, Scheme) else scheme
    per = int(round(window / ts))
    if per < 1 or abs(per * ts - window) > 1e-9 * window:
        raise ValueError(f"window {window} s is not a whole number of samples of {ts} s")
    n = (len(dtheta) // per) * per
    F = error_matrix(lat, earth)
    Phi, half = expm(F * window), expm(F * window / 2)[:, PHI]
    C0 = np.eye(3) if C0 is None else np.asarray(C0, dtype=float)
    step = max(per, (block // per) * per)
    x, out = np.zeros(7), [np.zeros(7)]
    for k0 in range(0, n, step):
        k1 = min(n, k0 + step)
        C = C0 @ schedule.dcm((np.arange(k0, k1) + 0.5) * ts)
        u = -np.einsum("nij,nj->ni", C, dtheta[k0:k1]).reshape(-1, per, 3).sum(1)
        for uj in u:
            x = Phi @ x + half @ uj
            out.append(x)
    return window * np.arange(len(out)), np.array(out)
