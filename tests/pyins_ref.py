"""pyins as an independent strapdown reference, driven in gcalign conventions.

A helper for tests and benchmarks (not part of the package): it feeds gcalign IMU
increments to the strapdown integrator of pyins (nmayorov/pyins, PyPI ``python-ins`` 1.0)
and returns the result in gcalign conventions, so our kernel can be cross-checked against
an implementation written by someone else.

pyins conventions (read from the installed source, ``pyins/__init__.py``,
``strapdown.py``, ``_numba_integrate.py``, ``earth.py``, ``transform.py``)
---------------------------------------------------------------------------------------
* Navigation frame n: North-East-Down. Body frame: forward-right-down (FRD, the aircraft
  convention of Groves); pyins itself only says "IMU axes", but its Euler angles and its
  simulator (``sim.generate_sine_velocity_motion``: heading = atan2(VE, VN), pitch up for
  climbing) fix x forward, y right, z down.
* ``mat_nb = transform.mat_from_rph([roll, pitch, heading])`` =
  ``Rotation.from_euler('xyz', rph, degrees=True)`` (extrinsic x-y-z) =
  ``Rz(heading) @ Ry(pitch) @ Rx(roll)``; heading clockwise from north, degrees.
  Position ``[lat (deg), lon (deg), alt (m)]``; velocity ``[VN, VE, VD]`` m/s.
* ``Integrator`` takes *increments*, not rates: a DataFrame with ``dt``, ``theta_x..z``
  (body rotation vector, rad) and ``dv_x..z`` (m/s), already corrected.
  ``strapdown.compute_increments_from_imu(imu, 'increment')`` makes them from raw
  increment-type sensors with a two-sample model (needs one "before" sample):
  coning ``θ_{k-1} × θ_k / 12``; sculling ``(θ_{k-1} × Δv_k + Δv_{k-1} × θ_k) / 12``;
  rotation ``½ θ_k × Δv_k``.
* The kernel (``_numba_integrate.integrate``, after Savage 1998), per step k-1 -> k, with
  Ω = earth rate, ρ = transport rate, χ = Ω + ρ (all NED, from the start-of-step state):
  ``v_k = v + C_nb(k-1) Δv - ((χ + Ω) × v - g_n + ½ χ × (C_nb Δv)) dt``, gravity magnitude
  evaluated at ``(lat_{k-1}, alt_{k-1} - ½ VD dt)``; position by the trapezoid rule;
  ``C_nb(k) = exp(-[χ' dt ×]) C_nb(k-1) exp([θ ×])`` with χ' from the mid-step velocity.
* Earth: WGS-84 a, e² (same as ``gcalign.nav.earth``), rate 7.292115e-5 rad/s (ours
  7.2921151467e-5, 1.5e-12 rad/s apart); gravity the closed Somigliana formula with a
  linear height term, ``g = GE (1 + k sin²L) / sqrt(1 - e² sin²L) (1 - 2h/a)``,
  GE = 9.7803253359. ``gcalign.nav.earth.gravity`` is the PSINS series
  ``9.7803267715 (1 + 5.27094e-3 sin²L + 2.32718e-5 sin⁴L) - 3.086e-6 h``; ours minus
  pyins is +0.15 µg at the equator, -2.4 µg at 34.25° (-3.0 µg at 380 m), -8.1 µg at
  the pole, and -17 µg at 10 km (the height terms differ: 3.086e-6 vs 2g/a = 3.07e-6 per
  m). Use :func:`pyins_gravity` when data must be consistent with pyins.

Frame transforms (derived here, proved in ``tests/test_pyins_ref.py``)
----------------------------------------------------------------------
One matrix serves both frames::

        P = [[0, 1, 0],      body:  [forward, right, down] = P [right, forward, up]
             [1, 0, 0],      nav:   [N, E, D]              = P [E, N, U]
             [0, 0, -1]]

P is symmetric, ``P @ P = I`` and ``det P = +1`` (a proper rotation: 180° about the
bisector of the first two axes), so axial vectors (Δθ, ω) transform like polar ones
(Δv, v) and cross products are preserved, ``P (a × b) = (P a) × (P b)``. Hence

* ``Δθ_p = P Δθ``, ``Δv_p = P Δv``, ``v_ned = P v_enu``;
* ``C_nb_p = P C_nb P`` (and back ``C_nb = P C_nb_p P``);
* Euler angles: conjugating by P maps a rotation about U by ψ to one about -D by ψ,
  about E (our x) to one about E (pyins y), about N-forward (our y) to pyins x, so
  ``P Rz(yaw) Rx(pitch) Ry(roll) P = Rz(-yaw) Ry(pitch) Rx(roll)``:
  ``roll_p = roll``, ``pitch_p = pitch``, ``heading = -yaw`` (degrees in pyins).
  A body pointing at yaw = 30° (CCW, i.e. 30° west of north) has heading 330° ≡ -30°.
* ``lla_p = [deg(lat), deg(lon), h]``.

Expected agreement (measured with pyins 1.0, ts = 0.01 s)
--------------------------------------------------------
* At rest with data built from pyins's own gravity and earth rate: 4.6e-10 m/s after
  100 s. Not round-off: pyins applies its ``½ χ × Δv_n`` term to the rotation-compensated
  Δv, leaving ``¼ |χ| ω_ie g ts³`` ≈ 6e-15 m/s per step.
* Data built with ``gcalign.nav.earth.gravity``: the vertical velocity drifts by
  ``(g_ours - g_pyins) t`` (-2.9e-3 m/s after 100 s at the lasergyro site) and the east
  velocity follows by Coriolis. Pass ``with_altitude=False`` to compare the horizontal
  channels without the gravity models; what then remains of the attitude difference is
  the earth-rate constant (1.5e-12 rad/s, 2.5e-8° after 300 s).

Timing: :func:`pyins_speed` times the whole adapter (pandas included) and pyins's bare
numba kernel on preallocated arrays; ``python tests/pyins_ref.py`` prints both.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np
import pandas as pd

try:
    import pyins
except ImportError:  # python-ins is a dev extra; skip (not error) when pytest collects us
    if "pytest" in sys.modules:
        import pytest

        pytest.skip("pyins (PyPI python-ins) is not installed", allow_module_level=True)
    raise
from pyins import earth as pearth
from pyins import strapdown, transform
from pyins._numba_integrate import integrate as _pyins_kernel
from pyins.util import ACCEL_COLS, DV_COLS, GYRO_COLS, THETA_COLS, TRAJECTORY_COLS

from gcalign.nav import earth
from gcalign.nav.rotation import dcm_to_euler, euler_to_dcm

#: Body RFU <-> FRD and navigation ENU <-> NED (symmetric, involutory, det +1).
P = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
#: Increment corrections applied before pyins's integrator (see :func:`pyins_integrate`).
COMPENSATIONS = ("none", "rotation", "pyins")
PYINS_VERSION = pyins.__version__
#: pyins's earth rate, rad/s (``pyins.earth.RATE``; ours is 7.2921151467e-5).
PYINS_RATE = pearth.RATE


def vec_to_pyins(v):
    """ENU -> NED or body RFU -> FRD for vectors, shape (..., 3) -> (..., 3)."""
    return np.asarray(v, dtype=float) @ P  # P symmetric: row vectors times P = P @ v


def vec_from_pyins(v):
    """NED -> ENU or body FRD -> RFU for vectors, shape (..., 3) -> (..., 3)."""
    return np.asarray(v, dtype=float) @ P


def dcm_to_pyins(C_nb):
    """gcalign C_nb (ENU <- RFU) -> pyins mat_nb (NED <- FRD), shape (..., 3, 3)."""
    return P @ np.asarray(C_nb, dtype=float) @ P


def dcm_from_pyins(mat_nb):
    """pyins mat_nb (NED <- FRD) -> gcalign C_nb (ENU <- RFU), shape (..., 3, 3)."""
    return P @ np.asarray(mat_nb, dtype=float) @ P


def att_to_pyins(att):
    """``[pitch, roll, yaw]`` (rad, ours) -> pyins ``[roll, pitch, heading]`` (deg).

    Goes through the matrix, so it is exact for every attitude; heading comes out in
    (-180°, 180°] (pyins accepts any range).
    """
    return transform.mat_to_rph(dcm_to_pyins(euler_to_dcm(att)))


def att_from_pyins(rph_deg):
    """pyins ``[roll, pitch, heading]`` (deg) -> ours ``[pitch, roll, yaw]`` (rad)."""
    return dcm_to_euler(dcm_from_pyins(transform.mat_from_rph(rph_deg)))


def lla_to_pyins(lla_rad_m):
    """``[lat (rad), lon (rad), h (m)]`` -> pyins ``[lat (deg), lon (deg), alt (m)]``."""
    lla = np.array(lla_rad_m, dtype=float)
    lla[..., :2] = np.degrees(lla[..., :2])
    return lla


def lla_from_pyins(lla_deg_m):
    """pyins ``[lat (deg), lon (deg), alt (m)]`` -> ``[lat (rad), lon (rad), h (m)]``."""
    lla = np.array(lla_deg_m, dtype=float)
    lla[..., :2] = np.radians(lla[..., :2])
    return lla


def pyins_gravity(lat, h=0.0):
    """pyins's gravity magnitude (m/s², down) at latitude `lat` (rad), height `h` (m).

    The formula the integrator uses (``_numba_integrate.gravity`` = ``earth.gravity``).
    """
    return pearth.gravity(np.degrees(lat), h)


def _corrected_increments(t, ts, dtheta_p, dv_p, compensation):
    """pyins Increments DataFrame (pyins frames) from raw increments and a compensation."""
    n = len(dtheta_p)
    if compensation == "pyins":
        # pyins's own two-sample coning/sculling; the "before" sample is a copy of the
        # first one (the convention of pyins.sim.generate_imu), so sample 1 gets only the
        # rotation term.
        raw = np.vstack([dtheta_p[:1], dtheta_p]), np.vstack([dv_p[:1], dv_p])
        imu = pd.DataFrame(
            np.hstack(raw), index=np.r_[t[0] - ts, t], columns=GYRO_COLS + ACCEL_COLS
        )
        inc = strapdown.compute_increments_from_imu(imu, "increment")
        inc["dt"] = ts  # exact step, not a difference of time stamps
        return inc
    if compensation == "rotation":
        # Single-sample rotation compensation ½ Δθ × Δv (PSINS with one sub-sample).
        dv_p = dv_p + 0.5 * np.cross(dtheta_p, dv_p)
    elif compensation != "none":
        raise ValueError(f"compensation must be one of {COMPENSATIONS}, got {compensation!r}")
    data = np.column_stack([np.full(n, float(ts)), dtheta_p, dv_p])
    return pd.DataFrame(data, index=t, columns=["dt"] + THETA_COLS + DV_COLS)


def pyins_integrate(
    t0, ts, dtheta, dv, lla0_rad_m, att0, v0_n, *, compensation="rotation", with_altitude=True
):
    """Integrate gcalign IMU increments with pyins's strapdown ``Integrator``.

    Parameters
    ----------
    t0 : float, s
        Time of the initial state (start of the first increment).
    ts : float, s
        Sample interval; increment k covers ``(t0 + (k-1) ts, t0 + k ts]``.
    dtheta : (N, 3) float, rad
        Gyro angle increments, body x right, y forward, z up.
    dv : (N, 3) float, m/s
        Velocity increments (integrated specific force), same body axes.
    lla0_rad_m : (3,) float
        Initial ``[lat (rad), lon (rad), h (m)]``.
    att0 : (3,) float, rad
        Initial ``[pitch, roll, yaw]`` (``C_nb = Rz(yaw) Rx(pitch) Ry(roll)``, yaw CCW).
    v0_n : (3,) float, m/s
        Initial ENU velocity.
    compensation : {"rotation", "none", "pyins"}
        Corrections applied to the increments before pyins's integrator:
        ``"rotation"`` (default) ``Δv + ½ Δθ × Δv``, no coning: right for gcalign's ideal
        data, whose Δθ are already exact rotation vectors, and the PSINS one-sub-sample
        algorithm; ``"none"`` feeds the increments as they are; ``"pyins"`` runs
        ``strapdown.compute_increments_from_imu(.., 'increment')`` (two-sample coning and
        sculling plus rotation), pyins as its author uses it on raw increment sensors.
    with_altitude : bool
        False freezes height and sets the vertical velocity to 0 (pyins option).

    Returns
    -------
    dict
        ``t`` (N+1,) s, from t0 (row 0 is the initial state); ``att`` (N+1, 3) rad
        ``[pitch, roll, yaw]``; ``C_nb`` (N+1, 3, 3) body RFU -> ENU; ``v_n`` (N+1, 3) m/s
        ENU; ``lla`` (N+1, 3) ``[lat (rad), lon (rad), h (m)]``.
    """
    dtheta = np.asarray(dtheta, dtype=float)
    dv = np.asarray(dv, dtype=float)
    if dtheta.ndim != 2 or dtheta.shape[1] != 3 or dv.shape != dtheta.shape:
        raise ValueError(
            f"dtheta and dv must have the same shape (N, 3), got {dtheta.shape} and {dv.shape}"
        )
    n = len(dtheta)
    t = t0 + ts * np.arange(1, n + 1)
    increments = _corrected_increments(t, ts, vec_to_pyins(dtheta), vec_to_pyins(dv), compensation)

    pva = pd.Series(
        np.r_[lla_to_pyins(lla0_rad_m), vec_to_pyins(v0_n), att_to_pyins(att0)],
        index=TRAJECTORY_COLS,
    )
    pva.name = float(t0)
    with warnings.catch_warnings():
        # pandas 3 deprecation notices from inside pyins 1.0 (``transpose(copy=True)``).
        warnings.simplefilter("ignore", DeprecationWarning)
        integrator = strapdown.Integrator(pva, with_altitude=with_altitude)
        traj = integrator.integrate(increments)
    mat_nb = integrator.mat_nb[: n + 1]
    C_nb = dcm_from_pyins(mat_nb)
    return {
        "t": np.r_[float(t0), t],
        "att": dcm_to_euler(C_nb),
        "C_nb": C_nb,
        "v_n": vec_from_pyins(traj[["VN", "VE", "VD"]].to_numpy()),
        "lla": lla_from_pyins(traj[["lat", "lon", "alt"]].to_numpy()),
    }


def stationary_increments(n, ts, lla_rad_m, att, gravity=earth.gravity, omega_ie=earth.OMEGA_IE):
    """Ideal increments of a body at rest: ``Δθ = C_bn ω_ie^n ts``, ``Δv = C_bn [0, 0, g] ts``.

    Exact for a stationary body (C_nb constant, so ω_ib^b and f_b are constant).
    `gravity(lat, h)` gives the magnitude and `omega_ie` the earth rate (rad/s): ours by
    default; :func:`pyins_gravity` and :data:`PYINS_RATE` make data pyins sees as exact.
    Returns ``(dtheta, dv)``, each (n, 3).
    """
    lat, _, h = lla_rad_m
    C_bn = euler_to_dcm(att).T
    w_b = C_bn @ (earth.omega_ie_n(lat) * (omega_ie / earth.OMEGA_IE))
    f_b = C_bn @ np.array([0.0, 0.0, float(gravity(lat, h))])
    return np.tile(w_b * ts, (n, 1)), np.tile(f_b * ts, (n, 1))


def pyins_speed(n=200_000, ts=0.01, repeat=3):
    """Time pyins on `n` stationary samples: whole adapter and bare numba kernel.

    Both are run once first (JIT compilation), then the best of `repeat` runs is kept.
    Returns a dict with ``n``, ``adapter_s``, ``kernel_s`` and the sample rates
    ``adapter_per_s``, ``kernel_per_s`` (samples per second).
    """
    lla = np.array([np.radians(34.0), np.radians(108.0), 380.0])
    att = np.radians([1.0, 2.0, 30.0])
    dtheta, dv = stationary_increments(n, ts, lla, att)

    def adapter():
        pyins_integrate(0.0, ts, dtheta, dv, lla, att, np.zeros(3))

    theta_p = np.ascontiguousarray(vec_to_pyins(dtheta))
    dv_p = np.ascontiguousarray(vec_to_pyins(dv + 0.5 * np.cross(dtheta, dv)))
    dt = np.full(n, ts)

    def kernel():
        lla_a = np.empty((n + 1, 3))
        vel = np.empty((n + 1, 3))
        mats = np.empty((n + 1, 3, 3))
        lla_a[0], vel[0], mats[0] = lla_to_pyins(lla), 0.0, dcm_to_pyins(euler_to_dcm(att))
        _pyins_kernel(dt, lla_a, vel, mats, theta_p, dv_p, 0, True)

    out = {"n": n}
    for name, fn in (("adapter", adapter), ("kernel", kernel)):
        fn()
        best = np.inf
        for _ in range(repeat):
            start = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - start)
        out[f"{name}_s"] = best
        out[f"{name}_per_s"] = n / best
    return out


if __name__ == "__main__":
    r = pyins_speed()
    print(
        f"pyins {PYINS_VERSION}, {r['n']} samples: adapter {r['adapter_s'] * 1e3:.1f} ms "
        f"({r['adapter_per_s'] / 1e6:.2f} M samples/s), numba kernel {r['kernel_s'] * 1e3:.1f} ms "
        f"({r['kernel_per_s'] / 1e6:.2f} M samples/s)"
    )
