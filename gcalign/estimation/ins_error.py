"""The 21-state φ-angle INS error model of in-flight calibration (spec 002 §2).

State (SI; order of the seed's P0 list, names as printed in every output)::

    x = [φE φN φU | δvE δvN δvU | δL δλ δh | εx εy εz | ∇x ∇y ∇z | δKgx δKgy δKgz | δKax δKay δKaz]
         rad        m/s          rad rad m   rad/s      m/s²       –                  –

φ is the platform (misalignment) angle of the φ-angle model, ``C_nb,INS = (I − [φ×]) C_nb``;
``δv = v_INS − v``, ``δp = p_INS − p``. IMU model (spec 002 §2 [R]):
``ω̃ = (I + diag δKg) ω_ib^b + ε + w_g`` and ``f̃ = (I + diag δKa) f^b + ∇ + w_a``, all
errors random constants. Navigation frame ENU, body right-forward-up (PSINS).

``F`` is PSINS ``etm`` (checked against the C++ ``CSINS::etm``) plus the diagonal
scale-factor columns of PSINS ``kffk`` case 34::

    row φ : [Maa  Mav  Map  −C   0    −C·diag(ω_ib^b)   0           ]
    row δv: [Mva  Mvv  Mvp   0   C     0                C·diag(f^b) ]
    row δp: [0    Mpv  Mpp   0   0     0                0           ]    rows 10–21 = 0

The δλ column is identically zero (nothing depends on longitude), and δh feeds δv_U
positively (≈ +2g/R), so the free vertical channel diverges with time constant
√(R/2g) ≈ 570 s. Measurements are horizontal in the seed (§2.4): velocity ``[δvE, δvN]``
(m/s) and position ``[R_Mh δL, R_Nh cos L δλ]`` (north, east in metres); with
``components="3d"`` they add the vertical ``δvU`` and ``δh`` (up, m), which holds the
vertical channel whenever the aiding source measures height (a GNSS receiver does).

Sensor processes (KF-GINS, PSINS): each sensor state is a random constant (the seed), a
first-order Gauss–Markov process ``ẋ = −x/τ + w`` with ``E[w²] = 2σ²/τ`` (stationary std
σ) or a random walk ``ẋ = w`` with ``E[w²] = q²``: :class:`SensorProcesses` holds the
decay rates β = 1/τ and the driving densities of the 12 sensor states.

>>> import numpy as np
>>> F = error_matrix(np.eye(3), [0.0, 0.0, 9.8], [0.0, 0.0, 0.0], np.zeros(3),
...                  [np.radians(38.0), 0.0, 0.0])
>>> F.shape, bool(np.all(F[:, IDX["dlam"]] == 0.0)), bool(np.all(F[9:] == 0.0))
((21, 21), True, True)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gcalign.choices import MEASUREMENTS
from gcalign.errors import ScenarioError
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.units import ARCMIN, ARCSEC, DPH, DPSH, PPM, UG, UGPSHZ

STATE_NAMES: tuple[str, ...] = (
    "phiE", "phiN", "phiU", "dvE", "dvN", "dvU", "dL", "dlam", "dh",
    "ebx", "eby", "ebz", "dbx", "dby", "dbz",
    "dKgx", "dKgy", "dKgz", "dKax", "dKay", "dKaz",
)  # fmt: skip
N_STATES = len(STATE_NAMES)
IDX = {name: i for i, name in enumerate(STATE_NAMES)}

PHI, DV, DP = slice(0, 3), slice(3, 6), slice(6, 9)
EB, DB, DKG, DKA = slice(9, 12), slice(12, 15), slice(15, 18), slice(18, 21)
NAV, IMU = slice(0, 9), slice(9, 21)

STATE_UNITS: tuple[str, ...] = (
    ("rad",) * 3 + ("m/s",) * 3 + ("rad", "rad", "m") + ("rad/s",) * 3 + ("m/s^2",) * 3
    + ("1",) * 6
)  # fmt: skip
"""SI unit of each state."""

DISPLAY_UNITS: tuple[str, ...] = (
    ("arcsec", "arcsec", "arcmin") + ("m/s",) * 3 + ("m",) * 3 + ("deg/h",) * 3
    + ("ug",) * 3 + ("ppm",) * 6
)  # fmt: skip
"""Units of the seed's P0 list (position in metres north, east, up); see :func:`display_scale`."""

