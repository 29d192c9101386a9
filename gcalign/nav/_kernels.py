"""Numba kernels: the one strapdown update, its pieces, and the block kernels over them.

Private: the public functions are in :mod:`gcalign.nav.strapdown`. Scalar helpers here are
inlined into every kernel by LLVM (the gyrocompass of :mod:`gcalign.align.kernel` uses the
same pieces); they repeat the vectorised formulas of :mod:`gcalign.nav.earth` and
:mod:`gcalign.nav.rotation`, and ``tests/test_strapdown.py`` holds the two in step (kernel
vs slow NumPy reference, 1e-12).

Earth models are values: every kernel takes the float64 vector of
:meth:`gcalign.nav.earth.EarthModel.params` (``[form, a, e2|f, ω_ie, g0, g1, g2, g3]``).

The navigation state is one float64 vector with named slices (:data:`Q`, :data:`V`,
:data:`P`, :data:`DA`): ``q_nb (4) | v_n ENU (3) | lat, lon, h (3) | vertical loop
acceleration (1)``, so that a stream of blocks hands it on.

One update serves both directions (DESIGN.md "Reverse navigation"): a reverse pass feeds
time-reversed data with negated gyro increments, negated velocity and ``earth_sign = -1``.
Every approximation in the step is evaluated at the middle of the interval, so the reverse
step undoes the forward step to second order in the step size.

Vertical channel (``vertical = [mode, k1, k2, k3]``): ``FREE`` integrates it (unstable,
time constant √(R/2g) ≈ 570 s); ``HOLD`` keeps h at the reference height and v_U = 0
(PSINS's height hold); ``DAMPED`` is the third-order loop of :func:`vertical_gains`.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit


def _arraymath_without_scipy() -> None:
    """Import ``numba.np.arraymath`` without importing scipy.linalg.

    Its module-level BLAS probe imports ``scipy.linalg.cython_blas`` and with it all of
    scipy.linalg: a quarter of a second of start-up, for a probe whose answer only says
    whether the BLAS extension is there. The probe is given that answer (the extension
    file in scipy's install) while the module loads; the linear algebra inside kernels, if
    any, still imports and checks scipy's BLAS when it is compiled.
    """
    if "numba.np.arraymath" in sys.modules:
        return
    import numba.np.linalg as nb_linalg

    spec = importlib.util.find_spec("scipy")
    linalg = Path(spec.origin).parent / "linalg" if spec and spec.origin else None
    has_blas = linalg is not None and any(
        (linalg / f"cython_blas{suffix}").is_file()
        for suffix in importlib.machinery.EXTENSION_SUFFIXES)

    def probe() -> None:
        if not has_blas:
            raise ImportError("scipy.linalg.cython_blas")

    real = nb_linalg.ensure_blas
    nb_linalg.ensure_blas = probe
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        nb_linalg.ensure_blas = real


#: numba versions (major, minor) on which cached kernels load through the shortcut below:
#: the built-in results files written from a cold cache and from a warm one are identical
#: (tests/test_cli_newcomer.py). Add a version once that test passes on it.
SHORTCUT_NUMBA = ((0, 68),)


def _numba_loads_without_compiler_setup() -> None:
    """Load cached kernels without setting up numba's compiler.

    Before loading a kernel from its cache numba refreshes its compiler: it imports and
    registers the typing and lowering of everything it can compile (lists, sets, dicts,
    NumPy's random generators, ...), and loading a kernel's environment imports the
    modules of numba it was built from: together about 80 ms of a warm ``gcalign align``
    (its first kernel call, 80 -> 28 ms), for nothing a cached kernel uses: its machine
    code is linked against the numba runtime (NRT) and the C helpers only. Here a cached
    load initialises the runtime and loads; a compilation still refreshes everything first
    (numba's compiler does so itself), so a kernel that is not in the cache, or a new
    signature, compiles as before (``numba.np.arraymath`` then imported without scipy).

    The methods replaced are numba's private ones: only on the numba versions this was
    checked on (SHORTCUT_NUMBA); any other loads its own way, as it always could.
    """
    import numba
    from numba.core import caching, cpu, environment
    from numba.core.runtime import rtsys

    cache, context = caching.Cache, cpu.CPUContext
    version = tuple(int(x) for x in numba.__version__.split(".")[:2] if x.isdigit())
    if getattr(cache, "_gcalign_load", False) or version not in SHORTCUT_NUMBA:
        return

    def load_overload(self: Any, sig: Any, target_context: Any) -> Any:
        rtsys.initialize(target_context)  # what cached machine code links against
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    registries = context.load_additional_registries

    def load_additional_registries(self: Any) -> None:
        _arraymath_without_scipy()
        registries(self)

    def rebuild_env(modname: str, consts: Any, env_name: str) -> Any:
        """numba's ``_rebuild_env`` without importing a module of numba's own that is not
        loaded yet: the environment of compiled code keeps its module's globals for object
        mode only (our kernels are nopython), so numba's implementation modules that a
        cached kernel was built from (array allocation, the random generators, ...) are
        not imported to load it."""
        env = environment.lookup_environment(env_name)
        if env is not None:
            return env
        module = sys.modules.get(modname)
        if module is None and modname.split(".")[0] != "numba":
            module = importlib.import_module(modname)
        env = environment.Environment(
            module.__dict__ if module is not None else {"__name__": modname})
        env.consts[:] = consts
        env.env_name = env_name
        environment.Environment._memo[env_name] = env
        return env

    setattr(cache, "load_overload", load_overload)  # noqa: B010 - a method replaced
    setattr(context, "load_additional_registries", load_additional_registries)  # noqa: B010
    setattr(environment, "_rebuild_env", rebuild_env)  # noqa: B010
    setattr(cache, "_gcalign_load", True)  # noqa: B010


_numba_loads_without_compiler_setup()

#: An earth model's float vector (:meth:`gcalign.nav.earth.EarthModel.params`), or the same
#: numbers as a tuple (a kernel that reads them at every step of a vectorised loop).
EarthParams = np.ndarray | tuple[float, ...]

Q = slice(0, 4)  #: q_nb in the state vector
V = slice(4, 7)  #: v_n, ENU, m/s
P = slice(7, 10)  #: lat, lon (rad), h (m)
DA = 10  #: vertical-loop acceleration estimate (m/s²), DAMPED only
NAV_STATE = 11
FREE, HOLD, DAMPED = 0, 1, 2

# PSINS cone factors (Savage's polynomial-rate optimum, cross product with the last
# sub-increment): φ = Σθ_i + (Σ_{i<n} c_i θ_i) × θ_n.
CONE = np.zeros((6, 5))
CONE[2, :1] = [2.0 / 3.0]
CONE[3, :2] = [9.0 / 20.0, 27.0 / 20.0]
CONE[4, :3] = [54.0 / 105.0, 92.0 / 105.0, 214.0 / 105.0]
CONE[5, :4] = [250.0 / 504.0, 525.0 / 504.0, 650.0 / 504.0, 1375.0 / 504.0]


def vertical_gains(tau: float, gravity_gradient: float) -> np.ndarray:
    """Gains ``[DAMPED, k1, k2, k3]`` of the third-order height loop with a triple pole at −1/τ.

    Loop (δh = h − h_ref):  ḣ = v_U − k1 δh;  v̇_U = f_U − g − k2 δh − a;  ȧ = k3 δh.
    Its error equations, with the positive gravity feedback ∂g/∂h = −g3 (≈ 2g/R), have the
    characteristic polynomial ``s³ + k1 s² + (k2 − g3) s + k3``; matching ``(s + 1/τ)³``
    gives ``k1 = 3/τ``, ``k2 = 3/τ² + g3``, ``k3 = 1/τ³``.
    """
    return np.array([DAMPED, 3.0 / tau, 3.0 / tau**2 + gravity_gradient, 1.0 / tau**3])


@njit(cache=True, inline="always")
def earth_at(E: EarthParams, lat: float, h: float) -> tuple[float, float, float, float, float]:
    """R_M, R_N (m), normal gravity g (m/s²), sin L, cos L of earth model `E` at (lat, h)."""
    return earth_sc(E, math.sin(lat), math.cos(lat), h)


@njit(cache=True, inline="always")
def earth_sc(E: EarthParams, sl: float, cl: float,
             h: float) -> tuple[float, float, float, float, float]:
    """:func:`earth_at` from sin L and cos L (a kernel over many runs takes the sines of
    all its runs in one loop, and the rest of the step in another, vectorised one)."""
    s2 = sl * sl
    if E[0] == 0.0:  # exact ellipsoid radii
        e2 = E[2]
        w = 1.0 - e2 * s2
        r_n = E[1] / math.sqrt(w)
        r_m = r_n * (1.0 - e2) / w
    else:  # first order in the flattening
        f = E[2]
        r_m = E[1] * (1.0 - 2.0 * f + 3.0 * f * s2)
        r_n = E[1] * (1.0 + f * s2)
    g = E[4] * (1.0 + E[5] * s2 + E[6] * s2 * s2) - E[7] * h
    return r_m, r_n, g, sl, cl


@njit(cache=True, inline="always")
def rv2q(rx: float, ry: float, rz: float,
         series: bool = False) -> tuple[float, float, float, float]:
    """Quaternion of a rotation vector. Below 0.05 rad the series of cos(θ/2) and
    sin(θ/2)/θ to θ⁸ are exact in float64 (the next terms are below 1e-22) and cost no
    transcendental function: every IMU increment takes this branch. `series` (a constant
    of the caller): the series whatever the angle, no branch (a vectorised kernel checks
    the angles itself and redoes a step that had a larger one)."""
    t2 = rx * rx + ry * ry + rz * rz
    if series or t2 < 2.5e-3:
        c = 1.0 - t2 * (1.0 / 8.0 - t2 * (1.0 / 384.0 - t2 * (1.0 / 46080.0
                                                            - t2 / 10321920.0)))
        s = 0.5 - t2 * (1.0 / 48.0 - t2 * (1.0 / 3840.0 - t2 * (1.0 / 645120.0
                                                             - t2 / 185794560.0)))
    else:
        t = math.sqrt(t2)
        c = math.cos(0.5 * t)
        s = math.sin(0.5 * t) / t
    return c, s * rx, s * ry, s * rz


@njit(cache=True, inline="always")
def qmul(aw: float, ax: float, ay: float, az: float, bw: float, bx: float, by: float,
         bz: float) -> tuple[float, float, float, float]:
    """Hamilton product a ⊗ b."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def qrot(qw: float, qx: float, qy: float, qz: float, vx: float, vy: float,
         vz: float) -> tuple[float, float, float]:
    """Rotate v by unit quaternion q: q ⊗ v ⊗ q* (as C(q) @ v)."""
    # t = 2 q_v × v;  v' = v + w t + q_v × t
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + qy * tz - qz * ty,
        vy + qw * ty + qz * tx - qx * tz,
        vz + qw * tz + qx * ty - qy * tx,
    )


@njit(cache=True, inline="always")
def rotate_small(rx: float, ry: float, rz: float, vx: float, vy: float,
                 vz: float) -> tuple[float, float, float]:
    """R(r) v for a small rotation vector r (Rodrigues, series to 4th order: |r| < 0.05)."""
    t2 = rx * rx + ry * ry + rz * rz
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0  # sin t / t
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0  # (1 - cos t) / t²
    cx = ry * vz - rz * vy
    cy = rz * vx - rx * vz
    cz = rx * vy - ry * vx
    return (
        vx + a * cx + b * (ry * cz - rz * cy),
        vy + a * cy + b * (rz * cx - rx * cz),
        vz + a * cz + b * (rx * cy - ry * cx),
    )


@njit(cache=True, inline="always")
def transport_rate(ve: float, vn: float, r_m: float, r_n: float, h: float, sl: float,
                   cl: float) -> tuple[float, float, float]:
    """ω_en^n = [-v_N/(R_M+h), v_E/(R_N+h), v_E tan L/(R_N+h)]."""
    return -vn / (r_m + h), ve / (r_n + h), ve * sl / (cl * (r_n + h))


@njit(cache=True, inline="always")
def specific_force_increment(q0: float, q1: float, q2: float, q3: float, bx: float, by: float,
                             bz: float, dx: float, dy: float, dz: float, wx: float, wy: float,
                             wz: float) -> tuple[float, float, float]:
    """Specific-force increment resolved at mid-interval: ``R(-ω_in T/2) C_nb R(Δθ/2) Δv``.

    (bx, by, bz) = Δθ, (dx, dy, dz) = Δv (body), (wx, wy, wz) = ω_in^n T.
    """
    ux, uy, uz = rotate_small(0.5 * bx, 0.5 * by, 0.5 * bz, dx, dy, dz)
    fx, fy, fz = qrot(q0, q1, q2, q3, ux, uy, uz)
    return rotate_small(-0.5 * wx, -0.5 * wy, -0.5 * wz, fx, fy, fz)


@njit(cache=True, inline="always")
def attitude_update(q0: float, q1: float, q2: float, q3: float, bx: float, by: float, bz: float,
                    wx: float, wy: float, wz: float,
                    series: bool = False) -> tuple[float, float, float, float]:
    """``q ← q(−ω_in T) ⊗ q ⊗ q(Δθ)``, renormalised: body rotation on the right,
    navigation-frame rotation (wx, wy, wz) = ω_in^n T on the left (`series`: see
    :func:`rv2q`)."""
    aw, ax, ay, az = rv2q(bx, by, bz, series)
    nw, nx, ny, nz = rv2q(-wx, -wy, -wz, series)
    p0, p1, p2, p3 = qmul(q0, q1, q2, q3, aw, ax, ay, az)
    p0, p1, p2, p3 = qmul(nw, nx, ny, nz, p0, p1, p2, p3)
    # renormalise: |q|² differs from 1 by round-off only, where one Newton step of 1/√x,
    # (3 − |q|²)/2, is exact (its error is the square of that round-off)
    nq = 1.5 - 0.5 * (p0 * p0 + p1 * p1 + p2 * p2 + p3 * p3)
    return p0 * nq, p1 * nq, p2 * nq, p3 * nq


@njit(cache=True, inline="always")
def radii_at(E: EarthParams, sl: float) -> tuple[float, float]:
    """R_M, R_N of earth model `E` where sin L = sl."""
    s2 = sl * sl
    if E[0] == 0.0:
        e2 = E[2]
        w = 1.0 - e2 * s2
        r_n = E[1] / math.sqrt(w)
        return r_n * (1.0 - e2) / w, r_n
    f = E[2]
    return E[1] * (1.0 - 2.0 * f + 3.0 * f * s2), E[1] * (1.0 + f * s2)


@njit(cache=True, inline="always")
def position_update(E: EarthParams, lat: float, lon: float, h: float, ue: float, un: float,
                    uu: float, ts: float, r_m: float, sl: float,
                    cl: float) -> tuple[float, float, float]:
    """Position after `ts` at mean ENU velocity (ue, un, uu) (trapezoid rule); radii at the
    mid-interval latitude and height. r_m, sl, cl: R_M and sin, cos of the start latitude;
    the mid latitude's sine and cosine follow to second order in the half step d
    (d < 1e-5 rad: the dropped d³ terms are below 1e-16)."""
    h_mid = h + 0.5 * uu * ts
    d = 0.5 * un * ts / (r_m + h_mid)
    half_d2 = 0.5 * d * d
    s_mid = sl + cl * d - sl * half_d2
    c_mid = cl - sl * d - cl * half_d2
    r_m, r_n = radii_at(E, s_mid)
    return lat + un * ts / (r_m + h_mid), lon + ue * ts / ((r_n + h_mid) * c_mid), h + uu * ts


#: The navigation state as the block kernels carry it from step to step, in local variables
#: (registers): the 11 floats of the state vector, in its order.
NavTuple = tuple[float, float, float, float, float, float, float, float, float, float, float]


@njit(cache=True, inline="always")
def strapdown_step(x: NavTuple, dtheta: np.ndarray, dv: np.ndarray, k: int, ts: float,
                   earth_sign: float, E: np.ndarray, vertical: np.ndarray,
                   h_ref: float) -> NavTuple:
    """One strapdown update of the state `x` (the state vector's floats, in its order) by
    increment `k` of `dtheta`, `dv`; returns the new state (see the module docstring).

    Velocity:  v_k = v_{k-1} + R(-ω_in T/2) C_nb(k-1) R(Δθ/2) Δv + (g_n - (2ω_ie + ω_en) × v_mid) T
               (the specific-force increment resolved at mid-interval; Coriolis at a
               predicted mid-interval velocity, gravity at the height it gives)
    Attitude:  q_k = q(-ω_in T) ⊗ q_{k-1} ⊗ q(Δθ_k),  ω_in = ω_ie + ω_en(v_mid)
    Position:  trapezoid in velocity, radii at the mid-interval latitude.
    Vertical:  HOLD: h = h_ref, v_U = 0; DAMPED: v_U −= (k2 δh + a) T, h −= k1 δh T,
               a += k3 δh T with δh = h − h_ref at the start of the step.
    """
    q0, q1, q2, q3, ve, vn, vu, lat, lon, h, da = x
    bx, by, bz = dtheta[k, 0], dtheta[k, 1], dtheta[k, 2]
    r_m, r_n, g, sl, cl = earth_at(E, lat, h)
    wie = earth_sign * E[3]
    wie_n, wie_u = wie * cl, wie * sl
    mode = vertical[0]

    inv_m, inv_n = 1.0 / (r_m + h), 1.0 / (r_n + h)  # the transport rate, twice below
    tan_l = sl / cl
    tx, ty, tz = -vn * inv_m, ve * inv_n, ve * tan_l * inv_n
    fx, fy, fz = specific_force_increment(
        q0, q1, q2, q3, bx, by, bz, dv[k, 0], dv[k, 1], dv[k, 2],
        tx * ts, (wie_n + ty) * ts, (wie_u + tz) * ts,
    )

    # Predict the mid-interval velocity, then Coriolis/transport and gravity there.
    me = ve + 0.5 * fx
    mn = vn + 0.5 * fy
    mu = 0.0 if mode == HOLD else vu + 0.5 * (fz - g * ts)
    tx, ty, tz = -mn * inv_m, me * inv_n, me * tan_l * inv_n
    cx, cy, cz = tx, 2.0 * wie_n + ty, 2.0 * wie_u + tz
    ve1 = ve + fx - (cy * mu - cz * mn) * ts
    vn1 = vn + fy - (cz * me - cx * mu) * ts
    # gravity at the mid-interval height (g is linear in h): at the start height a climb
    # at v_U would leave a bias of ½ g3 v_U T in the vertical velocity
    vu1 = vu + fz - ((cx * mn - cy * me) + g - E[7] * 0.5 * mu * ts) * ts

    q0, q1, q2, q3 = attitude_update(
        q0, q1, q2, q3, bx, by, bz, tx * ts, (wie_n + ty) * ts, (wie_u + tz) * ts,
    )

    dh = h - h_ref
    if mode == HOLD:
        vu, vu1 = 0.0, 0.0
    elif mode == DAMPED:
        vu1 -= (vertical[2] * dh + da) * ts
        da += vertical[3] * dh * ts
    lat1, lon1, h1 = position_update(
        E, lat, lon, h, 0.5 * (ve + ve1), 0.5 * (vn + vn1), 0.5 * (vu + vu1), ts, r_m, sl, cl
    )
    if mode == HOLD:
        h1 = h_ref
    elif mode == DAMPED:
        h1 -= vertical[1] * dh * ts
    return q0, q1, q2, q3, ve1, vn1, vu1, lat1, lon1, h1, da


@njit(cache=True)
def strapdown_block(s: np.ndarray, dtheta: np.ndarray, dv: np.ndarray, ts: float,
                    earth_sign: float, E: np.ndarray, vertical: np.ndarray, h_ref: np.ndarray,
                    stride: int, out: np.ndarray) -> None:
    """Integrate N increments from the state `s` (updated in place); after every `stride`
    steps write the state into the next row of `out` ((N // stride, NAV_STATE)).

    h_ref : (N,) reference height at the start of each step, or (1,) for a constant one.
    The state lives in local variables from the first step to the last (read from `s` once,
    written back once); the steps run in groups of `stride`, each followed by its row.
    """
    n = dtheta.shape[0]
    last = h_ref.shape[0] - 1
    x = (s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8], s[9], s[10])
    k = 0
    for row in range(n // stride):
        for _ in range(stride):
            x = strapdown_step(x, dtheta, dv, k, ts, earth_sign, E, vertical,
                               h_ref[k if k < last else last])
            k += 1
        (out[row, 0], out[row, 1], out[row, 2], out[row, 3], out[row, 4], out[row, 5],
         out[row, 6], out[row, 7], out[row, 8], out[row, 9], out[row, 10]) = x
    for _ in range(n - k):  # the steps after the last full group
        x = strapdown_step(x, dtheta, dv, k, ts, earth_sign, E, vertical,
                           h_ref[k if k < last else last])
        k += 1
    s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8], s[9], s[10] = x


