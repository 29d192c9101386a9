"""Calibration of a recording with measured velocity and/or position (``calibrate.aiding:
file``): the files of ``calibrate.files`` as fixes at their own epochs (never interpolated
across time: a gap in a file is an outage, where the filter only predicts), each fix's σ
where the file states them, the point each file measures (its ``lever_arm_m``, applied by
the filter), and the state the filter starts from.

The start comes from what the user says: a coarse alignment when
``calibrate.coarse.method`` asks for one (a vehicle parked at the start), else the
scenario's ``initial`` keys, else its ``reference`` at the start, else the recording's
header (PSINS). Its position: ``initial``, a position fix at the start (the IMU's, a lever
arm from the antenna's), the reference, else the site; its velocity: ``initial``, a
velocity fix at the start, the reference, else zero. The P0 of the
navigation states is ``initial.sigma`` where given, else ``calibrate.p0`` × ``p0_scale``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.calibrate.data import FlightData, Span
from gcalign.calibrate.fixes import Fixes, Outage, default_max_gap, find_outages
from gcalign.errors import ScenarioError
from gcalign.estimation.ins_error import antenna_offset
from gcalign.io.recorded.aiding import (
    GNSS_FORMATS,
    overlap,
    read_gnss,
    read_velocity_aiding,
)
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.calibrate import CalibrateConfig, PositionFile, VelocityFile
from gcalign.nav.earth import EarthModel
from gcalign.nav.rotation import euler_to_dcm
from gcalign.nav.strapdown import NavState

_TOL = 1e-6  #: s: two epochs this close are the same epoch


@dataclass(frozen=True)
class Epochs:
    """One aiding file as read: epochs (data time, s), values (M, 3) (ENU m/s, or
    ``[L, λ, h]``), their σ (M, 3) ENU or None, and what was read."""

    t: np.ndarray
    values: np.ndarray
    sigma: np.ndarray | None
    record: dict


def _every(t: np.ndarray, interval: float | None) -> np.ndarray:
    """Mask of the epochs at whole multiples of `interval` s (all without one)."""
    if interval is None:
        return np.ones(len(t), dtype=bool)
    return np.abs(t / interval - np.round(t / interval)) * interval < _TOL


def read_epochs(f: VelocityFile | PositionFile, key: str) -> Epochs:
    """The epochs of an aiding file: GNSS fixes with their σ, a velocity CSV, or a
    reference solution's velocity or position; ``interval_s`` applied."""
    if isinstance(f, PositionFile) and f.format in GNSS_FORMATS:
        fixes = read_gnss(f.path, f.format, f.columns, lever_arm_b=f.lever_arm_m)
        t, values, sigma, record = fixes.t, fixes.pos, fixes.sigma_enu, fixes.record
    elif isinstance(f, PositionFile):
        from gcalign.io.recorded.reference import read_reference

        ref = read_reference(f.path, "csv" if f.format == "reference-csv" else f.format,
                             f.variable, f.columns)
        t, values, sigma, record = ref.t, ref.pos, None, ref.record
    else:
        vel = read_velocity_aiding(f.path, f.format, f.columns, f.variable)
        assert vel.v_n is not None
        t, values, sigma, record = vel.t, vel.v_n, None, vel.record
    keep = _every(np.asarray(t, float), f.interval_s)
    if not keep.any():
        raise ScenarioError(f"calibrate.files.{key}.interval_s: no epoch of {f.path} lies on "
                            f"a whole multiple of {f.interval_s:g} s (it covers "
                            f"{float(t[0]):.3f} .. {float(t[-1]):.3f} s)")
    return Epochs(np.asarray(t, float)[keep], np.asarray(values, float)[keep],
                  None if sigma is None else np.asarray(sigma, float)[keep], record)


def _common(a: Epochs, b: Epochs) -> tuple[np.ndarray, np.ndarray, int]:
    """Indices into a and b of the epochs both have (within 1 µs), and how many of either
    have no partner."""
    j = np.clip(np.searchsorted(b.t, a.t), 1, len(b.t) - 1) if len(b.t) > 1 else \
        np.zeros(len(a.t), np.int64)
    near = np.where(np.abs(b.t[j - 1] - a.t) < np.abs(b.t[j] - a.t), j - 1, j) \
        if len(b.t) > 1 else j
    ok = np.abs(b.t[near] - a.t) < _TOL
    ia, ib = np.flatnonzero(ok), near[ok]
    return ia, ib, len(a.t) + len(b.t) - 2 * len(ia)