MEASUREMENT_NAMES = {
    "velocity": ("dvE", "dvN"),
    "position": ("dpN", "dpE"),
    "both": ("dvE", "dvN", "dpN", "dpE"),
}
COMPONENTS = ("horizontal", "3d")
"""The seed's horizontal measurements (eqs. 5–7), or with their vertical components."""
MEASUREMENT_NAMES_3D = {
    "velocity": ("dvE", "dvN", "dvU"),
    "position": ("dpN", "dpE", "dpU"),
    "both": ("dvE", "dvN", "dvU", "dpN", "dpE", "dpU"),
}


def measurement_names(measure: str, components: str = "horizontal") -> tuple[str, ...]:
    """Names of the measurement components: velocity east, north (up); position north,
    east (up) in metres."""
    _check_measure(measure)
    _check_components(components)
    return (MEASUREMENT_NAMES_3D if components == "3d" else MEASUREMENT_NAMES)[measure]

# Seed 002 §5.2 P0 list in display units (before the ×10); position in metres.
_P0_LISTED_DISPLAY = np.array(
    [20.0, 20.0, 30.0, 0.2, 0.2, 0.2, 1.0, 1.0, 1.0, 0.01, 0.01, 0.01, 50.0, 50.0, 50.0]
    + [100.0] * 6
)
P0_SCALE_DEFAULT = 10.0
ARW_DEFAULT = 0.001 * DPSH  #: spec 002 §2 [X]: 0.001 °/√h, in rad/√s
VRW_DEFAULT = 10.0 * UGPSHZ  #: spec 002 §2 [X]: 10 µg/√Hz, in m/s/√s


def display_scale(lat: float, h: float = 0.0, earth: EarthModel = WGS84) -> np.ndarray:
    """Factors (21,) that turn SI states into :data:`DISPLAY_UNITS`: ``x_display = x * k``.

    δL and δλ become metres north and east (``R_Mh``, ``R_Nh cos L`` at `lat`, `h`).
    """
    r_m, r_n = earth.radii(lat)
    per_si = [ARCSEC, ARCSEC, ARCMIN, 1.0, 1.0, 1.0, 1.0 / (r_m + h),
              1.0 / ((r_n + h) * np.cos(lat)), 1.0, DPH, DPH, DPH, UG, UG, UG] + [PPM] * 6
    return 1.0 / np.array(per_si, dtype=float)


def listed_sigma(pos: np.ndarray, earth: EarthModel = WGS84) -> np.ndarray:
    """The seed's P0 list (spec 002 §2) in SI, (21,): the values *before* the ×10.

    ``[20″, 20″, 30′; 0.2 m/s ×3; 1 m ×3; 0.01°/h ×3; 50 µg ×3; 100 ppm ×3; 100 ppm ×3]``;
    the 1 m of δL, δλ becomes radians at the latitude and height of `pos` ``[L, λ, h]``.
    """
    return _P0_LISTED_DISPLAY / display_scale(float(pos[0]), float(pos[2]), earth)


def initial_covariance(pos: np.ndarray, p0_scale: float = P0_SCALE_DEFAULT,
                       sigma: ArrayLike | None = None,
                       earth: EarthModel = WGS84) -> np.ndarray:
    """P0 = diag((p0_scale · σ_listed)²) (spec 002 §2, PSINS ``diag([...]*10)^2``), (21, 21).

    `sigma` (21,) SI replaces the listed σ (then scaled by `p0_scale` too).
    """
    if not np.isfinite(p0_scale) or p0_scale <= 0:
        raise ScenarioError(f"p0_scale: must be a positive number, got {p0_scale!r}")
    s = listed_sigma(pos, earth) if sigma is None else np.asarray(sigma, dtype=float)
    if s.shape != (N_STATES,) or not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ScenarioError(f"p0 sigma: need {N_STATES} positive finite values, got "
                            f"{np.array2string(s.ravel(), max_line_width=10**6)}")
    return np.diag((p0_scale * s) ** 2)


