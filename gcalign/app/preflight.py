"""Checks before a run: what `gcalign validate` and every command run first.

:func:`preflight` looks at a parsed scenario the way a command is about to use it -- where
its data come from (simulated motion or a recorded file, read and validated), the times
its sections name against the length of those data, each section's own ``check(sc)`` --
and estimates what the run will cost (samples to generate or read, memory it holds at once,
series it stores), refusing it with one line when a limit of :mod:`gcalign.limits` would be
exceeded. ``gcalign validate`` calls it for every section of the scenario; a command calls it
for its own section through :meth:`gcalign.app.registry.Command.execute`, so both take the
same decisions. Nothing here imports numba or scipy.
"""

from __future__ import annotations

from dataclasses import dataclass

from gcalign import limits
from gcalign.errors import ScenarioError
from gcalign.io.scenario import Scenario

#: commands that simulate their own data from their section (no motion or imu_file needed)
SELF_CONTAINED = ("northfind", "realtime")
#: commands that need a motion or an imu_file
DATA_COMMANDS = ("simulate", "navigate", "align")

_FLOAT = 8
#: doubles stored per output row: simulate (/truth t, att, v_n, pos, segment and /imu t,
#: dtheta, dv, q_bs), navigate (t, att, v_n, pos, errors, phi, ...)
_ROW_DOUBLES = {"simulate": 26, "navigate": 30}
_MEMORY_PER_SAMPLE = {  # doubles per sample held at once by runs that keep the whole window
    "align": 24,  # increments, reference velocity, stored truth rows
    "batch": 30,  # a batch variant's noise-free run (truth + ideal increments) + its errors
}


@dataclass(frozen=True)
class Extent:
    """The data a scenario gives: sample count, interval (s), whether recorded, truth."""

    samples: int
    ts: float
    recorded: bool
    has_truth: bool


def extent(sc: Scenario, read_recorded: bool = True) -> Extent | None:
    """Samples and interval of the scenario's data, or None if it has none. A recorded file
    is read and validated when `read_recorded` (validate), else only checked to exist."""
    if sc.imu_file is not None:
        from gcalign.app.data import read_data_file

        if not read_recorded:
            if not sc.imu_file.is_file():
                raise ScenarioError(f"imu_file: {sc.imu_file}: file not found")
            return None
        imu, truth = read_data_file(sc.imu_file, sc.recording_layout())
        if sc.site is None and imu.site is None and sc.reference is None:
            raise ScenarioError(f"site: missing; {sc.imu_file} does not give the site, so "
                                "the scenario must (site: {lat_deg, lon_deg, height_m}, "
                                "or a reference)")
        return Extent(len(imu), float(imu.ts), True, truth is not None)
    if sc.motion is None:
        return None
    ts = sc.imu.ts
    return Extent(int(round(sc.motion.duration() / ts)), ts, False, True)


def preflight(sc: Scenario, command: str | None = None, read_recorded: bool = True) -> None:
    """Refuse (ScenarioError, one line naming the field) what the run of `command` would
    refuse, and what would exceed a resource limit. ``command=None``: every section the
    scenario has (``gcalign validate``)."""
    commands = [command] if command else _commands_of(sc)
    check_seed(sc.imu.seed, "imu.seed")
    ext = extent(sc, read_recorded)
    if ext is not None and not ext.recorded:
        sensor_errors(sc)
    if ext is None and sc.imu_file is None:
        needs = [c for c in commands if c in DATA_COMMANDS]
        if needs or not any(c in SELF_CONTAINED for c in commands):
            raise ScenarioError("motion: missing; the scenario needs 'motion' (simulated data) "
                                "or 'imu_file' (recorded data)"
                                + ("" if command else ", or a northfind/realtime section"))
    for c in commands:
        section = getattr(sc, c, None) if c not in ("simulate", "navigate") else None
        check = getattr(section, "check", None)
        if callable(check):
            check(sc)
        if ext is not None:
            if c == "align":
                _align(sc, ext)
            elif c == "navigate":
                _navigate(sc, ext)
            budget(sc, c, ext)


def _commands_of(sc: Scenario) -> list[str]:
    out = ["simulate"] if sc.motion is not None else []
    out += ["navigate"] if sc.navigation is not None or sc.imu_file is not None else []
    from gcalign.app.registry import COMMANDS

    out += [c for c in COMMANDS if c not in ("simulate", "navigate", "batch")
            and getattr(sc, c, None) is not None]
    return out


def _stride(sc: Scenario, ext: Extent) -> int:
    try:
        return sc.output.stride(1.0 / ext.ts, ext.samples * ext.ts)
    except ValueError as err:
        raise ScenarioError(str(err)) from None


