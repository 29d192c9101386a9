"""Stage tables of spec 002 §3 [X] and their ``moving``-motion form (PSINS ``trjsegment``).

A stage is ``(name, duration s, forward acceleration m/s², Euler-angle rates [pitch, roll,
yaw] °/s)``. Velocity is along body y, so turns are flat (PSINS ``turnleft``); a left roll
is negative roll rate, a right turn negative yaw rate.

* :data:`SECTION_41` -- the "§4.1 set" for Table 1: static 60 s, ground roll, pitch-up 15 s
  to 30°, climb 60 s, level-off, level 60 s, acceleration to 165 m/s, roll 9+30+9 s (left
  first), turn 10+30+10 s (right first), then 10 s cruise.
* :data:`DESIGNED` -- the 21-stage, 590 s designed take-off; :data:`CONVENTIONAL` is its
  first 6 stages (static to level cruise), as the seed's §5.2 defines the conventional
  take-off.

On a 25 Hz grid the ground roll lasts 13.84 s (spec: 13.846 s, 90/6.5) and the last cruise
74.16 s (74.154 s), so stage boundaries fall on sample times and the total stays 590 s.
"""

from __future__ import annotations

import math

from gcalign.sim.motions import Moving, Segment

Stage = tuple[str, float, float, tuple[float, float, float]]

SECTION_41: tuple[Stage, ...] = (
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
)

DESIGNED: tuple[Stage, ...] = (
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
)

CONVENTIONAL: tuple[Stage, ...] = DESIGNED[:6]


def moving_motion(stages, yaw0: float = 0.0) -> tuple[Moving, list[str]]:
    """The ``moving`` motion of a stage table, and the stage names. `yaw0` in rad."""
    d = math.pi / 180.0
    segs = tuple(Segment(dur, acc, (p * d, r * d, y * d)) for _, dur, acc, (p, r, y) in stages)
    return (Moving((0.0, 0.0, yaw0), sum(s.duration for s in segs), segs),
            [name for name, *_ in stages])
