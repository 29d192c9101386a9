"""The block kernels against their previous form (``tests/kernels_prev.py``: the state in
an array, read and written at every step, the stride tested at every step), to the bit.

Keeping the state in local variables, and the reverse pass's data transform inside the
kernel, changes where values live, not one operation: every result is identical
(``np.array_equal``), on noisy data of the seed 000 moving base, both directions, every
vertical mode and strides with a remainder. (The formulas themselves are checked against
plain-NumPy transcriptions in test_strapdown.py, test_gyrocompass.py and
test_attitude_kernel.py.)
"""

from __future__ import annotations

import math
from dataclasses import replace

import kernels_prev as prev
import numpy as np
import pytest

from gcalign.align import cycles
from gcalign.align import kernel as AK
from gcalign.align.cycles import Block, loop_gains
from gcalign.align.stages import Stage
from gcalign.nav import _kernels as K
from gcalign.nav.earth import WGS84
from gcalign.nav.rotation import attitude_error, euler_to_quat, quat_to_euler, wrap_pi
from gcalign.sim.imu import ideal_imu
from gcalign.sim.motions import Moving, Segment
from gcalign.units import DEG

TS = 0.01
SITE = np.array([45.7796 * DEG, 126.6705 * DEG, 30.0])
N = 3001  # not a multiple of the strides below


@pytest.fixture(scope="module")
def data():
    """Seed 000 §5.3 moving base (accelerate, turn right and left, cruise) with sensor
    noise: every branch of the steps is taken with values that differ at every step."""
    right, left = (0.0, 0.0, -1.0 * DEG), (0.0, 0.0, 1.0 * DEG)
    motion = Moving((0.5 * DEG, -0.3 * DEG, 30.0 * DEG), N * TS,
                    (Segment(5.0), Segment(10.0, accel=1.0), Segment(5.0, rate=right),
                     Segment(5.0, rate=left), Segment(6.0)))
    truth, imu = ideal_imu(motion, SITE, TS)
    rng = np.random.default_rng(21)
    dtheta = imu.dtheta[:N] + 1e-7 * rng.standard_normal((N, 3))
    dv = imu.dv[:N] + 1e-5 * rng.standard_normal((N, 3))
    s0 = np.zeros(K.NAV_STATE)
    s0[K.Q], s0[K.V], s0[K.P] = euler_to_quat(truth.att[0]), truth.v_n[0], truth.pos[0]
    s0[K.DA] = 1e-4
    href = SITE[2] + 0.1 * np.sin(np.arange(N) * TS)
    return np.ascontiguousarray(dtheta), np.ascontiguousarray(dv), s0, href


VERTICAL = {"free": np.zeros(4), "hold": np.array([K.HOLD, 0.0, 0.0, 0.0]),
            "damped": K.vertical_gains(20.0, 3.1e-6)}