@dataclass(frozen=True)
class AidingInput:
    """The fixes of a recording's aiding files in the run's time base, with what the
    summary reports of them (``info``) and one line per thing to say (``warnings``)."""

    fixes: Fixes
    info: dict
    warnings: tuple[str, ...]
    outages: tuple[Outage, ...] = ()


def aiding_input(cfg: CalibrateConfig, t0: float, t_run: np.ndarray) -> AidingInput:
    """The fixes of ``calibrate.files`` for a run over `t_run` (N+1,) (s from the
    recording's sample 0; `t0` the data time of that sample)."""
    assert cfg.files is not None
    files = cfg.files
    pos = vel = None
    if cfg.measure != "velocity":
        assert files.position is not None
        pos = read_epochs(files.position, "position")
    if cfg.measure != "position":
        assert files.velocity is not None
        vel = read_epochs(files.velocity, "velocity")
    warnings: list[str] = []
    t_data = t_run + t0
    for key, ep in (("position", pos), ("velocity", vel)):
        if ep is not None:  # each file shares time with the run, or is refused naming both
            overlap(ep.t, t_data, ep.record.get("path", "the aiding file"),
                    f"calibrate.files.{key}")
    if pos is not None and vel is not None:
        ip, iv, alone = _common(pos, vel)
        if not len(ip):
            raise ScenarioError(f"calibrate.files: measure 'both' needs the velocity and the "
                                f"position at the same epochs; {vel.record.get('path')} and "
                                f"{pos.record.get('path')} share none")
        if alone:
            warnings.append(f"calibrate.files: {alone} epochs of the velocity and position "
                            "files have no partner at the same time and are not used "
                            "(measure both takes the epochs the two share)")
        pos = Epochs(pos.t[ip], pos.values[ip], None if pos.sigma is None else pos.sigma[ip],
                     pos.record)
        vel = Epochs(vel.t[iv], vel.values[iv], None, vel.record)
    main = pos if pos is not None else vel
    assert main is not None
    key = "position" if pos is not None else "velocity"
    path = main.record.get("path", "the aiding file")
    f_pos, f_vel = files.position, files.velocity
    fixes = Fixes(
        t=main.t - t0,
        pos=None if pos is None else pos.values, sigma_pos=None if pos is None else pos.sigma,
        v_n=None if vel is None else vel.values,
        lever_arm_p_b=np.asarray(f_pos.lever_arm_m if f_pos is not None else np.zeros(3), float),
        lever_arm_v_b=np.asarray(f_vel.lever_arm_m if f_vel is not None else np.zeros(3), float))
    max_gap = cfg.max_gap_s if cfg.max_gap_s is not None else default_max_gap(fixes.t)
    outages = find_outages(fixes.t, float(t_run[0]), float(t_run[-1]), max_gap)
    inside = (main.t >= t_data[0] - _TOL) & (main.t <= t_data[-1] + _TOL)
    first, last = float(main.t[inside][0]), float(main.t[inside][-1])
    if t_data[-1] - last > max_gap:
        warnings.append(f"calibrate.files.{key}: {path} ends at {last:.3f} s, "
                        f"{t_data[-1] - last:.1f} s before the end of the run: the rest ran "
                        "unaided (listed as an outage)")
    if first - t_data[0] > max_gap:
        warnings.append(f"calibrate.files.{key}: {path} begins at {first:.3f} s, "
                        f"{first - t_data[0]:.1f} s after the start of the run: its first part "
                        "ran unaided (listed as an outage)")
    sig = None if pos is None or pos.sigma is None else pos.sigma[inside]
    info = {"path": str(path), "format": main.record.get("format"),
            "epochs": int(inside.sum()), "epochs_in_file": int(len(main.t)),
            "first_s": first, "last_s": last,
            "median_interval_s": fixes.median_interval, "max_gap_s": float(max_gap),
            "max_gap_source": "calibrate.max_gap_s" if cfg.max_gap_s is not None
            else "twice the median interval",
            "sigma": "the file's, per fix" if sig is not None else "calibrate.sigma_p_m / "
            "sigma_v_mps (the file states none)",
            "sigma_enu_median_m": None if sig is None else np.median(sig, axis=0).tolist(),
            "sigma_enu_range_m": None if sig is None else [float(sig.min()), float(sig.max())],
            "outages": [{"start_s": o.start, "end_s": o.end, "length_s": o.length,
                         "start_data_s": o.start + t0, "end_data_s": o.end + t0}
                        for o in outages],
            "time_origin": main.record.get("time_origin", "the file's time column")}
    return AidingInput(fixes, info, tuple(warnings), outages)


