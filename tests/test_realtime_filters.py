"""Composite filter of seed 003 §2 (gcalign.realtime.filters) against closed forms and scipy
(spec 003 §5 tests 1–3; must-show 1)."""

from __future__ import annotations

import numpy as np
import pytest
from lazy import lazy_module

from gcalign.realtime.filters import (
    FilterChain,
    alignment_chain,
    design_fir,
    design_notch,
    first_moment,
    navigation_chain,
    notch_dc_delay,
)
from gcalign.realtime.settings import FilterSettings

signal = lazy_module("scipy.signal")

FS = 5000.0


@pytest.mark.parametrize(("order", "cutoff", "delay_ms"), [(180, 100.0, 18.0), (40, 200.0, 4.0)])
def test_fir_delay_is_half_its_order(order, cutoff, delay_ms):
    """Seed eq. (1): T = N/(2 Fs). First moment Σk·h_k/Σh_k = N/2, scipy's group delay flat
    at N/2 samples across the passband: 18.000 ms (order 180), 4.000 ms (order 40)."""
    h = design_fir(order, cutoff, FS)
    assert len(h) == order + 1
    assert h.sum() == pytest.approx(1.0, abs=1e-15)
    assert first_moment(h) == pytest.approx(order / 2, abs=1e-11)
    f = np.linspace(0.01, 0.8 * cutoff, 200)
    _, gd = signal.group_delay((h, [1.0]), w=f, fs=FS)
    np.testing.assert_allclose(gd, order / 2, atol=1e-8)
    chain = FilterChain(FS, h)
    assert chain.delay * 1e3 == pytest.approx(delay_ms, abs=1e-12)


def test_default_chains_give_the_seed_delays():
    fs = FilterSettings()
    assert alignment_chain(fs).delay == pytest.approx(18e-3, abs=1e-15)
    nav = navigation_chain(fs)
    assert nav.fir_delay == pytest.approx(4e-3, abs=1e-15)
    # spec 003 §2 [O]: notch + FIR41 → 4.0406 ms
    assert nav.delay * 1e3 == pytest.approx(4.0406, abs=5e-5)
    # the chain's delay is also scipy's group delay of the cascade at low frequency
    assert nav.group_delay(np.array([1e-3]))[0] == pytest.approx(nav.delay, rel=1e-9)


@pytest.mark.parametrize(("q", "spec_us"), [(5.0, 81.3), (10.0, 40.6), (30.0, 13.5)])
def test_notch_dc_delay_closed_form(q, spec_us):
    """1 − (a1 + 2a2)/(1 + a1 + a2) samples equals scipy's group delay at low frequency and is
    within 3 % of 1/(2π f0 Q) (spec 003 §5 test 2; spec's numbers 81.3/40.6/13.5 µs)."""
    b, a = design_notch(400.0, q, FS)
    closed = 1.0 - (a[1] + 2 * a[2]) / (1 + a[1] + a[2])
    assert notch_dc_delay(b, a) == pytest.approx(closed, rel=1e-12)
    _, gd = signal.group_delay((b, a), w=np.array([1e-4, 0.1]), fs=FS)
    np.testing.assert_allclose(gd, closed, rtol=1e-6)
    approx = 1.0 / (2 * np.pi * 400.0 * q) * FS
    assert abs(closed / approx - 1.0) < 0.03
    assert closed / FS * 1e6 == pytest.approx(spec_us, abs=0.05)


def test_fir41_attenuation_where_the_notch_is_needed():
    """Spec 003 §2 [O]: order 40 at 200 Hz attenuates 300 Hz by only 17.6 dB, 400 Hz by 44 dB."""
    h = design_fir(40, 200.0, FS)
    _, H = signal.freqz(h, [1.0], worN=np.array([300.0, 400.0]), fs=FS)
    np.testing.assert_allclose(-20 * np.log10(np.abs(H)), [17.6, 44.2], atol=0.05)


