"""Calibration of a recording with measured velocity and/or position (``calibrate.aiding:
file``): the files of ``calibrate.files`` interpolated to the navigation times (linearly;
:func:`gcalign.io.recorded.aiding.velocity_at` refuses a file that does not cover them),
and the state the filter starts from.

On a moving vehicle a coarse alignment cannot give that state (it takes the accelerations
for tilt), so it comes from the scenario's ``initial`` keys or its ``reference`` at the
start (:func:`gcalign.io.recorded.initial_state`), the velocity from the velocity file
when there is one, the position from the position file, else the reference, else the site.
The coarse alignment's attitude is the last resort (a vehicle parked at the start).
"""

from __future__ import annotations

import numpy as np

from gcalign.calibrate.data import FlightData, Span
from gcalign.io.recorded.aiding import (
    Velocities,
    overlap,
    read_gnss,
    read_velocity_aiding,
    velocity_at,
)
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.calibrate import CalibrateConfig
from gcalign.nav.earth import EarthModel
from gcalign.nav.strapdown import NavState


def _positions_at(path, fmt, columns, t: np.ndarray) -> np.ndarray:
    fixes = read_gnss(path, fmt, columns)
    as_velocity = Velocities(fixes.t, v_n=fixes.pos, record=fixes.record)  # same interpolation
    overlap(fixes.t, t, fixes.record["path"], "calibrate.files.position")
    pos, _ = velocity_at(as_velocity, t, "calibrate.files.position")
    return pos


def file_data(sc: Scenario, cfg: CalibrateConfig, t: np.ndarray, dtheta: np.ndarray,
              dv: np.ndarray, coarse_att: np.ndarray, site: np.ndarray, earth: EarthModel,
              t0: float, header_att=None) -> tuple[FlightData, np.ndarray, str]:
    """The filter's data at the navigation times `t` (N+1,) (from sample 0; `t0` the data
    time of sample 0): the measured velocity and position, the start state; and the start
    attitude with where it came from."""
    from gcalign.io.recorded.reference import initial_state, reference_at

    assert cfg.files is not None
    files = cfg.files
    t_data = t0 + np.asarray(t, float)
    n = len(t_data)
    ref_v = np.zeros((n, 3))
    ref_pos = np.tile(np.asarray(site, float), (n, 1))
    if files.velocity is not None:
        f = files.velocity
        ref_v, _ = velocity_at(read_velocity_aiding(f.path, f.format, f.columns, f.variable),
                               t_data, "calibrate.files.velocity")
    if files.position is not None:
        g = files.position
        ref_pos = _positions_at(g.path, g.format, g.columns, t_data)
    reference = sc.reference.read() if sc.reference is not None else None
    keys = {} if sc.initial is None else {"att_deg": sc.initial.att_deg,
                                         "v_enu_mps": sc.initial.v_enu_mps}
    if keys or reference is not None or header_att is not None:
        att, v0, source = initial_state(str(sc.imu_file), float(t_data[0]), reference=reference,
                                        header_att=header_att, **keys)
    else:
        att, v0, source = coarse_att, np.zeros(3), "the coarse alignment (a parked start)"
    pos0 = ref_pos[0]
    if files.position is None and reference is not None:
        pos0 = reference_at(reference, [t_data[0]], tol=1e-6)[2][0]
    if files.velocity is not None:
        v0 = ref_v[0]
    start = NavState.from_euler(att, v0, pos0)
    data = FlightData(t=np.asarray(t, float), dtheta=dtheta, dv=dv, start=start,
                      ref_v_n=ref_v, ref_pos=ref_pos,
                      segments=(Span("recorded", float(t[0]), float(t[-1])),), earth=earth)
    return data, np.asarray(att, float), source
