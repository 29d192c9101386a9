"""`gcalign allan` on a scenario's data: a recording of any layout, a ``simulate`` results
file, or a simulated scenario. The window's increments go to :func:`gcalign.allan.analyse`;
the fitted terms come back in the units and under the names of the scenario's ``imu`` keys
(``arw_dprh``, ``bias_instability_dph``, …), so that the ``imu`` part of the summary is a
section a scenario runs as it is (``--scenario``).

Conventions of the keys (IEEE Std 952-1997, Annex C):

* ``quantum_arcsec``, ``quantum_ugs``: the quantum q of the increments, q = √12·Q (Q the
  quantization coefficient of σ = √3·Q/τ): the scenario's quantiser.
* ``arw_dprh``, ``vrw_ugrhz``: white rate noise N, σ(1 s) of its −½ line.
* ``bias_instability_dph``, ``bias_instability_ug``: the flat part of σ divided by
  √(2 ln2/π) = 0.664.
* ``bias_rw_dphrh`` ((°/h)/√h), ``bias_rw_ughrh`` (µg/√h): rate random walk K, σ(3 s) of
  its +½ line.
"""

from __future__ import annotations

import math
import time

import numpy as np

from gcalign import units as u
from gcalign.app.command import Outcome
from gcalign.errors import InputError, ScenarioError
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.allan import AllanConfig

SQRT12 = math.sqrt(12.0)
#: (°/h)/√h -> rad/s/√s (rate random walk)
DPHRH = u.DPH / math.sqrt(u.HOUR)
#: µg/√h -> m/s²/√s (acceleration random walk)
UGRH = u.UG / math.sqrt(u.HOUR)

#: Per triad: the term of :data:`gcalign.allan.TERMS` -> (scenario key, factor SI -> key).
KEYS: dict[str, dict[str, tuple[str, float]]] = {
    "gyro": {"quantization": ("quantum_arcsec", SQRT12 / u.ARCSEC),
             "white": ("arw_dprh", 1.0 / u.DPSH),
             "instability": ("bias_instability_dph", 1.0 / u.DPH),
             "rate_rw": ("bias_rw_dphrh", 1.0 / DPHRH)},
    "accel": {"quantization": ("quantum_ugs", SQRT12 / u.UG),
              "white": ("vrw_ugrhz", 1.0 / u.UGPSHZ),
              "instability": ("bias_instability_ug", 1.0 / u.UG),
              "rate_rw": ("bias_rw_ughrh", 1.0 / UGRH)},
}
#: τ at which the summary gives σ (the values one compares across tools)
TAU_POINTS_S = (1.0, 10.0, 100.0)
#: 1-s means of the specific force straying more than this (m/s²) from their median: the
#: base moves or tilts (20 mg: an acceleration of 0.02 g, or a tilt of 1.1°). Measured: the
#: parked, disturbed lasergyro vehicle 4.7 mg over 1847 s (its tilt settles by 0.2°); PSINS's
#: MEMS vehicle on the road 574 mg. The norm |f| alone would miss a horizontal acceleration
#: (1 m/s² changes it by 5 mg).
FORCE_SPREAD = 20e-3 * u.G0


def window(cfg: AllanConfig, n: int, ts: float) -> tuple[int, int]:
    """The samples [k0, k1) of `n` at interval `ts` the section's window takes; a start
    past the end is refused (the preflight's check and the run's)."""
    k0 = int(round(cfg.start_s / ts))
    if k0 >= n:
        raise ScenarioError(f"allan.start_s: {cfg.start_s:g} s is past the end of the data "
                            f"({n * ts:g} s)")
    k1 = n if cfg.duration_s is None else min(n, k0 + int(round(cfg.duration_s / ts)))
    return k0, k1


def _list(a: np.ndarray) -> list:
    """An array as nested lists, NaN (not resolved, not applicable) as None."""
    return [_list(x) if np.ndim(x) else (float(x) if math.isfinite(x) else None) for x in a]


def _terms(fit, triad: str) -> dict:
    """The fitted terms of one triad under their scenario keys, in the keys' units."""
    out = {}
    for name, (key, f) in KEYS[triad].items():
        t = fit.terms[name]
        out[key] = {"value": _list(t.value * f),
                    "interval": _list(np.stack([t.lo * f, t.hi * f], axis=1)),
                    "tau_range_s": _list(t.tau_range),
                    "bound": _list(t.bound * f),
                    "slope": t.slope}
    return out


def imu_section(summary: dict) -> dict:
    """The ``imu`` section a scenario runs as it is: the resolved terms (an axis not resolved
    takes 0), a quantum as the mean of its resolved axes (the scenario's key is one number)."""
    out: dict = {"rate_hz": summary["rate_hz"]}
    for triad in ("gyro", "accel"):
        sec: dict = {}
        for key, term in summary[triad].items():
            v = term["value"]  # plain numbers, None where not resolved (_list)
            resolved = [x for x in v if x is not None]
            if resolved:
                sec[key] = (float(np.mean(resolved)) if key.startswith("quantum")
                            else [0.0 if x is None else x for x in v])
        out[triad] = sec
    return out


