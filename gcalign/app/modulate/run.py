"""`gcalign modulate`: strapdown navigation on a turning IMU, the same data with and without
modulation (seed 004; spec 004 §4–§6).

For each scheme of the plan (:func:`gcalign.io.scenario.modulate.plan_of`) the scenario's
motion is simulated with the IMU on that scheme's mechanism (``fixed``: on the body), with
the same sensor errors and the same noise seed, and navigated by
:func:`gcalign.app.navigate.run.run_navigation`: increments exact through every turn, errors
in the sensor frame, the body attitude through the mechanism angles, height held (vertical
``auto``), errors against truth at every sample. Beside each run: the scheme's invariant
report (:mod:`gcalign.modulate.invariants`) and, on a static base, the linear error model
(:mod:`gcalign.modulate.linear`) for the same errors, so that the two routes can be
compared number by number.

Stored series (HDF5, ``/modulate/<scheme>``) are decimated: 1 Hz up to 4 h, 0.1 Hz beyond,
unless ``output.rate_hz`` says otherwise; the horizontal error at the report hours is read
from the stored rows, so the rate must put each report hour on its grid.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from gcalign.app.command import Outcome
from gcalign.app.navigate.run import run_navigation
from gcalign.errors import ScenarioError
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.modulate import Entry, Plan, default_rate_hz, plan_of
from gcalign.io.scenario.navigation import NavigationConfig, OutputConfig
from gcalign.modulate.analysis import SchemeAnalysis, analyse_scheme
from gcalign.modulate.invariants import InvariantReport
from gcalign.modulate.linear import REPORT_HOURS, LinearErrors
from gcalign.modulate.terms import ErrorTerms
from gcalign.schema import plain, summary_of
from gcalign.units import ARCSEC, DPH, DPSH, HOUR, PPM, UG, UGPSHZ

Progress = Callable[[float, float, str], None]  # (done, total, what)


def hour_key(h: float) -> str:
    return f"{h:g}h"


def report_hours(hours: float) -> list[float]:
    """The report hours within a run of `hours` h, and the run's last hour always."""
    within = [h for h in REPORT_HOURS if h <= hours + 1e-9]
    return within if within and abs(within[-1] - hours) <= 1e-9 else within + [hours]


def seed_scenario(compare: Iterable[str], *, rate: float = 10.0,
                  hours: float = 72.0, gyro: dict | None = None, accel: dict | None = None,
                  mechanism: dict | None = None, navigation: dict | None = None, seed: int = 1,
                  linear: bool = True,
                  source: str = "seed004") -> Scenario:
    """The built-in seed 004 scenario (gcalign/scenarios/seed004_modulation.yaml) with the
    given changes, errors in user units (``imu.gyro``/``imu.accel`` sections replace the
    seed's): the cases of the tests and of docs/results_modulate.py. Default 10 Hz, which
    gives the seed's 100 Hz numbers on a static base (tests/test_modulate_navigation.py)."""
    from importlib import resources

    import yaml

    from gcalign.io.scenario import parse_scenario

    text = resources.files("gcalign.scenarios").joinpath("seed004_modulation.yaml").read_text(
        encoding="utf-8")
    d = yaml.safe_load(text)
    d["imu"].update(rate_hz=rate, seed=seed)
    for key, section, value in (("gyro", "imu", gyro), ("accel", "imu", accel),
                                ("mechanism", None, mechanism),
                                ("navigation", None, navigation)):
        if value is not None:
            (d[section] if section else d)[key] = value
    d["modulate"] = {"compare": list(compare), "hours": hours, "linear": linear}
    return parse_scenario(d, source)


