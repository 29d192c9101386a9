"""`gcalign align --mode transfer`: a slave IMU aligned against a master INS (spec 006).

Scenario -> arrays (the slave's increments from ``imu_file``, the master from
``align.transfer.reference``) -> :func:`gcalign.transfer.transfer_align` -> an
:class:`~gcalign.app.registry.Outcome`: the summary (SI in ``states``, in calibrate's shape
``{name: {estimate, sigma, sigma0}}``), the HDF5 group ``/align/transfer``, a table and
figures in the manner of PSINS's ``kfplot`` (estimates with ±σ against time, the file's
stored ``eb0``, ``db0``, ``mu0`` as reference lines).

PSINS ``.mat`` files are read by the recorded-data readers of that format
(:mod:`gcalign.io.recorded`), as every other command reads them.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gcalign.app.command import DOUBLE, Cost, Outcome
from gcalign.errors import ScenarioError
from gcalign.units import ARCMIN, DPH, UG

#: what :func:`load_inputs` reads: the slave's increments and times, the master, the file's
#: stored PSINS values and the master's path
Inputs = tuple[np.ndarray, np.ndarray, np.ndarray, Any, dict[str, np.ndarray], Path]

#: display unit and the factor from SI, per state group (the table's and figures')
DISPLAY = {"phi": ("arcmin", 1 / ARCMIN), "dv": ("m/s", 1.0), "eb": ("deg/h", 1 / DPH),
           "db": ("ug", 1 / UG), "mu": ("arcmin", 1 / ARCMIN), "th": ("arcmin", 1 / ARCMIN),
           "w": ("arcmin/s", 1 / ARCMIN)}
DECIMALS = {"arcmin": 2, "m/s": 3, "deg/h": 2, "ug": 0, "arcmin/s": 2}
SI_UNIT = {"phi": "rad", "dv": "m/s", "eb": "rad/s", "db": "m/s^2", "mu": "rad", "th": "rad",
           "w": "rad/s"}


#: the state groups in the filter's order, and what each is (the figures' axes)
GROUPS = {"phi": "φ attitude error", "dv": "δv velocity error", "eb": "ε gyro bias",
          "db": "∇ accel bias", "mu": "μ mounting misalignment", "th": "θ flexure angle",
          "w": "ω flexure rate"}
COLOURS = ("tab:blue", "tab:orange", "tab:green")  #: a group's three states in the figures


def group_of(name: str) -> str:
    """The state group of a state name (``phiE`` -> ``phi``, ``dbx`` -> ``db``)."""
    return next(g for g in GROUPS if name.startswith(g))


def state_groups(names: Sequence[str]) -> list[tuple[str, list[int]]]:
    """The state groups among `names`, in the filter's order, with their states' indices."""
    return [(gr, idx) for gr in GROUPS
            if (idx := [i for i, n in enumerate(names) if group_of(n) == gr])]


def display(names: Sequence[str]) -> dict[str, dict[str, Any]]:
    """Per state its SI unit, the unit the table and figures give it in and the factor from
    SI: a summary's ``units``, ``display_units`` and ``display_scale``."""
    return {"units": {n: SI_UNIT[group_of(n)] for n in names},
            "display_units": {n: DISPLAY[group_of(n)][0] for n in names},
            "display_scale": {n: DISPLAY[group_of(n)][1] for n in names}}


def write_display(g: Any, names: Sequence[str]) -> None:
    """The states' display units and factors from SI as attributes of the group `g`."""
    g.attrs["display_units"] = ",".join(DISPLAY[group_of(n)][0] for n in names)
    g.attrs["display_scale"] = np.array([DISPLAY[group_of(n)][1] for n in names])


def reference_path(sc) -> Path:
    """The master's file: the imu_file itself (``reference.path`` null), else the path,
    a relative one taken from the imu_file's folder."""
    path = sc.align.transfer.reference.path
    if path is None:
        return sc.imu_file
    return path if path.is_absolute() else sc.imu_file.parent / path


