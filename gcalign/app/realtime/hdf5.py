"""The /realtime group of a results file: the filter chain's response and, per case, the
per-pulse records (SI, radians; Euler ``[pitch, roll, yaw]``).

Layout::

    /realtime                attrs: reference, delay (T used, s), chain_delay (s),
                             solution_hz, fs_hz, predictors, settle_s, corner_s
    /realtime/filter         h (FIR taps), notch_b, notch_a (if any), freq (Hz),
                             magnitude (|H| of the chain), magnitude_fir, magnitude_notch,
                             group_delay (s)
    /realtime/cases/NN       attrs: name, kind, component, axis, seed_before, seed_after,
                             pulses; t (P,) pulse edge times, k (P,) latched solution,
                             dt_true, dt (P,) Δt true and measured, t_update, t_valid (P,),
                             latched, truth, ins_ref (P, 3), predicted/<name> (P, 3)
"""

from __future__ import annotations

import h5py
import numpy as np

from gcalign.io.results import put
from gcalign.io.stored import write_fields
from gcalign.realtime.filters import FilterChain

#: frequency grid of the stored response (Hz): a quarter step off the notch's zero, where
#: the group delay is singular
_FREQ_STEP = 0.5


def write_filter(g: h5py.Group, chain) -> None:
    """The chain's taps and its magnitude and group-delay response."""
    fs = chain.fs
    freq = (np.arange(int(fs / 2 / _FREQ_STEP)) + 0.25) * _FREQ_STEP
    put(g, "h", chain.h, "1", description="FIR taps, sum 1")
    put(g, "freq", freq, "Hz")
    put(g, "magnitude", np.abs(chain.response(freq)), "1", description="|H| of the chain")
    put(g, "magnitude_fir", np.abs(FilterChain(fs, chain.h).response(freq)), "1")
    if chain.notch_ba is not None:
        b, a = chain.notch_ba
        put(g, "notch_b", b, "1")
        put(g, "notch_a", a, "1")
        notch = FilterChain(fs, np.ones(1), chain.notch_ba)  # the notch alone
        put(g, "magnitude_notch", np.abs(notch.response(freq)), "1")
    put(g, "group_delay", chain.group_delay(freq), "s")
    g.attrs.update(fs=fs, fir_delay=chain.fir_delay, notch_delay=chain.notch_delay,
                   delay=chain.delay, order=chain.order)


def write_realtime(f: h5py.File, run) -> None:
    """/realtime: the run's settings, the filter, and the per-pulse arrays of every case."""
    s = run.result.settings
    g = f.create_group("realtime")
    T = run.result.delay
    g.attrs.update(reference=run.cfg.reference, delay=T, chain_delay=run.result.chain_delay,
                   solution_hz=s.solution_hz, fs_hz=s.filter.fs_hz,
                   predictors=",".join(s.predictors), settle_s=s.settle_s,
                   corner_s=s.corner_s,
                   units="delay, chain_delay, settle_s, corner_s: s; solution_hz, fs_hz: Hz")
    write_filter(g.create_group("filter"), run.result.chain)
    cases = g.create_group("cases")
    for i, res in enumerate(run.result.cases):
        c = cases.create_group(f"{i:02d}")
        case = res.case
        train = case.pulses or s.pulses
        c.attrs.update(name=case.name, kind=case.kind, component=case.component,
                       axis=np.asarray(case.shape.axis if case.shape.axis else [np.nan] * 3),
                       seed_before=case.seed_before, seed_after=case.seed_after,
                       pulses=train.mode, pulse_rate_hz=train.rate_hz,
                       rate=case.shape.rate, duration=case.duration)
        write_fields(c, res)  # the pulse records as CaseResult's fields say