def at_rest_warning(sc: Scenario, dtheta: np.ndarray, dv: np.ndarray, ts: float, site,
                    earth, t_a: float, t_b: float) -> tuple[dict, list[str]]:
    """What says whether the window's base was at rest: the spread of the 1-s means of the
    specific force about their median (a base at rest feels the same g throughout), and the
    shared evidence of the recorded-data commands (:func:`gcalign.app.at_rest.evidence`: a
    reference that moves, or the velocity change no base at rest can produce)."""
    from gcalign.app.at_rest import evidence

    per = max(1, int(round(1.0 / ts)))
    k = len(dv) // per
    spread = 0.0
    if k >= 2:
        f = dv[:k * per].reshape(k, per, 3).sum(axis=1) / (per * ts)  # 1-s means (k, 3)
        spread = float(np.linalg.norm(f - np.median(f, axis=0), axis=1).max())
    clauses = []
    if spread > FORCE_SPREAD:
        clauses.append(f"the 1-s means of its specific force stray {spread / u.UG / 1e3:.3g} mg "
                       f"from their median (at rest they stay within "
                       f"{FORCE_SPREAD / u.UG / 1e3:g} mg: an acceleration of 0.02 g or a "
                       "tilt of 1.1°)")
    why = evidence(sc, dtheta, dv, ts, np.asarray(site, float), earth, t_a, t_b)
    if why is not None:
        clauses.append(why)
    record = {"force_spread_mg": spread / u.UG / 1e3, "moving": bool(clauses)}
    if not clauses:
        return record, []
    return record, [f"allan: the Allan deviation takes the IMU to be at rest, but "
                    f"{'; and '.join(clauses)}: the motion enters every fitted term (record "
                    "on a still base, or choose a still window with allan.start_s, "
                    "allan.duration_s)"]


#: RMS distance of the curve from the model, in its 1σ, above which the terms are said not
#: to describe the data
MISFIT = 3.0


def misfit_warnings(misfit: dict) -> list[str]:
    """One warning per triad whose curve the four terms do not describe."""
    out = []
    for triad, values in misfit.items():
        bad = [f"{a} {v:.3g}" for a, v in zip("xyz", values, strict=True)
               if v is not None and v > MISFIT]
        if bad:
            out.append(f"allan: the four noise terms do not describe the {triad} curves "
                       f"(RMS distance from the fitted model in the curve's own 1σ: "
                       f"{', '.join(bad)}; about 1 when they do): something else shapes "
                       "σ(τ) -- a swaying base, a periodic disturbance, a trend -- and the "
                       "fitted values there are not the sensor's noise")
    return out


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            progress=None, recording=None) -> Outcome:
    """Allan deviation and noise terms of the scenario's data (the registry's entry)."""
    from gcalign.allan import analyse
    from gcalign.app.data import scenario_data

    t_start = time.perf_counter()
    data = scenario_data(sc, seed, cache_key, recording)
    imu = data.imu
    if imu.q_bs is not None:
        raise ScenarioError("mechanism: the IMU turns on a mechanism; an Allan deviation "
                            "needs the sensors still (remove the mechanism)")
    ts = imu.ts
    cfg = sc.allan or AllanConfig()
    k0, k1 = window(cfg, len(imu), ts)
    dtheta, dv = imu.dtheta[k0:k1], imu.dv[k0:k1]
    if progress is not None:
        progress(0.0, 1.0, "Allan deviation")
    try:
        res = analyse(dtheta, dv, ts, cfg.per_decade, cfg.min_clusters,
                      None if cfg.fit_tau_s is None else (cfg.fit_tau_s[0], cfg.fit_tau_s[1]))
    except InputError as err:
        if err.field == "tau":
            raise ScenarioError(f"allan.fit_tau_s: {err.message}") from None
        raise ScenarioError(f"allan: the window holds {k1 - k0} samples: {err.message}; "
                            "give a longer window (allan.duration_s) or fewer clusters "
                            "(allan.min_clusters)") from None
    t0 = float(imu.t[0] - ts)
    rest, warnings = at_rest_warning(sc, dtheta, dv, ts, data.site, data.earth,
                                     t0 + k0 * ts, t0 + k1 * ts)
    summary: dict = {
        "scenario": sc.name,
        "source": imu.source,
        "seed": data.seed,
        "samples": k1 - k0,
        "rate_hz": 1.0 / ts,
        "start_s": k0 * ts,
        "duration_s": (k1 - k0) * ts,
        "site_deg_m": [*np.degrees(data.site[:2]).tolist(), float(data.site[2])],
        "header_attitude_deg": None if imu.att0 is None else np.degrees(imu.att0).tolist(),
        "per_decade": cfg.per_decade,
        "min_clusters": cfg.min_clusters,
        "fit_tau_s": cfg.fit_tau_s,
        "mean_rate_dph": (res.mean_rate / u.DPH).tolist(),
        "mean_force_ug": (res.mean_force / u.UG).tolist(),
        "at_rest": rest,
        "gyro": _terms(res.gyro_fit, "gyro"),
        "accel": _terms(res.accel_fit, "accel"),
        "adev_at": {"tau_s": list(TAU_POINTS_S),
                    "gyro_dph": [_list(res.gyro.at(t) / u.DPH) for t in TAU_POINTS_S],
                    "accel_ug": [_list(res.accel.at(t) / u.UG) for t in TAU_POINTS_S]},
        "compute_s": 0.0,
    }
    summary["misfit"] = {"gyro": _list(res.gyro_fit.misfit),
                         "accel": _list(res.accel_fit.misfit)}
    summary["imu"] = imu_section(summary)
    warnings += misfit_warnings(summary["misfit"])
    summary["compute_s"] = time.perf_counter() - t_start

    def write(f) -> None:
        from gcalign.io.stored import write_fields

        write_fields(f.create_group("allan"), res.stored())

    return Outcome(summary, write, None, data.seed, tuple(warnings), result=res)
