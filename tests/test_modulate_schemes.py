"""Rotation schemes as data (gcalign.modulate.schemes): the built-in tables against the
seed's and PSINS's listings, user rows in user units, and bad input named by row and field.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.errors import ScenarioError
from gcalign.modulate.schemes import (
    BUILTIN_NAMES,
    Row,
    Turn,
    builtin_rows,
    builtin_scheme,
    rows_from_dicts,
    scheme_from_rows,
)

DEG = math.pi / 180.0
A = np.eye(3)
B = np.diag([-1.0, -1.0, 1.0])  # Rz(π)
C = np.diag([-1.0, 1.0, -1.0])  # Ry(π)
D = np.diag([1.0, -1.0, -1.0])  # Rx(π)


def dwell_positions(scheme):
    """C at the middle of each row's dwell (the position the row ends at)."""
    s = scheme.schedule
    ends = np.cumsum([st.duration for st in s.steps])
    mids = ends - 0.5 * np.array([st.dwell for st in s.steps])
    return s.dcm(mids)


def test_seed12_visits_the_patent_positions():
    """Spec §2 table, 'path' row: B C A C B A B C A C B A, with A = I, B = Rz(π), C = Ry(π);
    the patent's timing (Ts 300 s, 180° in 4 + 4 + 4 s) gives a 3744 s cycle."""
    s = builtin_scheme("seed-12")
    expected = [B, C, A, C, B, A, B, C, A, C, B, A]
    np.testing.assert_allclose(dwell_positions(s), expected, atol=1e-15)
    assert s.period == 3744.0 and s.reference == "navigation"
    axes = "".join("xyz"[int(np.argmax(np.abs(r.axis)))] for r in s.rows)
    assert axes == "zxyyxzzxyyxz"  # spec §2 'axis' row
    assert [round(r.angle / DEG) for r in s.rows] == [180] * 6 + [-180] * 6  # ccw ×6, cw ×6
    # 5.625 °/s² and 22.5 °/s (spec §2 [R])
    p = s.schedule.steps[0].profile.pieces
    assert p[0].accel == pytest.approx(5.625 * DEG) and p[1].rate == pytest.approx(22.5 * DEG)


def test_four_position_12_visits_each_of_four_positions_three_times():
    """Spec §2 [P]: A→B, B→C, C→A, A→D, D→B, B→A, A→C, C→B, B→D, D→C, C→D, D→A."""
    s = builtin_scheme("four-position-12")
    expected = [B, C, A, D, B, A, C, B, D, C, D, A]
    np.testing.assert_allclose(dwell_positions(s), expected, atol=1e-15)
    assert all(r.angle > 0 for r in s.rows)  # one sense throughout (slip rings)


def test_four_position_24_is_the_forward_reverse_version():
    s24, s12 = builtin_scheme("four-position-24"), builtin_scheme("four-position-12")
    assert s24.period == pytest.approx(124.8 * 60)  # spec §2: 124.8 min
    np.testing.assert_allclose(dwell_positions(s24), np.concatenate([dwell_positions(s12)] * 2),
                               atol=1e-15)
    assert [r.angle for r in s24.rows[12:]] == [-r.angle for r in s12.rows]


# PSINS test_RSINS_2_axis.m, rows 1–16 (axis, degrees) before its x → y swap.
PSINS_DUAL_16 = [("z", 180), ("x", -180), ("z", 180), ("x", -180), ("x", -180), ("z", 180),
                 ("x", -180), ("z", 180), ("z", -180), ("x", 180), ("z", -180), ("x", 180),
                 ("x", 180), ("z", -180), ("x", 180), ("z", -180)]


@pytest.mark.parametrize("name", ["dual-16", "dual-16-improved"])
def test_dual_16_follows_psins(name):
    rows = PSINS_DUAL_16
    if name == "dual-16-improved":  # paras(9:16,:) = paras([10,9,12,11,14,13,16,15],:)
        rows = rows[:8] + [rows[k - 1] for k in (10, 9, 12, 11, 14, 13, 16, 15)]
    s = builtin_scheme(name)
    got = [("xyz"[int(np.argmax(np.abs(r.axis)))], round(r.angle / DEG)) for r in s.rows]
    assert got == rows
    assert s.period == 16 * 312.0 and s.period / 60 == pytest.approx(83.2)  # spec §3
    # dwell positions: the group {I, Rz, Ry, Rx}, each four times (spec §3)
    pos = dwell_positions(s)
    for M in (A, B, C, D):
        assert sum(np.allclose(p, M, atol=1e-12) for p in pos) == 4


def test_single_4_and_continuous():
    s = builtin_scheme("single-4")
    assert [round(r.angle / DEG) for r in s.rows] == [180, -180, -180, 180]
    assert s.period == 4 * 312.0
    c = builtin_scheme("continuous", rate=10 * DEG, axis="x")
    assert c.period == pytest.approx(36.0)
    np.testing.assert_allclose(c.schedule.rate(np.array([5.0])), [[10 * DEG, 0, 0]])
    f = builtin_scheme("fixed", dwell=100.0)
    np.testing.assert_allclose(f.schedule.dcm(np.array([0.0, 50.0, 321.0])), [A] * 3)


