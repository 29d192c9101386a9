"""Is a recording's base at rest? The check of the aiding that assumes it (spec 005, "Safety
on recordings"): alignment without aiding (a zero reference velocity) and calibration with
zero-velocity updates take the vehicle to be parked; on a vehicle that drives they give a
confident wrong answer (a yaw of 74° or 104.7° against −1.6°, exit 0).

The evidence, in this order: a reference solution of the recording (``reference``), whose
speed and displacement over the window are measured; else the IMU itself, through
:func:`gcalign.align.coarse.unexplained_velocity` (the velocity change no base at rest can
produce), against what a tilt of :data:`TILT_RAD` would give over the window, g·1e-3·T.
A vehicle at a constant speed on a straight road cannot be told from a parked one by its
accelerometers; its reference can.
"""

from __future__ import annotations

import numpy as np

from gcalign.align.coarse import unexplained_velocity
from gcalign.io.scenario import Scenario
from gcalign.nav.earth import EarthModel

#: A base moving faster than this (m/s) by its reference solution is not at rest.
MOVING_MPS = 0.5
#: The IMU's unexplained velocity change is compared with a tilt of this size over the
#: window (g·TILT_RAD·T): 1e-3 rad is 0.06°, the order the level loops reach.
TILT_RAD = 1e-3


def evidence(sc: Scenario, dtheta: np.ndarray, dv: np.ndarray, ts: float, site: np.ndarray,
             earth: EarthModel, t_a: float, t_b: float) -> str | None:
    """Why the base of data times [t_a, t_b] is not at rest (one clause with the measured
    numbers), or None when nothing says so."""
    T = t_b - t_a
    if sc.reference is not None:
        ref = sc.reference.read()
        inside = (ref.t >= t_a) & (ref.t <= t_b)
        if inside.sum() >= 2:
            from gcalign.nav.navigate import position_error_enu

            speed = np.linalg.norm(ref.v_n[inside], axis=1)
            pos = ref.pos[inside]
            moved = position_error_enu(pos, np.broadcast_to(pos[0], pos.shape), earth)
            far = float(np.hypot(moved[:, 0], moved[:, 1]).max())
            if speed.max() > MOVING_MPS:
                return (f"its reference ({sc.reference.path.name}) moves at {speed.min():.1f}"
                        f"-{speed.max():.1f} m/s and {far:.0f} m over the {T:.4g} s window")
            return None
    change = unexplained_velocity(dtheta, dv, ts, float(site[0]), float(site[2]), earth)
    limit = TILT_RAD * float(earth.gravity(float(site[0]))) * T
    if change > limit:
        return (f"its accelerometers show a velocity change of {change:.3g} m/s over the "
                f"{T:.4g} s window that no base at rest can produce (a tilt of 1e-3 rad gives "
                f"{limit:.3g} m/s): the vehicle drives, or its gyros drift far beyond the "
                "earth's rate")
    return None


def zero_velocity_warnings(sc: Scenario, case, summary: dict) -> list[str]:
    """A calibration case (:class:`gcalign.app.calibrate.run.Case`) of recorded data under
    zero-velocity updates: one warning when its window moves, with the evidence, and the
    filter's mean NIS when it lies above its 95 % band (from the `summary`)."""
    if case.aiding != "zero-velocity" or sc.imu_file is None:
        return []
    d = case.data
    ts = float(d.t[1] - d.t[0])
    t0 = case.t0  # data time of sample 0
    why = evidence(sc, d.dtheta, d.dv, ts, np.asarray(d.start.pos, float), d.earth,
                   t0 + float(d.t[0]), t0 + float(d.t[-1]))
    nis = summary.get("nis") or {}
    if nis and nis["mean"] > nis["band_95"][1]:
        clause = (f"the filter's mean NIS is {nis['mean']:.3g} against its 95 % band "
                  f"{nis['band_95'][0]:.2g}-{nis['band_95'][1]:.3g} (dof {nis['dof']})")
        why = clause if why is None else f"{why}, and {clause}"
    if why is None:
        return []
    return [f"calibrate.aiding: 'zero-velocity' takes the vehicle to be parked, but {why}; "
            "the estimates are not a calibration (calibrate a recording of a parked vehicle, "
            "or one with a reference velocity)"]
