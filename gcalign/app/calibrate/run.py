"""In-flight calibration of a scenario: data, filter, summary (seed 002; spec 002 §2, §5).

Simulated flights: the truth and ideal increments of the motion (computed once per batch
variant), the injected errors (``calibrate.truth``: the scenario's own, or all 21 drawn
from P0 with the run's seed), sensor noise from ``imu``, navigation increments combined
from IMU ones, DGNSS velocity/position from the truth plus noise of σ. Recorded data: a
coarse alignment at the start of the window, then zero-velocity updates at the site (the
same filter as a zero-velocity fine alignment).

Random streams: the sensor noise is ``default_rng(seed)`` (the same numbers as ``gcalign
simulate`` of the scenario), the truth draw ``default_rng([seed, 2])``, the DGNSS noise
``default_rng([seed, 3])`` (shared by the measurements and trajectories of ``--compare``:
common random numbers).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gcalign.app.calibration_files import AidingInput
from gcalign.app.command import Outcome
from gcalign.calibrate import (
    CalibrationResult,
    FlightData,
    Settings,
    Trajectory,
    calibrate,
    combine_increments,
    draw_truth,
    flight_from_ideal,
    motion_spans,
    parked_data,
    sampled_truth,
    trajectory,
    zero_velocity_aiding,
)
from gcalign.calibrate.filter import warm_up
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.estimation.calibration import Errors
from gcalign.io.recorded.reference import Reference
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.calibrate import CalibrateConfig
from gcalign.nav.earth import EarthModel
from gcalign.nav.rotation import quat_to_euler
from gcalign.schema import plain, summary_of
from gcalign.sim.motions import Truth

if TYPE_CHECKING:
    import h5py

    from gcalign.app.data import RunData

MEASURES = ie.MEASUREMENTS
Progress = Callable[[int, int, str], None]  # (done, total, what)


@dataclass(frozen=True)
class Case:
    """A scenario's calibration input at the navigation rate and how it was made.

    data : the filter's input. settings : the filter settings (SI). source : "simulated"
    or the recorded file. aiding : "dgnss" | "zero-velocity". subsamples : IMU increments
    per navigation step. imu_rate : Hz. seed : the run's seed (None for recorded data).
    truth_source : "scenario" | "draw" | None. coarse_att : the start attitude (rad) of
    recorded data (a coarse alignment's, or the user's). window : (start, coarse end, end),
    s from sample 0 as ``data.t``. t0 : the recording's own time of sample 0 (s; 0 for a
    simulation): ``data.t + t0`` is the time of the recording's files and reference.
    aid : the aiding files' fixes and what to report of them (``aiding: file``).
    start_source : where the start state came from. output_stride : navigation steps per
    stored row of the solution. reference : the scenario's reference solution, read once
    (recorded data), or None. coarse : whether coarse_att is a coarse alignment's (else the
    start the user gave).
    """

    data: FlightData
    settings: Settings
    source: str
    aiding: str
    subsamples: int
    imu_rate: float
    seed: int | None
    truth_source: str | None
    coarse_att: np.ndarray | None
    window: tuple[float, float, float]
    t0: float = 0.0
    aid: AidingInput | None = None
    start_source: str = ""
    output_stride: int = 1
    reference: Reference | None = None
    coarse: bool = False

    @property
    def navigation_rate(self) -> float:
        return self.imu_rate / self.subsamples

    def display_scale(self) -> np.ndarray:
        """(21,) the factors from SI to the display units at the start (``DISPLAY_UNITS``)."""
        pos = self.data.start.pos
        return ie.display_scale(float(pos[0]), float(pos[2]), self.data.earth)

    def dgnss_rng(self) -> np.random.Generator:
        """The stream of the DGNSS noise (the module doc): one per seed, 0 for recorded data."""
        return np.random.default_rng([0 if self.seed is None else self.seed, 3])

    def truth(self) -> Truth | None:
        """The truth at the navigation rate (for /truth), with the segment of each sample."""
        tr = self.data.truth
        return None if tr is None else sampled_truth(tr, self.data.segments)


def config_of(sc: Scenario) -> CalibrateConfig:
    return sc.calibrate or CalibrateConfig()


def injected_truth(sc: Scenario, cfg: CalibrateConfig, settings: Settings, site: np.ndarray,
                   earth: EarthModel, seed: int) -> np.ndarray:
    """The 21 injected errors (SI): the imu section's biases and scale factors and
    ``calibrate.initial_error`` (truth: scenario), or a draw from the filter's P0."""
    if cfg.truth == "draw":
        P0 = settings.covariances(site, earth)[0]
        return draw_truth(P0, np.random.default_rng([seed, 2]))
    err = sc.imu.errors()
    x = np.zeros(ie.N_STATES)
    x[ie.NAV] = cfg.initial_error.to_si(float(site[0]), float(site[2]), earth)
    x[ie.EB], x[ie.DB] = err.gyro.bias, err.accel.bias
    x[ie.DKG], x[ie.DKA] = err.gyro.scale, err.accel.scale
    return x