def load_inputs(sc: Any) -> Inputs:
    """The slave's increments, the master series and the file's stored PSINS values
    (``eb0``, ``db0``, ``mu0`` in SI, those present), read by the recorded-data readers of
    the psins-mat format (:mod:`gcalign.io.recorded`): the slave as a recording with the
    scenario's layout (variable ``align.transfer.imu_variable``), the master as a reference
    (10 columns, or 7 without attitude)."""
    from gcalign.io.recorded import read_recording, read_reference
    from gcalign.io.recorded.mat import read_vectors
    from gcalign.transfer import MasterSeries

    cfg = sc.align.transfer
    if sc.imu_file is None or sc.imu_file.suffix.lower() != ".mat":
        raise ScenarioError(f"imu_file: align.mode 'transfer' reads the slave from a PSINS "
                            f".mat file (variable align.transfer.imu_variable), got "
                            f"{sc.imu_file}")
    if not sc.imu_file.is_file():
        raise ScenarioError(f"imu_file: {sc.imu_file}: file not found")
    layout = sc.recording_layout()
    if "imu_variable" in cfg.model_fields_set and layout.variable != cfg.imu_variable:
        raise ScenarioError(f"align.transfer.imu_variable: {cfg.imu_variable!r} contradicts "
                            f"imu_file.variable {layout.variable!r}; give one of them")
    try:
        imu = read_recording(sc.imu_file, layout)
    except ScenarioError as err:
        text = str(err)
        field = ("align.transfer.imu_variable" if ": variable" in text
                 else "" if text.startswith("imu_file") else "imu_file")
        raise ScenarioError(f"{field}: {text}" if field else text) from None
    ref, path = cfg.reference, reference_path(sc)
    if not path.is_file():
        raise ScenarioError(f"align.transfer.reference.path: {path}: file not found")
    try:
        avp = read_reference(path, ref.format, ref.variable, attitude_optional=True)
    except ScenarioError as err:
        field = "variable" if "variable" in str(err) else "path"
        raise ScenarioError(f"align.transfer.reference.{field}: {err}") from None
    if cfg.matching != "velocity" and avp.att is None:
        raise ScenarioError(f"align.transfer.matching: {cfg.matching!r} needs the reference's "
                            f"attitude; {ref.variable!r} in {path} has 7 columns [v pos t], "
                            "no attitude (allowed: 'velocity')")
    master = MasterSeries(t=avp.t, att=avp.att, v_n=avp.v_n, pos=avp.pos)
    names = ("eb0", "db0", "mu0")
    stored = read_vectors(path, names)
    if path != sc.imu_file:  # the demo keeps them beside the slave
        stored = {**read_vectors(sc.imu_file, names), **stored}
    return imu.dtheta, imu.dv, imu.t, master, stored, path


def summary(sc, result, stored: dict, ref_path: Path, compute_s: float) -> dict:
    """The run's summary: ``states`` in SI, the rest in the units their keys name."""
    from gcalign.estimation.health import mean_nis_band
    from gcalign.transfer import attitude_error_vs

    r, s = result, result.settings
    conv = r.convergence_s()
    last = r.t >= r.t[-1] - 10.0

    def final_and_rms(e: np.ndarray) -> dict[str, list[float]]:  # arcmin; RMS: last 10 s
        return {"final": (e[-1] / ARCMIN).tolist(),
                "rms_last_10s": (np.sqrt(np.mean(e[last] ** 2, axis=0)) / ARCMIN).tolist()}

    states = {n: {"estimate": float(r.x[-1, i]), "sigma": float(r.sigma[-1, i]),
                  "sigma0": float(r.sigma0[i])} for i, n in enumerate(r.names)}
    lo, hi = mean_nis_band(1, r.m)  # the band of one epoch
    mean_lo, mean_hi = mean_nis_band(len(r.nis), r.m)
    out = {
        "scenario": sc.name,
        "mode": "transfer",
        "source": str(sc.imu_file),
        "reference": str(ref_path),
        "matching": s.matching,
        "flexure": s.flexure,
        "feedback": {"bias": s.bias_feedback, "attitude": s.attitude_feedback},
        "gravity": s.gravity,
        "lever_arm_m": list(s.lever_arm_b),
        "t0_s": r.t0,
        "duration_s": float(r.t[-1] - r.t0),
        "epochs": len(r.t),
        "states": states,
        **display(r.names),
        "convergence_s": conv,
        "attitude_error_vs_reference_arcmin": None if r.settings.matching == "velocity"
        and np.isnan(r.q_master).any() else final_and_rms(r.attitude_error),
        "nis": {"mean": float(r.nis.mean()), "dof": r.m, "band_95": [lo, hi],
                "band_95_of_mean": [mean_lo, mean_hi],
                "consistent": bool(mean_lo <= r.nis.mean() <= mean_hi)},
        "slave_attitude_deg": np.degrees(r.att_slave[-1]).tolist(),
        "psins_stored": {f"{k}_{unit}": (stored[k] / si).tolist() if k in stored else None
                         for k, unit, si in (("eb0", "dph", DPH), ("db0", "ug", UG),
                                             ("mu0", "arcmin", ARCMIN))},
        "compute_s": compute_s,
    }
    if "mu0" in stored and not np.isnan(r.q_master).any():
        out["attitude_error_vs_psins_mu0_arcmin"] = final_and_rms(
            attitude_error_vs(r, stored["mu0"]))
    return out


