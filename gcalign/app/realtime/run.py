"""Real-time attitude output of a scenario (seed 003; spec 003): every case through the
chain on the core, summarised per the JSON contract of ``gcalign realtime --json``.

``execute(sc, seed)`` turns the ``realtime`` section into core settings and cases and
runs them (:func:`gcalign.realtime.table.run_realtime`: each case on its own child
generator); ``realtime_summary(result, sc, ...)`` is the plain dict that ``--json`` prints,
the results file stores and ``gcalign show`` reprints.

Summary (arc-seconds, milliseconds, degrees). Top level: ``filter_delay_ms`` (the T the
predictors use), ``chain_delay_ms`` (the designed chain's own low-frequency group delay),
``reference`` (``seed``: errors against the INS's own output T later, the seed's
semi-physical metric; ``truth``: against the true attitude at the pulse time), the noise
model and tracker tuning (``model``), ``cases``. Per case: ``name``, ``motion``
(``rate | accel | swing | turntable``), the parameters that apply (``rate_dps``,
``accel_dps2``, ``jerk_dps3``, ``amplitude_deg``, ``frequency_hz``), ``pulses``
(``synchronous | asynchronous``), ``before_max_arcsec`` (the latched attitude's peak error),
``before_slope_arcsec_per_s`` (accel), ``before_theory_*`` (the closed form), per predictor
``after_max_arcsec`` and ``after_rms_arcsec`` (and ``corner_max_arcsec`` on ramps), all on
the reference; the same against the truth under ``truth``; ``lag_ms`` at uniform rate
(seed Fig. 4). Errors are those of the Euler angle the turn moves (``component``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from gcalign import units as u
from gcalign.app.command import Outcome
from gcalign.io.scenario import Scenario
from gcalign.realtime.cases import Case
from gcalign.realtime.chain import CaseResult
from gcalign.realtime.table import CaseSummary, RealtimeResult
from gcalign.realtime.table import run_realtime as core_run
from gcalign.schema import plain

if TYPE_CHECKING:
    import h5py

__all__ = ["execute", "realtime_summary"]

COMPONENTS = ("pitch", "roll", "yaw")


def _user(x: float, unit: float = 1.0) -> float:
    """SI → user units, without the round trip's last-digit noise (15 °/s, not 14.999…)."""
    return float(f"{x / unit:.12g}")


def _motion(case: Case) -> dict:
    s = case.shape
    d = u.DEG
    out: dict = {"motion": s.kind, "axis": None if s.axis is None else list(s.axis),
                 "component": COMPONENTS[case.component], "duration_s": case.duration,
                 "attitude_deg": [_user(a, d) for a in case.att0]}
    if s.kind in ("rate", "accel"):
        out["rate_dps"] = _user(s.rate, d)
    if s.kind == "accel":
        out["accel_dps2"] = _user(s.accel, d)
        out["jerk_dps3"] = None if s.jerk is None else _user(s.jerk, d)
    if s.kind == "swing":
        out["amplitude_deg"] = _user(s.amplitude, d)
        out["frequency_hz"] = _user(s.frequency)
    return out


def _errors(row: CaseSummary, metric: str, kind: str) -> dict:
    """The errors of one case on `metric` (arc-seconds; NaN as None)."""
    def per(part: str) -> dict:  # per predictor
        return {p: plain(getattr(st, part)[metric], "arcsec") for p, st in row.stats.items()}

    out = {"before_max_arcsec": plain(row.before_max[metric], "arcsec"),
           "after_max_arcsec": per("max"), "after_rms_arcsec": per("rms")}
    theory = plain(row.before_theory[metric], "arcsec")
    if kind != "accel":
        return out | {"before_theory_arcsec": theory}
    return out | {"before_slope_arcsec_per_s": plain(row.before[metric], "arcsec"),
                  "before_theory_arcsec_per_s": theory, "corner_max_arcsec": per("corner_max")}


def case_summary(res: CaseResult, row: CaseSummary, reference: str) -> dict:
    """One case of the summary (see the module docstring)."""
    case, p = res.case, res.pulses
    train = case.pulses or res.settings.pulses
    return {"name": case.name, **_motion(case),
            "pulses": "synchronous" if train.mode == "solution" else "asynchronous",
            "pulse_rate_hz": train.rate_hz, "n_pulses": row.n_pulses,
            "dt_us": {"min": float(np.min(p.dt_true)) * 1e6 if len(p) else None,
                      "max": float(np.max(p.dt_true)) * 1e6 if len(p) else None},
            **_errors(row, reference, case.kind),
            "truth": _errors(row, "truth", case.kind),
            "lag_ms": None if not math.isfinite(row.lag) else row.lag * 1e3,
            "seed_before": case.seed_before, "seed_after": case.seed_after}