_TRAJECTORIES: list[tuple[RunData, int, tuple, Trajectory]] = []  # noise-free data, subsamples,
# earth, its trajectory: the last few, in this process


def shared_trajectory(raw: RunData, n: int, earth: EarthModel) -> Trajectory:
    """The :func:`gcalign.calibrate.trajectory` of a batch's cached noise-free simulation
    (:func:`gcalign.app.data.cached_noise_free`), computed once per simulation, subsamples
    and earth model in this process (the seeds of a variant share it; about a fifth of a
    seed 002 run) and read-only like the simulation it comes from."""
    key = tuple(earth.params().tolist())
    for data, m, e, traj in _TRAJECTORIES:
        if data is raw and m == n and e == key:
            return traj
    assert raw.truth is not None
    tr = raw.truth
    traj = trajectory(tr.t, tr.att, tr.v_n, tr.pos, raw.imu.dtheta, raw.imu.dv, earth, n)
    for value in vars(traj).values():
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    _TRAJECTORIES.insert(0, (raw, n, key, traj))
    del _TRAJECTORIES[4:]
    return traj


def simulated_case(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
                   cfg: CalibrateConfig | None = None) -> Case:
    """The flight of a simulated scenario with its injected errors (see the module doc)."""
    from gcalign.app.data import cached_noise_free, noise_free

    cfg = cfg or config_of(sc)
    cfg.check(sc)
    assert sc.motion is not None
    raw = cached_noise_free(sc, cache_key) if cache_key is not None else noise_free(sc)
    assert raw.truth is not None
    seed = sc.imu.seed if seed is None else seed
    earth, site = sc.earth_model, raw.site
    n = cfg.subsamples(sc.imu.rate_hz)
    settings = cfg.settings(site, earth, sc=sc)
    x = injected_truth(sc, cfg, settings, site, earth, seed)
    traj = None if cache_key is None else shared_trajectory(raw, n, earth)
    data = flight_from_ideal(raw.truth, raw.imu, x, sc.imu.errors(), np.random.default_rng(seed),
                             motion_spans(sc.motion.to_motion(), float(raw.truth.t[-1])), n,
                             earth, traj)
    window = cfg.window(sc.motion.duration(), 1.0 / sc.imu.rate_hz)
    if window[0] > 0 or window[2] < data.t[-1] - 1e-9:
        data = data.between(window[0], window[2])
    if cfg.aiding_for(sc) == "zero-velocity":
        data = zero_velocity_aiding(data)
    return Case(data, settings, "simulated", cfg.aiding_for(sc), n, sc.imu.rate_hz, seed,
                cfg.truth, None, window, output_stride=cfg.output_stride(sc.imu.rate_hz / n))


