"""The resolved values of a scenario, in user units and in SI, for `gcalign validate`."""

from __future__ import annotations

import numpy as np

from gcalign.io.scenario.models import Scenario
from gcalign.io.scenario.motion import SwingModel
from gcalign.sim.motions import Swing, Turntable


def _v(x, digits=6) -> str:
    a = np.atleast_1d(np.asarray(x, dtype=float))
    text = ", ".join(f"{v:.{digits}g}" for v in a.ravel())
    return text if a.size == 1 else f"[{text}]"


def resolved_rows(sc: Scenario, imu=None) -> list[tuple[str, str, str]]:
    """``(field, value in user units, value in SI)`` for every setting the run will use;
    `imu`: the recorded file as the preflight read it (else read here)."""
    rows: list[tuple[str, str, str]] = [("name", sc.name, "")]
    if sc.site is not None:
        si = sc.site.to_si()
        rows += [
            ("site.lat_deg", _v(sc.site.lat_deg) + " °", _v(si[0], 10) + " rad"),
            ("site.lon_deg", _v(sc.site.lon_deg) + " °", _v(si[1], 10) + " rad"),
            ("site.height_m", _v(sc.site.height_m) + " m", _v(si[2]) + " m"),
        ]
    if sc.imu_file is not None:
        rows.append(("imu_file", str(sc.imu_file), "(recorded data; imu errors not applied)"))
        from gcalign.io.results import HDF5_SUFFIXES

        if imu is None and sc.imu_file.suffix.lower() not in HDF5_SUFFIXES:
            from gcalign.io.recorded import read_recording

            imu = read_recording(sc.imu_file, sc.recording_layout())
        rows += recording_rows(sc, imu)
        rows += reference_rows(sc, imu)
    else:
        imu, err = sc.imu, sc.imu.errors()
        rows += [("imu.rate_hz", _v(imu.rate_hz) + " Hz", _v(imu.ts) + " s"),
                 ("imu.seed", str(imu.seed), "")]
        g, a = imu.gyro, imu.accel
        for key, value, unit, si, si_unit in (
                ("gyro.bias_dph", g.bias_dph, "°/h", err.gyro.bias, " rad/s"),
                ("gyro.arw_dprh", g.arw_dprh, "°/√h", err.gyro.noise, " rad/√s"),
                ("gyro.scale_ppm", g.scale_ppm, "ppm", err.gyro.scale, ""),
                ("accel.bias_ug", a.bias_ug, "µg", err.accel.bias, " m/s²"),
                ("accel.vrw_ugrhz", a.vrw_ugrhz, "µg/√Hz", err.accel.noise, " m/s/√s"),
                ("accel.scale_ppm", a.scale_ppm, "ppm", err.accel.scale, "")):
            rows.append((f"imu.{key}", f"{_v(value)} {unit}", _v(si) + si_unit))
        for name, sensor, m in (("gyro", imu.gyro, err.gyro), ("accel", imu.accel, err.accel)):
            if sensor.misalignment_arcsec is not None:
                rows.append((f"imu.{name}.misalignment_arcsec",
                             _v(sensor.misalignment_arcsec) + " ″", _v(m.misalignment) + " rad"))
            if m.quantum:
                unit = "rad" if name == "gyro" else "m/s"
                rows.append((f"imu.{name}.quantum", "", _v(m.quantum) + f" {unit}"))
    if sc.motion is not None:
        rows += motion_rows(sc)
    rows.append(("earth", sc.earth, ""))
    for section in type(sc).model_fields:  # every command section that can explain itself
        model = getattr(sc, section, None)
        if model is not None and hasattr(model, "resolved_rows"):
            rows += model.resolved_rows(sc)
    return rows


def motion_rows(sc: Scenario) -> list[tuple[str, str, str]]:
    """The motion as the run will see it: kind, start, duration and its pieces."""
    mo = sc.motion
    assert mo is not None
    motion = mo.to_motion()
    n = int(round(motion.duration * sc.imu.rate_hz))
    rows = [
        ("motion.kind", mo.kind, ""),
        ("motion.attitude_deg", _v(mo.attitude_deg) + " °",
         _v(np.radians(mo.attitude_deg)) + " rad"),
        ("motion.duration_s", _v(motion.duration) + " s", f"{n} samples"),
    ]
    if isinstance(motion, Swing) and isinstance(mo, SwingModel):
        rows += [
            ("motion.swing.amplitude_deg", _v(mo.swing.amplitude_deg) + " °",
             _v(motion.amplitude) + " rad"),
            ("motion.swing.period_s", _v(motion.period) + " s", ""),
            ("motion.swing.phase_deg", _v(mo.swing.phase_deg) + " °", _v(motion.phase) + " rad"),
        ]
    for i, seg in enumerate(getattr(motion, "segments", ())):
        rows.append((f"motion.segments.{i}" + (f" ({seg.name})" if seg.name else ""),
                     f"{seg.duration:g} s, {seg.accel:g} m/s², {_v(np.degrees(seg.rate))} °/s",
                     _v(seg.rate) + " rad/s"))
    if isinstance(motion, Turntable):
        for i, st in enumerate(motion.schedule.steps):
            rows.append((f"motion.steps.{i}", f"axis {_v(st.axis)}, "
                         f"{np.degrees(st.profile.angle):g}° in {st.profile.duration:g} s, "
                         f"dwell {st.dwell:g} s", f"{st.profile.angle:.9g} rad"))
    return rows


