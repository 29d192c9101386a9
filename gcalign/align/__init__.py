"""Initial alignment (seed 000): coarse alignment, gyrocompass loop gains, loops and modes.

Modules:

- :mod:`gcalign.align.gyrocompass` -- the public function ``align`` on arrays of
  increments, with ``AlignSettings``, returning an ``Alignment`` (the seed-000 timeline).
- :mod:`gcalign.align.coarse` -- analytic double-vector and inertial-frame coarse alignment.
- :mod:`gcalign.align.gains` -- loop gains by pole placement (seed 000 §2, eqs. 5-9).
- :mod:`gcalign.align.kernel` -- numba kernel of the strapdown gyrocompass loops.
- :mod:`gcalign.align.cycles` -- conventional, full-cycle and half-cycle passes, stages.
- :mod:`gcalign.align.lockstep` -- many runs of one variant (Monte Carlo seeds) through
  the passes together, each run's numbers those of ``align`` to the bit.

Conventions are those of the package (ENU navigation frame, body x right / y forward /
z up, ``att = [pitch, roll, yaw]`` in radians, ``C_nb = Rz(yaw) Rx(pitch) Ry(roll)``).
Import the submodules directly; this package file imports nothing.
"""