def recorded_case(sc: Scenario, cfg: CalibrateConfig | None = None,
                  recording=None) -> Case:
    """Recorded data: a coarse alignment over the start of the window when
    ``calibrate.coarse.method`` asks for one, then the filter to the end of the window,
    aided by the files at their own epochs (``aiding: file``) or by zero velocity at the
    site. Without a coarse alignment the start is the user's (``initial``, the reference,
    the file's header: :func:`gcalign.app.calibration_files.start_state`)."""
    from gcalign.align import coarse as coarse_mod
    from gcalign.app.calibration_files import file_data, start_state
    from gcalign.app.data import scenario_data

    cfg = cfg or config_of(sc)
    cfg.check(sc)
    run = scenario_data(sc, recording=recording)  # as the preflight read it, if it did
    imu, ts, site, earth = run.imu, run.imu.ts, run.site, run.earth
    rate = 1.0 / ts
    n = cfg.subsamples(rate)
    cfg.steps_per_update(rate)
    start, coarse_end, end = cfg.window(len(imu) * ts, ts)
    i0, i1, i2 = (int(round(t / ts)) for t in (start, coarse_end, end))
    att = None
    if cfg.coarse.method != "none":
        dth, dv = imu.dtheta[i0:i1], imu.dv[i0:i1]
        try:
            if cfg.coarse.method == "analytic":
                att = coarse_mod.analytic_coarse(dth, dv, ts, site[0], earth)
            else:
                att = coarse_mod.inertial_frame_coarse(dth, dv, ts, site[0], site[1], site[2],
                                                       earth=earth)
        except ValueError as err:
            raise ScenarioError(f"calibrate.coarse.duration_s: {err}") from None
    aiding = cfg.aiding_for(sc)
    reference = sc.reference.read() if sc.reference is not None else None  # read once
    t0 = float(imu.t[0] - ts)  # the recording's time of sample 0
    dth, dv = combine_increments(imu.dtheta[i1:i2], imu.dv[i1:i2], n)
    t = coarse_end + np.arange(len(dth) + 1) * n * ts
    aid, source = None, "the coarse alignment (a parked start)"
    if aiding == "file":  # measured velocity / position at their epochs
        data, aid, source = file_data(sc, cfg, t, dth, dv, site, earth, t0, att, imu,
                                      reference)
    else:
        if att is None:
            state, source = start_state(sc, cfg, float(t[0]), t0, site, earth,
                                        dth[0] / (n * ts), header=imu, reference=reference)
            att = quat_to_euler(state.q_nb)
        data = parked_data(imu.dtheta[i1:i2], imu.dv[i1:i2], ts, att, site, t0=coarse_end,
                           subsamples=n, earth=earth)
    start_att = att if att is not None else quat_to_euler(data.start.q_nb)
    return Case(data, cfg.settings(site, earth, sc=sc), imu.source, aiding, n, rate, None,
                None, start_att, (start, coarse_end, end), t0, aid, source,
                cfg.output_stride(rate / n), reference, cfg.coarse.method != "none")


def scenario_case(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
                  recording=None) -> Case:
    if sc.imu_file is not None:
        return recorded_case(sc, recording=recording)
    return simulated_case(sc, seed, cache_key)


@dataclass(frozen=True)
class Run:
    """One filter run on a case: its label, the result, its compute time (s) and the
    statistics of its solution's errors at every navigation sample (None without truth or
    reference)."""

    label: str
    data: FlightData
    result: CalibrationResult
    compute_s: float
    errors: dict | None = None
    epoch_errors: dict | None = None


def solution_errors(sc: Scenario, case: Case, data: FlightData):
    """What the solution is compared with: the simulation's truth, else the scenario's
    reference (its gaps left out), else nothing (:class:`gcalign.app.calibrate.solution.
    Errors`)."""
    from gcalign.app.calibrate.solution import Errors
    from gcalign.io.recorded.reference import reference_gaps

    if data.truth is not None:
        return Errors(data.earth, truth=data.truth)
    ref = case.reference
    if ref is None or sc.reference is None:
        return Errors(data.earth)
    return Errors(data.earth, reference=ref, ref_gaps=reference_gaps(ref, sc.reference.max_gap_s))


def run_filter(case: Case, measure: str | None = None, data: FlightData | None = None,
               label: str = "", group=None, errors=None) -> Run:
    """The calibration filter on the case's data (or `data`, a part of it). With `group`
    (an h5py group) the solution at the output rate goes into it as the run goes; with
    `errors` (:class:`gcalign.app.calibrate.solution.Errors`) its errors at every sample
    are summed inside and outside the outages."""
    from dataclasses import replace

    from gcalign.app.calibrate.solution import SolutionSink

    s = case.settings if measure is None else replace(case.settings, measure=measure)
    data = case.data if data is None else data
    sink = None
    if group is not None or errors is not None:
        from gcalign.app.calibrate.solution import Errors

        outages = () if case.aid is None else case.aid.outages
        origin = "" if case.aid is None else case.aid.info["time_origin"]
        sink = SolutionSink(group, case.output_stride, case.t0, errors or Errors(data.earth),
                            outages, case.navigation_rate, origin)
    warm_up()
    t0 = time.perf_counter()
    result = calibrate(data, s, case.dgnss_rng(), on_rows=sink)
    compute = time.perf_counter() - t0
    stats = None if sink is None else sink.close()
    at_epochs = None
    if errors is not None and errors.against is not None:
        at_epochs = _epoch_errors(case, result, errors)
    return Run(label, data, result, compute, stats, at_epochs)


