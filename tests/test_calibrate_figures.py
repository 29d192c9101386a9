"""The calibrate figures say what the run was and show every curve whole: the attitude
figure of a file-aided recording names its aiding (it said "zero-velocity updates") and
holds the whole pitch curve (its limits came from the second half and cut the first);
sigma.png draws a group that learnt almost nothing (scale factors held at a 1 ppm prior)
as 1 − σ/σ0, where its ticks read "10 × 10⁻¹" each."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from gcalign.cli import app

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow  # a 100 s calibration of the recording (several s)


@pytest.fixture(scope="module")
def figs(tmp_path_factory):
    from gcalign.app.calibrate.plots import figures

    out = tmp_path_factory.mktemp("cal") / "c.h5"
    res = CliRunner().invoke(app, ["calibrate", str(ROOT / "configs/mems_fog_calibrate.yaml"),
                                   "-o", str(out)])
    assert res.exit_code == 0, res.output
    with h5py.File(out) as f:
        att = f["calibrate/runs"][sorted(f["calibrate/runs"])[0]]["att"][()]
        return figures(f, "mems"), np.degrees(att)


def test_attitude_figure_names_the_file_aiding_and_holds_the_whole_curves(figs):
    fg, att = figs
    fig = fg["attitude"]
    title = fig.texts[0].get_text()
    assert "velocity and position from a file" in title and "zero-velocity" not in title
    for ax, j in zip(fig.axes[:3], range(3), strict=True):
        lo, hi = ax.get_ylim()
        assert lo <= att[:, j].min() and att[:, j].max() <= hi, (j, (lo, hi))


def test_sigma_panels_read_plain_numbers(figs):
    fg, _ = figs
    fig = fg["sigma"]
    fig.canvas.draw()
    for ax in fig.axes[:4]:
        labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
        assert len(set(labels)) == len(labels) >= 2, (ax.get_title(), labels)
    held = [ax for ax in fig.axes[:4] if "within 1 % of P0" in ax.get_title()]
    assert [ax.get_title().split(" —")[0] for ax in held] == [
        "gyro scale factor δKg", "accelerometer scale factor δKa"]
    assert all(ax.get_ylabel() == "1 − σ / σ0" for ax in held)


def test_innovations_title_names_the_panels_drawn_and_the_aiding(figs):
    """A recording has no truth, so no NEES panel: the title must not promise one."""
    fig = figs[0]["innovations"]
    title = fig.texts[0].get_text()
    assert len(fig.axes) == 2 and "NEES" not in title
    assert "NIS (velocity and position from a file)" in title
