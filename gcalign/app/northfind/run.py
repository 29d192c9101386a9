"""Multi-position north-finding of a scenario (seed 001; DESIGN.md "North-finding").

``run_northfind(sc, seed)`` converts the scenario's ``northfind`` section to a
:class:`gcalign.northfind.NorthfindSetup`, simulates the turntable and estimates the azimuth
by each method; ``northfind_summary(run, sc)`` turns the result into the plain dict that
``gcalign northfind --json`` prints, the results file stores and ``gcalign show`` reprints.

Array layout: the core returns ``(P, M, R)`` (methods × azimuths × repeats); the summary and
the results file use ``(R, M)`` per method (repeats × azimuths). Flat lists in the summary
are that ``(R, M)`` array in C order: ``errors_deg[r * M + m]``; ``shape`` is ``[R, M]``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gcalign import northfind as nf
from gcalign import units as u
from gcalign.app.command import Outcome
from gcalign.io.scenario import Scenario
from gcalign.io.scenario.northfind import NorthfindConfig, axis
from gcalign.schema import placed, plain, summary_of

if TYPE_CHECKING:
    import h5py

__all__ = ["NorthfindRun", "execute", "northfind_summary", "run_northfind"]


@dataclass(frozen=True)
class NorthfindRun:
    """A north-finding run: configuration, SI setup, core result (radians), seed, timing."""

    cfg: NorthfindConfig
    setup: nf.NorthfindSetup
    result: nf.NorthfindResult
    seed: int
    compute_s: float


def run_northfind(sc: Scenario, seed: int | None = None) -> NorthfindRun:
    """Simulate and solve the scenario's north-finder.

    Parameters
    ----------
    sc : Scenario
        Needs ``site`` and a ``northfind`` section.
    seed : int, optional
        Overrides ``imu.seed``; the same scenario and seed give the same numbers.

    Raises
    ------
    ScenarioError
        A value the north-finder cannot use (names the field); a missing section is the
        preflight's refusal (:meth:`gcalign.app.command.Command.check`).
    """
    cfg = sc.northfind
    assert cfg is not None
    setup = cfg.to_setup(sc)
    seed = sc.imu.seed if seed is None else int(seed)  # checked by the registry's run
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    result = nf.run_northfind(setup, rng, methods=tuple(cfg.methods), samples=cfg.samples)
    return NorthfindRun(cfg=cfg, setup=setup, result=result, seed=seed,
                        compute_s=time.perf_counter() - t0)


def northfind_summary(run: NorthfindRun, sc: Scenario) -> dict:
    """Plain-number summary (degrees): the JSON contract of ``gcalign northfind --json``.

    Per method (``methods[name]``): ``max_abs_error_deg`` and ``rms_error_deg`` over all
    azimuths and repeats; ``errors_deg`` and ``estimates_deg`` (flat ``(R, M)``); per azimuth
    (length M) ``mean_deg`` (mean estimate), ``std_deg`` (sample std over repeats, ddof 1,
    None for one repeat), ``bias_deg`` (mean error, the seed's "deviation from truth"),
    ``std_pred_deg`` (linearised prediction) and ``error_pred_deg`` (noise-free closed form,
    None where there is none); ``max_abs_error_pred_deg``.
    """
    res, setup, cfg = run.result, run.setup, run.cfg
    p, m, r = res.azimuth_est.shape
    err = np.swapaxes(res.azimuth_error, 1, 2)  # (P, R, M)
    mean_err = err.mean(1)  # (P, M)
    truth_deg = np.mod(cfg.azimuths_deg(), 360.0)  # as configured, no round trip through rad
    std = err.std(1, ddof=1) if r > 1 else np.full((p, m), np.nan)
    fields = summary_of(res)  # the tilts; per method its errors, estimates and predictions
    methods = fields.pop("methods")
    for i, (name, d) in enumerate(methods.items()):
        e, pred = err[i], res.error_pred[i]
        methods[name] = placed(d, {  # the figures derived from the fields, in their places
            "errors_deg": {"max_abs_error_deg": float(np.degrees(np.abs(e).max())),
                           "rms_error_deg": float(np.degrees(np.sqrt(np.mean(e * e))))},
            "std_pred_deg": {
                "mean_deg": plain(np.mod(truth_deg + np.degrees(mean_err[i]), 360.0)),
                "std_deg": plain(std[i], "deg"), "bias_deg": plain(mean_err[i], "deg")}},
            {"max_abs_error_pred_deg": None if np.all(np.isnan(pred))
             else float(np.degrees(np.nanmax(np.abs(pred))))})
    tilt, direction = cfg.tilt_rad()
    n_dwell = setup.n_samples
    dwell_time = n_dwell / setup.rate_hz
    g, a = sc.imu.gyro, sc.imu.accel
    site = sc.site
    assert site is not None  # run_northfind checked it
    return {
        "scenario": sc.name,
        "seed": run.seed,
        "latitude_deg": float(site.lat_deg),
        "height_m": setup.height,
        "positions": setup.positions,
        "dwell_s": setup.dwell_s,
        "rate_hz": setup.rate_hz,
        "samples_per_dwell": n_dwell,
        "samples": cfg.samples,
        "repeats": r,
        "shape": [r, m],
        "index_error_arcsec": cfg.index_error_arcsec,
        "azimuth_true_deg": plain(truth_deg),
        "sweep": None if cfg.sweep is None else cfg.sweep.model_dump(),
        "tilt_deg": float(np.degrees(tilt)),
        "tilt_direction_deg": float(np.degrees(direction)),
        "tilt_reference": cfg.reference,
        **fields,  # tilt_direction_true_deg, tilt_est_deg, tilt_direction_est_deg
        "gyro": {
            "axis": "body y (in the table plane)",
            "bias_dph": axis(g.bias_dph, 1), "arw_dprh": axis(g.arw_dprh, 1),
            "scale_ppm": axis(g.scale_ppm, 1),
            "dwell_sigma_dph": setup.gyro_arw / math.sqrt(dwell_time) / u.DPH,
        },
        "accel": {
            "axes": "body x, y",
            "bias_ug": [axis(a.bias_ug, 0), axis(a.bias_ug, 1)],
            "vrw_ugrhz": axis(a.vrw_ugrhz, 0),
            "dwell_sigma_ug": setup.accel_vrw / math.sqrt(dwell_time) / u.UG,
        },
        "method_order": list(res.methods),
        "methods": methods,
        "compute_s": run.compute_s,
    }


def execute(sc: Scenario, seed: int | None = None, cache_key: str | None = None) -> Outcome:
    """Simulate the turntable, estimate, summarise; the registry's entry point."""
    run = run_northfind(sc, seed)
    return Outcome(northfind_summary(run, sc), lambda f: write_northfind(f, run), None, run.seed,
                   result=run.result)


def write_northfind(f: h5py.File, run: NorthfindRun) -> None:
    """/northfind: the setup and the result as their fields say (SI, radians), beside what
    no field holds (the tilt of a single azimuth, the samples per dwell, gravity)."""
    from gcalign.io.stored import write_fields

    s = run.setup
    g = f.create_group("northfind")
    write_fields(g, s)
    g.attrs.update(n_samples=s.n_samples, gravity=s.gravity, tilt=float(np.atleast_1d(s.tilt)[0]),
                   tilt_direction=float(np.atleast_1d(s.tilt_direction)[0]),
                   samples=bool(run.cfg.samples),
                   units="lat, tilt, tilt_direction, index_error: rad; dwell_s: s; rate_hz: "
                   "Hz; height: m; gyro_bias: rad/s; gyro_arw: rad/sqrt(s); accel_bias: m/s^2 "
                   "[x, y]; accel_vrw: m/s/sqrt(s); gravity: m/s^2")
    write_fields(g, run.result)