def write(f, result, stored: dict) -> None:
    """``/align/transfer``: per-epoch estimates and σ (SI, columns in the order of the
    ``states`` attribute), NIS, the corrected slave attitude and velocity, its error against
    master ∘ μ̂, the bias totals fed back; the file's stored PSINS values as attributes."""
    from gcalign.io.results import put
    from gcalign.io.stored import write_fields

    r = result
    g = f.require_group("align").create_group("transfer")
    g.attrs["mode"] = "transfer"
    g.attrs["matching"] = r.settings.matching
    g.attrs["state_units"] = ",".join(SI_UNIT[group_of(n)] for n in r.names)
    write_display(g, r.names)
    for k, v in stored.items():
        g.attrs[f"psins_{k}"] = v
        g.attrs[f"psins_{k}_units"] = {"eb0": "rad/s", "db0": "m/s^2", "mu0": "rad"}[k]
    write_fields(g, r)
    put(g, "nis", r.nis, "1", dof=r.m)


def _covered(sc, t, master, ref_path) -> None:
    """The core's check that the master covers the IMU run (its measurement epochs), as a
    refusal naming the key and both files."""
    from gcalign.transfer.filter import measurement_epochs

    try:
        measurement_epochs(t, master)
    except ScenarioError as err:
        raise ScenarioError(f"align.transfer.{err} ({ref_path} against {sc.imu_file})"
                            ) from None


def check(sc, loaded=None) -> None:
    """Refuse what the run would refuse (``gcalign validate``, the preflight of a run): the
    files and their variables, the matching against the reference's columns, the settings,
    the reference's cover of the IMU run. Reads the files unless `loaded` (what
    :func:`load_inputs` returned, the preflight's); loads no numba."""
    dtheta, dv, t, master, _, ref_path = loaded or load_inputs(sc)
    sc.align.transfer.settings(sc.earth_model)
    _covered(sc, t, master, ref_path)


#: multiply-adds of the filter per n³ (n states): an IMU step's Φ P Φᵀ with a dense Φ, and
#: a measurement epoch's gain and Joseph-form update
STEP_OPS_N3, UPDATE_OPS_N3 = 2.0, 4.0
INPUT_DOUBLES = 4 * 7  #: per IMU sample: the file's array, the reader's copies, the kernel's
EPOCH_DOUBLES = 40  #: per epoch beside x, σ and P: NIS, attitudes, velocity, errors, feedback


def sizes(sc) -> tuple[int, int, int]:
    """IMU samples, master epochs (the measurements are at most as many) and states of a
    run, from the MAT files' headers (no data read; the check has read them)."""
    from gcalign.io.recorded.mat import shapes

    cfg = sc.align.transfer
    variable = sc.recording_layout().variable or cfg.imu_variable
    imu = shapes(sc.imu_file).get(variable, (0,))
    master = shapes(reference_path(sc)).get(cfg.reference.variable, (0,))
    return imu[0], master[0], 21 if cfg.flexure else 15