def recording_rows(sc: Scenario, imu) -> list[tuple[str, str, str]]:
    """What the reader assumed of the scenario's recorded file `imu` as read (format, axes,
    units, time, rate, gaps, gravity; a results file of ours says nothing here)."""
    from gcalign.io.results import HDF5_SUFFIXES

    assert sc.imu_file is not None
    if sc.imu_file.suffix.lower() in HDF5_SUFFIXES:
        return []
    r = imu.meta["recording"]
    gravity = r["gravity_check"]
    gaps = r["gaps"]
    return [
        ("imu_file.format", r["format"], r["time_origin"]),
        ("imu_file.axes", f"{r['axes']} ({r['axes_source']})",
         f"v_rfu = C v_file, C = {np.asarray(r['C_rfu_file']).astype(int).tolist()}"
         if np.all(np.isin(r["C_rfu_file"], (-1, 0, 1))) else f"C = {r['C_rfu_file']}"),
        ("imu_file.units", f"gyro {r['units']['gyro']}, accel {r['units']['accel']}",
         f"{r['quantity']}: {r['rate_rule']}"),
        ("imu_file.time", r["time_stamp"], f"t {r['t_first_s']:.6f} .. {r['t_last_s']:.6f} s, "
         f"{r['samples']} samples"),
        ("imu_file.rate", f"{r['rate_hz']:.6g} Hz ({r['ts_rule']})",
         f"{r['ts_s']:.6g} s, jitter up to {r['jitter_max']:.2%}"),
        ("imu_file.gaps", "none" if not gaps else f"{len(gaps)} filled",
         "; ".join(f"{g['length_s']:.3g} s after {g['after_t_s']:.6f} s" for g in gaps)),
        ("imu_file.gravity",
         "not checked" if isinstance(gravity, str) else
         f"tilt {gravity['tilt_deg']:.2f}° over the first {gravity['window_s']:g} s",
         "" if isinstance(gravity, str) else
         f"f = {_v(gravity['specific_force_rfu_mps2'], 5)} m/s² (RFU)"),
        ("imu_file.gyros", *_gyro_rows(r.get("gyro_check"))),
    ]


def _gyro_rows(check) -> tuple[str, str]:
    """The gyro check of a recording (gcalign.io.recorded.consistency) as a validate row."""
    if not isinstance(check, dict):
        return "not checked", str(check or "")
    if not check.get("judged"):
        return "not judged", str(check.get("why", ""))
    rest = check.get("at_rest")
    at_rest = (f"; at rest {rest['ratio_to_earth_rate']:.3g} × the earth rate, "
               f"{rest['angle_from_up_deg']:.1f}° from up ({rest['expected_deg']:.1f}° "
               "expected)" if isinstance(rest, dict) and rest.get("judged") else "")
    verdict = "disagree with" if check.get("warning") else "agree with"
    return (f"{verdict} the accelerometers (k {check['k']:.3g})",
            f"specific force turns as the gyros say: correlation {check['rho']:.2f} over "
            f"{check['windows']} windows{at_rest}")


def reference_rows(sc: Scenario, imu) -> list[tuple[str, str, str]]:
    """The reference file and initial keys, read and checked: the reference must cover the
    navigation window (``navigation.start_s``, ``duration_s``; the whole recording by
    default) of the recorded data (ScenarioError naming both spans otherwise) when the
    scenario navigates: it has a navigation section, or no align or calibrate section
    (those check their own windows when they run). `imu`: the recorded file as read."""
    from gcalign.io.recorded.reference import reference_at

    rows: list[tuple[str, str, str]] = []
    if sc.initial is not None:
        rows.append(("initial.att_deg", _v(sc.initial.att_deg) + " °",
                     _v(np.radians(sc.initial.att_deg)) + " rad"))
        rows.append(("initial.v_enu_mps", _v(sc.initial.v_enu_mps) + " m/s", ""))
    if sc.reference is None or sc.imu_file is None:
        return rows
    ref = sc.reference.read()
    r = ref.record
    if imu is None:  # a results file of ours
        from gcalign.io.results import read_imu

        imu = read_imu(sc.imu_file)
    nav = sc.navigation
    start = float(imu.t[0] - imu.ts) + (nav.start_s if nav is not None else 0.0)
    end = float(imu.t[-1]) if nav is None or nav.duration_s is None else min(
        float(imu.t[-1]), start + nav.duration_s)
    # navigate needs the whole window; align and calibrate check their own windows
    navigates = nav is not None or (sc.align is None and sc.calibrate is None)
    if navigates:
        reference_at(ref, [start, end])  # refuses a reference that does not cover the run
    rows.append(("reference", f"{r['path']} ({r['format']}"
                 + (f", {r['variable']}" if "variable" in r else "") + ")",
                 f"{r['epochs']} epochs at {r['rate_hz']:.4g} Hz, t {r['t_first_s']:.3f} .. "
                 f"{r['t_last_s']:.3f} s ({r['time_origin']})"))
    if navigates:
        rows.append(("reference covers", f"{start:.3f} .. {end:.3f} s",
                     "the navigation window"))
    return rows
