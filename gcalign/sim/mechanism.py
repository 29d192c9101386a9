"""The sensor frame s: an IMU turned by a mechanism inside the body (seed 004).

A :class:`Mechanism` is a rotation :class:`~gcalign.sim.schedule.Schedule` and the frame it
is referenced to:

* ``body`` -- single- and dual-axis mechanisms fixed to the carrier: the schedule gives
  ``C_s^b(t) = S(t)`` (its start orientation is the sensor's mounting);
* ``navigation`` -- a three-axis mechanism that isolates the carrier's angular motion
  (the seed's): the schedule gives ``C_s^n(t) = S(t)`` (start orientation: the body's
  initial attitude unless the schedule's own ``q0`` says otherwise), and the mechanism
  angles are ``C_s^b = C_n^b C_s^n``.

Ideal increments and sensor errors are in the sensor frame; navigation integrates the
sensor frame and reports the body attitude through the known mechanism angles,
``C_b^n = C_s^n (C_s^b)ᵀ`` (:func:`body_attitude`); the simulation records the angles at
every sample (what the encoders of a real mechanism read).

Lever arm (spec 004 §6): accelerometers at ``lever`` (m, sensor frame) from the rotation
centre sense, besides the specific force at the centre, ``ω̇ × r + ω × (ω × r)`` from the
mechanism's own rate ω (relative to its reference frame, sensor axes): at 22.5 °/s and
5 cm the centripetal part is ≈ 790 µg. The carrier's and the earth's rotation are left
out of this term (Ω²·r < 3e-10 m/s² at 5 cm); :meth:`Mechanism.lever_dv` gives its
velocity increments, which the ideal increments include.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.nav.rotation import quat_conj, quat_mult
from gcalign.sim.schedule import Schedule

REFERENCES = ("body", "navigation")


@dataclass(frozen=True)
class Mechanism:
    """A schedule turning the sensor frame, referenced to the body or the navigation frame."""

    schedule: Schedule
    reference: str = "body"
    lever: tuple[float, float, float] | None = None  # m, sensor frame (module docstring)

    def __post_init__(self) -> None:
        if self.reference not in REFERENCES:
            raise ValueError(f"mechanism reference: got {self.reference!r}, allowed: "
                             f"{', '.join(REFERENCES)}")

    def q_ns(self, t: ArrayLike, q_nb: ArrayLike) -> NDArray[np.float64]:
        """Sensor attitude quaternion q_ns (N, 4) at times t for body attitudes q_nb (N, 4)."""
        S = self.schedule.quat(t)
        return quat_mult(q_nb, S) if self.reference == "body" else S

    def q_bs(self, t: ArrayLike, q_nb: ArrayLike) -> NDArray[np.float64]:
        """Mechanism angles as the quaternion q_bs (C_s^b), (N, 4)."""
        S = self.schedule.quat(t)
        return S if self.reference == "body" else quat_mult(quat_conj(q_nb), S)


    def lever_dv(self, k0: int, n: int, ts: float) -> NDArray[np.float64]:
        """Velocity increments (n, 3) of the lever-arm term over samples k0 .. k0+n-1 (m/s,
        sensor frame): ``∫ ω̇ dt × r = (ω(b) − ω(a)) × r`` exactly (a rate that jumps at a
        sample time is given to the sample that ends there, so the sum telescopes), and
        ``∫ ω × (ω × r) dt`` by 3-point Gauss–Legendre per sample (exact for the
        polynomial profiles when their corners fall on sample times). Samples within one
        rest piece are zero without evaluation."""
        out = np.zeros((n, 3))
        if self.lever is None:
            return out
        r = np.asarray(self.lever, dtype=float)
        a = (k0 + np.arange(n)) * ts
        idx = np.flatnonzero(~self._at_rest(a, a + ts))
        if idx.size == 0:
            return out
        s = self.schedule
        x, w = np.polynomial.legendre.leggauss(3)
        nodes = (a[idx, None] + 0.5 * ts * (1.0 + x)).ravel()
        om = s.rate(nodes).reshape(len(idx), 3, 3)
        centripetal = np.cross(om, np.cross(om, r))
        out[idx] = (np.cross(s.rate(a[idx] + ts) - s.rate(a[idx]), r)
                    + 0.5 * ts * np.einsum("j,mjc->mc", w, centripetal))
        return out

    def _at_rest(self, a: np.ndarray, b: np.ndarray) -> NDArray[np.bool_]:
        """Whether [a, b] lies inside one rest piece of the schedule (no rate)."""
        tb = self.schedule.tables()
        T = float(tb["period"])
        rest = (tb["kind"] == 0) & np.all(tb["coef"] == 0.0, axis=1)
        eps = 1e-9 * max(T, 1.0)
        if not self.schedule.repeat:
            past = a >= T - eps
            a, b = np.minimum(a, T), np.minimum(b, T)
        else:
            past = np.zeros(a.shape, dtype=bool)
        ka, kb = np.floor(a / T), np.floor((b - eps) / T)
        ja = np.searchsorted(tb["t0"], a - ka * T, side="right") - 1
        jb = np.searchsorted(tb["t0"], b - eps - kb * T, side="right") - 1
        return past | ((ka == kb) & (ja == jb) & rest[ja])


def body_attitude(q_ns: ArrayLike, q_bs: ArrayLike) -> NDArray[np.float64]:
    """q_nb = q_ns ⊗ q_bs*: the body attitude from the sensor attitude and the mechanism
    angles (C_b^n = C_s^n (C_s^b)ᵀ), (N, 4)."""
    return quat_mult(q_ns, quat_conj(q_bs))