def _at_start(ep: Fixes, values: np.ndarray | None, t_start: float,
              max_gap: float) -> np.ndarray | None:
    """The value of the fix at the start of the run (within one fix interval), or None."""
    if values is None or not len(ep.t):
        return None
    k = int(np.argmin(np.abs(ep.t - t_start)))
    return values[k] if abs(ep.t[k] - t_start) <= max_gap / 2 + _TOL else None


def start_state(sc: Scenario, cfg: CalibrateConfig, t_start: float, t0: float,
                site: np.ndarray, earth: EarthModel, w0: np.ndarray,
                fixes: Fixes | None = None, coarse_att: np.ndarray | None = None,
                header=None, reference=None) -> tuple[NavState, str]:
    """The INS state at run time `t_start` (s from sample 0; data time ``t_start + t0``)
    and where it came from (module docstring). `w0` the first body rate (rad/s, for an
    antenna's velocity); `coarse_att` the coarse alignment's attitude when one ran;
    `reference` the scenario's reference as read."""
    from gcalign.io.recorded.reference import initial_state, reference_at

    t_data = t_start + t0
    ini = sc.initial
    if coarse_att is not None:
        att, v0, source = coarse_att, np.zeros(3), "the coarse alignment (a parked start)"
    else:
        keys = {} if ini is None else {"att_deg": ini.att_deg, "v_enu_mps": ini.v_enu_mps}
        att, v0, source = initial_state(
            str(sc.imu_file), t_data, reference=reference,
            header_att=None if header is None else header.att0,
            header_v=None if header is None else getattr(header, "v0_n", None), **keys)
    C_nb = euler_to_dcm(att)
    w_ie = earth.omega_ie_n(float(site[0]))
    pos0 = None if ini is None else ini.position()
    max_gap = cfg.max_gap_s or (default_max_gap(fixes.t) if fixes is not None else 0.0)
    if pos0 is None and fixes is not None:
        fix = _at_start(fixes, fixes.pos, t_start, max_gap)
        if fix is not None:  # the antenna's position: the IMU's lies a lever arm away
            r_m, r_n = earth.radii(float(fix[0]))
            e, n_, up = antenna_offset(C_nb, w0, w_ie, fixes.lever_arm_p_b)[1]
            pos0 = fix - np.array([n_ / (r_m + fix[2]), e / ((r_n + fix[2]) * np.cos(fix[0])),
                                   up])
    if pos0 is None and reference is not None:
        pos0 = reference_at(reference, [t_data], tol=1e-6)[2][0]
    if pos0 is None:
        pos0 = np.asarray(site, float)
    keyed_v = ini is not None and "v_enu_mps" in ini.model_fields_set
    if fixes is not None and not keyed_v:
        fix_v = _at_start(fixes, fixes.v_n, t_start, max_gap)
        if fix_v is not None:  # the antenna's velocity, likewise
            v0 = fix_v - antenna_offset(C_nb, w0, w_ie, fixes.lever_arm_v_b)[0]
    return NavState.from_euler(att, v0, pos0), source


def file_data(sc: Scenario, cfg: CalibrateConfig, t: np.ndarray, dtheta: np.ndarray,
              dv: np.ndarray, site: np.ndarray, earth: EarthModel, t0: float,
              coarse_att: np.ndarray | None = None, header=None, reference=None
              ) -> tuple[FlightData, AidingInput, str]:
    """The filter's data at the navigation times `t` (N+1,) (from sample 0; `t0` the data
    time of sample 0): the fixes, the start state; and where the start came from."""
    aid = aiding_input(cfg, t0, np.asarray(t, float))
    w0 = dtheta[0] / (t[1] - t[0])
    start, source = start_state(sc, cfg, float(t[0]), t0, site, earth, w0, aid.fixes,
                                coarse_att, header, reference)
    data = FlightData(t=np.asarray(t, float), dtheta=dtheta, dv=dv, start=start,
                      ref_v_n=None, ref_pos=None,
                      segments=(Span("recorded", float(t[0]), float(t[-1])),), earth=earth,
                      fixes=aid.fixes)
    return data, aid, source
