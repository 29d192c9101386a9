"""The navigation error kernel (:func:`gcalign.nav._kernels.error_block`, what every
navigate summary and stored error row comes from) against a NumPy reference built from
the rotation helpers: Euler differences with roll and yaw wrapped (also across ±180°),
ENU position errors at the true latitude, φ from direction-cosine matrices (a second route
to the kernel's quaternion one), the body attitude through the mechanism angles, the
stride of the stored rows and the maxima over every sample."""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.app.navigate.run import position_error_enu
from gcalign.nav import _kernels as K
from gcalign.nav.earth import SEED004, WGS84
from gcalign.nav.rotation import (
    attitude_error,
    euler_to_quat,
    misalignment,
    quat_conj,
    quat_mult,
    quat_to_dcm,
    quat_to_euler,
)


def case(n: int, moving: bool, mechanism: bool, seed: int = 5):
    rng = np.random.default_rng(seed)
    att_t = np.column_stack([rng.uniform(-1.2, 1.2, n), rng.uniform(-np.pi, np.pi, n),
                             rng.uniform(-np.pi, np.pi, n)])
    att_t[:5, 1] = np.pi - 1e-4  # roll and yaw near ±180°: the wrap is crossed
    att_t[:5, 2] = -np.pi + 1e-4
    if not moving:  # one attitude, the one near ±180°
        att_t[:] = att_t[0]
    q_t = euler_to_quat(att_t)
    q_nb = quat_mult(q_t, euler_to_quat(rng.normal(0, 1e-3, (n, 3))))  # errors of ~0.06°
    q_bs = euler_to_quat(rng.uniform(-np.pi, np.pi, (n, 3))) if mechanism else None
    v_t = rng.normal(0, 30, (n, 3))
    pos_t = np.column_stack([0.8 + rng.normal(0, 1e-3, n), 2.2 + rng.normal(0, 1e-3, n),
                             rng.uniform(0, 3000, n)])
    if not moving:
        v_t[:], pos_t[:] = 0.0, pos_t[0]
    states = np.zeros((n, K.NAV_STATE))
    states[:, K.Q] = q_nb if q_bs is None else quat_mult(q_nb, q_bs)  # q_ns
    states[:, K.V] = v_t + rng.normal(0, 0.1, (n, 3))
    states[:, K.P] = pos_t + np.column_stack([rng.normal(0, 1e-6, (n, 2)),
                                              rng.normal(0, 5, n)])
    return states, q_bs, att_t, q_t, v_t, pos_t, q_nb


@pytest.mark.parametrize("moving", [False, True])
@pytest.mark.parametrize("mechanism", [False, True])
@pytest.mark.parametrize("earth", [WGS84, SEED004], ids=["wgs84", "seed004"])
def test_error_kernel_matches_numpy_reference(moving, mechanism, earth):
    n, stride, k_first = 500, 7, 3
    states, q_bs, att_t, q_t, v_t, pos_t, q_nb = case(n, moving, mechanism)
    pos0 = states[0, K.P] + np.array([1e-5, -2e-5, 10.0])
    nt = n if moving else 1  # a fixed truth is passed as one row
    acc = np.zeros((9, 3))
    out = np.empty((n // stride + 1, 21))
    rows = K.error_block(states, q_bs if mechanism else np.zeros((1, 4)), mechanism,
                         att_t[:nt].copy(), q_t[:nt].copy(), v_t[:nt].copy(),
                         pos_t[:nt].copy(), True, earth.params(), pos0, k_first, stride, acc,
                         out)

    att = quat_to_euler(q_nb)
    e_att = attitude_error(att, att_t)
    e_v = states[:, K.V] - v_t
    e_pos = position_error_enu(states[:, K.P], pos_t, earth)
    phi = misalignment(quat_to_dcm(q_nb), quat_to_dcm(q_t))
    disp = position_error_enu(states[:, K.P], np.tile(pos0, (n, 1)), earth)
    keep = np.flatnonzero((k_first + np.arange(n) + 1) % stride == 0)

    assert rows == len(keep)
    ref = np.hstack([att, states[:, K.V], states[:, K.P], e_att, e_v, e_pos, phi])[keep]
    assert np.allclose(out[:rows], ref, rtol=1e-12, atol=1e-12)
    assert np.abs(e_att[:, 1:]).max() < 0.01  # the ±180° crossings wrapped, not 2π
    peak = np.array([np.abs(x).max(axis=0) for x in (e_att, e_v, e_pos)])
    assert np.allclose(acc[:3], peak, rtol=1e-12, atol=1e-12)
    assert np.isclose(acc[3, 0], np.hypot(e_pos[:, 0], e_pos[:, 1]).max(), rtol=1e-12)
    assert np.isclose(acc[3, 1], np.hypot(disp[:, 0], disp[:, 1]).max(), rtol=1e-12)
    assert np.allclose(acc[4], np.abs(phi).max(axis=0), rtol=1e-9, atol=1e-15)
    assert np.allclose(acc[5:9], [e_att[-1], e_v[-1], e_pos[-1], phi[-1]], rtol=1e-9,
                       atol=1e-12)


def test_reference_sees_a_mechanism_mistake():
    """The reference can fail: ignoring the mechanism angles moves φ by the whole turn."""
    states, q_bs, *_, q_t, _, _, q_nb = case(50, False, True)
    wrong = misalignment(quat_to_dcm(states[:, K.Q]), quat_to_dcm(q_t))
    right = misalignment(quat_to_dcm(quat_mult(states[:, K.Q], quat_conj(q_bs))),
                         quat_to_dcm(q_t))
    assert np.abs(right).max() < 0.01 < np.abs(wrong).max()