def process_noise_density(arw: float = ARW_DEFAULT, vrw: float = VRW_DEFAULT) -> np.ndarray:
    """Qc = diag(ARW², ARW², ARW², VRW², VRW², VRW²) (6, 6) for ``w = [w_g; w_a]``.

    ARW in rad/√s and VRW in m/s/√s: white-noise densities of the gyro and accelerometer
    (the per-sample std of an increment over ts is ``density · √ts``).
    """
    for name, value in (("arw", arw), ("vrw", vrw)):
        if not np.isfinite(value) or value < 0:
            raise ScenarioError(f"{name}: must be a non-negative number, got {value!r}")
    return np.diag([arw**2] * 3 + [vrw**2] * 3)


def _skew(v: np.ndarray) -> np.ndarray:
    """[v×] over leading axes, (..., 3) -> (..., 3, 3)."""
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def error_matrix(C_nb: ArrayLike, f_b: ArrayLike, omega_ib_b: ArrayLike, v_n: ArrayLike,
                 pos: ArrayLike, earth: EarthModel = WGS84) -> np.ndarray:
    """System matrix F of the 21-state model (spec 002 §2), vectorised over leading axes.

    Parameters
    ----------
    C_nb : (..., 3, 3) body-to-ENU attitude.
    f_b : (..., 3) specific force in the body frame, m/s².
    omega_ib_b : (..., 3) body angular rate w.r.t. inertial space, rad/s.
    v_n : (..., 3) ENU velocity, m/s.
    pos : (..., 3) ``[L, λ, h]`` (rad, rad, m).
    earth : earth model (radii, rate, normal gravity; the δL, δh gravity terms use its
        coefficients, which for WGS-84 are PSINS's ``5.27094e-3``, ``2.32718e-5``, ``3.086e-6``).

    Returns
    -------
    F : (..., 21, 21), 1/s in SI state units.
    """
    C = np.asarray(C_nb, dtype=float)
    f_b = np.asarray(f_b, dtype=float)
    w_b = np.asarray(omega_ib_b, dtype=float)
    v = np.asarray(v_n, dtype=float)
    pos = np.asarray(pos, dtype=float)
    shape = np.broadcast_shapes(C.shape[:-2], f_b.shape[:-1], w_b.shape[:-1], v.shape[:-1],
                                pos.shape[:-1])
    C = np.broadcast_to(C, shape + (3, 3))
    f_b = np.broadcast_to(f_b, shape + (3,))
    w_b = np.broadcast_to(w_b, shape + (3,))
    v = np.broadcast_to(v, shape + (3,))
    lat, h = np.broadcast_to(pos[..., 0], shape), np.broadcast_to(pos[..., 2], shape)
    ve, vn = v[..., 0], v[..., 1]
    sl, cl = np.sin(lat), np.cos(lat)
    tl, secl = sl / cl, 1.0 / cl
    r_m, r_n = earth.radii(lat)
    r_mh, r_nh = r_m + h, r_n + h
    wie = earth.omega_ie
    zero = np.zeros(shape)

    w_ie = np.stack([zero, wie * cl, wie * sl], -1)
    w_en = np.stack([-vn / r_mh, ve / r_nh, ve * tl / r_nh], -1)
    f_n = np.einsum("...ij,...j->...i", C, f_b)

    def mat(rows: list[list[np.ndarray]]) -> np.ndarray:
        return np.stack([np.stack(r, -1) for r in rows], -2)

    Mav = mat([[zero, -1.0 / r_mh, zero], [1.0 / r_nh, zero, zero], [tl / r_nh, zero, zero]])
    M1 = mat([[zero, zero, zero], [-wie * sl, zero, zero], [wie * cl, zero, zero]])
    M2 = mat([[zero, zero, vn / r_mh**2], [zero, zero, -ve / r_nh**2],
              [ve * secl**2 / r_nh, zero, -ve * tl / r_nh**2]])
    Vx = _skew(v)
    Mvv = Vx @ Mav - _skew(2.0 * w_ie + w_en)
    Mvp = Vx @ (2.0 * M1 + M2)
    # Normal gravity g0 (1 + g1 sin²L + g2 sin⁴L) − g3 h falls with latitude and height:
    # δv̇_U = −∂g/∂L δL − ∂g/∂h δh
    # (PSINS etm: −g0(2·5.27094e-3 + 4·2.32718e-5 sin²L) sL cL at δL, +3.086e-6 at δh)
    Mvp[..., 2, 0] -= earth.g0 * (2.0 * earth.g1 + 4.0 * earth.g2 * sl**2) * sl * cl
    Mvp[..., 2, 2] += earth.g3
    Mpv = mat([[zero, 1.0 / r_mh, zero], [secl / r_nh, zero, zero], [zero, zero, zero + 1.0]])
    Mpp = mat([[zero, zero, -vn / r_mh**2], [ve * secl * tl / r_nh, zero, -ve * secl / r_nh**2],
               [zero, zero, zero]])

    F = np.zeros(shape + (N_STATES, N_STATES))
    F[..., PHI, PHI] = -_skew(w_ie + w_en)  # Maa = −[ω_in×]
    F[..., PHI, DV] = Mav
    F[..., PHI, DP] = M1 + M2  # Map
    F[..., PHI, EB] = -C
    F[..., PHI, DKG] = -C * w_b[..., None, :]  # −C diag(ω_ib^b)
    F[..., DV, PHI] = _skew(f_n)  # Mva = [f^n×]
    F[..., DV, DV] = Mvv
    F[..., DV, DP] = Mvp
    F[..., DV, DB] = C
    F[..., DV, DKA] = C * f_b[..., None, :]  # C diag(f^b)
    F[..., DP, DV] = Mpv
    F[..., DP, DP] = Mpp
    return F


