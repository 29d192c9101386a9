r"""Multi-position strapdown gyro north-finding with analytic tilt compensation (seed 001).

A north-finder stands on an indexing turntable. The table turns its platform to ``n``
positions ``θ_i = (i-1)·2π/n`` about the table normal, dwells at each, and averages one
gyro (sensitive axis in the table plane) and two accelerometers (platform x and y). The
harmonics of the readings over one turn give the azimuth of the table's reference axis;
the accelerometer harmonics give the tilt of the table, which leaks the vertical earth
rate into the gyro and must be compensated. This package simulates the table (truth and
sensor errors) and implements the estimators of seed 001 §2, derived again in the
docstrings of the functions that implement them (listed below) because the seed's
formulas are garbled. The same derivation, typeset, is in ``docs/northfind_derivation.md``.

Modules
-------
- :mod:`gcalign.northfind.geometry` -- the tilted table: its frame ``C_nt``, the table
  angles, tilt ↔ pitch/roll, and the noise-free sensor readings (seed eqs. 4–5).
- :mod:`gcalign.northfind.simulate` -- :class:`NorthfindSetup` (validated SI parameters)
  and :func:`simulate_table` (dwell means: exact averaged draw, or every sample in a numba
  kernel).
- :mod:`gcalign.northfind.estimate` -- harmonic least squares (seed eqs. 4–7), tilt from
  the accelerometers (eq. 9) and the azimuth methods of :data:`METHODS` (eqs. 1–3, 8, 10,
  11); :func:`estimate_northfind` is the array route (dwell means of a recorded or
  simulated turn → :class:`NorthfindEstimate`, with the errors when the truth is given).
- :mod:`gcalign.northfind.theory` -- closed-form tilt-induced errors and noise predictions.
- :mod:`gcalign.northfind.run` -- :func:`run_northfind`: simulate, estimate, and compare
  with the truth and the closed forms (:class:`NorthfindResult`).

Every public name is re-exported here (``from gcalign.northfind import run_northfind``).

Frames and truth
----------------
ENU navigation frame n, unit vectors ``E, N, U``; earth rate
``ω_ie^n = Ω [0, cos L, sin L]`` (Ω = ``earth.OMEGA_IE``, L latitude); specific force at
rest ``f^n = g U`` (g = ``earth.gravity(L, h)``).

Table frame t: ``x_t`` (right), ``y_t`` (reference axis, the north-finder's "forward"),
``z_t`` (table normal, up). ``C_nt`` has the columns ``x_t, y_t, z_t`` resolved in ENU, and
is a PSINS body attitude: ``C_nt = Rz(-ψ) Rx(p) Ry(r)`` (:func:`gcalign.nav.rotation.euler_to_dcm`
with ``att = [p, r, -ψ]``). The truth is given by

* ``ψ`` — the *azimuth* of the table: the azimuth (clockwise from true north) of the
  horizontal projection of ``y_t``; it equals ``-yaw`` of the PSINS Euler angles, and is
  what a north-finder must report (seed: "the angle in the horizontal plane");
* ``ε`` — the tilt: the angle between ``z_t`` and ``U``;
* ``ζ`` — the tilt direction: the azimuth toward which the table surface descends (the
  normal leans toward the low side), either fixed to the earth (``"north"``: a sloping
  base under an instrument set at several azimuths) or fixed to the table (``"table"``:
  measured clockwise from the reference axis, ``ζ = ψ + ζ_rel``; a tilted instrument turned
  as a whole, which is what the seed's figures show).

With ``h = [sin ψ, cos ψ, 0]`` and ``d = [sin ζ, cos ζ, 0]`` (see :func:`table_dcm`)::

    z_t = cos ε U + sin ε d,    y_t ∝ h - tan ε cos(ψ-ζ) U,    x_t = y_t × z_t.

Derivations, and where they live
--------------------------------
- Readings (seed eqs. 4–5): ``gcalign.northfind.geometry._ideal_readings``; harmonic least
  squares (seed eqs. 6–7): :func:`fit_harmonics`.
- Tilt (seed eq. 9): :func:`tilt_from_accel`.
- Four azimuth methods, ``coordinate`` (seed eqs. 1–3), ``vector`` (seed eq. 10,
  corrected; ``vector_literal`` as printed), ``naive`` (seed eq. 11), ``none`` (seed eq. 8
  on tilted data): :func:`azimuth_from_harmonics`.
- Closed-form error of ``none`` (seed §1, §3.1) and of ``naive``: :func:`none_error`,
  :func:`naive_error`.
- Noise: :func:`predict_azimuth_std`, :func:`azimuth_std_level`.
- Simulation shortcut (dwell means drawn directly): :func:`simulate_table`.

>>> import numpy as np
>>> setup = NorthfindSetup(azimuths=np.radians([30.0, 200.0]), lat=np.radians(40.0),
...                        tilt=np.radians(5.0), tilt_direction=np.radians(120.0))
>>> res = run_northfind(setup, np.random.default_rng(0))
>>> np.degrees(res.estimate("coordinate")[:, 0]).round(9).tolist()
[30.0, 200.0]
>>> float(np.degrees(np.abs(res.error("none")).max()).round(2))
3.41
"""

from __future__ import annotations

from gcalign.northfind.estimate import (
    METHODS,
    NorthfindEstimate,
    azimuth_from_harmonics,
    estimate_northfind,
    fit_harmonics,
    tilt_from_accel,
)
from gcalign.northfind.geometry import (
    pitch_roll_from_tilt,
    position_angles,
    table_dcm,
    tilt_from_pitch_roll,
)
from gcalign.northfind.run import NorthfindResult, run_northfind
from gcalign.northfind.simulate import (
    NorthfindSetup,
    TableData,
    simulate_table,
)
from gcalign.northfind.theory import (
    azimuth_std_level,
    naive_error,
    none_error,
    predict_azimuth_std,
    predicted_error,
)

__all__ = [
    "METHODS",
    "NorthfindEstimate",
    "NorthfindResult",
    "NorthfindSetup",
    "TableData",
    "azimuth_from_harmonics",
    "azimuth_std_level",
    "estimate_northfind",
    "fit_harmonics",
    "naive_error",
    "none_error",
    "pitch_roll_from_tilt",
    "position_angles",
    "predict_azimuth_std",
    "predicted_error",
    "run_northfind",
    "simulate_table",
    "table_dcm",
    "tilt_from_accel",
    "tilt_from_pitch_roll",
]