@njit(cache=True, inline="always")
def coned_rotation(dtheta: np.ndarray, i0: int, n: int) -> tuple[float, float, float]:
    """Coning-corrected rotation vector of increments i0 … i0+n−1:
    ``φ = Σθ_i + (Σ_{i<n} c_i θ_i) × θ_n`` (:data:`CONE`)."""
    sx = sy = sz = 0.0
    cxs = cys = czs = 0.0
    for i in range(n):
        sx += dtheta[i0 + i, 0]
        sy += dtheta[i0 + i, 1]
        sz += dtheta[i0 + i, 2]
        if i < n - 1:
            c = CONE[n, i]
            cxs += c * dtheta[i0 + i, 0]
            cys += c * dtheta[i0 + i, 1]
            czs += c * dtheta[i0 + i, 2]
    lx, ly, lz = dtheta[i0 + n - 1, 0], dtheta[i0 + n - 1, 1], dtheta[i0 + n - 1, 2]
    return sx + cys * lz - czs * ly, sy + czs * lx - cxs * lz, sz + cxs * ly - cys * lx


@njit(cache=True)
def attitude_block(q: np.ndarray, dtheta: np.ndarray, ts: float, w_in: np.ndarray,
                   subsamples: int, stride: int, out: np.ndarray) -> None:
    """Attitude-only strapdown over N increments in groups of `subsamples` (N a multiple):
    each group is one update over ``subsamples·ts`` with the coning-corrected rotation
    vector ``φ = Σθ_i + (Σ_{i<n} c_i θ_i) × θ_n`` (:data:`CONE`), and
    ``q ← q(−ω_in T) ⊗ q ⊗ q(φ)`` with the constant navigation-frame rate `w_in` (3,) (rad/s;
    zeros integrates the gyros alone). `q` (4,) is updated in place; after every `stride`
    updates it is written into the next row of `out` ((N // subsamples // stride, 4)).
    """
    n = subsamples
    T = n * ts
    wx, wy, wz = w_in[0] * T, w_in[1] * T, w_in[2] * T
    updates = dtheta.shape[0] // n
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    k = 0
    for row in range(updates // stride):
        for _ in range(stride):
            px, py, pz = coned_rotation(dtheta, k * n, n)
            q0, q1, q2, q3 = attitude_update(q0, q1, q2, q3, px, py, pz, wx, wy, wz)
            k += 1
        out[row, 0], out[row, 1], out[row, 2], out[row, 3] = q0, q1, q2, q3
    for _ in range(updates - k):
        px, py, pz = coned_rotation(dtheta, k * n, n)
        q0, q1, q2, q3 = attitude_update(q0, q1, q2, q3, px, py, pz, wx, wy, wz)
        k += 1
    q[0], q[1], q[2], q[3] = q0, q1, q2, q3


@njit(cache=True, inline="always")
def euler_of(q0: float, q1: float, q2: float, q3: float) -> tuple[float, float, float]:
    """[pitch, roll, yaw] of q_nb (C_nb = Rz(yaw) Rx(pitch) Ry(roll)), as rotation.quat_to_euler."""
    c21 = 2.0 * (q2 * q3 + q0 * q1)
    c20 = 2.0 * (q1 * q3 - q0 * q2)
    c22 = q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3
    c01 = 2.0 * (q1 * q2 - q0 * q3)
    c11 = q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3
    return math.asin(min(max(c21, -1.0), 1.0)), math.atan2(-c20, c22), math.atan2(-c01, c11)


@njit(cache=True, inline="always")
def wrapped(d: float) -> float:
    """A difference of two angles in [−π, π] wrapped to [−π, π), as rotation.wrap_pi (one
    turn at most, so a branch does it: a floating-point modulo costs ~15 ns more)."""
    if d >= math.pi:
        return d - 2.0 * math.pi
    if d < -math.pi:
        return d + 2.0 * math.pi
    return d


@njit(cache=True, inline="always")
def wrap_pi(d: float) -> float:
    """`d` wrapped to [−π, π) by the formula of rotation.wrap_pi, ``(d + π) mod 2π − π``,
    to the bit (the sum with π rounds: unlike :func:`wrapped`, which leaves d in
    [−π, π) untouched). Where d + π is already in [0, 2π) the modulo returns it as it is,
    so a comparison stands for it there (a floating-point modulo costs ~15 ns)."""
    x = d + math.pi
    if 0.0 <= x < 2.0 * math.pi:
        return x - math.pi
    return x % (2.0 * math.pi) - math.pi


@njit(cache=True)
def error_block(states: np.ndarray, q_bs: np.ndarray, has_qbs: bool, att_t: np.ndarray,
                q_t: np.ndarray, v_t: np.ndarray, pos_t: np.ndarray, has_truth: bool,
                E: np.ndarray, pos0: np.ndarray, k_first: int, stride: int, acc: np.ndarray,
                out: np.ndarray) -> int:
    """Errors of a block of navigation states against the truth at every sample, folded
    into `acc`, and every `stride`-th sample written as a row of `out`.

    states (n, NAV_STATE) (q is q_ns when `has_qbs`: the body attitude is q_ns ⊗ q_bs*);
    att_t, q_t (quaternion), v_t, pos_t (n or 1, 3 or 4) truth; pos0 (3,) start position;
    k_first: samples from the start to the first state of the block minus one;
    acc (9, 3): rows |att err| max, |v err| max, |pos err| max, [horizontal error max,
    horizontal displacement max, 0], |φ| max, then the last sample's att, v, pos and φ
    errors; out (≥ rows, 21): att, v, pos, att err, v err, pos err, φ.
    Attitude errors: Euler differences est − true with roll and yaw wrapped to ±π (the
    seeds' convention; ill-defined near pitch ±90°) and the misalignment φ (ENU) from
    C_est C_trueᵀ = exp(−[φ×]), which always is defined.
    Returns the number of rows written.
    """
    n = states.shape[0]
    nt = att_t.shape[0]
    r_m0, r_n0, _, _, cl0 = earth_at(E, pos0[0], pos0[2])
    rows = 0
    e = np.zeros(12)
    r_mt, r_nt, _, _, clt = earth_at(E, pos_t[0, 0], pos_t[0, 2])  # a fixed truth: once
    for i in range(n):
        q0, q1, q2, q3 = states[i, 0], states[i, 1], states[i, 2], states[i, 3]
        if has_qbs:
            q0, q1, q2, q3 = qmul(q0, q1, q2, q3, q_bs[i, 0], -q_bs[i, 1], -q_bs[i, 2],
                                  -q_bs[i, 3])
        p, r, y = euler_of(q0, q1, q2, q3)
        lat, lon, h = states[i, 7], states[i, 8], states[i, 9]
        de = (lon - pos0[1]) * (r_n0 + pos0[2]) * cl0
        dn = (lat - pos0[0]) * (r_m0 + pos0[2])
        acc[3, 1] = max(acc[3, 1], math.sqrt(de * de + dn * dn))
        j = i if i < nt else nt - 1
        if has_truth:
            e[0] = p - att_t[j, 0]
            e[1] = wrapped(r - att_t[j, 1])
            e[2] = wrapped(y - att_t[j, 2])
            for c in range(3):
                e[3 + c] = states[i, 4 + c] - v_t[j, c]
            if nt > 1:
                r_mt, r_nt, _, _, clt = earth_at(E, pos_t[j, 0], pos_t[j, 2])
            e[6] = (lon - pos_t[j, 1]) * (r_nt + pos_t[j, 2]) * clt
            e[7] = (lat - pos_t[j, 0]) * (r_mt + pos_t[j, 2])
            e[8] = h - pos_t[j, 2]
            # φ = −rotvec(q_est ⊗ q_true*)
            dw, dx, dy, dz = qmul(q0, q1, q2, q3, q_t[j, 0], -q_t[j, 1], -q_t[j, 2], -q_t[j, 3])
            if dw < 0.0:
                dw, dx, dy, dz = -dw, -dx, -dy, -dz
            nrm = math.sqrt(dx * dx + dy * dy + dz * dz)
            k = -2.0 * math.atan2(nrm, dw) / nrm if nrm > 1e-12 else -2.0 / dw
            e[9], e[10], e[11] = k * dx, k * dy, k * dz
            for c in range(9):
                a = abs(e[c])
                if a > acc[c // 3, c % 3]:
                    acc[c // 3, c % 3] = a
            for c in range(3):
                acc[4, c] = max(acc[4, c], abs(e[9 + c]))
            acc[3, 0] = max(acc[3, 0], math.sqrt(e[6] * e[6] + e[7] * e[7]))
            if i == n - 1:
                for c in range(12):
                    acc[5 + c // 3, c % 3] = e[c]
        if (k_first + i + 1) % stride == 0:
            out[rows, 0], out[rows, 1], out[rows, 2] = p, r, y
            for c in range(3):
                out[rows, 3 + c] = states[i, 4 + c]
                out[rows, 6 + c] = states[i, 7 + c]
            for c in range(12):
                out[rows, 9 + c] = e[c]
            rows += 1
    return rows