def cost(sc, runs: int = 1) -> Cost:
    """`runs` filter runs over the whole file: per IMU step the covariance propagation, per
    master epoch the update; held at once: the inputs and every epoch's x, σ and P (the
    result); stored: x, σ and the series of :func:`write`."""
    N, K, n = sizes(sc)
    per_epoch = n * n + 2 * n + EPOCH_DOUBLES
    return Cost(samples=float(N),
                memory_bytes=(N * INPUT_DOUBLES + K * per_epoch) * DOUBLE,
                output_bytes=K * (2 * n + 16) * DOUBLE,
                work=runs * (N * STEP_OPS_N3 + K * UPDATE_OPS_N3) * n**3,
                work_what=f"{runs} run(s) × (IMU samples × {STEP_OPS_N3:g} + epochs × "
                f"{UPDATE_OPS_N3:g}) × {n}³",
                memory_what="the inputs and every epoch's covariance")


def run_filter(sc: Any, recording: Inputs | None = None
               ) -> tuple[Any, dict[str, np.ndarray], Path, float]:
    """The filter over the slave and the master (`recording`: as the preflight read them,
    :func:`load_inputs`): its result, the file's stored PSINS values, the master's path
    and the filter's CPU time (s)."""
    from gcalign.transfer import transfer_align

    dtheta, dv, t, master, stored, ref_path = recording or load_inputs(sc)
    _covered(sc, t, master, ref_path)
    start = time.process_time()
    result = transfer_align(dtheta, dv, t, master, sc.align.transfer.settings(sc.earth_model))
    return result, stored, ref_path, time.process_time() - start


def execute(sc, seed: int | None = None, cache_key: str | None = None,
            progress=None, recording=None) -> Outcome:
    """Align (:func:`run_filter`), summarise (the align room's mode transfer)."""
    result, stored, ref_path, compute_s = run_filter(sc, recording)
    out = summary(sc, result, stored, ref_path, compute_s)
    # the filter's consistency (mean NIS, σ growth): calibrate's checks, on recorded data too
    warnings = (*sc.align.unused(sc), *result.health_warnings())
    out["warnings"] = list(warnings)
    return Outcome(out, lambda f: write(f, result, stored), None, None, warnings)


# -- table and figures (rich and matplotlib loaded by the caller's import of this module) --

#: the last state of each group but the last: a line under it in the tables
GROUP_ENDS = ("phiU", "dvU", "ebz", "dbz", "muz", "thz")


def table(s: dict):
    """One row per state: estimate ± σ (display units), σ0, convergence, PSINS's stored
    value where the file has one."""
    from gcalign.app.report import DASH, titled

    stored = s.get("psins_stored") or {}
    ref = {"eb": stored.get("eb0_dph"), "db": stored.get("db0_ug"),
           "mu": stored.get("mu0_arcmin")}
    fb = s["feedback"]
    loop = ("bias" if fb["bias"] else "no bias") + (" + attitude" if fb["attitude"] else "")
    t = titled(f"gcalign align --mode transfer: {s['scenario']} — {s['matching']} matching "
               f"over {s['duration_s']:.1f} s, {len(s['states'])} states, {loop} feedback, "
               f"gravity {s['gravity']}", ("state", "unit"),
               ("estimate", "σ", "σ0", "conv. s", "PSINS", "− PSINS"))
    for name, v in s["states"].items():
        k, unit = s["display_scale"][name], s["display_units"][name]
        g = group_of(name)
        vals = ref.get(g)
        st = vals["xyz".index(name[-1])] if vals is not None and name[-1] in "xyz" else None
        est, d = v["estimate"] * k, DECIMALS[unit]
        t.add_row(name, unit, f"{est:.{d}f}", f"{v['sigma'] * k:.{d}f}",
                  f"{v['sigma0'] * k:.{d}f}", f"{s['convergence_s'][name]:.1f}",
                  *((DASH, DASH) if st is None else (f"{st:.{d}f}", f"{est - st:+.{d}f}")),
                  end_section=name in GROUP_ENDS)
    e = s["attitude_error_vs_reference_arcmin"]
    notes = ["corrected slave vs master ∘ μ̂: the reference has no attitude" if e is None
             else f"corrected slave vs master ∘ μ̂ (φ E, N, U, ′): final "
             f"{_three(e['final'])}, RMS last 10 s {_three(e['rms_last_10s'])}",
             _nis_line(s["nis"], s["epochs"]),
             "conv. s: first time after which the estimate stays within 2σ (the final σ) "
             "of its final value; PSINS: the file's eb0, db0, mu0 (PSINS's own end-of-run "
             "estimates, not a truth)"]
    if "attitude_error_vs_psins_mu0_arcmin" in s:
        e0 = s["attitude_error_vs_psins_mu0_arcmin"]
        notes.insert(1, f"corrected slave vs master ∘ PSINS mu0 (′): final "
                        f"{_three(e0['final'])}, RMS last 10 s {_three(e0['rms_last_10s'])}")
    t.caption = "\n".join(notes)
    return t


