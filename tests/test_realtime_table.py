"""Our Table 1 of seed 003 (gcalign.realtime.table) with the default noise model: the
requirements of must-show 5. The seed's semi-physical claims on its own metric are the
built-in run's (tests/test_cli_realtime.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gcalign.realtime import (
    TABLE1,
    Settings,
    rate_case,
    run_case,
    summarise,
    table1,
)
from gcalign.units import ARCSEC, DEG

LIMIT = {"rate": 1.0, "accel": 1.0, "swing": 3.0}  # ″, must-show 5 (rate: hard requirement)


@pytest.fixture(scope="module")
def default_rows():
    return [summarise(r) for r in table1(Settings(), np.random.default_rng(2027))]


@pytest.mark.slow
def test_table_has_the_seed_cases(default_rows):
    assert [r.name for r in default_rows] == [c.name for c in TABLE1]
    assert [r.kind for r in default_rows] == ["rate"] * 4 + ["accel"] * 4 + ["swing"] * 4


def test_before_prediction_within_one_percent_of_the_closed_forms(default_rows):
    for r in default_rows:
        for m in ("truth", "seed"):
            assert r.before[m] == pytest.approx(r.before_theory[m], rel=0.01), (r.name, m)


def test_after_kalman_ls_within_the_requirements(default_rows):
    """≤ 1″ on every uniform-rate case (hard), ≤ 1″ on the ramps away from the corners,
    ≤ 3″ on the swings up to 1 Hz — against the truth and on the seed's metric; taylor is
    reported beside it; the corners separately."""
    for r in default_rows:
        for m in ("truth", "seed"):
            assert r.stats["kalman-ls"].max[m] / ARCSEC <= LIMIT[r.kind], (r.name, m)
            assert r.stats["kalman-ls"].rms[m] <= r.stats["kalman-ls"].max[m]
            assert math.isfinite(r.stats["taylor"].max[m])
            corner = r.stats["kalman-ls"].corner_max[m]
            assert math.isfinite(corner) == (r.kind == "accel")
        # prediction removes at least 99 % of the lag
        assert r.stats["kalman-ls"].max["truth"] < 0.01 * r.stats["none"].max["truth"]


def test_each_case_draws_from_its_own_generator():
    s = Settings()
    cases = [rate_case(f"rate {v}°/s", v * DEG, 3.0) for v in (5, 10, 15)]
    rows = table1(s, np.random.default_rng(4), cases)
    alone = run_case(cases[2], s, np.random.default_rng(4).spawn(3)[2])
    np.testing.assert_array_equal(rows[2].predicted["kalman-ls"], alone.predicted["kalman-ls"])


def test_summary_without_the_none_predictor_still_reports_before():
    s = Settings(predictors=("kalman-ls",))
    row = summarise(run_case(rate_case("rate 10°/s", 10 * DEG, 3.0), s, np.random.default_rng(0)))
    assert set(row.stats) == {"kalman-ls"}
    assert row.before["truth"] == pytest.approx(row.before_theory["truth"], rel=0.01)