def test_every_builtin_returns_to_its_start():
    for name in BUILTIN_NAMES:
        s = builtin_scheme(name)
        q = s.schedule.cycle_rotation
        assert abs(abs(q[0]) - 1.0) < 1e-15, name
        t = np.array([0.0, s.period, 3 * s.period])
        np.testing.assert_allclose(s.schedule.dcm(t), [A] * 3, atol=1e-13)


def test_user_rows_in_user_units_make_the_same_schedule():
    """The seed-12 table written as user rows, in each profile form, gives the built-in's
    rotation at any time; the three forms describe the same 4 + 4 + 4 s turn."""
    forms = [
        {"t_accel_s": 4, "t_const_s": 4, "t_decel_s": 4},
        {"t_turn_s": 12, "t_accel_s": 4, "t_decel_s": 4},
        {"rate_dps": 22.5, "accel_dps2": 5.625},
    ]
    ref = builtin_scheme("seed-12").schedule
    t = np.random.default_rng(1).uniform(0, 2 * ref.period, 200)
    for form in forms:
        rows = [{"axis": a, "angle_deg": sign * 180, "dwell_s": 300, **form}
                for a, sign in zip("zxyyxzzxyyxz", [1] * 6 + [-1] * 6, strict=True)]
        s = scheme_from_rows(rows, name="mine", reference="navigation")
        assert s.period == pytest.approx(3744.0, abs=1e-9)
        np.testing.assert_allclose(s.schedule.dcm(t), ref.dcm(t), atol=1e-9)


def test_user_row_forms():
    rows = rows_from_dicts([
        {"axis": [0.6, 0.8, 0.0], "angle_deg": 90, "rate_dps": 10},   # constant rate, 9 s
        {"axis": "-z", "angle_deg": -90, "t_accel_s": 1, "t_decel_s": 1},  # triangle
        {"axis": "x", "dwell_s": 5},                                  # pure dwell
    ])
    assert rows[0].rate == pytest.approx(10 * DEG) and rows[0].accel is None
    assert rows[0].step().duration == pytest.approx(9.0)
    assert rows[1].axis == (0.0, 0.0, -1.0) and rows[1].t_const == 0.0
    assert rows[1].step().duration == pytest.approx(2.0)
    assert rows[2].angle == 0.0 and rows[2].step().duration == 5.0


@pytest.mark.parametrize("rows, match", [
    ([{"axis": "z", "angle_deg": 180, "t_accel_s": 4, "t_const_s": 4, "t_decel_s": 4,
       "dwell_s": -1}], r"row 1: dwell_s: must be ≥ 0"),
    ([{"axis": "z", "angle_deg": 180, "t_turn_s": 6, "t_accel_s": 4, "t_decel_s": 4}],
     r"row 1: t_turn_s: the turn \(6 s\) is shorter than its acceleration plus deceleration"),
    ([{"axis": [1, 1, 0], "angle_deg": 180, "rate_dps": 10}],
     r"row 1: axis: .*norm 1\.41421.*unit vector"),
    ([{"axis": "w", "angle_deg": 180, "rate_dps": 10}], r"row 1: axis: got 'w'"),
    ([{"axis": "z", "angle_deg": 180, "rate_dps": 10, "dwell": 3}], r"row 1: dwell: unknown key"),
    ([{"axis": "z", "angle_deg": 90, "dwell_s": 3}], r"row 1: angle_deg: .*needs a profile"),
    ([{"axis": "z", "angle_deg": 360, "rate_dps": 10},
      {"axis": "x", "angle_deg": 180, "rate_dps": -5}], r"row 2: rate_dps: must be > 0"),
    ([{"axis": "z", "angle_deg": 180, "rate_dps": 10, "dwell_s": 1},
      {"axis": "x", "angle_deg": 180, "rate_dps": 10}],
     r"does not return the IMU to its start: .* 180 deg about"),
    ([], r"empty"),
])
def test_bad_rows_are_named(rows, match):
    with pytest.raises(ScenarioError, match=match) as e:
        scheme_from_rows(rows)
    assert isinstance(e.value, ValueError) and e.value.exit_code == 2


def test_bad_si_rows_and_builtins_are_named():
    good = Row((0.0, 0.0, 1.0), math.pi, 10.0, t_accel=4, t_const=4, t_decel=4)
    with pytest.raises(ScenarioError, match=r"row 2: dwell_s: must be ≥ 0"):
        scheme_from_rows([good, Row((0.0, 0.0, 1.0), -math.pi, -2.0, rate=1.0)])
    with pytest.raises(ScenarioError, match=r"row 1: axis: .*unit vector"):
        scheme_from_rows([Row((0.0, 0.0, 2.0), 0.0, 10.0)])
    with pytest.raises(ScenarioError, match=r"row 1: angle: a turn of .* needs a profile"):
        scheme_from_rows([Row((0.0, 0.0, 1.0), math.pi, 10.0)])
    with pytest.raises(ScenarioError, match=r"unknown scheme 'seed-13'; built-in: fixed, "):
        builtin_scheme("seed-13")
    with pytest.raises(ScenarioError, match=r"dwell_s: must be ≥ 0"):
        builtin_rows("seed-12", dwell=-5.0)
    with pytest.raises(ScenarioError, match=r"reference: got 'earth'"):
        scheme_from_rows([good, good], reference="earth")
    # a turn with a given timing and dwell 0 is fine (continuous indexing)
    s = builtin_scheme("four-position-12", dwell=0.0, turn=Turn(2.0, 0.0, 2.0))
    assert s.period == pytest.approx(48.0)