def summaries_of_seeds(sc: Scenario, seeds: list[int],
                       cache_key: str | None) -> list[dict | Exception]:
    """The summary of each seed's run of a simulated scenario, as :func:`execute` would give
    it, the seeds' filters stepped together (:func:`gcalign.calibrate.lockstep.
    calibrate_runs`: each seed's numbers to the bit those of its own run; ``compute_s`` is
    the lockstep's time per run). A seed whose run fails has its exception in its place. For
    a batch: the noise-free simulation and its trajectory are shared through `cache_key`,
    and the caller has made the variant's preflight."""
    from gcalign.calibrate.lockstep import calibrate_runs
    from gcalign.io.results import finite_summary

    out: list[dict | Exception] = []
    cases, where = [], []
    for seed in seeds:
        try:
            cases.append(simulated_case(sc, seed, cache_key))
        except Exception as err:  # noqa: BLE001 - recorded for this seed, as a run would be
            out.append(err)
            continue
        where.append(len(out))
        out.append(ScenarioError("not run"))
    warm_up()
    t0 = time.perf_counter()
    results = calibrate_runs([(c.data, c.settings, c.dgnss_rng()) for c in cases])
    compute = (time.perf_counter() - t0) / max(len(cases), 1)
    for i, case, res in zip(where, cases, results, strict=True):
        try:
            if isinstance(res, Exception):
                raise res
            s = summary(sc, case, [Run("", case.data, res, compute)], False, [None])
            finite_summary(s, "calibrate")
            out[i] = s
        except Exception as err:  # noqa: BLE001 - as above
            out[i] = err
    return out


def lockstep_ok(sc: Scenario) -> bool:
    """Can a batch run this variant's seeds in lockstep (:func:`summaries_of_seeds`)? A
    simulated flight (the seeds share its truth)."""
    return sc.imu_file is None and sc.motion is not None


def _epoch_errors(case: Case, r: CalibrationResult, errors) -> dict:
    """The forward filter's and (with it) the smoother's solutions at the filter epochs
    against the truth or the reference, inside and outside the outages (the smoothed
    errors themselves under ``smoothed_series``, for the file)."""
    from gcalign.app.calibrate.solution import epoch_errors

    assert r.index is not None
    outages = () if case.aid is None else case.aid.outages
    out: dict = {"forward": epoch_errors(errors, r.t, case.t0, r.index, r.att, r.v_n, r.pos,
                                         outages)[0]}
    if r.smoothed is not None:
        sm = r.smoothed
        out["smoothed"], out["smoothed_series"] = epoch_errors(
            errors, r.t, case.t0, r.index, sm.att, sm.v_n, sm.pos, outages,
            "the smoothed solution - the truth or the reference")
    return out


def compare_runs(case: Case, segments: int, progress: Progress | None = None,
                 group_of=None, errors_of=None) -> list[Run]:
    """The seed's Table 3: velocity, position and both on the whole flight ("designed")
    and on its first `segments` segments ("conventional"), on the same data and noise;
    `progress(done, total, what)` hears of each of the six filter runs; `group_of(i)` and
    `errors_of(data)` give run i's solution group and what its errors are taken against."""
    spans = case.data.segments
    if case.data.truth is None or len(spans) <= segments:
        raise ScenarioError(f"calibrate.conventional_segments: --compare needs a simulated "
                            f"flight with more than {segments} segments (the conventional "
                            f"take-off is its first {segments}); this one has {len(spans)}")
    short = case.data.between(float(case.data.t[0]), spans[segments - 1].end)
    runs: list[Run] = []
    for label, data in (("designed", case.data), ("conventional", short)):
        for measure in MEASURES:
            runs.append(run_filter(case, measure, data, label,
                                   None if group_of is None else group_of(len(runs)),
                                   None if errors_of is None else errors_of(data)))
            if progress is not None:
                progress(len(runs), 2 * len(MEASURES), "filter runs")
    return runs


