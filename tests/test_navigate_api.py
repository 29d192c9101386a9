"""Navigation on arrays (:func:`gcalign.nav.navigate.navigate`): the same numbers as
``gcalign navigate`` to the last bit; Schuler's closed form through the arrays alone."""

from __future__ import annotations

import math
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

import gcalign
from gcalign.errors import InputError
from gcalign.nav.earth import WGS84
from gcalign.nav.navigate import NavTruth, navigate, navigate_blocks, position_error_enu
from gcalign.nav.rotation import euler_to_dcm
from gcalign.nav.strapdown import NavState, Vertical

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module", params=["moving", "swing"])
def simulated(request, tmp_path_factory):
    """A simulated run (with sensor noise) stored by `gcalign simulate`: its file, its
    increments and its truth."""
    d = yaml.safe_load((ROOT / "configs/seed000_moving_full_cycle.yaml").read_text())
    d.pop("align")
    d["motion"]["duration_s"] = 120
    if request.param == "swing":
        d["motion"] = {"kind": "swing", "attitude_deg": [0, 0, 30], "duration_s": 120,
                       "swing": {"amplitude_deg": [2, 3, 4], "period_s": [10, 10, 20]}}
    sim = gcalign.run("simulate", d, seed=5, output=tmp_path_factory.mktemp("s") / "sim.h5")
    return sim.path, sim.imu(), sim.truth()


@pytest.mark.parametrize("vertical, rate, start_s", [("hold", "full", 0.0),
                                                     ("damped", 10, 0.0), ("free", 1, 30.0)])
def test_array_route_is_the_command_route_bit_for_bit(simulated, tmp_path, vertical, rate,
                                                      start_s):
    path, imu, truth = simulated
    sc = {"name": "nav", "imu_file": str(path), "output": {"rate_hz": rate},
          "navigation": {"vertical": vertical, "start_s": start_s}}
    cli = gcalign.run("navigate", sc, init="truth", output=tmp_path / "n.h5")
    k = int(round(start_s / imu.ts))
    stride = 1 if rate == "full" else int(round(1.0 / (rate * imu.ts)))
    start = NavState.from_euler(truth.att[k], truth.v_n[k], truth.pos[k])
    nav = navigate(imu.dtheta[k:], imu.dv[k:], imu.ts, start, vertical=Vertical(vertical),
                   truth=NavTruth(truth.att[k + 1:], truth.v_n[k + 1:], truth.pos[k + 1:]),
                   stride=stride, t0=truth.t[k])
    with h5py.File(cli.path) as f:
        g = f["navigate"]
        for name in ("t", "att", "v_n", "pos"):
            assert np.array_equal(g[name][()], getattr(nav.rows, name)), name
        for name in ("att", "v_n", "pos", "phi"):
            assert np.array_equal(g["error"][name][()], getattr(nav.rows.error, name)), name
    assert cli["max_horizontal_error_m"] == nav.max_horizontal_error
    assert cli["displacement_m"] == nav.displacement.tolist()
    assert cli["final_state"]["velocity_mps"] == nav.final.v_n.tolist()
    assert cli["samples"] == nav.samples == len(imu) - k
    assert cli.value is not None and np.array_equal(cli.value.final.q_nb, nav.final.q_nb)


def test_blocks_of_any_size_give_the_same_numbers(simulated):
    _, imu, truth = simulated
    start = NavState.from_euler(truth.att[0], truth.v_n[0], truth.pos[0])
    whole = navigate(imu.dtheta, imu.dv, imu.ts, start, stride=7,
                     truth=NavTruth(truth.att[1:], truth.v_n[1:], truth.pos[1:]))
    from gcalign.nav.navigate import Increments

    def blocks(size: int):
        for k0 in range(0, len(imu), size):
            sl = slice(k0, k0 + size)
            yield Increments(k0, imu.t[sl], imu.dtheta[sl], imu.dv[sl],
                             NavTruth(truth.att[1:][sl], truth.v_n[1:][sl], truth.pos[1:][sl]))

    got = []
    split = navigate_blocks(blocks(1001), imu.ts, start, k_end=len(imu), stride=7,
                            on_rows=got.append)
    assert split.rows is None and split.max_error is not None and whole.max_error is not None
    assert np.array_equal(split.max_error.stack(), whole.max_error.stack())
    assert np.array_equal(np.concatenate([r.pos for r in got]), whole.rows.pos[1:])


def test_still_ideal_imu_stays_and_schuler_closed_form():
    """A still, ideal IMU started 0.1 m/s off in east velocity: the horizontal position
    error at a quarter Schuler period is δv/ω_s (the earth-rate coupling only turns the
    oscillation, at ω_ie sin L); started exactly, it does not move (< 1e-6 m)."""
    lat, ts = math.radians(30.0), 0.1
    w_s = WGS84.schuler_rate(lat)
    n = 10 * int(round(0.5 * math.pi / w_s / ts / 10))  # a quarter period, whole rows
    att = np.radians([0.5, -0.3, 60.0])
    C_bn = euler_to_dcm(att).T
    w_b = C_bn @ WGS84.omega_ie_n(lat)
    f_b = C_bn @ np.array([0.0, 0.0, float(WGS84.gravity(lat))])
    dth, dv = np.tile(w_b * ts, (n, 1)), np.tile(f_b * ts, (n, 1))
    pos0 = np.array([lat, 2.0, 0.0])
    truth = NavTruth(np.tile(att, (n, 1)), np.zeros((n, 3)), np.tile(pos0, (n, 1)))
    exact = navigate(dth, dv, ts, NavState.from_euler(att, np.zeros(3), pos0), truth=truth)
    assert exact.max_horizontal_error is not None and exact.max_horizontal_error < 1e-6
    off = navigate(dth, dv, ts, NavState.from_euler(att, [0.1, 0.0, 0.0], pos0), truth=truth,
                   stride=10)
    assert off.final_error is not None
    horizontal = math.hypot(*off.final_error.pos[:2])
    assert horizontal == pytest.approx(0.1 / w_s, rel=2e-3), (horizontal, 0.1 / w_s)
    assert np.array_equal(off.rows.error.pos[-1], off.final_error.pos)
    d = position_error_enu(off.rows.pos, np.broadcast_to(pos0, off.rows.pos.shape))
    assert np.array_equal(d[-1], off.displacement)


@pytest.mark.parametrize("kwargs, field", [
    ({"dv": np.zeros((3, 3))}, "dv"),
    ({"dtheta": np.zeros((0, 3))}, "dtheta"),
    ({"ts": -1.0}, "ts"),
    ({"stride": 0}, "stride"),
    ({"truth": NavTruth(np.zeros((4, 3)), np.zeros((4, 3)), np.zeros((4, 3)))}, "truth.att"),
    ({"q_bs": np.tile([1.0, 0, 0, 0], (5, 1))}, "q_bs0"),
])
def test_refusals_name_the_argument(kwargs, field):
    args = {"dtheta": np.zeros((5, 3)), "dv": np.zeros((5, 3)), "ts": 0.01,
            "start": NavState.from_euler(np.zeros(3), np.zeros(3), [0.5, 0.0, 0.0])}
    extra = {k: v for k, v in kwargs.items() if k not in args}
    args.update({k: v for k, v in kwargs.items() if k in args})
    with pytest.raises(InputError, match=f"^{field}: "):
        navigate(**args, **extra)