def _nis_line(nis: dict, epochs: int) -> str:
    """The mean NIS against the 95 % band of a mean over the run's epochs (the health
    check), marked when outside it; the band of one epoch beside it."""
    lo, hi = nis.get("band_95_of_mean", (None, None))
    one = (f"one epoch {nis['band_95'][0]:.2f}–{nis['band_95'][1]:.2f}")
    if lo is None:  # a results file of an earlier version (gcalign show)
        return f"NIS mean {nis['mean']:.2f} (dof {nis['dof']}, 95 % band of {one})"
    text = (f"NIS mean {nis['mean']:.3g} over {epochs} epochs (dof {nis['dof']}); 95 % band "
            f"of such a mean {lo:.2f}–{hi:.2f}, of {one}")
    if nis.get("consistent", True):
        return text
    return f"[bold yellow]{text}: the mean lies OUTSIDE its band (see the warning)[/]"


def _three(v) -> str:
    return "(" + ", ".join(f"{x:+.2f}" for x in v) + ")"


def figures(f, name: str) -> dict:
    """kfplot-like panels: per state group, the estimate with ±σ against time and, for ε,
    ∇, μ, PSINS's stored value as a dashed line."""
    from gcalign.app.plots import finish, new_figure
    from gcalign.io.stored import read_fields
    from gcalign.transfer import TransferResult

    g = f["align/transfer"]
    r = read_fields(g, TransferResult)  # the filter's series, as its fields say
    names, t, x, sig = r.names, r.t, r.x, r.sigma
    units = str(g.attrs["display_units"]).split(",")
    scale = np.asarray(g.attrs["display_scale"], dtype=float)
    groups = state_groups(names)
    fig, axes = new_figure(len(groups), width=9.0, height=2.2 * len(groups) + 1.2)
    for ax, (gr, idx) in zip(axes, groups, strict=True):
        for c, i in zip(COLOURS, idx, strict=True):
            k = scale[i]
            ax.plot(t, x[:, i] * k, color=c, linewidth=1.0, label=names[i])
            ax.fill_between(t, (x[:, i] - sig[:, i]) * k, (x[:, i] + sig[:, i]) * k,
                            color=c, alpha=0.18, linewidth=0)
        # the ±σ band of the first seconds spans P0: the axis shows the estimates after
        # the first 10 % of the run, ±2σ at the end, and the stored values
        k0 = int(np.searchsorted(t, t[0] + 0.1 * (t[-1] - t[0])))
        vals = [x[k0:, idx] * scale[idx], (x[-1, idx] + 2 * sig[-1, idx]) * scale[idx],
                (x[-1, idx] - 2 * sig[-1, idx]) * scale[idx]]
        if (ref := g.attrs.get(f"psins_{gr}0")) is not None:  # eb0, db0, mu0
            vals.append(np.asarray(ref, dtype=float) * scale[idx])
            for c, i, v in zip(COLOURS, idx, vals[-1], strict=True):
                ax.axhline(v, color=c, linestyle="--", linewidth=0.9,
                           label=f"PSINS {gr}0 {names[i][-1]}")
        v = np.concatenate([np.ravel(a) for a in vals])
        pad = 0.1 * (np.nanmax(v) - np.nanmin(v)) + 1e-9
        ax.set_ylim(np.nanmin(v) - pad, np.nanmax(v) + pad)
    ylabels = [f"{GROUPS[gr]}\n({units[idx[0]]})" for gr, idx in groups]
    return {"transfer_states": finish(
        fig, axes, "time (s)", f"{name}: transfer alignment ({g.attrs.get('matching', '')} "
        "matching) — estimates ± 1σ; dashed: the file's stored PSINS values", ylabels)}