# ---------------------------------------------------------------------- summary


def _chi2_band(dof: int, level: float = 0.95) -> list[float]:
    from scipy.stats import chi2

    return [float(chi2.ppf((1 - level) / 2, dof)), float(chi2.ppf((1 + level) / 2, dof))]


def run_summary(run: Run) -> dict:
    """The per-state part of the summary (SI): the JSON contract of ``gcalign calibrate``."""
    r, data = run.result, run.data
    x0, end = data.x_true, None if r.truth is None else r.truth[-1]
    states = {name: {"injected": None if x0 is None else float(x0[i]),
                     "truth": None if end is None else float(end[i]),
                     "estimate": float(r.estimate[-1, i]),
                     "error": None if end is None else float(r.estimate[-1, i]) - float(end[i]),
                     "sigma": float(r.sigma[-1, i]), "sigma0": float(r.sigma[0, i])}
              for i, name in enumerate(ie.STATE_NAMES)}
    m = r.dof
    out = {
        "label": run.label,
        "measure": r.settings.measure,
        "duration_s": float(r.t[-1] - r.t[0]),
        "epochs": len(r.t),
        "segments": summary_of(data.segments),
        "states": states,
        "normalized_error": None if r.error is None
        else (r.error[-1] / r.sigma[-1]).tolist(),
        "nees": None,
        "nis": {"mean": float(r.nis.mean()), "dof": m, "band_95": _chi2_band(m)},
        "innovation": {"names": list(r.measure_names),
                       "standardized_mean": r.standardized.mean(0).tolist(),
                       "standardized_std": r.standardized.std(0).tolist()},
        "attitude_deg": np.degrees(r.att[-1]).tolist(),
        "velocity_mps": r.v_n[-1].tolist(),
        "position_deg_m": [*np.degrees(r.pos[-1, :2]).tolist(), float(r.pos[-1, 2])],
        "compute_s": run.compute_s,
    }
    if r.updated is not None and not r.updated[1:].all():
        out["updates"] = int(r.updated.sum())
        out["predict_only_epochs"] = int(len(r.t) - 1 - r.updated.sum())
        out["fixes_unused"] = r.fixes_unused
    if run.errors is not None:
        out["solution_errors"] = run.errors
    if run.epoch_errors is not None:
        out["epoch_errors"] = {k: v for k, v in run.epoch_errors.items()
                               if k != "smoothed_series"}
    if r.nees is not None:
        lo, hi = _chi2_band(ie.N_STATES)
        out["nees"] = {"final": float(r.nees[-1]), "mean": float(r.nees.mean()),
                       "dof": ie.N_STATES, "band_95": [lo, hi],
                       "inside_95": float(np.mean((r.nees > lo) & (r.nees < hi)))}
    if r.smoothed is not None:
        sm = r.smoothed
        out["smoothed_initial"] = {
            name: {"estimate": float(sm.estimate[0, i]), "sigma": float(sm.sigma[0, i]),
                   "filtered_sigma": float(r.sigma[0, i]),
                   "truth": None if r.truth is None else float(r.truth[0, i])}
            for i, name in enumerate(ie.STATE_NAMES[:9])}
    return out