def _align_window(sc: Scenario, ext: Extent) -> tuple[int, int]:
    """First and last sample the alignment reads (as ``app.align.run``: ``_index``)."""
    from gcalign.io.scenario.align import AlignConfig

    cfg = sc.align or AlignConfig()
    his = []
    for field in ("start_s", "t1_s", "t2_s", "t3_s"):
        t = 0.0 if field == "start_s" else getattr(cfg, field)
        if t == "measured":
            continue
        k = int(round((cfg.start_s + t) / ext.ts))
        if k > ext.samples:
            raise ScenarioError(
                f"align.{field}: {t} s (+ start_s {cfg.start_s} s) is past the end of the data "
                f"({ext.samples * ext.ts:.2f} s); lengthen motion.duration_s or choose an "
                "earlier time")
        his.append(k)
    return int(round(cfg.start_s / ext.ts)), max(his)


def _align(sc: Scenario, ext: Extent) -> None:
    from gcalign.io.scenario.align import AlignConfig

    cfg = sc.align or AlignConfig()
    if sc.site is not None and abs(sc.site.lat_deg) > 85.0:
        raise ScenarioError(f"site.lat_deg: gyrocompassing needs |latitude| < 85°, got "
                            f"{sc.site.lat_deg:.4f}° (the horizontal earth rate vanishes)")
    if not ext.has_truth:
        if cfg.aiding.source in ("odometer", "nav"):
            raise ScenarioError(f"align.aiding.source: {cfg.aiding.source!r} needs a simulated "
                                "motion (truth); recorded data take 'file' or 'none'")
        if cfg.coarse.method == "given":
            raise ScenarioError("align.coarse.method: 'given' needs truth; use 'analytic' or "
                                "'inertial' for recorded data")
    _align_window(sc, ext)
    _stride(sc, ext)


def _navigate(sc: Scenario, ext: Extent) -> None:
    from gcalign.io.scenario.navigation import NavigationConfig

    cfg = sc.navigation or NavigationConfig()
    k = int(round(cfg.start_s / ext.ts))
    if k >= ext.samples:
        raise ScenarioError(f"navigation.start_s: {cfg.start_s:g} s is past the end of the "
                            f"data ({ext.samples * ext.ts:g} s)")
    _stride(sc, ext)


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


def cost(sc: Scenario, command: str, ext: Extent) -> tuple[float, float, float]:
    """(samples processed, bytes held at once, bytes of stored series) of one run."""
    n = float(ext.samples)
    held = 0.0
    stored = 0.0
    if command == "align":
        lo, hi = _align_window(sc, ext)
        n = float(hi)
        held = (hi - lo) * _MEMORY_PER_SAMPLE["align"] * _FLOAT
        passes = getattr(sc.align, "pass_count", 5) if sc.align is not None else 5
        stored = passes * (hi - lo) / _stride(sc, ext) * 12 * _FLOAT
    elif command in _ROW_DOUBLES:
        stored = n / _stride(sc, ext) * _ROW_DOUBLES[command] * _FLOAT
    return n, held, stored


def budget(sc: Scenario, command: str, ext: Extent, workers: int = 1,
           where: str | None = None) -> None:
    """Refuse a run whose estimated cost exceeds a limit (one line, the variable to raise)."""
    n, held, stored = cost(sc, command, ext)
    where = where or f"{command}"
    limits.MAX_SAMPLES.check(n, where, f"{n * ext.ts:.3g} s of data at {1 / ext.ts:g} Hz")
    if command == "batch" or workers > 1:
        held = max(held, ext.samples * _MEMORY_PER_SAMPLE["batch"] * _FLOAT) * workers
    limits.MAX_MEMORY_MB.check(held / 2**20, where,
                               f"{workers} worker(s)" if workers > 1 else "")
    limits.MAX_OUTPUT_MB.check(stored / 2**20, where, "store fewer rows with output.rate_hz")


def check_seed(seed: int | None, what: str = "--seed") -> int | None:
    """A seed within [0, 2^63) (numpy takes any non-negative integer, HDF5 attributes and
    the JSON summary signed 64-bit ones); ScenarioError (exit 2) otherwise."""
    if seed is None:
        return None
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= limits.SEED_MAX:
        text = str(seed)
        text = text if len(text) <= 30 else text[:27] + "..."
        raise ScenarioError(f"{what}: must be a whole number within [0, 2^63), got {text}")
    return seed


def total_runs(variants: int, seeds: int, where: str) -> None:
    limits.MAX_VARIANTS.check(variants, where, "a smaller grid")
    limits.MAX_RUNS.check(variants * seeds, where, f"{variants} variant(s) × {seeds} seed(s)")

