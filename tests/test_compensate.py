"""T2 → T3 attitude compensation (seed 000 eqs. 14-18): from the true state at T2, ideal
data must carry the attitude to the true one at T3 — the physics leaves nothing else."""

from __future__ import annotations

import numpy as np
import pytest

from gcalign.align import kernel as K
from gcalign.align.compensate import compensate
from gcalign.align.cycles import Block
from gcalign.nav.rotation import euler_to_dcm, euler_to_quat, misalignment, quat_to_dcm
from gcalign.sim.imu import ideal_imu
from gcalign.sim.motions import Moving, Segment, Swing

D = np.pi / 180
SITE = np.array([45.7796 * D, 126.6705 * D, 0.0])
MOTIONS = {
    "swing": Swing((0, 0, 30 * D), 60.0, amplitude=(2 * D, 3 * D, 4 * D), period=(10, 10, 20)
    ),
    "moving": Moving((0, 0, 30 * D),
        60.0,
        segments=(
            Segment(10),
            Segment(10, 1.0),
            Segment(10, 0, (0, 0, -D)),
            Segment(10, 0, (0, 0, D)),
            Segment(10, 0.5, (0, 0, -2 * D)),
            Segment(10),
        ),
    ),
}


@pytest.mark.parametrize("kind", ["swing", "moving"])
@pytest.mark.parametrize("method", ["one-off", "continued"])
@pytest.mark.parametrize("body", [False, True])
def test_compensation_reaches_the_true_attitude(kind, method, body):
    truth, imu = ideal_imu(MOTIONS[kind], SITE, 0.01)
    i2, i3 = 1500, 6000  # T2 = 15 s, T3 = 60 s: 45 s of latency through turns
    v_n = truth.v_n
    vref = np.einsum("kji,kj->ki", euler_to_dcm(truth.att), v_n) if body else v_n
    after = Block(
        first=i2,
        t0=0.0,
        dtheta=imu.dtheta[i2:i3],
        dv=imu.dv[i2:i3],
        vref=vref[i2 : i3 + 1],
        vref_body=body,
        ts=imu.ts,
    )
    state = K.new_state(euler_to_quat(truth.att[i2]), v_n[i2], truth.pos[i2])
    q3 = compensate(method, state, after)
    phi = misalignment(quat_to_dcm(q3), euler_to_dcm(truth.att[i3]))
    assert np.degrees(np.abs(phi)).max() < 1e-6


def test_none_reports_the_t2_attitude():
    truth, imu = ideal_imu(MOTIONS["swing"], SITE, 0.01)
    after = Block(
        first=100,
        t0=0.0,
        dtheta=imu.dtheta[100:200],
        dv=imu.dv[100:200],
        vref=np.zeros((101, 3)),
        vref_body=False,
        ts=imu.ts,
    )
    state = K.new_state(euler_to_quat(truth.att[100]), np.zeros(3), truth.pos[100])
    np.testing.assert_array_equal(compensate("none", state, after), state[K.ATT])