@pytest.mark.parametrize("vertical", list(VERTICAL))
@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("stride", [1, 7, N + 1])
@pytest.mark.parametrize("ref", ["per-step", "constant"])
def test_strapdown_block_is_the_previous_to_the_bit(data, vertical, sign, stride, ref):
    dtheta, dv, s0, href = data
    h_ref = href if ref == "per-step" else href[:1]
    E, vert = WGS84.params(), VERTICAL[vertical]
    s_new, s_old = s0.copy(), s0.copy()
    o_new = np.full((N // stride, K.NAV_STATE), np.nan)
    o_old = o_new.copy()
    K.strapdown_block(s_new, dtheta, dv, TS, sign, E, vert, h_ref, stride, o_new)
    prev.strapdown_block(s_old, dtheta, dv, TS, sign, E, vert, h_ref, stride, o_old)
    assert np.array_equal(s_new, s_old) and np.array_equal(o_new, o_old)
    assert not np.array_equal(s_new, s0)


def test_a_one_term_change_is_seen(data):
    """The comparison can fail: the previous kernel on data of which one increment changed
    by 1e-12 of itself (a millionth of what an equation's error would be) gives other
    bits."""
    dtheta, dv, s0, href = data
    E, vert = WGS84.params(), VERTICAL["damped"]
    s_new, s_old = s0.copy(), s0.copy()
    other = dtheta.copy()
    other[N // 2, 0] *= 1.0 + 1e-12
    o = np.empty((N, K.NAV_STATE))
    K.strapdown_block(s_new, dtheta, dv, TS, 1.0, E, vert, href, 1, o)
    prev.strapdown_block(s_old, other, dv, TS, 1.0, E, vert, href, 1, o.copy())
    assert not np.array_equal(s_new, s_old)


@pytest.mark.parametrize("subsamples", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("stride", [1, 4])
def test_attitude_block_is_the_previous_to_the_bit(data, subsamples, stride):
    dtheta = data[0][: N - N % subsamples]
    q0 = data[2][K.Q]
    w_in = np.array([1e-5, 5e-5, 6e-5])
    rows = len(dtheta) // subsamples // stride
    q_new, q_old = q0.copy(), q0.copy()
    o_new, o_old = np.full((rows, 4), np.nan), np.full((rows, 4), np.nan)
    K.attitude_block(q_new, dtheta, TS, w_in, subsamples, stride, o_new)
    prev.attitude_block(q_old, dtheta, TS, w_in, subsamples, stride, o_old)
    assert np.array_equal(q_new, q_old) and np.array_equal(o_new, o_old)


# ------------------------------------------------------------------ gyrocompass passes


@pytest.fixture(scope="module")
def block(data):
    """The moving-base data as a pass block with a noisy ENU reference velocity; the
    odometer variant gets the body-frame forward speed."""
    dtheta, dv, _, _ = data
    rng = np.random.default_rng(3)
    t = np.arange(N + 1) * TS  # the block starts at record sample 0, time 0
    vref = np.zeros((N + 1, 3))
    vref[:, 1] = np.clip(t - 5.0, 0.0, 10.0)
    vref += 0.01 * rng.standard_normal((N + 1, 3))
    return {body: Block(0, 0.0, dtheta, dv, vref, body, TS) for body in (False, True)}


@pytest.mark.parametrize("mode", [AK.ATTITUDE, AK.LEVEL, AK.COMPASS])
@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize("body", [False, True])
@pytest.mark.parametrize("stride", [1, 7, 100])
@pytest.mark.parametrize("lo, hi", [(0, N), (113, 2000), (50, 50)])
def test_stored_pass_is_the_previous_to_the_bit(block, data, mode, reverse, body, stride,
                                                lo, hi):
    """A pass that reads the block backwards with the signs inside the kernel, writing only
    the stored rows, gives the rows, the sample indices and the final state of the pass
    run on reversed and negated copies with every row written."""
    b = block[body]
    s0 = AK.new_state(data[2][K.Q], [0.3, 0.5, 0.0], data[2][K.P])
    s0[AK.INTEGRALS], s0[AK.WCU] = [1e-3, -2e-3], 1e-6
    gains = loop_gains(Stage(20.0, 100.0, 0.707), SITE[0], SITE[2], "double-oscillator")
    s_new, s_old = s0.copy(), s0.copy()
    i_new, q_new = cycles.run_stored(s_new, b, lo, hi, reverse, gains, mode, stride)
    i_old, q_old = prev.run_stored(s_old, b, lo, hi, reverse, gains, mode, stride)
    assert np.array_equal(i_new, i_old) and np.array_equal(q_new, q_old)
    assert np.array_equal(s_new, s_old)
    q_all_new, q_all_old = np.empty((hi - lo + 1, 4)), np.empty((hi - lo + 1, 4))
    s_new, s_old = s0.copy(), s0.copy()
    cycles.run_block(s_new, b, lo, hi, reverse, gains, mode, q_all_new)
    prev.run_block(s_old, b, lo, hi, reverse, gains, mode, q_all_old)
    assert np.array_equal(q_all_new, q_all_old) and np.array_equal(s_new, s_old)


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize("stride", [1, 7])
def test_kernel_calls_of_a_long_pass_are_the_previous_to_the_bit(block, data, reverse,
                                                                 stride, monkeypatch):
    """A pass longer than one kernel call (here calls of 1000 steps): the same calls, the
    same rows (the end of each call is kept), the same final state."""
    monkeypatch.setattr(cycles, "CHUNK", 1000)
    monkeypatch.setattr(prev, "CHUNK", 1000)
    b = block[True]
    s0 = AK.new_state(data[2][K.Q], [0.3, 0.5, 0.0], data[2][K.P])
    gains = loop_gains(Stage(20.0, 100.0, 0.707), SITE[0], SITE[2], "double-oscillator")
    s_new, s_old = s0.copy(), s0.copy()
    i_new, q_new = cycles.run_stored(s_new, b, 0, N, reverse, gains, AK.COMPASS, stride)
    i_old, q_old = prev.run_stored(s_old, b, 0, N, reverse, gains, AK.COMPASS, stride)
    assert np.array_equal(i_new, i_old) and np.array_equal(q_new, q_old)
    assert np.array_equal(s_new, s_old)


@pytest.fixture(scope="module")
def block_truth(data):
    """A true attitude at every sample of the block (the simulation's, with a yaw near
    ±180° in places so that the wrap of the errors is taken both ways)."""
    rng = np.random.default_rng(5)
    att = np.zeros((N + 1, 3))
    att[:, 0] = 0.5 * DEG + 1e-4 * rng.standard_normal(N + 1)
    att[:, 1] = -0.3 * DEG + 1e-4 * rng.standard_normal(N + 1)
    att[:, 2] = np.where(np.arange(N + 1) % 3 == 0, 179.9, 30.0) * DEG
    return att


@pytest.mark.parametrize("mode", ["full-cycle", "half-cycle", "conventional"])
@pytest.mark.parametrize("chunk", [cycles.CHUNK, 1000])
@pytest.mark.parametrize("stride", [1, 10])
def test_passes_are_the_previous_to_the_bit(block, data, mode, chunk, stride, monkeypatch):
    """The whole sequence of passes (level phase, direction changes, stages, several kernel
    calls a pass), each pass's rows written once into arrays of their size: the same
    times, samples, attitude and final state as the passes as they were; and the samples
    they keep are those kept_samples names (where the truth must be held)."""
    monkeypatch.setattr(cycles, "CHUNK", chunk)
    monkeypatch.setattr(prev, "CHUNK", chunk)
    stages = [Stage(20.0, 100.0, 0.707, 3), Stage(10.0, 50.0, 0.707)]
    s0 = AK.new_state(data[2][K.Q], [0.0, 0.0, 0.0], data[2][K.P])
    passes = 1 if mode == "conventional" else 5
    b = replace(block[False], first=40)  # block sample k is record sample 40 + k
    new = cycles.run_passes(s0, b, mode, passes, stages, "double-oscillator", 6.0,
                            stride=stride)
    old = prev.run_passes(s0, b, mode, passes, stages, "double-oscillator", 6.0,
                          stride=stride)
    assert np.array_equal(new[0], old[0])
    for a, o in zip(new[1], old[1], strict=True):
        assert np.array_equal(a.t, o.t) and np.array_equal(a.q_nb, o.q_nb)
        assert np.array_equal(a.samples, o.samples)
    kept = cycles.kept_samples(N, mode, passes, 6.0, TS, stride)
    stored = np.unique(np.concatenate([r.samples for r in new[1]])) - 40
    assert np.array_equal(stored, kept) and 600 in kept


def _libm_euler(q):
    """quat_to_euler with the scalar libm arcsin/arctan2 that the kernels call (NumPy's
    vector forms are another implementation on some CPUs)."""
    w, x, y, z = q.T
    c21 = np.clip(2.0 * (y * z + w * x), -1.0, 1.0)
    c20, c22 = 2.0 * (x * z - w * y), w * w - x * x - y * y + z * z
    c01, c11 = 2.0 * (x * y - w * z), w * w - x * x + y * y - z * z
    return np.array([[math.asin(a), math.atan2(-b, c), math.atan2(-d, e)]
                     for a, b, c, d, e in zip(c21, c20, c22, c01, c11, strict=True)])


@pytest.mark.parametrize("reverse", [False, True])
def test_error_kernel_is_numpy_to_the_bit(block, data, block_truth, reverse):
    """The error kernel on a pass's stored rows (forward or reverse order, from the truth
    at the kept samples only) gives what NumPy gives from the truth gathered at every row:
    rotation.attitude_error(rotation.quat_to_euler(q), truth), to the bit where the angles
    come from libm as in the kernel, with the roll and yaw wrap taken both ways (yaw near
    ±180°)."""
    s0 = AK.new_state(data[2][K.Q], [0.3, 0.5, 0.0], data[2][K.P])
    gains = loop_gains(Stage(20.0, 100.0, 0.707), SITE[0], SITE[2], "double-oscillator")
    idx, q = cycles.run_stored(s0, block[True], 0, N, reverse, gains, AK.COMPASS, 3)
    kept = np.unique(idx)
    out = np.full((len(idx), 3), np.nan)
    assert AK.attitude_errors(q, idx, kept, block_truth[kept], out) == len(idx)
    expected = attitude_error(_libm_euler(q), block_truth[idx])
    assert np.array_equal(out, expected)
    # NumPy's vector arcsin/arctan2 (SIMD on AVX-512 machines) may differ from libm by an ulp
    np.testing.assert_allclose(out, attitude_error(quat_to_euler(q), block_truth[idx]),
                               rtol=0, atol=1e-14)
    assert (np.abs(out[:, 2]) > np.radians(100)).any()  # the wrapped rows are there
    short = np.delete(kept, 10)
    missing = int(np.flatnonzero(idx == kept[10])[0])
    assert AK.attitude_errors(q, idx, short, block_truth[short], out) == missing


@pytest.mark.parametrize("n", [1, 2, 9, 14501])
def test_column_spread_is_numpy_to_the_bit(n):
    """The spread of a pass's errors (mean, std ddof 0, max |·| per column) as NumPy's
    reductions give it: rows summed in order, the variance from the deviations."""
    rng = np.random.default_rng(n)
    e = 1e-3 * rng.standard_normal((n, 3)) + rng.standard_normal(3)
    mean, std, peak = AK.column_spread(e)
    assert np.array_equal(mean, e.mean(0)) and np.array_equal(std, e.std(0))
    assert np.array_equal(peak, np.abs(e).max(0))
    e[n // 2, 1] = np.nan
    assert np.isnan(AK.column_spread(e)[2][1]) and np.isnan(np.abs(e).max(0)[1])


def test_kernel_wrap_is_numpys_to_the_bit():
    """The kernels' wrap (a comparison where the modulo leaves d + π as it is) against
    rotation.wrap_pi's (d + π) mod 2π − π, at and around every boundary and far outside."""
    pi = np.pi
    edges = np.array([-pi, pi, 0.0, -0.0, 2 * pi, -2 * pi, 3 * pi, -3 * pi, 1e-300, 50.0])
    near = np.concatenate([np.nextafter(edges, np.inf), np.nextafter(edges, -np.inf), edges])
    rng = np.random.default_rng(4)
    d = np.concatenate([near, rng.uniform(-7, 7, 20_000), rng.uniform(-1e6, 1e6, 1000),
                        [np.inf, -np.inf, np.nan]])
    got = np.array([K.wrap_pi(x) for x in d])
    with np.errstate(invalid="ignore"):  # ±inf mod 2π is NaN, as it should be
        want = wrap_pi(d)
    assert np.array_equal(got, want, equal_nan=True)
    assert np.array_equal(np.signbit(got), np.signbit(want))  # the zeros too