def realtime_summary(r: RealtimeResult, sc: Scenario, seed: int, compute_s: float) -> dict:
    """Plain-number summary: the JSON contract of ``gcalign realtime --json``."""
    s, chain, cfg, site, T = r.settings, r.chain, sc.realtime, sc.site, r.delay
    assert cfg is not None and site is not None
    f, sen, tr = s.filter, s.sensor, s.tracker
    return {
        "scenario": sc.name,
        "seed": seed,
        "semi_physical": cfg.semi_physical,
        "reference": cfg.reference,
        "filter_delay_ms": T * 1e3,
        "delay_intervals": T / s.tau,
        "chain_delay_ms": chain.delay * 1e3,
        "fir_delay_ms": chain.fir_delay * 1e3,
        "notch_delay_us": chain.notch_delay * 1e6,
        "fs_hz": f.fs_hz,
        "solution_hz": s.solution_hz,
        "predictors": list(s.predictors),
        "site": {"lat_deg": site.lat_deg, "lon_deg": site.lon_deg, "height_m": site.height_m},
        "earth": sc.earth,
        "model": {
            "chain": f.chain,
            "fir_order": f.nav_order if f.chain == "navigation" else f.align_order,
            "fir_cutoff_hz": f.nav_cutoff_hz if f.chain == "navigation" else f.align_cutoff_hz,
            "window": f.window,
            "notch_hz": f.notch_hz if f.chain == "navigation" else None,
            "notch_q": f.notch_q,
            "quantum_arcsec": sen.quantum / u.ARCSEC,
            "arw_dprh": sen.arw / u.DPSH,
            "dither_arcsec": sen.dither_amplitude / u.ARCSEC,
            "dither_hz": sen.dither_hz,
            "qc_rad2ps5": tr.qc,
            "r_std_arcsec": math.sqrt(tr.r) / u.ARCSEC,
            "p0_std": [tr.sigma0[0] / u.ARCSEC, tr.sigma0[1] / u.DEG, tr.sigma0[2] / u.DEG],
        },
        "settle_s": s.settle_s,
        "corner_ms": s.corner_s * 1e3,
        "cases": [case_summary(res, row, cfg.reference)
                  for res, row in zip(r.cases, r.rows, strict=True)],
        "compute_s": compute_s,
    }


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            progress: Callable[[int, int, str], None] | None = None) -> Outcome:
    """Every case of the scenario's ``realtime`` section through the chain on the core
    (each case on its own child generator), summarised; the registry's entry point
    (`progress`: one report per case; the preflight checked the section is there)."""
    cfg = sc.realtime
    assert cfg is not None
    cases = cfg.cases_of(sc)  # refuses a value the chain cannot use, naming the field
    settings = cfg.to_settings()
    seed = sc.imu.seed if seed is None else int(seed)  # checked by the registry's run
    assert sc.site is not None  # checked by cases_of
    t0 = time.perf_counter()
    r = core_run(settings, np.random.default_rng(seed), cases, site=sc.site.to_si(),
                 earth=sc.earth_model, progress=progress)
    summary = realtime_summary(r, sc, seed, time.perf_counter() - t0)
    return Outcome(summary, lambda f: write_realtime(f, r, cfg.reference), None, seed,
                   result=r)


def write_realtime(f: h5py.File, r: RealtimeResult, reference: str) -> None:
    """/realtime: the run's settings; ``filter``, the chain's response (its fields say how);
    ``cases/NN``, each case's motion and pulse train, and its per-pulse records (CaseResult's
    fields say how)."""
    from gcalign.io.stored import write_fields

    s = r.settings
    g = f.create_group("realtime")
    g.attrs.update(reference=reference, delay=r.delay, chain_delay=r.chain_delay,
                   solution_hz=s.solution_hz, fs_hz=s.filter.fs_hz,
                   predictors=",".join(s.predictors), settle_s=s.settle_s,
                   corner_s=s.corner_s,
                   units="delay, chain_delay, settle_s, corner_s: s; solution_hz, fs_hz: Hz")
    write_fields(g.create_group("filter"), r.chain.on_grid())
    cases = g.create_group("cases")
    for i, res in enumerate(r.cases):
        c, case = cases.create_group(f"{i:02d}"), res.case
        train = case.pulses or s.pulses
        c.attrs.update(name=case.name, kind=case.kind, component=case.component,
                       axis=np.asarray(case.shape.axis if case.shape.axis else [np.nan] * 3),
                       seed_before=case.seed_before, seed_after=case.seed_after,
                       pulses=train.mode, pulse_rate_hz=train.rate_hz,
                       rate=case.shape.rate, duration=case.duration)
        write_fields(c, res)