def summary(sc: Scenario, case: Case, runs: list[Run], compare: bool,
            against: list[Errors | None] | None = None) -> dict:
    """The command's summary: the run's settings and data, then one run (or the six of
    ``--compare`` under ``runs``); `against`, one per run, their errors against a
    reference (:func:`reference_series`)."""
    against = against or [None] * len(runs)
    d = case.data
    s = case.settings
    out = {
        "scenario": sc.name,
        "seed": case.seed,
        "source": case.source,
        "aiding": case.aiding,
        "truth_source": case.truth_source,
        "feedback": s.feedback,
        "smoother": s.smoother,
        "discretization": s.discretization,
        "imu_rate_hz": case.imu_rate,
        "navigation_rate_hz": case.navigation_rate,
        "filter_rate_hz": s.filter_rate,
        "p0_scale": s.p0_scale,
        "sigma_v_mps": s.sigma_v,
        "sigma_p_m": s.sigma_p,
        "window_s": list(case.window),
        "site_deg_m": [*np.degrees(d.start.pos[:2]).tolist(), float(d.start.pos[2])],
        "earth": d.earth.name,
        "units": dict(zip(ie.STATE_NAMES, ie.STATE_UNITS, strict=True)),
        "display_scale": dict(zip(ie.STATE_NAMES, case.display_scale().tolist(), strict=True)),
        "display_units": dict(zip(ie.STATE_NAMES, ie.DISPLAY_UNITS, strict=True)),
        "coarse_attitude_deg": plain(case.coarse_att if case.coarse else None, "deg"),
        "aiding_files": aiding_files(config_of(sc)),
        "compare": compare,
        "components": s.components,
        "processes": processes_summary(config_of(sc)),
    }
    if case.source != "simulated":
        out["start"] = {"source": case.start_source, "t_s": float(d.t[0]),
                        "t_data_s": float(d.t[0] + case.t0),
                        "attitude_deg": plain(case.coarse_att, "deg")}
        out["time"] = {"t0_s": case.t0, "origin": "the recording's time base (t_data = t + "
                       "t0)" if case.aid is None else case.aid.info["time_origin"]}
    if case.aid is not None:
        out["fixes"] = case.aid.info
    if compare:
        out["runs"] = [run_summary(r) | reference_errors(e)
                       for r, e in zip(runs, against, strict=True)]
        out["compute_s"] = float(sum(r.compute_s for r in runs))
    else:
        out |= run_summary(runs[0]) | reference_errors(against[0])
    return out


def processes_summary(cfg: CalibrateConfig) -> dict | None:
    """The filter's sensor processes as the scenario gives them (user units), or None when
    every sensor state is a random constant."""
    out = {k: v.model_dump() if hasattr(v, "model_dump") else list(v) for k in (
        "gyro_bias_gm", "gyro_bias_rw_dphrh", "accel_bias_gm", "accel_bias_rw_ughrh",
        "gyro_scale_gm", "accel_scale_gm") if (v := getattr(cfg.q, k)) is not None}
    return out or None


def aiding_files(cfg: CalibrateConfig) -> dict | None:
    """The files of ``aiding: file`` with the point each measures (the lever arm the filter
    applies), or None."""
    if cfg.files is None:
        return None
    return {key: {"path": str(f.path), "format": f.format, "lever_arm_m": list(f.lever_arm_m)}
            for key, f in (("velocity", cfg.files.velocity), ("position", cfg.files.position))
            if f is not None}


def reference_series(sc: Scenario, case: Case, run: Run) -> Errors | None:
    """A recording's INS solution against the scenario's reference at every filter epoch
    the reference covers (:meth:`gcalign.app.calibrate.solution.Errors.of`: the reference
    at the recording's time ``t + t0``, to 1 µs beyond its ends as
    :func:`~gcalign.io.recorded.reference.reference_at` takes it, none inside its gaps);
    None without a reference, with truth, or with no epoch inside it."""
    from gcalign.app.calibrate.solution import epoch_errors

    errors, r = solution_errors(sc, case, run.data), run.result
    if errors.against != "reference":
        return None
    e = epoch_errors(errors, r.t, case.t0, r.index, r.att, r.v_n, r.pos, (),
                     "INS solution - reference, at the epochs it covers", tol=1e-6)[1]
    return e if len(e.t) else None


