"""Trajectories for the calibration tests at 25 Hz and 38°N (spec 002 §3): the stage tables
of :mod:`gcalign.calibrate.trajectories`, and a shorter set with the same manoeuvres (162 s)
for Monte Carlo runs."""

from __future__ import annotations

import numpy as np

from gcalign.calibrate.trajectories import CONVENTIONAL, DESIGNED, SECTION_41, moving_motion

TS = 0.04
SITE = np.array([np.radians(38.0), np.radians(110.0), 0.0])

SHORT = (
    ("static", 30.0, 0.0, (0, 0, 0)),
    ("ground roll", 13.84, 6.5, (0, 0, 0)),
    ("pitch-up", 10.0, 0.0, (2, 0, 0)),
    ("climb", 20.0, 0.0, (0, 0, 0)),
    ("level-off", 10.0, 0.0, (-2, 0, 0)),
    ("roll left", 9.0, 0.0, (0, -5, 0)),
    ("bank hold", 10.0, 0.0, (0, 0, 0)),
    ("roll right", 9.0, 0.0, (0, 5, 0)),
    ("turn right", 10.0, 0.0, (0, 0, -9)),
    ("turn hold", 10.0, 0.0, (0, 0, 0)),
    ("turn left", 10.0, 0.0, (0, 0, 9)),
    ("cruise", 10.0, 0.0, (0, 0, 0)),
)


def section_41_set():
    return moving_motion(SECTION_41)


def short_set():
    return moving_motion(SHORT)


def designed_590():
    return moving_motion(DESIGNED)


def conventional():
    return moving_motion(CONVENTIONAL)
