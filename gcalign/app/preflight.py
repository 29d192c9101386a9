"""Checks before a run: what `gcalign validate`, every command run and a batch's variants
run first.

:func:`preflight` looks at a parsed scenario the way a command is about to use it -- where
its data come from (simulated motion or a recorded file, read and validated), then each
command's own :meth:`~gcalign.app.command.Command.check` and
:meth:`~gcalign.app.command.Command.cost`, refusing a run with one line when a limit of
:mod:`gcalign.limits` would be exceeded (:func:`budget`). ``gcalign validate`` calls it for
every section of the scenario; a run calls it for its own command (:func:`checked_run`),
so both take the same decisions. Nothing here imports numba or scipy.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

from gcalign import limits
from gcalign.app.command import DOUBLE, Command, Cost, Extent, Inputs, Outcome, config, loading
from gcalign.app.registry import COMMANDS, command
from gcalign.errors import GcalignError, ScenarioError, clip
from gcalign.io.paths import not_a_file
from gcalign.io.scenario import Scenario

if TYPE_CHECKING:
    from gcalign.app.data import Recording

__all__ = ["Extent", "budget", "check_seed", "checked_run", "load", "preflight", "sensor_errors",
           "total_runs"]

BATCH_DOUBLES = 30  #: per sample held by a batch variant: its noise-free run and its errors


def load(sc: Scenario, read_recorded: bool = True,
         recording: Recording | None = None) -> Inputs:
    """The scenario's inputs (:class:`~gcalign.app.command.Inputs`): a recorded file read
    and validated when `read_recorded` (`recording`: as an earlier run of the same scenario
    read it, a batch's), else only checked to exist; the extent of its data (None if it
    has none)."""
    if sc.reads_own_recording:
        return Inputs(sc)
    if sc.imu_file is not None:
        if not read_recorded:
            if not sc.imu_file.is_file():
                raise ScenarioError(f"imu_file: {sc.imu_file}: {not_a_file(sc.imu_file)}")
            return Inputs(sc)
        from gcalign.app.data import no_site
        from gcalign.app.data import read_recorded as read

        recording = recording or read(sc)
        imu = recording.imu
        lat = None if imu.site is None else float(imu.site[0])
        ext = Extent(len(imu), float(imu.ts), True, recording.truth is not None, lat)
        start_pos = sc.initial is not None and sc.initial.position() is not None
        if sc.site is None and ext.lat is None and sc.reference is None and not start_pos:
            raise no_site(sc)
        return Inputs(sc, recording, ext)
    if sc.motion is None:
        return Inputs(sc)
    ts = sc.imu.ts
    return Inputs(sc, None, Extent(int(round(sc.motion.duration() / ts)), ts, False, True))


def preflight(sc: Scenario, name: str | None = None, read_recorded: bool = True,
              recording: Recording | None = None) -> Inputs:
    """Refuse (ScenarioError, one line naming the field) what the run of command `name`
    would refuse, and what would exceed a resource limit. ``name=None``: every section the
    scenario has (``gcalign validate``). Returns the inputs it loaded (:func:`load`), for
    the run; `recording` as :func:`load`."""
    commands = [command(name)] if name else _commands_of(sc)
    if name is not None:
        recorded_defaults(sc, commands[0].section)
    check_seed(sc.imu.seed, "imu.seed")
    # recorded data are read only for a command that can use them (the others refuse them)
    inputs = load(sc, read_recorded and any(c.options.recorded for c in commands), recording)
    if name is not None and read_recorded and sc.reads_own_recording:
        inputs = replace(inputs, recording=recording or commands[0].read_own(sc))
    ext = inputs.extent
    if ext is not None and not ext.recorded:
        sensor_errors(sc)
    if ext is None and sc.imu_file is None and not (
            commands and all(c.options.self_contained for c in commands)):
        raise ScenarioError("motion: missing; the scenario needs 'motion' (simulated data) "
                            "or 'imu_file' (recorded data)"
                            + ("" if name else ", or a northfind/realtime section"))
    if ext is not None and ext.recorded and recording is None:  # a held one was checked
        consistent(sc, inputs.recording)                          # at its variant's first seed
    for c in commands:
        try:
            c.check(inputs)
            budget(inputs, c)
        except GcalignError:
            raise
        except (ValueError, TypeError) as err:  # a settings object refused what it was given
            raise setup_error(c.section or c.name, err) from None
    return inputs


def consistent(sc: Scenario, recording: Recording) -> None:
    """A recording against what else the scenario says of the same vehicle
    (:mod:`gcalign.io.recorded.consistency`): at rest, its gyros against the earth rate at
    the site (a PSINS header's site is checked as the file is read); a reference's attitude
    against its gyros; its forward axis against a velocity (the reference's, a velocity
    aiding file's). ScenarioError naming the likely fix; ``imu_file.check_consistency:
    false`` and ``reference.check_attitude: false`` turn them off."""
    import numpy as np

    from gcalign.io.recorded import consistency as K

    layout = sc.recording_layout()
    assert sc.imu_file is not None
    imu = recording.imu
    record = imu.meta.get("recording") or {}
    if not record or not layout.check_consistency:
        return
    name = str(sc.imu_file)
    units = record["units"]["gyro"]
    ref = sc.reference.read() if sc.reference is not None else None
    if imu.site is None:
        lat = (sc.site.to_si()[0] if sc.site is not None else
               float(ref.pos[0, 0]) if ref is not None else None)
        if lat is not None:
            K.earth_rate_at_rest(name, imu.dtheta, imu.dv, imu.ts, float(lat),
                                 gyro_units=units, fmt=record["format"])
    if ref is not None and ref.att is not None and sc.reference is not None and \
            sc.reference.check_attitude:
        K.reference_against_gyros(str(sc.reference.path), ref.t, ref.att, float(ref.pos[0, 0]),
                                  imu.t, imu.dtheta, sc.reference.format)
    velocity = None
    if ref is not None:
        velocity = (ref.t, ref.v_n, f"the reference {sc.reference.path}")  # type: ignore[union-attr]
    elif sc.align is not None and sc.align.aiding.source == "file" and \
            sc.align.aiding.format != "odometer":
        v = sc.align.aiding.read()
        velocity = (v.t, v.v_n, f"align.aiding {sc.align.aiding.path}")
    elif (sc.calibrate is not None and sc.calibrate.files is not None
          and sc.calibrate.files.velocity is not None):
        from gcalign.io.recorded.aiding import read_velocity_aiding

        f = sc.calibrate.files.velocity
        v = read_velocity_aiding(f.path, f.format, f.columns, f.variable)
        velocity = (v.t, v.v_n, f"calibrate.files.velocity {f.path}")
    if velocity is not None and velocity[1] is not None:
        K.forward_axis(name, imu.t, imu.dtheta, imu.dv, velocity[0], velocity[1],
                       np.asarray(record["C_rfu_file"], dtype=float), velocity[2])


def recorded_defaults(sc: Scenario, section: str | None) -> None:
    """A recording's scenario without the command's section runs with the section
    ``--imu-file X`` alone gets (:data:`gcalign.io.scenario.recording.RECORDED_DEFAULTS`:
    an inertial-frame coarse alignment over the first minute, not the simulated default
    'given', which needs truth), set on `sc` in place."""
    from gcalign.io.scenario.recording import RECORDED_DEFAULTS

    if sc.imu_file is not None and section in RECORDED_DEFAULTS and getattr(sc, section) is None:
        setattr(sc, section, config(sc, section, RECORDED_DEFAULTS[section]))


def setup_error(section: str, err: Exception) -> ScenarioError:
    """A ValueError or TypeError raised while a run is set up from its scenario (settings
    built, checked, costed; before any computation) as bad input naming the section: one
    line, exit 2. Pydantic's errors become its one-line-per-field form."""
    from pydantic import ValidationError

    from gcalign.io.scenario.messages import scenario_errors

    if isinstance(err, ValidationError):
        return ScenarioError(scenario_errors(err, section, Scenario))
    return ScenarioError(f"{section}: {err}")


def _commands_of(sc: Scenario) -> list[Command]:
    """The commands a scenario's sections ask for: simulate (a motion), navigate (a
    navigation section or recorded data), and every command whose section it has."""
    out = [COMMANDS["simulate"]] if sc.motion is not None else []
    if sc.navigation is not None or sc.imu_file is not None:
        out.append(COMMANDS["navigate"])
    return out + [c for c in COMMANDS.values() if c.name not in ("simulate", "navigate")
                  and c.section is not None and getattr(sc, c.section, None) is not None]


def checked_run(name: str, sc: Scenario, seed: int | None = None, *args: Any,
                progress: Any = None, recording: Recording | None = None,
                **options: Any) -> tuple[Outcome, Inputs]:
    """Command `name`'s ``execute`` after its preflight (the checks and the cost estimate
    ``gcalign validate`` makes), with the seed checked to lie in [0, 2^63); the summary is
    checked to be finite. `progress` goes to a command whose ``execute`` takes it (asked
    after the preflight: the run's modules load only for a run that will happen). Returns
    the outcome and the inputs the preflight loaded and the run used (the recorded file
    read once, for both; `recording`: as an earlier run of the same scenario read it, which
    a batch's runs of a variant pass along)."""
    from gcalign.io.results import finite_summary

    check_seed(seed)
    inputs = preflight(sc, name, recording=recording)
    cmd = command(name)
    with loading():  # the run's modules, numba and its kernels with them
        takes_progress = cmd.accepts("progress")
    if progress is not None and takes_progress:
        options["progress"] = progress
    outcome = cmd.execute(sc, seed, *args, recording=inputs.recording, **options)
    finite_summary(outcome.summary, name)
    return outcome, inputs


def sensor_errors(sc: Scenario) -> None:
    """Refuse sensor errors that alone put a simulated increment past the bounds recorded
    data are held to (:data:`gcalign.io.imu_files.MAX_DTHETA_RAD`, ``MAX_DV_MPS`` per
    sample), so that validate refuses what the run would refuse in its first block
    (:func:`gcalign.app.data.check_finite_block`, e.g. ``bias_ug: [1e308, 0, 0]``): the bias
    over one sample, a tenth of the bound for one standard deviation of the noise (a
    Gaussian tail would cross it within a run), and scale-factor and misalignment errors
    beyond 100 % (1e6 ppm, 1 rad). Necessary, not sufficient: the motion adds its own
    increments, which only the run sees."""
    import numpy as np

    from gcalign.io.imu_files import MAX_DTHETA_RAD, MAX_DV_MPS

    ts = sc.imu.ts
    errs = sc.imu.errors()
    for name, e, bound, keys, unit in (
            ("gyro", errs.gyro, MAX_DTHETA_RAD, ("bias_dph", "arw_dprh"), "rad"),
            ("accel", errs.accel, MAX_DV_MPS, ("bias_ug", "vrw_ugrhz"), "m/s")):
        for key, per_sample, cap in ((keys[0], np.abs(e.bias) * ts, bound),
                                     (keys[1], e.noise * np.sqrt(ts), bound / 10)):
            if not (per_sample <= cap).all():
                raise ScenarioError(
                    f"imu.{name}.{key}: {float(per_sample.max()):.3g} {unit} per sample at "
                    f"{sc.imu.rate_hz:g} Hz, beyond {cap:g} {unit} (no instrument is this bad)")
        for key, a, cap in (("scale_ppm", np.abs(e.scale) + np.abs(e.asym), 1.0),
                            ("misalignment_arcsec", np.abs(e.misalignment), 1.0)):
            if not (a <= cap).all():
                raise ScenarioError(f"imu.{name}.{key}: beyond 100 % (1e6 ppm, 1 rad) of the "
                                    "input; check the units")


def budget(inputs: Inputs, cmd: Command, workers: int = 1, where: str | None = None,
           batch: bool = False) -> Cost:
    """Refuse a run whose estimated cost (:meth:`Command.cost`) exceeds a limit: one line
    naming the estimate, the limit and the variable that raises it. `workers` runs at once
    (a batch: each holds its variant's noise-free simulation)."""
    cost, ext = cmd.cost(inputs), inputs.extent
    where = where or cmd.name
    seconds = "" if ext is None else f"{cost.samples * ext.ts:.3g} s of data at {1 / ext.ts:g} Hz"
    limits.MAX_SAMPLES.check(cost.samples, where, seconds)
    held = cost.memory_bytes
    if batch or workers > 1:
        per_run = 0.0 if ext is None else ext.samples * BATCH_DOUBLES * DOUBLE
        held = max(held, per_run) * workers
    hint = ", ".join(x for x in (cost.memory_what and f"held by {cost.memory_what}",
                                 f"{workers} worker(s)" if workers > 1 else "") if x)
    limits.MAX_MEMORY_MB.check(held / 2**20, where, hint)
    limits.MAX_OUTPUT_MB.check(cost.output_bytes / 2**20, where,
                               "store fewer rows with output.rate_hz")
    limits.MAX_WORK.check(cost.work, where, cost.work_what)
    return cost


def check_seed(seed: int | None, what: str = "--seed") -> int | None:
    """A seed within [0, 2^63) (numpy takes any non-negative integer, HDF5 attributes and
    the JSON summary signed 64-bit ones); ScenarioError (exit 2) otherwise."""
    if seed is None:
        return None
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= limits.SEED_MAX:
        raise ScenarioError(f"{what}: must be a whole number within [0, 2^63), got "
                            f"{clip(str(seed), 30)}")
    return seed


def total_runs(variants: int, seeds: int, where: str) -> None:
    limits.MAX_VARIANTS.check(variants, where, "a smaller grid")
    limits.MAX_RUNS.check(variants * seeds, where, f"{variants} variant(s) × {seeds} seed(s)")