def reference_errors(e: Errors | None) -> dict:
    """The summary's errors against a reference (:func:`reference_series`) at the last
    epoch it covers, in the fields navigate gives against truth: ``final_error`` and
    ``error_source: "reference"``."""
    if e is None:
        return {}
    return {"error_source": "reference", "final_error": {
        "t_s": float(e.t[-1]), "attitude_deg": np.degrees(e.att[-1]).tolist(),
        "velocity_mps": e.v_n[-1].tolist(), "position_m": e.pos[-1].tolist()}}


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None,
            compare: bool = False, progress: Progress | None = None, sink=None,
            recording=None) -> Outcome:
    """Build the case, run the filter (or the six runs of `compare`), summarise; the
    Outcome's result is the :class:`~gcalign.calibrate.CalibrationResult` (with `compare`: the
    six, in the summary's order). With `sink` (an open results file) each run's solution at
    the output rate goes into ``/calibrate/runs/NN/navigation`` as it is computed."""
    if progress is not None:
        progress(0, 1, "simulating / reading the data")
    case = scenario_case(sc, seed, cache_key, recording)
    if progress is not None and not compare:
        progress(0, 1, "filter run")

    def group_of(i: int):
        return None if sink is None else sink.require_group(f"calibrate/runs/{i:02d}/navigation")

    def errors_of(data: FlightData):  # a batch run (no file) sums no solution errors
        return None if sink is None and case.aid is None else solution_errors(sc, case, data)

    runs = (compare_runs(case, config_of(sc).conventional_segments, progress, group_of,
                         errors_of) if compare
            else [run_filter(case, group=group_of(0), errors=errors_of(case.data))])
    if progress is not None and not compare:
        progress(1, 1, "filter run")
    against = [reference_series(sc, case, r) for r in runs]
    out = summary(sc, case, runs, compare, against)
    from gcalign.app.at_rest import zero_velocity_warnings  # a moving recording under ZUPT

    result = tuple(r.result for r in runs) if compare else runs[0].result
    warnings = (*zero_velocity_warnings(sc, case, out), *filter_warnings(runs, compare),
                *(() if case.aid is None else case.aid.warnings), *sigma_warnings(sc, case))
    return Outcome(out, lambda f: write_calibration(f, case, runs, compare, against),
                   case.truth(), case.seed, warnings, result=result)


def write_calibration(f: h5py.File, case: Case, runs: list[Run], compare: bool,
                      against: list[Errors | None] | None = None) -> None:
    """``/calibrate``: the run's settings, the flight's segments and outages, and per run
    (``runs/NN``) the filter's result as its fields say
    (:class:`~gcalign.calibrate.CalibrationResult`), the innovations in the measurement's
    units, the errors of the smoothed solution and, with `against` (one per run, or None),
    the INS solution's against a reference (:func:`reference_series`)."""
    from gcalign.estimation.calibration import Spans
    from gcalign.io.results import put, write_segments
    from gcalign.io.stored import write_fields

    d = case.data
    write_segments(f, case.truth(), d.segments)
    g = f.require_group("calibrate")
    g.attrs.update(aiding=case.aiding, navigation_rate_hz=case.navigation_rate,
                   filter_rate_hz=case.settings.filter_rate, compare=compare,
                   states=",".join(ie.STATE_NAMES), state_units=",".join(ie.STATE_UNITS),
                   display_units=",".join(ie.DISPLAY_UNITS), display_scale=case.display_scale())
    write_fields(g.create_group("segments"), Spans.of(d.segments))
    if case.aid is not None:
        og = g.create_group("outages")
        og.attrs.update(t0=case.t0, max_gap_s=case.aid.info["max_gap_s"], description=(
            "stretches without a fix longer than max_gap_s (s from the run's sample 0; + t0: "
            "the recording's time)"))
        for name in ("start", "end", "length"):
            put(og, name, [getattr(o, name) for o in case.aid.outages], "s")
    for i, run in enumerate(runs):
        rg, r = g.require_group(f"runs/{i:02d}"), run.result
        rg.attrs.update(label=run.label, measure=r.settings.measure)
        write_fields(rg, r)
        if r.updated is not None:
            put(rg, "update_t", r.update_t, "s", description="the epochs with a measurement")
        e = (run.epoch_errors or {}).get("smoothed_series")
        if r.smoothed is not None and e is not None:
            write_fields(rg["smoothed"].create_group("error"), e)
        if against is not None and against[i] is not None:
            write_fields(rg.create_group("reference_error"), against[i])


def sigma_warnings(sc: Scenario, case: Case) -> tuple[str, ...]:
    """``calibrate.sigma_p_m`` set while every fix has its own σ: it cannot matter."""
    cfg = config_of(sc)
    if case.aid is None or case.aid.fixes.sigma_pos is None or \
            "sigma_p_m" not in cfg.model_fields_set:
        return ()
    return (f"calibrate.sigma_p_m: {cfg.sigma_p_m:g} m cannot matter: every fix of "
            f"{case.aid.info['path']} has its own σ, which the filter uses",)


def filter_warnings(runs: list[Run], compare: bool) -> tuple[str, ...]:
    """The core's consistency checks of each run (:mod:`gcalign.calibrate.health`)."""
    from gcalign.calibrate.health import health_warnings

    return tuple(w for r in runs for w in health_warnings(
        r.result, f"{r.label} {r.result.settings.measure}: " if compare else ""))
