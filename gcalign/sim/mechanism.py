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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.nav.rotation import quat_conj, quat_mult
from gcalign.sim.schedule import Schedule

REFERENCES = ("body", "navigation")


@dataclass(frozen=True)
class Mechanism:
    """A schedule turning the sensor frame, referenced to the body or the navigation frame."""

    schedule: Schedule
    reference: str = "body"

    def __post_init__(self):
        if self.reference not in REFERENCES:
            raise ValueError(f"mechanism reference: got {self.reference!r}, allowed: "
                             f"{', '.join(REFERENCES)}")

    def q_ns(self, t, q_nb) -> np.ndarray:
        """Sensor attitude quaternion q_ns (N, 4) at times t for body attitudes q_nb (N, 4)."""
        S = self.schedule.quat(t)
        return quat_mult(q_nb, S) if self.reference == "body" else S

    def q_bs(self, t, q_nb) -> np.ndarray:
        """Mechanism angles as the quaternion q_bs (C_s^b), (N, 4)."""
        S = self.schedule.quat(t)
        return S if self.reference == "body" else quat_mult(quat_conj(q_nb), S)


def body_attitude(q_ns, q_bs) -> np.ndarray:
    """q_nb = q_ns ⊗ q_bs*: the body attitude from the sensor attitude and the mechanism
    angles (C_b^n = C_s^n (C_s^b)ᵀ), (N, 4)."""
    return quat_mult(q_ns, quat_conj(q_bs))