def noise_matrix(C_nb: ArrayLike) -> np.ndarray:
    """G (..., 21, 6) for ``w = [w_g; w_a]``: rows φ get −C, rows δv get +C (spec 002 §2)."""
    C = np.asarray(C_nb, dtype=float)
    G = np.zeros(C.shape[:-2] + (N_STATES, 6))
    G[..., PHI, 0:3] = -C
    G[..., DV, 3:6] = C
    return G


def _check_measure(measure: str) -> None:
    if measure not in MEASUREMENTS:
        raise ScenarioError(f"measure: got {measure!r}, allowed: {', '.join(MEASUREMENTS)}")


def _check_components(components: str) -> None:
    if components not in COMPONENTS:
        raise ScenarioError(f"components: got {components!r}, allowed: {', '.join(COMPONENTS)}")


def _rows(measure: str, components: str) -> tuple[list[int], list[int]]:
    """Rows of the full 3-D velocity [E, N, U] and position [N, E, U] blocks kept."""
    _check_measure(measure)
    _check_components(components)
    keep = [0, 1, 2] if components == "3d" else [0, 1]
    return (keep if measure != "position" else []), (keep if measure != "velocity" else [])


def measurement_matrix(measure: str, pos: np.ndarray, earth: EarthModel = WGS84,
                       components: str = "horizontal") -> np.ndarray:
    """H (m, 21) of seed eqs. (5)–(7): ``velocity`` [δvE, δvN]; ``position`` [north, east] in
    metres, ``R_Mh δL`` and ``R_Nh cos L δλ`` at `pos` ``[L, λ, h]``; ``both`` stacks them.
    ``components="3d"`` adds δvU after the horizontal velocity and δh (up, m) after the
    horizontal position."""
    rv, rp = _rows(measure, components)
    H_v = np.zeros((3, N_STATES))
    H_v[0, IDX["dvE"]] = H_v[1, IDX["dvN"]] = H_v[2, IDX["dvU"]] = 1.0
    lat, h = float(pos[0]), float(pos[2])
    r_m, r_n = earth.radii(lat)
    H_p = np.zeros((3, N_STATES))
    H_p[0, IDX["dL"]] = r_m + h
    H_p[1, IDX["dlam"]] = (r_n + h) * np.cos(lat)
    H_p[2, IDX["dh"]] = 1.0
    return np.vstack([H_v[rv], H_p[rp]])


