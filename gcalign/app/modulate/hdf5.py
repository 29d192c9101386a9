"""The /modulate group of a results file.

``/modulate`` (attrs ``compare``, ``hours``) holds one group per scheme:

* the navigation series (:func:`gcalign.app.navigate.run.navigate_stream`): ``t``, ``att``,
  ``v_n``, ``pos``, ``error/{att, v_n, pos, phi}``, decimated;
* ``mechanism/``: one cycle of the schedule: ``t``, ``angle`` (turned about each sensor
  axis), ``C_diag`` (diagonal of C_s^r), ``q`` (C_s^r);
* ``invariants/``: the invariant report (:class:`gcalign.modulate.InvariantReport`);
* ``linear/``: the linear error model (static base): ``t``, ``north``, ``east``,
  ``horizontal``, ``phi``, and ``sigma_horizontal`` with noise.
"""

from __future__ import annotations

import numpy as np

from gcalign.io.results import put
from gcalign.io.scenario.modulate import Entry
from gcalign.modulate.analysis import SchemeAnalysis

REF = "reference frame of the scheme (body or navigation), sensor axes in columns"


def _packed(group, name: str, data, units: str, frame: str | None = None, **attrs):
    """A compressed dataset with its units (and frame) attributes."""
    ds = group.create_dataset(name, data=np.asarray(data), compression="gzip", shuffle=True)
    ds.attrs["units"] = units
    if frame:
        ds.attrs["frame"] = frame
    for k, v in attrs.items():
        ds.attrs[k] = v


def write_scheme(g, entry: Entry, analysis: SchemeAnalysis, ts: float) -> None:
    r, lin, cycle = analysis.invariants, analysis.linear, analysis.cycle
    s = entry.scheme
    g.attrs["scheme"] = entry.name
    g.attrs["reference"] = s.reference
    g.attrs["description"] = s.description
    g.attrs["period_s"] = r.period
    g.attrs["imu_ts"] = ts
    g.attrs["mechanism"] = entry.mechanism is not None
    m = g.create_group("mechanism")
    _packed(m, "t", cycle.t, "s", description="time in the cycle")
    _packed(m, "angle", cycle.angle, "rad", "sensor axes x, y, z",
            description="angle turned about each sensor axis since the start of the cycle")
    _packed(m, "C_diag", cycle.C_diag, "", REF, description="diagonal of C_s^r(t)")
    _packed(m, "q", cycle.q, "", REF, description="quaternion of C_s^r(t), scalar first")
    inv = g.create_group("invariants")
    inv.attrs["period_s"] = r.period
    inv.attrs["schuler_period_s"] = r.schuler_period
    inv.attrs["warnings"] = list(r.warnings) or [""]
    for name, units in (("integral_C", "s"), ("mean_C", ""), ("rate_tensor", "rad"),
                        ("abs_rate_integral", "rad"), ("peak_integral_C", "s"),
                        ("residual_gyro_bias", "rad/s"), ("residual_accel_bias", "m/s^2"),
                        ("gyro_bias_excursion", "rad"), ("gyro_bias_offset", "rad"),
                        ("scale_factor_net", "rad"), ("scale_factor_peak", "rad"),
                        ("scale_factor_offset", "rad"), ("misalignment_net", "rad"),
                        ("misalignment_peak", "rad"), ("misalignment_offset", "rad"),
                        ("asym_net", "rad")):
        put(inv, name, getattr(r, name), units, REF)
    if lin is None:
        return
    li = g.create_group("linear")
    put(li, "t", lin.t, "s")
    put(li, "north", lin.north, "m")
    put(li, "east", lin.east, "m")
    put(li, "horizontal", lin.horizontal, "m")
    put(li, "phi", lin.phi, "rad", "ENU")
    if lin.P is not None:
        put(li, "sigma_horizontal", lin.sigma_horizontal, "m",
            description="RMS horizontal error from noise")
