"""The sweep model: a base scenario × a grid of overrides × seeds, validated up front.

The sweep format is described in ``docs/batch.md``.

A *sweep* is a base scenario (a path relative to the sweep file, or an inline mapping), a
*grid* of overrides by dotted key (``align.stages.0.t_z_s: [100, 150, 200]``), optional
named *cases* (settings that change several keys together, e.g. an IMU grade and its
aiding), a seed count and the *metrics* to aggregate (dotted paths into the run summary,
e.g. ``error_t3_deg``). A *variant* is one point of the Cartesian product cases × grid; a
*run* is a variant and a seed. Every variant runs the same seeds
``seed_start .. seed_start + seeds - 1`` (common random numbers), so differences between
variants are not masked by different noise.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path

from gcalign.app.batch.overrides import apply_override
from gcalign.errors import ScenarioError
from gcalign.io.scenario.loader import _cut
from gcalign.limits import SEED_MAX


def batchable() -> dict[str, tuple[str, ...]]:
    """The commands a sweep can run -> their default metrics (from the registry)."""
    from gcalign.app.registry import batchable as registered

    return {name: c.options.batch_metrics for name, c in registered().items()}


SWEEP_KEYS = ("name", "base", "command", "cases", "grid", "seeds", "seed_start", "metrics")
CASE_KEY = "case"  # the pseudo grid key of a variant's case (not a scenario key)


@dataclass(frozen=True)
class Variant:
    """One grid point: its overrides (dotted key -> value; ``case`` -> the case's name when
    the sweep has cases) and the resulting scenario."""

    index: int
    overrides: dict
    scenario: dict
    key: str  # hash of command, metrics and scenario: identifies its runs across resumes

    @property
    def label(self) -> str:
        if not self.overrides:
            return "base"
        return ", ".join(f"{k}={_short(v)}" for k, v in self.overrides.items())


@dataclass(frozen=True)
class Sweep:
    """A validated sweep: every variant's scenario has passed ``parse_scenario``."""

    name: str
    command: str
    source: str
    text: str
    base_source: str
    base_text: str
    grid: dict  # with cases: {"case": [names], **grid}, the axes in variant order
    cases: dict  # case name -> its overrides (dotted key -> value); {} without cases
    seeds: int
    seed_start: int
    metrics: tuple[str, ...]
    variants: tuple[Variant, ...]

    @property
    def seed_values(self) -> range:
        return range(self.seed_start, self.seed_start + self.seeds)

    def run_keys(self) -> list[tuple[int, int]]:
        """``(variant, seed)`` of every run, in canonical order."""
        return [(v.index, s) for v in self.variants for s in self.seed_values]

    @property
    def fingerprint(self) -> str:
        return _hash([v.key for v in self.variants], list(self.seed_values))


def _short(v) -> str:
    text = json.dumps(v) if not isinstance(v, str) else v
    return text if len(text) <= 40 else text[:37] + "..."