@pytest.mark.parametrize("order", [40, 180])
def test_a_ramp_in_rate_comes_out_delayed_by_half_the_order(order):
    """Spec 003 §5 test 3: ω(t) = a + b t through a FIR with Σh = 1 is ω(t − N/(2 Fs))."""
    h = design_fir(order, 150.0, FS)
    t = np.arange(3000) / FS
    a, b = 0.3, 0.7  # rad/s, rad/s²
    y = signal.lfilter(h, [1.0], a + b * t)
    np.testing.assert_allclose(y[order:], a + b * (t[order:] - order / (2 * FS)), rtol=0,
                               atol=1e-14)
    # a deliberate error in the delay by 1 % of a sample is seen
    assert np.max(np.abs(y[order:] - (a + b * (t[order:] - 1.01 * order / (2 * FS))))) > 1e-7


def test_streamed_chunks_equal_one_pass():
    """Carried state: chunks of any sizes give the one-pass output, and that is scipy's
    lfilter (notch, then FIR) from rest."""
    chain = navigation_chain(FilterSettings())
    rng = np.random.default_rng(3)
    x = rng.normal(size=(5003, 2))
    y_all, _ = chain.apply(x, chain.initial_state(2))
    ref = signal.lfilter(chain.h, [1.0], signal.lfilter(*chain.notch_ba, x, axis=0), axis=0)
    np.testing.assert_allclose(y_all, ref, rtol=0, atol=1e-13)
    state, parts, i = chain.initial_state(2), [], 0
    for n in [1, 7, 40, 41, 600, 1200, 3114]:
        y, state = chain.apply(x[i:i + n], state)
        parts.append(y)
        i += n
    assert i == len(x)
    np.testing.assert_allclose(np.concatenate(parts), y_all, rtol=0, atol=1e-14)


def test_a_long_fir_through_ffts_is_scipys_lfilter_streamed_in_chunks():
    """An FIR of more than DIRECT_TAPS taps is applied through FFTs (order 59999 on the
    default cases ran over 5 minutes by direct convolution): the same output as scipy's
    lfilter from rest, to round-off, in one pass and in chunks shorter than the FIR."""
    from gcalign.realtime.filters import DIRECT_TAPS

    order = 3 * DIRECT_TAPS
    chain = FilterChain(FS, design_fir(order, 200.0, FS, "hamming"))
    rng = np.random.default_rng(5)
    x = rng.normal(size=(4 * order + 17, 3))
    ref = signal.lfilter(chain.h, [1.0], x, axis=0)
    y_all, _ = chain.apply(x, chain.initial_state(3))
    np.testing.assert_allclose(y_all, ref, rtol=0, atol=1e-12)
    state, parts, i = chain.initial_state(3), [], 0
    for n in [1, 500, order + 3, 2 * order, len(x) - 1 - 500 - (order + 3) - 2 * order]:
        y, state = chain.apply(x[i:i + n], state)
        parts.append(y)
        i += n
    assert i == len(x)
    np.testing.assert_allclose(np.concatenate(parts), ref, rtol=0, atol=1e-12)


def test_initial_state_is_the_steady_state_of_a_constant():
    chain = navigation_chain(FilterSettings())
    y, _ = chain.apply(np.full((300, 1), 2.5), chain.initial_state(1, 2.5))
    np.testing.assert_allclose(y, 2.5, rtol=1e-12)


def test_the_notch_removes_the_dither_that_the_fir_alone_passes():
    """A 400 Hz dither: the notch on it leaves nothing in steady state; the FIR alone passes
    it at −44 dB."""
    fs = FilterSettings()
    t = np.arange(20000) / FS
    x = np.sin(2 * np.pi * 400.0 * t)[:, None]
    with_notch = navigation_chain(fs)
    y, _ = with_notch.apply(x, with_notch.initial_state(1))
    assert np.max(np.abs(y[15000:])) < 1e-12
    fir_only = FilterChain(FS, with_notch.h)
    y2, _ = fir_only.apply(x, fir_only.initial_state(1))
    # amplitude by least squares on sin/cos over the last 5000 samples (160 periods)
    ts = t[15000:]
    A = np.stack([np.sin(2 * np.pi * 400.0 * ts), np.cos(2 * np.pi * 400.0 * ts)], -1)
    amp = np.hypot(*np.linalg.lstsq(A, y2[15000:, 0], rcond=None)[0])
    H400 = np.abs(fir_only.response(np.array([400.0]))[0])
    assert amp == pytest.approx(H400, rel=1e-9)
    assert 20 * np.log10(amp) == pytest.approx(-44.2, abs=0.05)
