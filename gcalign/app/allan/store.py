"""The ``/allan`` group of a results file: per triad (``gyro``, ``accel``) the curve (τ, σ,
its 1σ interval, the clusters), the fitted model and each term's value, interval and τ range
(SI, with units), readable with plain h5py."""

from __future__ import annotations

import numpy as np

from gcalign.allan import AllanResult, NoiseFit
from gcalign.allan.curve import AllanCurve
from gcalign.io.results import put

#: SI units of σ and of each term's coefficient, per triad
UNITS = {
    "gyro": {"sigma": "rad/s", "quantization": "rad", "white": "rad/sqrt(s)",
             "instability": "rad/s", "rate_rw": "rad/s/sqrt(s)"},
    "accel": {"sigma": "m/s^2", "quantization": "m/s", "white": "m/s/sqrt(s)",
              "instability": "m/s^2", "rate_rw": "m/s^2/sqrt(s)"},
}
MEANING = {
    "quantization": "Q: sigma = sqrt(3) Q / tau (quantum q = sqrt(12) Q)",
    "white": "N (ARW/VRW): sigma = N / sqrt(tau)",
    "instability": "B: flat sigma = 0.6643 B (sqrt(2 ln2 / pi))",
    "rate_rw": "K: sigma = K sqrt(tau / 3)",
}


def _triad(g, curve: AllanCurve, fit: NoiseFit, units: dict) -> None:
    frame = "sensor axes x, y, z"
    put(g, "tau", curve.tau, "s")
    put(g, "adev", curve.adev, units["sigma"], frame)
    put(g, "adev_lo", curve.lo, units["sigma"], frame, what="1 sigma, 1/sqrt(2(K-1))")
    put(g, "adev_hi", curve.hi, units["sigma"], frame, what="1 sigma, 1/sqrt(2(K-1))")
    put(g, "clusters", curve.clusters.astype(np.int64), "", what="K = floor(N/m)")
    put(g, "model", fit.model(curve.tau), units["sigma"], frame,
        what="sqrt of the sum of the four fitted terms")
    for name, t in fit.terms.items():
        tg = g.create_group(f"terms/{name}")
        tg.attrs["slope"] = t.slope
        tg.attrs["meaning"] = MEANING[name]
        put(tg, "value", t.value, units[name], frame, what="NaN: not resolved")
        put(tg, "interval", np.stack([t.lo, t.hi], axis=1), units[name], frame,
            what="1 sigma [lo, hi]")
        put(tg, "bound", t.bound, units[name], frame, what="not resolved: the largest "
            "coefficient the curve allows; NaN where resolved")
        put(tg, "tau_range", t.tau_range, "s", frame)


def write_allan(f, res: AllanResult) -> None:
    """Write ``/allan`` into an open results file."""
    g = f.create_group("allan")
    g.attrs["samples"] = res.gyro.samples
    g.attrs["ts"] = res.gyro.ts
    if res.fit_tau is not None:
        g.attrs["fit_tau_s"] = np.asarray(res.fit_tau, float)
    _triad(g.create_group("gyro"), res.gyro, res.gyro_fit, UNITS["gyro"])
    _triad(g.create_group("accel"), res.accel, res.accel_fit, UNITS["accel"])