def _hash(*parts) -> str:
    text = json.dumps(parts, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_sweep(path: Path) -> Sweep:
    """Read and validate a sweep file (ScenarioError, exit 2, on any bad input)."""
    from gcalign.io.scenario.loader import read_yaml

    path = Path(path)
    data = read_yaml(path)
    return sweep_from_mapping(data, str(path), path.parent, path.read_text(encoding="utf-8"),
                              default_name=path.stem)


def sweep_from_mapping(data, source: str = "sweep", base_dir: Path | None = None,
                       text: str | None = None, default_name: str = "sweep") -> Sweep:
    """Validate a parsed sweep mapping; every variant is parsed before anything runs.

    Raises ScenarioError with one line naming the key and the value that is wrong.
    """
    import yaml

    from gcalign.io.scenario import parse_scenario
    from gcalign.io.scenario.loader import read_yaml

    base_dir = Path(base_dir or ".")
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: a sweep must be a YAML mapping, got {type(data).__name__}")
    for k in data:
        if k not in SWEEP_KEYS:
            raise ScenarioError(f"{source}: {k}: unknown key (a sweep has: "
                                f"{', '.join(SWEEP_KEYS)})")
    text = text if text is not None else yaml.safe_dump(data, sort_keys=False)

    name = data.get("name", default_name)
    if not isinstance(name, str) or not name or any(c in name for c in "/\\ \t"):
        raise ScenarioError(f"{source}: name: must be a non-empty word (used in file names), "
                            f"got {_cut(name)}")

    # Base scenario: a file relative to the sweep, or an inline mapping.
    if "base" not in data:
        raise ScenarioError(f"{source}: base: missing; give a scenario file (relative to the "
                            "sweep file) or an inline scenario mapping")
    base = data["base"]
    if isinstance(base, str):
        base_path = (base_dir / base) if not Path(base).is_absolute() else Path(base)
        if not base_path.is_file():
            raise ScenarioError(f"{source}: base: {_cut(base)}: file not found ({base_path})")
        base_data = read_yaml(base_path)
        base_source, base_text = str(base_path), base_path.read_text(encoding="utf-8")
        imu_dir = base_path.parent
    elif isinstance(base, dict):
        base_data, base_source = copy.deepcopy(base), f"{source}: base"
        base_text, imu_dir = yaml.safe_dump(base, sort_keys=False), base_dir
    else:
        raise ScenarioError(f"{source}: base: must be a scenario file name or a mapping, "
                            f"got {type(base).__name__} {_cut(base)}")
    if isinstance(base_data, dict) and isinstance(base_data.get("imu_file"), str):
        p = Path(base_data["imu_file"])  # workers may run elsewhere: make it absolute
        base_data["imu_file"] = str(p if p.is_absolute() else (imu_dir / p).resolve())
    base_model = parse_scenario(base_data, base_source)

    command = data.get("command")
    if command is None:
        has = [c for c in batchable() if isinstance(base_data, dict) and c in base_data]
        if len(has) > 1:
            raise ScenarioError(f"{source}: command: the base has sections for "
                                f"{', '.join(has)}; say which to run (command: "
                                f"{' | '.join(has)})")
        command = has[0] if has else "align"
    if command not in batchable():
        raise ScenarioError(f"{source}: command: must be one of {', '.join(batchable())}, "
                            f"got {_cut(command)}")

    seeds = data.get("seeds", 1)
    if isinstance(seeds, bool) or not isinstance(seeds, int) or seeds < 1:
        raise ScenarioError(f"{source}: seeds: must be a whole number ≥ 1 (the seed count), "
                            f"got {_cut(seeds)}")
    seed_start = data.get("seed_start", 1)
    if isinstance(seed_start, bool) or not isinstance(seed_start, int) or seed_start < 0:
        raise ScenarioError(f"{source}: seed_start: must be a whole number ≥ 0, got "
                            f"{_cut(seed_start)}")
    if seed_start + seeds - 1 > SEED_MAX:
        raise ScenarioError(f"{source}: seed_start: the seeds {seed_start} .. "
                            f"{seed_start + seeds - 1} pass 2^63 - 1 (seeds are signed 64-bit)")

    metrics = data.get("metrics", list(batchable()[command]))
    if isinstance(metrics, str):
        metrics = [metrics]
    if not isinstance(metrics, list) or not metrics:
        raise ScenarioError(f"{source}: metrics: must be a non-empty list of dotted paths into "
                            f"the run summary (e.g. [error_t3_deg]), got {_cut(metrics)}")
    for m in metrics:
        if not isinstance(m, str) or not m or "/" in m or any(p == "" for p in m.split(".")):
            raise ScenarioError(f"{source}: metrics: {_cut(m)} is not a dotted path "
                                "(e.g. error_t3_deg, passes.2.error_deg)")
    if len(set(metrics)) != len(metrics):
        raise ScenarioError(f"{source}: metrics: {_cut(metrics)} names a metric twice")

    grid = data.get("grid") or {}
    if not isinstance(grid, dict):
        raise ScenarioError(f"{source}: grid: must be a mapping of dotted key -> list of values, "
                            f"got {type(grid).__name__}")
    cases = _cases(data.get("cases"), source)
    axes: dict[str, list] = {}
    for key, values in grid.items():
        if not isinstance(key, str) or not key:
            raise ScenarioError(f"{source}: grid: {_cut(key)}: keys must be dotted paths "
                                "(e.g. align.mode)")
        if key == CASE_KEY:
            raise ScenarioError(f"{source}: grid: {CASE_KEY}: reserved for the names of the "
                                "sweep's cases; give settings under 'cases:'")
        if not isinstance(values, list):
            values = [values]  # one fixed value
        if not values:
            raise ScenarioError(f"{source}: grid: {key} = []: empty list of values; give at "
                                "least one value")
        seen = [json.dumps(v, sort_keys=True, default=str) for v in values]
        for i, s in enumerate(seen):
            if s in seen[:i]:
                raise ScenarioError(f"{source}: grid: {key}: value {_cut(values[i])} appears twice")
        axes[key] = values

    n_variants = math.prod(len(v) for v in axes.values()) * max(1, len(cases))
    from gcalign.app.preflight import total_runs

    total_runs(n_variants, seeds, source)

    # Each case alone, then each grid key and value alone against the base: a message that
    # names exactly that case or pair.
    for case, over in cases.items():
        trial = copy.deepcopy(base_data)
        where = f"{source}: cases: {case}"
        for key, value in over.items():
            try:
                apply_override(trial, key, value, base_model)
            except ScenarioError as err:
                raise ScenarioError(f"{where}: {key} = {_cut(value)}: {err}") from None
        _check_section(parse_scenario(trial, where), command, where)
    for key, values in axes.items():
        for value in values:
            trial = copy.deepcopy(base_data)
            try:
                apply_override(trial, key, value, base_model)
            except ScenarioError as err:
                raise ScenarioError(f"{source}: grid: {key} = {_cut(value)}: {err}") from None
            where = f"{source}: grid: {key} = {_cut(value)}"
            _check_section(parse_scenario(trial, where), command, where)

    # Then every combination (a value may be valid alone but not with another one). A case's
    # overrides are applied first, then the grid's.
    if cases:
        axes = {CASE_KEY: list(cases), **axes}
    keys = list(axes)
    variants = []
    for i, combo in enumerate(itertools.product(*(axes[k] for k in keys))):
        overrides = dict(zip(keys, combo, strict=True))
        scenario = copy.deepcopy(base_data)
        label = ", ".join(f"{k} = {_cut(v)}" for k, v in overrides.items())
        applied = [*cases.get(str(overrides.get(CASE_KEY)), {}).items(),
                   *((k, v) for k, v in overrides.items() if k != CASE_KEY)]
        try:
            for k, v in applied:
                apply_override(scenario, k, v, base_model)
        except ScenarioError as err:
            raise ScenarioError(f"{source}: grid: variant {label}: {err}") from None
        where = f"{source}: grid: variant {label}"
        _check_section(parse_scenario(scenario, where), command, where)
        variants.append(Variant(i, overrides, scenario,
                                _hash(command, list(metrics), scenario)))
    return Sweep(name=name, command=command, source=source, text=text,
                 base_source=base_source, base_text=base_text, grid=axes, cases=cases,
                 seeds=seeds,
                 seed_start=seed_start, metrics=tuple(metrics), variants=tuple(variants))


def _cases(cases, source: str) -> dict[str, dict]:
    """The ``cases:`` mapping checked for shape: name -> mapping of dotted key -> value."""
    if cases is None:
        return {}
    if not isinstance(cases, dict) or not cases:
        raise ScenarioError(f"{source}: cases: must be a non-empty mapping of case name -> "
                            f"overrides (dotted key -> value), got {_cut(cases)}")
    out: dict[str, dict] = {}
    for name, over in cases.items():
        if not isinstance(name, str) or not name.strip():
            raise ScenarioError(f"{source}: cases: {_cut(name)}: a case name must be a non-empty "
                                "string")
        over = {} if over is None else over
        if not isinstance(over, dict):
            raise ScenarioError(f"{source}: cases: {name}: must be a mapping of dotted key -> "
                                f"value (or empty), got {_cut(over)}")
        for key in over:
            if not isinstance(key, str) or not key:
                raise ScenarioError(f"{source}: cases: {name}: {_cut(key)}: keys must be dotted "
                                    "paths (e.g. imu.gyro.arw_dprh)")
        out[name] = dict(over)
    return out


def _check_section(sc, command: str, where: str) -> None:
    """The checks a run of the command makes first (:func:`gcalign.app.preflight.preflight`:
    the section's own ``check``, times against the data, the cost of one run)."""
    from gcalign.app.preflight import preflight

    section = getattr(sc, command, None)
    if section is None and command != "align":
        raise ScenarioError(f"{where}: {command}: missing; command {_cut(command)} needs a "
                            f"'{command}' section in the base scenario")
    try:
        preflight(sc, command, read_recorded=False)
    except ScenarioError as err:
        raise ScenarioError(f"{where}: {err}") from None


#: The pseudo grid key of a batch over a list of scenario files: each file is a variant.
FILE_KEY = "scenario"


def sweep_from_files(paths: list[Path], command: str | None = None, seeds: int = 1,
                     seed_start: int = 1, metrics: list[str] | None = None) -> Sweep:
    """A batch over a plain list of scenario files (``gcalign batch a.yaml b.yaml …``):
    every file is a variant (labelled by its name under the pseudo key ``scenario``), run
    for the same seeds; each file is validated before anything runs.

    The command is `command`, or the one batchable command whose section every file has
    (``align`` when they have none); `metrics` default to the command's.
    """
    import yaml

    from gcalign.io.scenario import parse_scenario
    from gcalign.io.scenario.loader import read_yaml

    if not paths:
        raise ScenarioError("batch: give a sweep file or one or more scenario files")
    paths = [Path(p) for p in paths]
    datas, texts = [], []
    for path in paths:
        data = read_yaml(path)
        if isinstance(data, dict) and "base" in data:
            raise ScenarioError(f"{path}: a sweep file (it has 'base'); a batch takes one "
                                "sweep file, or a list of scenario files")
        if isinstance(data, dict) and isinstance(data.get("imu_file"), str):
            p = Path(data["imu_file"])  # workers may run elsewhere: make it absolute
            data["imu_file"] = str(p if p.is_absolute() else (path.parent / p).resolve())
        parse_scenario(copy.deepcopy(data), str(path))
        datas.append(data)
        texts.append(path.read_text(encoding="utf-8"))
    if command is None:
        found = {c for d in datas for c in batchable() if isinstance(d, dict) and c in d}
        if len(found) > 1:
            raise ScenarioError(f"batch: the files have sections of {', '.join(sorted(found))}; "
                                "say which command to run (--command)")
        command = found.pop() if found else "align"
    if command not in batchable():
        raise ScenarioError(f"--command: must be one of {', '.join(batchable())}, got {command!r}")
    labels = [p.name for p in paths]
    if len(set(labels)) < len(labels):
        labels = [str(p) for p in paths]
    if len(set(labels)) < len(labels):
        raise ScenarioError("batch: a scenario file is listed twice")
    spec = {"files": [str(p) for p in paths], "command": command, "seeds": seeds,
            "seed_start": seed_start, "metrics": list(metrics or batchable()[command])}
    stems = [p.name.split(".")[0] for p in paths]
    name = "+".join(stems) if len(stems) <= 3 else f"{stems[0]}+{len(stems) - 1}-more"
    # The checks of seeds, seed_start and metrics are the sweep's (one variant: file 1).
    sweep = sweep_from_mapping({"name": name, "base": copy.deepcopy(datas[0]),
                                "command": command, "seeds": seeds, "seed_start": seed_start,
                                "metrics": spec["metrics"]}, "batch")
    variants = []
    for i, (label, data) in enumerate(zip(labels, datas, strict=True)):
        where = f"{paths[i]}"
        _check_section(parse_scenario(copy.deepcopy(data), where), command, where)
        variants.append(Variant(i, {FILE_KEY: label}, data,
                                _hash(command, list(sweep.metrics), data)))
    base_text = "".join(f"# --- {p}\n{t}\n" for p, t in zip(paths, texts, strict=True))
    return Sweep(name=name, command=command, source="batch of " + ", ".join(map(str, paths)),
                 text=yaml.safe_dump(spec, sort_keys=False), base_source=", ".join(
                     map(str, paths)), base_text=base_text, grid={FILE_KEY: labels}, cases={},
                 seeds=sweep.seeds, seed_start=sweep.seed_start, metrics=sweep.metrics,
                 variants=tuple(variants))