def antenna_offset(C_nb: ArrayLike, omega_ib_b: ArrayLike, omega_ie_n: ArrayLike,
                   lever_b: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(v_a − v, r_a − r)`` (3,) ENU, m/s and m: the velocity and position of a point at
    `lever_b` (body axes, m) beyond the IMU's, ``C (ω_ib^b × l) − ω_ie^n × C l`` and
    ``C l`` (derived in :func:`lever_arm_terms`)."""
    C = np.asarray(C_nb, dtype=float)
    Cl = C @ np.asarray(lever_b, dtype=float)
    u = -(C @ _skew(np.asarray(lever_b, dtype=float))) @ np.asarray(omega_ib_b, dtype=float)
    return u - _skew(np.asarray(omega_ie_n, dtype=float)) @ Cl, Cl


def lever_arm_terms(measure: str, C_nb: ArrayLike, omega_ib_b: ArrayLike,
                    omega_ie_n: ArrayLike, lever_v_b: ArrayLike | None = None,
                    lever_p_b: ArrayLike | None = None,
                    components: str = "horizontal") -> tuple[np.ndarray, np.ndarray]:
    """What an aiding antenna at a lever arm adds to the measurement: ``(offset (m,), H_l
    (m, 21))`` with ``z = INS + offset − fix`` and ``H = measurement_matrix + H_l``.

    The velocity fix is taken at `lever_v_b`, the position fix at `lever_p_b` (the point
    each measures, from the IMU in body axes x right, y forward, z up; m; None: the IMU).
    `C_nb` (3, 3) and `omega_ib_b` (3,) rad/s are the INS's attitude and compensated rate
    at the epoch, `omega_ie_n` (3,) the earth rate. Components in the order of
    :func:`measurement_names` (velocity east, north (up); position north, east (up) in
    metres).

    Derivation (φ convention ``Ĉ = (I − [φ×]) C``, so ``(Ĉ − C) u = −φ × C u = [(C u)×] φ``;
    l taken as exactly known, products of errors dropped):

    * Position. The antenna is at ``r_a = r + C l`` (ENU metres about the IMU); the INS
      puts it at ``r̂ + Ĉ l``, so ``r̂_a − r_a = δr + [(C l)×] φ``: the offset is
      ``(Ĉ l)`` north, east (PSINS ``pos + Mpv·Cnb·lever`` in metres) and the φ columns
      the north and east rows of ``[(Ĉ l)×]``.
    * Velocity. In the earth frame ``r_a^e = r^e + C_b^e l``, and ``v`` is the
      earth-referenced velocity resolved in n, so ``v_a = v + C (ω_eb^b × l)`` with
      ``ω_eb^b = ω_ib^b − C^T ω_ie^n``: ``v_a = v + C (ω_ib^b × l) − ω_ie^n × C l``. Both
      terms are kept; the transport rate does not enter (the n frame's turn is not a motion
      of the antenna against the earth: a form with ω_in^n in place of ω_ie^n is wrong by
      ω_en^n × C l, 8e-6 m/s per metre at 50 m/s). With ``Ĉ`` and the compensated rate
      ``ω̂ = ω + δω``, ``δω = x_ε + diag(ω) x_δKg`` (the filter's sensor states):
      ``v̂_a − v_a = δv + ([(C(ω×l))×] − [ω_ie×][(C l)×]) φ − C [l×] (x_ε + diag(ω) x_δKg)``:
      columns at φ, ε and δKg. Left out: the δp dependence of ω_ie^n (≈ ω_ie l δL, 1e-12).

    >>> off, H = lever_arm_terms("position", np.eye(3), np.zeros(3), np.zeros(3),
    ...                          lever_p_b=[0.0, 2.0, 0.0])
    >>> off.tolist(), (H[:, :3] + 0.0).tolist()  # 2 m ahead = north; φU > 0 (the INS turned
    ([2.0, 0.0], [[0.0, 0.0, 0.0], [0.0, 0.0, 2.0]])
    >>> # right by φU) puts the antenna east by 2 m · φU
    """
    rv, rp = _rows(measure, components)
    C = np.asarray(C_nb, dtype=float)
    w = np.asarray(omega_ib_b, dtype=float)
    w_ie = np.asarray(omega_ie_n, dtype=float)
    l_v = np.zeros(3) if lever_v_b is None else np.asarray(lever_v_b, dtype=float)
    l_p = np.zeros(3) if lever_p_b is None else np.asarray(lever_p_b, dtype=float)
    off_v, Cl = antenna_offset(C, w, w_ie, l_v)
    ClX = C @ _skew(l_v)  # C [l×]
    u = -ClX @ w  # C (ω × l)
    H_v = np.zeros((3, N_STATES))
    H_v[:, PHI] = _skew(u) - _skew(w_ie) @ _skew(Cl)
    H_v[:, EB] = -ClX
    H_v[:, DKG] = -ClX * w[None, :]  # −C [l×] diag(ω)
    Cl_p = C @ l_p
    H_p = np.zeros((3, N_STATES))
    H_p[:, PHI] = _skew(Cl_p)
    off_p, H_p = Cl_p[[1, 0, 2]], H_p[[1, 0, 2]]  # north, east, up
    return (np.concatenate([off_v[rv], off_p[rp]]), np.vstack([H_v[rv], H_p[rp]]))


def measurement_noise(measure: str, sigma_v: float = 0.2, sigma_p: float = 1.0,
                      components: str = "horizontal") -> np.ndarray:
    """R (m, m) from the seed's standard deviations (spec 002 §2): R = diag(σ²)."""
    rv, rp = _rows(measure, components)
    for name, value in (("sigma_v", sigma_v), ("sigma_p", sigma_p)):
        if not np.isfinite(value) or value <= 0:
            raise ScenarioError(f"{name}: R needs a positive standard deviation, got {value!r}")
    return np.diag(np.square([sigma_v] * len(rv) + [sigma_p] * len(rp)))


PROCESS_KINDS = ("constant", "gauss-markov", "random-walk")
"""How a sensor state evolves: random constant, first-order Gauss–Markov, random walk."""


@dataclass(frozen=True)
class SensorProcesses:
    """Dynamics of the 12 sensor states (ε, ∇, δKg, δKa in the state order):
    ``ẋ_i = −β_i x_i + w_i``, ``E[w wᵀ] = diag(q) δ(t − s)``.

    beta : (12,) decay rates 1/τ (1/s); 0 for a constant or a random walk.
    q : (12,) driving-noise densities (state unit² per s): ``2σ²/τ`` for a Gauss–Markov
        process of stationary std σ, the squared density for a random walk, 0 for a
        constant.
    """

    beta: np.ndarray
    q: np.ndarray

    @classmethod
    def of(cls, kinds: Sequence[str], std: ArrayLike, tau: ArrayLike,
           density: ArrayLike) -> SensorProcesses:
        """From one kind per state (:data:`PROCESS_KINDS`), the stationary std and τ of the
        Gauss–Markov states and the density of the random walks (each (12,), SI)."""
        std, tau, dens = (np.broadcast_to(np.asarray(a, dtype=float), (12,))
                          for a in (std, tau, density))
        beta, q = np.zeros(12), np.zeros(12)
        for i, kind in enumerate(kinds):
            if kind == "gauss-markov":
                if not (np.isfinite(tau[i]) and tau[i] > 0 and np.isfinite(std[i])
                        and std[i] >= 0):
                    raise ScenarioError(f"{STATE_NAMES[9 + i]}: a Gauss–Markov process needs "
                                        f"std ≥ 0 and τ > 0, got std {std[i]!r}, τ {tau[i]!r}")
                beta[i], q[i] = 1.0 / tau[i], 2.0 * std[i] ** 2 / tau[i]
            elif kind == "random-walk":
                if not (np.isfinite(dens[i]) and dens[i] >= 0):
                    raise ScenarioError(f"{STATE_NAMES[9 + i]}: a random walk needs a "
                                        f"density ≥ 0, got {dens[i]!r}")
                q[i] = dens[i] ** 2
            elif kind != "constant":
                raise ScenarioError(f"{STATE_NAMES[9 + i]}: process {kind!r}; allowed: "
                                    f"{', '.join(PROCESS_KINDS)}")
        return cls(beta, q)

    @property
    def constant(self) -> bool:
        """Every sensor state a random constant (the seed's model)."""
        return not (self.beta.any() or self.q.any())

    def discrete(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """``(a, Q)`` (12,) over `dt`: ``a = e^{−β dt}`` and the variance the driving noise
        adds, ``q (1 − e^{−2β dt})/(2β)`` (``q dt`` for β = 0): exact."""
        a = np.exp(-self.beta * dt)
        bt = 2.0 * self.beta * dt
        # (1 − e^{−x})/x → 1 as x → 0: expm1 keeps it exact for small β dt
        frac = np.where(bt > 0, -np.expm1(-bt) / np.where(bt > 0, bt, 1.0), 1.0)
        return a, self.q * dt * frac

    def augment(self, F: np.ndarray, G: np.ndarray,
                Qc: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """F (21, 21), G (21, 6 + 12), Qc (18, 18) of the whole model with the processes
        (for Van Loan): ``−β`` on the sensor diagonal, the driving noise on new columns."""
        F = F.copy()
        F[IMU, IMU] -= np.diag(self.beta)
        G2 = np.zeros((N_STATES, G.shape[1] + 12))
        G2[:, : G.shape[1]] = G
        G2[IMU, G.shape[1]:] = np.eye(12)
        Q2 = np.zeros((G2.shape[1],) * 2)
        Q2[: Qc.shape[0], : Qc.shape[0]] = Qc
        Q2[Qc.shape[0]:, Qc.shape[0]:] = np.diag(self.q)
        return F, G2, Q2


def with_processes(Phi: np.ndarray, Qd: np.ndarray, processes: SensorProcesses,
                   dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Φ, Q_d over `dt` of the model with sensor processes, from Φ_c, Q_d,c of the model
    with constant sensors (the navigation steps' accumulation) by a symmetric splitting:
    half the sensors' own dynamics, the coupled step, the other half,
    ``Φ = D Φ_c D`` and ``Q_d = D (Φ_c Q_s Φ_cᵀ + Q_d,c) D + Q_s`` with
    ``D = diag(1, e^{−β dt/2})`` and Q_s the variance the driving noise adds in dt/2.

    The splitting leaves the navigation block's accumulation as it was and errs by terms of
    third order in dt, β dt³ in the coupling of the sensors into velocity: about a sixth of
    what the decay changes there. Against Van Loan on the whole model over dt = 1 s: 1.4e-4
    of the coupling block of Φ and 5e-4 of Q_d at τ = 600 s, 2.3e-5 and 9e-5 at τ = 1 h
    (``tests/test_aided_filter.py``), far below the model's own approximations.
    """
    a, Qs = processes.discrete(0.5 * dt)
    d = np.ones(N_STATES)
    d[IMU] = a
    Q_half = np.zeros((N_STATES, N_STATES))
    Q_half[IMU, IMU] = np.diag(Qs)
    Phi_out = d[:, None] * Phi * d[None, :]
    inner = Phi @ Q_half @ Phi.T + Qd
    Q_out = d[:, None] * inner * d[None, :] + Q_half
    return Phi_out, 0.5 * (Q_out + Q_out.T)


def accumulate(F_steps: np.ndarray, G_steps: np.ndarray, Qc: np.ndarray,
               ts: float) -> tuple[np.ndarray, np.ndarray]:
    """Φ and Q_d over K navigation steps from F, G at each step (the alternative to Van Loan).

    ``Φ = A_K ⋯ A_1`` with ``A_k = I + F_k ts + (F_k ts)²/2`` (second order per step: a
    first-order product misses 1/K of every second-order term, 4 % at 25 steps);
    ``Q_d ← A_k (Q_d + ½ G_k Qc G_kᵀ ts) A_kᵀ + ½ G_k Qc G_kᵀ ts`` (the trapezoid rule of
    ``∫Φ G Qc Gᵀ Φᵀ``: a rectangle rule would give the position variance 3/(2K) too small).
    F_steps (K, n, n), G_steps (K, n, p). Returns ``(Φ, Q_d)``.
    """
    n = F_steps.shape[-1]
    A = np.eye(n) + F_steps * ts
    FF = F_steps @ F_steps
    A = A + 0.5 * ts * ts * FF
    GQG = 0.5 * ts * G_steps @ Qc @ np.swapaxes(G_steps, -1, -2)
    Phi = np.eye(n)
    Qd = np.zeros((n, n))
    for k in range(len(F_steps)):
        Phi = A[k] @ Phi
        Qd = A[k] @ (Qd + GQG[k]) @ A[k].T + GQG[k]
    return Phi, 0.5 * (Qd + Qd.T)