def variant(sc: Scenario, entry: Entry, plan: Plan) -> Scenario:
    """The scenario one scheme runs: its mechanism, the plan's duration (a static base lasts
    that long), and the stored-series rate."""
    v = sc.model_copy(deep=True)
    assert v.motion is not None
    if v.motion.kind == "static":
        v.motion = v.motion.model_copy(update={"duration_s": plan.duration_s})
    v.mechanism = entry.mechanism
    nav = v.navigation or NavigationConfig()
    v.navigation = nav.model_copy(update={"duration_s": plan.duration_s, "start_s": 0.0})
    if v.output.rate_hz is None:
        v.output = OutputConfig(rate_hz=default_rate_hz(plan.duration_s, sc.imu.rate_hz))
    return v


def _stride_checked(v: Scenario, hours: list[float]) -> int:
    stride = v.output.stride(v.imu.rate_hz, 0.0)
    for h in hours:
        n = h * HOUR * v.imu.rate_hz
        if abs(n - round(n)) > 1e-6 or round(n) % stride:
            raise ScenarioError(f"output.rate_hz: {v.output.rate_hz} Hz does not store a row at "
                                f"{h:g} h; modulate needs a rate whose period divides 1 h")
    return stride


class HourProbe:
    """Collects, from the stored rows as they stream by, the horizontal position error at the
    report hours (m) and its RMS over the stored rows (m)."""

    def __init__(self, hours: list[float]):
        self.t = np.array([h * HOUR for h in hours])
        self.keys = [hour_key(h) for h in hours]
        self.value: dict[str, float] = {}
        self._sum_sq, self._n = 0.0, 1  # the start row (zero error) is a stored row too

    def __call__(self, rows: dict) -> None:
        t, pos = rows["t"], rows["error/pos"]
        horizontal = np.hypot(pos[:, 0], pos[:, 1])
        self._sum_sq += float(np.sum(horizontal**2))
        self._n += len(horizontal)
        k = np.searchsorted(t, self.t - 1e-6)
        for key, tk, i in zip(self.keys, self.t, k, strict=True):
            if i < len(t) and abs(t[i] - tk) < 1e-6:
                self.value[key] = float(horizontal[i])

    @property
    def rms(self) -> float:
        return math.sqrt(self._sum_sq / self._n)


def error_terms(sc: Scenario, entry: Entry) -> ErrorTerms:
    """The sensor errors of the scenario as the linear model and the invariants take them."""
    e = sc.imu.errors()
    lever = entry.mechanism.lever() if entry.mechanism is not None else None
    return ErrorTerms.of_sensors(e.gyro, e.accel, (0.0, 0.0, 0.0) if lever is None else lever)


def _clean(v: np.ndarray, scale: float) -> np.ndarray:
    """Entries below 1e-12 of `scale` (round-off of a cancelling sum) as 0."""
    return np.where(np.abs(v) <= 1e-12 * scale, 0.0, v)


def invariants_summary(r: InvariantReport, rotated: bool = True) -> dict:
    """The invariants in user units; an unrotated scheme has no cycle (``cycle_s`` None)."""
    e = r.errors
    return {
        "cycle_s": r.period if rotated else None,
        "cycle_mean": _clean(r.mean_C, 1.0).tolist(),
        "residual_gyro_bias_dph": (_clean(r.residual_gyro_bias, np.abs(e.gyro_bias).sum())
                                   / DPH).tolist(),
        "residual_accel_bias_ug": (_clean(r.residual_accel_bias, np.abs(e.accel_bias).sum())
                                   / UG).tolist(),
        **summary_of(r),  # the invariants whose fields name a summary unit
        "asym_drift_dph": (r.asym_net / r.period / DPH).tolist(),
        "schuler_period_s": r.schuler_period,
        "schuler_warnings": list(r.warnings),
    }


def _linear_at(lin: LinearErrors, h: float) -> float | None:
    """The linear model's horizontal error at `h` hours, None if that is not an output time."""
    try:
        return float(lin.at(h)[0])
    except ValueError:
        return None


def linear_summary(lin: LinearErrors, hours: list[float]) -> dict:
    return {
        "horizontal_error_m": {hour_key(h): _linear_at(lin, h) for h in hours},
        "max_horizontal_error_m": float(lin.horizontal.max()),
        "final_horizontal_error_m": float(lin.horizontal[-1]),
        "max_misalignment_arcsec": plain(np.abs(lin.phi).max(0), "arcsec"),
        "sigma_horizontal_final_m": float(lin.sigma_horizontal[-1]),
    }


