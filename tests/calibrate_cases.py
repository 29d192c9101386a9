"""Trajectories for the calibration tests, built from the ``moving`` motion (velocity along
body y, Euler-angle rates; PSINS ``trjsegment`` style flat turns), at 25 Hz.

* :func:`section_41_set` -- spec 002 §3 "§4.1 set" [X] for Table 1: static 60 s, ground
  roll, pitch-up 15 s to 30°, climb 60 s, level-off, level 60 s, acceleration to 165 m/s,
  roll 9+30+9 s, turn 10+30+10 s (left roll first, right turn first), then 10 s cruise.
* :func:`short_set` -- the same manoeuvres, shorter (162 s), for Monte Carlo runs.
* :func:`designed_590` -- spec 002 §3 [X], the 21-stage, 590 s designed take-off; its
  first 6 stages are the conventional take-off (:func:`conventional`).

Boundaries sit on the 0.04 s grid: the ground roll lasts 13.84 s (13.846 s in the spec)
and the last cruise 74.16 s (74.154 s), so the total stays 590 s.
"""

from __future__ import annotations

import numpy as np

from gcalign.sim.motions import Motion, Segment

D = np.pi / 180.0
TS = 0.04
SITE = np.array([38.0 * D, 110.0 * D, 0.0])  # spec 002 §3: latitude 38°N


def _motion(stages, yaw0=0.0):
    segs = tuple(Segment(d, a, (p * D, r * D, y * D)) for _, d, a, (p, r, y) in stages)
    names = [n for n, *_ in stages]
    return Motion(kind="moving", att0=(0.0, 0.0, yaw0), duration=sum(s.duration for s in segs),
                  segments=segs), names


SECTION_41 = [
    ("static", 60.0, 0.0, (0, 0, 0)),
    ("ground roll", 13.84, 6.5, (0, 0, 0)),
    ("pitch-up", 15.0, 0.0, (2, 0, 0)),
    ("climb", 60.0, 0.0, (0, 0, 0)),
    ("level-off", 15.0, 0.0, (-2, 0, 0)),
    ("level", 60.0, 0.0, (0, 0, 0)),
    ("accelerate", 10.0, 7.5, (0, 0, 0)),
    ("roll left", 9.0, 0.0, (0, -5, 0)),
    ("bank hold", 30.0, 0.0, (0, 0, 0)),
    ("roll right", 9.0, 0.0, (0, 5, 0)),
    ("turn right", 10.0, 0.0, (0, 0, -9)),
    ("turn hold", 30.0, 0.0, (0, 0, 0)),
    ("turn left", 10.0, 0.0, (0, 0, 9)),
    ("cruise", 10.0, 0.0, (0, 0, 0)),
]

SHORT = [
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
]

DESIGNED = [
    ("static", 60.0, 0.0, (0, 0, 0)),
    ("ground roll", 13.84, 6.5, (0, 0, 0)),
    ("pitch-up", 30.0, 0.0, (2, 0, 0)),
    ("climb 60 deg", 64.0, 0.15625, (0, 0, 0)),
    ("level-off", 30.0, 0.0, (-2, 0, 0)),
    ("cruise 100", 40.0, 0.0, (0, 0, 0)),
    ("accelerate", 10.0, 6.5, (0, 0, 0)),
    ("left turn 180", 20.0, 0.0, (0, 0, 9)),
    ("cruise", 30.0, 0.0, (0, 0, 0)),
    ("roll left", 9.0, 0.0, (0, -5, 0)),
    ("bank hold", 30.0, 0.0, (0, 0, 0)),
    ("roll right", 9.0, 0.0, (0, 5, 0)),
    ("cruise", 30.0, 0.0, (0, 0, 0)),
    ("right 90", 10.0, 0.0, (0, 0, -9)),
    ("cruise", 30.0, 0.0, (0, 0, 0)),
    ("left 90", 10.0, 0.0, (0, 0, 9)),
    ("cruise", 30.0, 0.0, (0, 0, 0)),
    ("left turn 180", 20.0, 0.0, (0, 0, 9)),
    ("cruise", 30.0, 0.0, (0, 0, 0)),
    ("decelerate", 10.0, -6.5, (0, 0, 0)),
    ("cruise 100", 74.16, 0.0, (0, 0, 0)),
]


def section_41_set():
    return _motion(SECTION_41)


def short_set():
    return _motion(SHORT)


def designed_590():
    return _motion(DESIGNED)


def conventional():
    return _motion(DESIGNED[:6])
