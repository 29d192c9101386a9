"""IMU data blocks, and whole-run simulation built on the block generator.

Increments follow PSINS: sample k holds the gyro angle increment Δθ_k (rad) and the
velocity increment Δv_k (m/s) over (t_k - T, t_k], both in the sensor frame (the body
frame unless a mechanism turns the IMU).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from gcalign.nav.earth import WGS84, EarthModel
from gcalign.sim.errors import ErrorStream, ImuErrors, SensorErrors
from gcalign.sim.mechanism import Mechanism
from gcalign.sim.motions import MotionType, Truth

__all__ = ["ImuData", "ImuErrors", "SensorErrors", "apply_errors", "ideal_imu"]


@dataclass(frozen=True)
class ImuData:
    """A block of IMU increments.

    Attributes
    ----------
    t : (N,) float, s. End time of each increment.
    dtheta : (N, 3) float, rad. Gyro angle increments in the sensor frame.
    dv : (N, 3) float, m/s. Velocity increments (integrated specific force), sensor frame.
    ts : float, s. Sample interval.
    site : (3,) float or None. ``[lat (rad), lon (rad), height (m)]`` if the source gives it.
    att0 : (3,) float or None. Initial ``[pitch, roll, yaw]`` (rad) if the source gives it.
    v0_n : (3,) float or None. Initial ENU velocity (m/s) if the source gives it.
    source : str. Where the data came from (file path or "simulated").
    q_bs : (N, 4) float or None. Mechanism angles (C_s^b) at t, if the IMU turns.
    """

    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    ts: float
    site: np.ndarray | None = None
    att0: np.ndarray | None = None
    v0_n: np.ndarray | None = None
    source: str = "simulated"
    meta: dict[str, Any] = field(default_factory=dict)
    q_bs: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.t)


def apply_errors(ideal: ImuData, errors: ImuErrors, rng: np.random.Generator) -> ImuData:
    """Measured increments from ideal ones: scale/misalignment, bias, white noise, quantum.

    Gyro noise is drawn before accelerometer noise, so a seed fixes both.
    """
    stream = ErrorStream(errors, ideal.ts, rng, len(ideal))
    dtheta, dv = stream.apply(ideal.dtheta, ideal.dv)
    return replace(ideal, dtheta=dtheta, dv=dv)


def ideal_imu(motion: MotionType, site: ArrayLike, ts: float, substeps: int = 2,
              earth: EarthModel = WGS84,
              mechanism: Mechanism | None = None) -> tuple[Truth, ImuData]:
    """Truth and exact ideal increments of a whole run (see :mod:`gcalign.sim.ideal`).

    Returns ``(Truth, ImuData)``; truth has N+1 samples from t = 0, the IMU N increments.
    For long runs iterate :func:`gcalign.sim.ideal.ideal_blocks` instead.
    """
    from gcalign.sim.ideal import ideal_blocks, initial_truth

    first = initial_truth(motion, site, earth)
    assert first.segment is not None  # the start of a run is in its first segment
    blocks = list(ideal_blocks(motion, site, ts, earth, mechanism, substeps=substeps))

    def cat(name: str, head: np.ndarray) -> np.ndarray:
        return np.concatenate([head] + [getattr(b, name) for b in blocks])

    truth = Truth(t=cat("t", first.t), att=cat("att", first.att), v_n=cat("v_n", first.v_n),
                  pos=cat("pos", first.pos), segment=cat("segment", first.segment))
    q_bs = None if mechanism is None else np.concatenate([b.q_bs for b in blocks])
    imu = ImuData(t=truth.t[1:], dtheta=cat("dtheta", np.empty((0, 3))),
                  dv=cat("dv", np.empty((0, 3))), ts=ts, site=np.asarray(site, float),
                  q_bs=q_bs)
    return truth, imu