def run_scheme(sc: Scenario, entry: Entry, plan: Plan, seed: int | None, group: Any = None,
               linear: bool = True, progress: Progress | None = None
               ) -> tuple[dict, SchemeAnalysis]:
    """Navigate one scheme and analyse it (:func:`gcalign.modulate.analyse_scheme`); its
    summary and the analysis. `group`: an h5py group for the series, the invariants, the
    mechanism cycle and the linear model; `progress(done_s, total_s, what)` hears of every
    block navigated."""
    hours = report_hours(plan.hours)
    v = variant(sc, entry, plan)
    _stride_checked(v, [h for h in hours if h in REPORT_HOURS])  # the last: its final row
    probe = HourProbe(hours)
    nav, stream = run_navigation(v, seed, None, group, on_rows=probe, progress=progress)
    terms = error_terms(sc, entry)
    assert sc.site is not None and sc.motion is not None
    static = linear and sc.motion.kind == "static"
    analysis = analyse_scheme(entry.scheme, terms, lat=float(sc.site.to_si()[0]),
                              earth=sc.earth_model,
                              att0=np.radians(sc.motion.attitude_deg) if static else None,
                              duration=plan.duration_s, name=entry.name)
    report, lin = analysis.invariants, analysis.linear
    me, fe = nav["max_error"], nav["final_error"]
    final = float(math.hypot(*fe["position_m"][:2]))  # the last hour if off the stored grid
    s = entry.scheme
    out = {
        "description": s.description,
        "reference": s.reference,
        "mechanism": entry.mechanism is not None,
        **invariants_summary(report, rotated=entry.mechanism is not None),
        "horizontal_error_m": {k: probe.value.get(k, final) for k in probe.keys},
        "max_horizontal_error_m": nav["max_horizontal_error_m"],
        "final_horizontal_error_m": final,
        "rms_horizontal_error_m": probe.rms,
        "max_misalignment_arcsec": [3600.0 * x for x in me["misalignment_deg"]],
        "max_attitude_error_arcsec": [3600.0 * x for x in me["attitude_deg"]],
        "final_misalignment_arcsec": [3600.0 * x for x in fe["misalignment_deg"]],
        "max_velocity_error_mps": me["velocity_mps"],
        "linear": None if lin is None else linear_summary(lin, hours),
        "compute_s": nav["compute_s"],
    }
    if group is not None:  # the scheme, then the analysis as its fields say
        from gcalign.io.stored import write_fields

        group.attrs.update(scheme=entry.name, reference=s.reference, description=s.description,
                           period_s=report.period, imu_ts=stream.ts, mechanism=out["mechanism"])
        write_fields(group, analysis)
        group["invariants"].attrs["warnings"] = list(report.warnings) or [""]
        if lin is not None:
            write_fields(group.create_group("linear"), lin.series())
    return out, analysis


def ratios_to_fixed(schemes: dict[str, dict], last: str) -> None:
    """Beside each rotated scheme, how many times smaller its horizontal error is than the
    unrotated run's (``fixed`` in the comparison): at the last report hour (one instant of an
    oscillating curve), of the whole-run maxima and of the RMS over the stored rows."""
    ref = schemes.get("fixed")
    for name, r in schemes.items():
        if ref is None or name == "fixed":
            r["ratio_to_fixed"] = None
            continue
        pairs = {"last_hour": (ref["horizontal_error_m"].get(last),
                               r["horizontal_error_m"].get(last)),
                 "max": (ref["max_horizontal_error_m"], r["max_horizontal_error_m"]),
                 "rms": (ref["rms_horizontal_error_m"], r["rms_horizontal_error_m"])}
        r["ratio_to_fixed"] = {k: (a / b if a is not None and b else None)
                               for k, (a, b) in pairs.items()}


