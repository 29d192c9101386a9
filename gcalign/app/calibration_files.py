"""Calibration of a recording with measured velocity and/or position (``calibrate.aiding:
file``): the files of ``calibrate.files`` interpolated to the navigation times (linearly;
:func:`gcalign.io.recorded.aiding.velocity_at` refuses a file that does not cover them),
the point each file measures (its ``lever_arm_m``, applied by the filter:
``FlightData.lever_arm_v_b``, ``lever_arm_p_b``), and the state the filter starts from.

On a moving vehicle a coarse alignment cannot give that state (it takes the accelerations
for tilt), so it comes from the scenario's ``initial`` keys or its ``reference`` at the
start (:func:`gcalign.io.recorded.initial_state`), the velocity from the velocity file
when there is one, the position from the position file, else the reference, else the site.
The coarse alignment's attitude is the last resort (a vehicle parked at the start).
"""

from __future__ import annotations

import numpy as np

from gcalign.calibrate.data import FlightData, Span
from gcalign.estimation.ins_error import antenna_offset
from gcalign.io.recorded.aiding import (
    GNSS_FORMATS,
    Velocities,
    overlap,
    read_gnss,
    read_velocity_aiding,
    velocity_at,
)
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.calibrate import CalibrateConfig, PositionFile
from gcalign.nav.earth import EarthModel
from gcalign.nav.rotation import euler_to_dcm
from gcalign.nav.strapdown import NavState

_HINT = "move calibrate.start_s or set calibrate.duration_s"


def _positions_at(g: PositionFile, t: np.ndarray) -> np.ndarray:
    """The positions of the file `g` at the data times `t` (M, 3) [L, λ, h]: GNSS fixes,
    or a reference solution's positions."""
    if g.format in GNSS_FORMATS:
        fixes = read_gnss(g.path, g.format, g.columns, lever_arm_b=g.lever_arm_m)  # recorded
        t_fix, pos, record = fixes.t, fixes.pos, fixes.record
    else:
        from gcalign.io.recorded.reference import read_reference

        ref = read_reference(g.path, "csv" if g.format == "reference-csv" else g.format,
                             g.variable, g.columns)
        t_fix, pos, record = ref.t, ref.pos, ref.record
    as_velocity = Velocities(t_fix, v_n=pos, record=record)  # the same interpolation
    overlap(t_fix, t, record["path"], "calibrate.files.position")
    return velocity_at(as_velocity, t, "calibrate.files.position", _HINT)[0]


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
    lever_v, lever_p = np.zeros(3), np.zeros(3)
    if files.velocity is not None:
        f = files.velocity
        ref_v, _ = velocity_at(read_velocity_aiding(f.path, f.format, f.columns, f.variable),
                               t_data, "calibrate.files.velocity", _HINT)
        lever_v = np.asarray(f.lever_arm_m, float)
    if files.position is not None:
        g = files.position
        ref_pos = _positions_at(g, t_data)
        lever_p = np.asarray(g.lever_arm_m, float)
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
    # the files measure their points; the INS starts at the IMU's
    C_nb, w0 = euler_to_dcm(att), dtheta[0] / (t[1] - t[0])
    w_ie = earth.omega_ie_n(float(pos0[0]))
    if files.velocity is not None:
        v0 = v0 - antenna_offset(C_nb, w0, w_ie, lever_v)[0]
    if files.position is not None:
        r_m, r_n = earth.radii(float(pos0[0]))
        e, n_, u = antenna_offset(C_nb, w0, w_ie, lever_p)[1]
        pos0 = pos0 - np.array([n_ / (r_m + pos0[2]), e / ((r_n + pos0[2]) * np.cos(pos0[0])),
                                u])
    start = NavState.from_euler(att, v0, pos0)
    data = FlightData(t=np.asarray(t, float), dtheta=dtheta, dv=dv, start=start,
                      ref_v_n=ref_v, ref_pos=ref_pos,
                      segments=(Span("recorded", float(t[0]), float(t[-1])),), earth=earth,
                      lever_arm_v_b=lever_v, lever_arm_p_b=lever_p)
    return data, np.asarray(att, float), source
