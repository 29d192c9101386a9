"""An independent simulator of a land vehicle with a KF-GINS-grade IMU and GNSS receiver.

It shares no code with gcalign's ``sim/`` or ``nav/`` (it is the second route to the truth
that the aided-navigation benchmark compares both programs with). Conventions are
KF-GINS's: navigation frame NED, body FRD, Euler angles roll, pitch, yaw (ZYX), GNSS
seconds of week; SI and radians inside, KF-GINS's units in its files.

Modules: :mod:`.earth` (WGS-84), :mod:`.route` (the drive: speed, curvature, terrain),
:mod:`.trajectory` (the truth in closed form), :mod:`.imu` (increments and sensor errors),
:mod:`.gnss` (fixes with per-epoch σ and outages), :mod:`.files` (KF-GINS's layouts and
the gcalign scenario), :mod:`.strapdown` (the increments' check), :mod:`.dataset` (one
seeded run of all of it).
"""