def errors_summary(sc: Scenario, lever_cm: Any) -> dict:
    e = sc.imu.errors()
    g, a = e.gyro, e.accel
    return {
        "gyro_bias_dph": (g.bias / DPH).tolist(), "accel_bias_ug": (a.bias / UG).tolist(),
        "gyro_scale_ppm": (g.scale / PPM).tolist(), "accel_scale_ppm": (a.scale / PPM).tolist(),
        "gyro_asym_ppm": (g.asym / PPM).tolist(), "accel_asym_ppm": (a.asym / PPM).tolist(),
        "gyro_misalignment_arcsec": (g.misalignment / ARCSEC).tolist(),
        "accel_misalignment_arcsec": (a.misalignment / ARCSEC).tolist(),
        "arw_dprh": (g.noise / DPSH).tolist(), "vrw_ugrhz": (a.noise / UGPSHZ).tolist(),
        "lever_arm_cm": lever_cm,
    }


def run_modulate(sc: Scenario, seed: int | None = None, sink: Any = None,
                 progress: Progress | None = None
                 ) -> tuple[dict, tuple[str, ...], dict[str, SchemeAnalysis]]:
    """Every scheme of the plan; the summary (plain numbers), the warnings and the analysis
    of each scheme by name. `progress(done_s, total_s, what)` hears of every block of every
    scheme (one stage per scheme)."""
    t0 = time.perf_counter()
    plan = plan_of(sc)
    cfg = sc.modulate
    linear = True if cfg is None else cfg.linear
    root = None if sink is None else sink.create_group("modulate")
    schemes: dict[str, dict] = {}
    analyses: dict[str, SchemeAnalysis] = {}
    warnings: list[str] = []
    n = len(plan.entries)
    for i, entry in enumerate(plan.entries):
        group = None if root is None else root.create_group(entry.name)
        what = f"{entry.name} {i + 1}/{n}" if n > 1 else entry.name  # counts: data s
        stage = None if progress is None else (
            lambda done, total, _, p=progress, w=what: p(done, total, w))
        r, analyses[entry.name] = run_scheme(sc, entry, plan, seed, group, linear, stage)
        schemes[entry.name] = r
        warnings += [f"{entry.name}: {w}" for w in r["schuler_warnings"]]
    assert sc.site is not None and sc.motion is not None
    if linear and sc.motion.kind != "static":
        warnings.append(f"linear model: static base only; motion {sc.motion.kind!r} runs the "
                        "navigation alone")
    lever = next((e.mechanism.lever_arm_cm for e in plan.entries
                  if e.mechanism is not None and e.mechanism.lever_arm_cm is not None), None)
    names = [e.name for e in plan.entries]
    ratios_to_fixed(schemes, hour_key(report_hours(plan.hours)[-1]))
    if root is not None:
        root.attrs["compare"] = names
        root.attrs["hours"] = plan.hours
    summary = {
        "scenario": sc.name,
        "seed": sc.imu.seed if seed is None else seed,
        "earth": sc.earth,
        "site_deg_m": [sc.site.lat_deg, sc.site.lon_deg, sc.site.height_m],
        "motion": sc.motion.kind,
        "rate_hz": sc.imu.rate_hz,
        "hours": plan.hours,
        "report_hours": report_hours(plan.hours),
        "errors": errors_summary(sc, lever),
        "compare": names,
        "schemes": schemes,
        "max_horizontal_error_m": [schemes[n]["max_horizontal_error_m"] for n in names],
        "wall_s": time.perf_counter() - t0,
    }
    return summary, tuple(warnings), analyses


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            sink: Any = None, progress: Progress | None = None) -> Outcome:
    """The registry's entry point: with `sink` (an open results file) the series go into
    its /modulate group as they are computed. The Outcome's result is the
    :class:`~gcalign.modulate.SchemeAnalysis` of each scheme, by name."""
    summary, warnings, analyses = run_modulate(sc, seed, sink, progress)
    return Outcome(summary, lambda f: None, None, summary["seed"], warnings, result=analyses)
