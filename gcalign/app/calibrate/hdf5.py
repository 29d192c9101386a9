"""The /calibrate group of a results file: every filter run's estimates, σ, truth and
innovations at the filter epochs (SI), and the flight's segments.

Layout::

    /calibrate                 attrs: aiding, navigation_rate_hz, filter_rate_hz, compare,
                                      states (names), state_units, display_units,
                                      display_scale (SI -> display factors)
    /calibrate/segments        name (strings), t0, t1 (s)
    /calibrate/outages         start, end, length (s, the run's time base; attribute t0: the
                               recording's time of its 0), with aiding files
    /calibrate/runs/NN         attrs: label (designed | conventional | ""), measure
        t (K+1,) s; estimate, sigma, truth (K+1, 21) SI in the state order; nees (K+1,);
        updated (K+1,) 1 where a measurement updated the filter; update_t (U,) those
        epochs; innovation, standardized (U, m); nis (U,); sigma_z (U, m) the σ of R;
        att, v_n, pos (K+1, 3) the corrected INS solution; smoothed/estimate,
        smoothed/sigma (K+1, 21), smoothed/att, v_n, pos (K+1, 3) with the RTS smoother,
        smoothed/error/t, att, v_n, pos its errors at the epochs compared;
        navigation/ the solution at every navigation sample (or the output rate): t (the
        recording's time), t_run, att, v_n, pos, and error/t, att, v_n, pos against the
        truth or the reference where they are compared
"""

from __future__ import annotations

import h5py
import numpy as np

from gcalign.estimation import ins_error as ie
from gcalign.io.results import ATT_FRAME, put

STATE_SHAPE = "(epochs, 21) in the order of the 'states' attribute, SI units of 'state_units'"


def write_segments(f: h5py.File, truth, segments) -> None:
    """/truth/segment (index of each sample's manoeuvre) and /truth/segment_names."""
    if "truth" not in f or truth is None:
        return
    g = f["truth"]
    if "segment" not in g and truth.segment is not None:
        put(g, "segment", truth.segment, "1", description="index into segment_names")
    g.create_dataset("segment_names", data=np.array([s.name for s in segments],
                                                     dtype=h5py.string_dtype()))


def write_calibration(f: h5py.File, case, runs, compare: bool, against=None) -> None:
    """``/calibrate``; `against` (one per run, or None) the INS solution's errors against a
    reference (:func:`gcalign.app.calibrate.run.reference_series`)."""
    d = case.data
    write_segments(f, case.truth(), d.segments)
    g = f.require_group("calibrate")
    g.attrs["aiding"] = case.aiding
    g.attrs["navigation_rate_hz"] = case.navigation_rate
    g.attrs["filter_rate_hz"] = case.settings.filter_rate
    g.attrs["compare"] = compare
    g.attrs["states"] = ",".join(ie.STATE_NAMES)
    g.attrs["state_units"] = ",".join(ie.STATE_UNITS)
    g.attrs["display_units"] = ",".join(ie.DISPLAY_UNITS)
    g.attrs["display_scale"] = ie.display_scale(float(d.start.pos[0]), float(d.start.pos[2]),
                                                d.earth)
    seg = g.create_group("segments")
    seg.create_dataset("name", data=np.array([s.name for s in d.segments],
                                             dtype=h5py.string_dtype()))
    put(seg, "t0", [s.start for s in d.segments], "s")
    put(seg, "t1", [s.end for s in d.segments], "s")
    if case.aid is not None:
        og = g.create_group("outages")
        og.attrs["t0"] = case.t0
        og.attrs["max_gap_s"] = case.aid.info["max_gap_s"]
        og.attrs["description"] = ("stretches without a fix longer than max_gap_s (s from the "
                                   "run's sample 0; + t0: the recording's time)")
        outs = case.aid.outages
        put(og, "start", [o.start for o in outs], "s")
        put(og, "end", [o.end for o in outs], "s")
        put(og, "length", [o.length for o in outs], "s")
    rg = g.require_group("runs")
    for i, run in enumerate(runs):
        _write_run(rg.require_group(f"{i:02d}"), run)
        e = None if against is None else against[i]
        if e is not None:
            _put_errors(rg[f"{i:02d}"].create_group("reference_error"),
                        "INS solution - reference, at the epochs it covers",
                        e["t"], e["att"], e["v_n"], e["pos"])


def _put_errors(g: h5py.Group, description: str, t, att, v_n, pos) -> None:
    """A solution's errors at its epochs: t (s), att (Euler differences), v_n, pos (ENU)."""
    g.attrs["description"] = description
    put(g, "t", t, "s")
    put(g, "att", att, "rad", description="Euler differences, roll and yaw wrapped: pitch, "
        "roll, yaw")
    put(g, "v_n", v_n, "m/s", "ENU")
    put(g, "pos", pos, "m", "ENU")


def _write_run(g: h5py.Group, run) -> None:
    r = run.result
    g.attrs["label"] = run.label
    g.attrs["measure"] = r.settings.measure
    g.attrs["measure_names"] = ",".join(r.measure_names)
    put(g, "t", r.t, "s", description="filter epochs (t[0]: the start, no update)")
    put(g, "estimate", r.estimate, "SI", shape=STATE_SHAPE,
        description="sensor errors: the parameters in force after the update; navigation "
        "errors: the estimated error of the INS before the correction")
    put(g, "sigma", r.sigma, "SI", shape=STATE_SHAPE, description="posterior 1-sigma")
    if r.truth is not None:
        put(g, "truth", r.truth, "SI", shape=STATE_SHAPE)
        put(g, "nees", r.nees, "1", description="chi-square, 21 degrees of freedom")
    units = "m/s" if r.settings.measure == "velocity" else (
        "m" if r.settings.measure == "position" else "m/s, m/s, m, m")
    if r.updated is not None:
        put(g, "updated", r.updated.astype(np.int8), "1",
            description="1: a measurement updated the filter at the epoch, 0: predict only")
        put(g, "update_t", r.update_t, "s", description="the epochs with a measurement")
    put(g, "innovation", r.innovation, units, names=",".join(r.measure_names),
        description="z - H x-, z = INS - reference")
    put(g, "standardized", r.standardized, "1", description="L^-1 innovation, S = L L^T")
    put(g, "nis", r.nis, "1", description=f"chi-square, {r.standardized.shape[1]} dof")
    if r.sigma_z is not None:
        put(g, "sigma_z", r.sigma_z, units, names=",".join(r.measure_names),
            description="the measurement sigma of each update (R = diag sigma^2)")
    put(g, "att", r.att, "rad", ATT_FRAME)
    put(g, "v_n", r.v_n, "m/s", "ENU")
    put(g, "pos", r.pos, "rad, rad, m", "[latitude, longitude, height]")
    if r.smoothed is not None:
        s = g.create_group("smoothed")
        put(s, "estimate", r.smoothed.estimate, "SI", shape=STATE_SHAPE)
        put(s, "sigma", r.smoothed.sigma, "SI", shape=STATE_SHAPE)
        put(s, "att", r.smoothed.att, "rad", ATT_FRAME, description="the smoothed solution")
        put(s, "v_n", r.smoothed.v_n, "m/s", "ENU")
        put(s, "pos", r.smoothed.pos, "rad, rad, m", "[latitude, longitude, height]")
        e = (run.epoch_errors or {}).get("smoothed_series")
        if e is not None:
            _put_errors(s.create_group("error"), "the smoothed solution - the truth or the "
                        "reference", e["t"], e["attitude"], e["velocity"], e["position"])
