"""A bound from physics on an aided solution of the simulated vehicle: how far its INS can
drift in a GNSS outage, whatever filter fed it.

Into the outage the solution carries errors, all known here against the truth: position
δp0, velocity δv0, attitude (tilt φ_h0, heading φ_v0), and what its sensor estimates leave
of the sensors' true errors (δb_g, δb_a, δs_g, δs_a: estimate minus truth, per body
axis; constant over a minute, as the 4 h Gauss–Markov processes are). Along the truth's own
motion in the outage these act as rate and specific-force errors in NED,
δω^n = C_b^n (δb_g + δs_g ∘ ω_ib^b) and δf^n = C_b^n (δb_a + δs_a ∘ f^b), and the
free-inertial error equations (Schuler and Coriolis feedback left out: their factor over t
is (ω_s t)²/2, 0.3 % at 60 s; a margin of 5 % covers them and the instability of the
height, cosh(t/√(R/2g)) − 1 = 0.6 %) bound the errors by::

    φ_h(t) ≤ φ_h0 + ∫ |δω^n_h| dτ + k ARW √t,    φ_v(t) ≤ φ_v0 + ∫ |δω^n_v| dτ + k ARW √t
    |δa_h| ≤ φ_h |f_v| + φ_v |f_h| + |δf^n_h|,    |δa_v| ≤ φ_h |f_h| + |δf^n_v|
    |δv(t)| ≤ |δv0| + ∫ |δa| dτ + k VRW √t,        |δp(t)| ≤ |δp0| + ∫ |δv| dτ

(|φ × f| split by parts: the tilt turns gravity into horizontal acceleration, the heading
turns the vehicle's own acceleration), with the white noise at k σ.
"""

from __future__ import annotations

import numpy as np

from benchmarks.vehicle.dataset import Dataset

#: the neglected feedback terms over a minute (module docstring)
MARGIN = 1.05


def outage_bound(ds: Dataset, t0: float, t1: float, dp0, dv0, phi0, sensor_residual,
                 k: float = 3.0, step: float = 0.01
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(t, horizontal, vertical)``: times (s from the route's start) and the bounds (m)
    on the horizontal and vertical position errors from `t0` to `t1`, for the errors at
    `t0`: δp0 (NED m), δv0 (NED m/s), φ0 (NED rad: north, east tilt, down heading), and
    `sensor_residual` (4, 3): estimate minus truth of the gyro biases (rad/s),
    accelerometer biases (m/s²), gyro and accelerometer scale factors, body FRD."""
    e = ds.config.errors.si()
    n = max(1, int(np.ceil((t1 - t0) / step)))
    t = np.linspace(t0, t1, n + 1)
    st = ds.trajectory.state(t)
    r = np.asarray(sensor_residual, float)
    d_w = np.einsum("kij,kj->ki", st.C_nb, r[0] + r[2] * st.omega_ib_b)
    d_f = np.einsum("kij,kj->ki", st.C_nb, r[1] + r[3] * st.f_b)
    f_n = np.einsum("kij,kj->ki", st.C_nb, st.f_b)
    f_h, f_v = np.hypot(f_n[:, 0], f_n[:, 1]), np.abs(f_n[:, 2])
    tau = t - t0

    def integral(y: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])

    arw = k * e["arw"] * np.sqrt(tau)
    phi_h = np.hypot(phi0[0], phi0[1]) + integral(np.hypot(d_w[:, 0], d_w[:, 1])) + arw
    phi_v = abs(phi0[2]) + integral(np.abs(d_w[:, 2])) + arw
    a_h = phi_h * f_v + phi_v * f_h + np.hypot(d_f[:, 0], d_f[:, 1])
    a_v = phi_h * f_h + np.abs(d_f[:, 2])
    vrw = k * e["vrw"] * np.sqrt(tau)
    v_h = np.hypot(dv0[0], dv0[1]) + integral(a_h) + vrw
    v_v = abs(dv0[2]) + integral(a_v) + vrw
    return (t, MARGIN * (np.hypot(dp0[0], dp0[1]) + integral(v_h)),
            MARGIN * (abs(dp0[2]) + integral(v_v)))
