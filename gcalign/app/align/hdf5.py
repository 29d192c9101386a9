"""The /align group of a results file: every pass and the result at T2 and T3."""

from __future__ import annotations

import h5py
import numpy as np

from gcalign.io.results import ATT_FRAME, PHI_FRAME, put

GAIN_NAMES = "K_E1, K_E2, K_E3, K_N1, K_N2, K_N3, K_U1, K_U2, K_U3, K_U4"


def write_alignment(f: h5py.File, run, stream=None, error_source: str = "truth") -> None:
    """/align/pass_NN (attitude and error per pass, NN = 01, 02, …), /align/result,
    /align/gains, and the true attitude at the stored samples under /truth (t, att), or
    the reference's under /reference (`error_source` "reference": recorded data)."""
    if run.pass_truth is not None:
        # every stored sample once, in time order (a later pass's row of a time kept, as a
        # mapping from time to row would); not a Python loop over the 10^5 rows
        t_all = np.concatenate([rec.t for rec in run.passes])
        att_all = np.concatenate(run.pass_truth)
        t, last = np.unique(t_all[::-1], return_index=True)
        tg = f.create_group(error_source)
        put(tg, "t", t, "s", description="the samples the passes stored (output rate)")
        put(tg, "att", att_all[::-1][last], "rad", ATT_FRAME)
    g = f.create_group("align")
    g.attrs["error_source"] = error_source
    g.attrs["mode"] = run.settings.mode
    g.attrs["azimuth_poles"] = run.azimuth_poles
    g.attrs["t1_s"], g.attrs["t2_s"], g.attrs["t3_s"] = run.t1, run.t2, run.t3
    for rec, att, err, phi in zip(run.passes, run.pass_att, run.pass_errors, run.pass_phi,
                                  strict=True):
        p = g.create_group(f"pass_{rec.index + 1:02d}")  # numbered from 1, as in the table
        p.attrs["direction"], p.attrs["kind"] = rec.direction, rec.kind
        p.attrs["stage"] = rec.stage + 1
        put(p, "t", rec.t, "s",
            description="data time, processing order (decreasing in a reverse pass)")
        put(p, "att", att, "rad", ATT_FRAME)
        put(p, "gains", rec.gains, "SI", names=GAIN_NAMES)
        if err is not None:
            put(p, "error", err, "rad", "Euler differences est - true, yaw wrapped")
            put(p, "phi", phi, "rad", PHI_FRAME)
    r = g.create_group("result")
    put(r, "coarse_att", run.coarse_att, "rad", ATT_FRAME)
    put(r, "att_t2", run.att_t2, "rad", ATT_FRAME)
    put(r, "att_t3", run.att_t3, "rad", ATT_FRAME)
    if run.truth_t2 is not None:
        put(r, "truth_t2", run.truth_t2, "rad", ATT_FRAME)
        put(r, "truth_t3", run.truth_t3, "rad", ATT_FRAME)
        put(r, "error_t2", run.error_t2, "rad", "Euler differences est - true, yaw wrapped")
        put(r, "error_t3", run.error_t3, "rad", "Euler differences est - true, yaw wrapped")
        put(r, "phi_t2", run.phi_t2, "rad", PHI_FRAME)
        put(r, "phi_t3", run.phi_t3, "rad", PHI_FRAME)
    r.attrs["compute_s"] = run.compute_s
    r.attrs["equivalent_s"] = run.equivalent_s
