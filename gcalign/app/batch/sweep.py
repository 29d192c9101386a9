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
import dataclasses
import functools
import hashlib
import itertools
import json
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from pydantic import Field, ValidationError, ValidationInfo, field_validator, model_validator

from gcalign.app.batch.overrides import apply_override
from gcalign.errors import ScenarioError, clip
from gcalign.io.scenario.base import Model
from gcalign.io.scenario.messages import cut, scenario_errors
from gcalign.io.scenario.recording import absolute_paths, replace_paths
from gcalign.limits import SEED_MAX


def batchable() -> dict[str, tuple[str, ...]]:
    """The commands a sweep can run -> their default metrics (from the registry)."""
    from gcalign.app.registry import batchable as registered

    return {name: c.options.batch_metrics for name, c in registered().items()}


CASE_KEY = "case"  # the pseudo grid key of a variant's case (not a scenario key)


@dataclasses.dataclass(frozen=True)
class Variant:
    """One grid point: its overrides (dotted key -> value; ``case`` -> the case's name when
    the sweep has cases) and the resulting scenario."""

    index: int
    overrides: dict
    scenario: dict

    @property
    def label(self) -> str:
        if not self.overrides:
            return "base"
        return ", ".join(f"{k}={_short(v)}" for k, v in self.overrides.items())


@dataclasses.dataclass(frozen=True)
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
    #: keys that cannot matter to the command, over the variants, one line each (a grid key
    #: among them makes variants that differ only by it): warnings of batch and validate
    warnings: tuple[str, ...] = ()

    @property
    def seed_values(self) -> range:
        return range(self.seed_start, self.seed_start + self.seeds)

    def run_keys(self) -> list[tuple[int, int]]:
        """``(variant, seed)`` of every run, in canonical order."""
        return [(v.index, s) for v in self.variants for s in self.seed_values]

    @functools.cached_property
    def keys(self) -> tuple[str, ...]:
        """Each variant's key, which identifies its runs across resumes: a hash of the
        command, the metrics and its scenario, in which a file it names stands for its
        content, not its path (a moved or copied folder resumes, a recording changed in
        place runs again); each file is read once, when a batch first asks."""
        content = functools.cache(_digest)
        keys = []
        for v in self.variants:
            scenario = copy.deepcopy(v.scenario)
            replace_paths(scenario, content)
            keys.append(_hash(self.command, list(self.metrics), scenario))
        return tuple(keys)

    @property
    def fingerprint(self) -> str:
        return _hash(list(self.keys), list(self.seed_values))


def _short(v) -> str:
    return clip(json.dumps(v) if not isinstance(v, str) else v, 40)


def _hash(*parts) -> str:
    text = json.dumps(parts, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _digest(path: Path) -> str:
    """What a file holds: its SHA-256, read in 1 MiB chunks; its path where it is not a
    readable regular file (a FIFO would block; its runs say why)."""
    sha = hashlib.sha256()
    try:
        if not path.is_file():
            return str(path)
        with open(path, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                sha.update(chunk)
    except OSError:
        return str(path)
    return "sha256:" + sha.hexdigest()


def load_sweep(path: Path) -> Sweep:
    """Read and validate a sweep file (ScenarioError, exit 2, on any bad input)."""
    from gcalign.io.scenario.loader import read_yaml

    path = Path(path)
    data = read_yaml(path)
    return sweep_from_mapping(data, str(path), path.parent, path.read_text(encoding="utf-8"),
                              default_name=path.stem)


class SweepFile(Model):
    """The keys of a sweep file, checked for shape (docs/batch.md); what they mean for the
    base scenario is checked by :func:`sweep_from_mapping`."""

    name: str | None = None
    base: Any = None
    command: Any = None
    cases: dict[str, dict[str, Any]] = Field(default_factory=dict)
    grid: dict[str, list[Any]] = Field(default_factory=dict)
    seeds: int = 1
    seed_start: int = 1
    metrics: list[str] | None = None

    @model_validator(mode="before")
    @classmethod
    def _base_given(cls, data: Any) -> Any:
        if "base" not in data and set(data) <= set(cls.model_fields):  # else: name the unknown key
            raise ValueError("base: missing; give a scenario file (relative to the sweep "
                             "file) or an inline scenario mapping")
        return data

    @field_validator("name", mode="before")
    @classmethod
    def _word(cls, v: Any) -> Any:
        if v is not None and (not isinstance(v, str) or not v or any(c in v for c in "/\\ \t")):
            raise ValueError(f"must be a non-empty word (used in file names), got {cut(v)}")
        return v

    @field_validator("base", mode="before")
    @classmethod
    def _base(cls, v: Any) -> Any:
        if not isinstance(v, (str, dict)):
            raise ValueError(f"must be a scenario file name or a mapping, got "
                             f"{type(v).__name__} {cut(v)}")
        return v

    @field_validator("seeds", "seed_start", mode="before")
    @classmethod
    def _whole(cls, v: Any, info: ValidationInfo) -> int:
        least, what = (1, " (the seed count)") if info.field_name == "seeds" else (0, "")
        if isinstance(v, bool) or not isinstance(v, int) or v < least:
            raise ValueError(f"must be a whole number ≥ {least}{what}, got {cut(v)}")
        return v

    @field_validator("metrics", mode="before")
    @classmethod
    def _metrics(cls, v: Any) -> Any:
        if v is None:
            return v
        v = [v] if isinstance(v, str) else v
        if not isinstance(v, list) or not v:
            raise ValueError("must be a non-empty list of dotted paths into the run summary "
                             f"(e.g. [error_t3_deg]), got {cut(v)}")
        for m in v:
            if not isinstance(m, str) or not m or "/" in m or "" in m.split("."):
                raise ValueError(f"{cut(m)} is not a dotted path (e.g. error_t3_deg, "
                                 "passes.2.error_deg)")
        if len(set(v)) != len(v):
            raise ValueError(f"{cut(v)} names a metric twice")
        return v

    @field_validator("grid", mode="before")
    @classmethod
    def _grid(cls, v: Any) -> dict:
        if not v:
            return {}
        if not isinstance(v, dict):
            raise ValueError("must be a mapping of dotted key -> list of values, got "
                             f"{type(v).__name__}")
        axes = {}
        for key, values in v.items():
            if not isinstance(key, str) or not key:
                raise ValueError(f"{cut(key)}: keys must be dotted paths (e.g. align.mode)")
            if key == CASE_KEY:
                raise ValueError(f"{CASE_KEY}: reserved for the names of the sweep's cases; "
                                 "give settings under 'cases:'")
            values = values if isinstance(values, list) else [values]  # one fixed value
            if not values:
                raise ValueError(f"{key} = []: empty list of values; give at least one value")
            seen = [json.dumps(x, sort_keys=True, default=str) for x in values]
            for i, text in enumerate(seen):
                if text in seen[:i]:
                    raise ValueError(f"{key}: value {cut(values[i])} appears twice")
            axes[key] = values
        return axes

    @field_validator("cases", mode="before")
    @classmethod
    def _cases(cls, v: Any) -> dict:
        """name -> mapping of dotted key -> value."""
        if v is None:
            return {}
        if not isinstance(v, dict) or not v:
            raise ValueError("must be a non-empty mapping of case name -> overrides (dotted "
                             f"key -> value), got {cut(v)}")
        out: dict[str, dict] = {}
        for name, over in v.items():
            if not isinstance(name, str) or not name.strip():
                raise ValueError(f"{cut(name)}: a case name must be a non-empty string")
            over = {} if over is None else over
            if not isinstance(over, dict):
                raise ValueError(f"{name}: must be a mapping of dotted key -> value (or "
                                 f"empty), got {cut(over)}")
            for key in over:
                if not isinstance(key, str) or not key:
                    raise ValueError(f"{name}: {cut(key)}: keys must be dotted paths (e.g. "
                                     "imu.gyro.arw_dprh)")
            out[name] = dict(over)
        return out

    @model_validator(mode="after")
    def _seed_range(self) -> SweepFile:
        last = self.seed_start + self.seeds - 1
        if last > SEED_MAX:
            raise ValueError(f"seed_start: the seeds {self.seed_start} .. {last} pass 2^63 - 1 "
                             "(seeds are signed 64-bit)")
        return self


def _read_base(spec: SweepFile, source: str, base_dir: Path) -> tuple[dict, str, str]:
    """The base scenario's mapping (its file paths made absolute: workers may run
    elsewhere), source and text."""
    import yaml

    from gcalign.io.scenario.loader import read_yaml

    if isinstance(spec.base, dict):
        data, where, folder = copy.deepcopy(spec.base), f"{source}: base", base_dir
        text = yaml.safe_dump(spec.base, sort_keys=False)
    else:
        path = base_dir / spec.base  # (an absolute path stays itself)
        if not path.is_file():
            raise ScenarioError(f"{source}: base: {cut(spec.base)}: file not found ({path})")
        data, where, folder = read_yaml(path), str(path), path.parent
        text = path.read_text(encoding="utf-8")
    absolute_paths(data, folder)
    return data, where, text


def _command_of(spec: SweepFile, base_data: Any, source: str) -> str:
    """The sweep's command, or the one batchable command whose section the base has."""
    commands = batchable()
    command = spec.command
    if command is None:
        has = [c for c in commands if isinstance(base_data, dict) and c in base_data]
        if len(has) > 1:
            raise ScenarioError(f"{source}: command: the base has sections for "
                                f"{', '.join(has)}; say which to run (command: "
                                f"{' | '.join(has)})")
        command = has[0] if has else "align"
    if command not in commands:
        raise ScenarioError(f"{source}: command: must be one of {', '.join(commands)}, "
                            f"got {cut(command)}")
    return str(command)


def sweep_from_mapping(data, source: str = "sweep", base_dir: Path | None = None,
                       text: str | None = None, default_name: str = "sweep",
                       sets: Sequence[tuple[str, Any]] = ()) -> Sweep:
    """Validate a parsed sweep mapping (:class:`SweepFile`); every variant is parsed and
    preflighted before anything runs. `sets` (``--set KEY=VALUE`` of the command line, as
    (key, value)) change the base scenario before the grid is applied.

    Raises ScenarioError with one line naming the key and the value that is wrong.
    """
    import yaml

    from gcalign.app.preflight import total_runs
    from gcalign.io.scenario import parse_scenario
    from gcalign.io.scenario.loader import with_overrides
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: a sweep must be a YAML mapping, got {type(data).__name__}")
    try:
        spec = SweepFile.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(scenario_errors(err, source, SweepFile, "sweep")) from None
    text = text if text is not None else yaml.safe_dump(data, sort_keys=False)
    base_data, base_source, base_text = _read_base(spec, source, Path(base_dir or "."))
    base_model = parse_scenario(base_data, base_source)
    if sets:
        grid_keys = set(spec.grid) | {k for over in spec.cases.values() for k in over}
        apply_sets(base_data, sets, base_model, grid_keys)
        base_model = parse_scenario(base_data, base_source)
        text = with_overrides(text, " of the base", dict(sets))
    command = _command_of(spec, base_data, source)
    metrics = spec.metrics or list(batchable()[command])
    axes, cases = dict(spec.grid), spec.cases
    total_runs(math.prod(len(v) for v in axes.values()) * max(1, len(cases)), spec.seeds,
               source)

    def variant(applied, where: str, name_key: bool = False) -> tuple[dict, list[str]]:
        """The base with `applied` (key, value) overrides, parsed and preflighted, and its
        keys that cannot matter; a bad override is reported at `where` (and by its key and
        value with `name_key`)."""
        scenario = copy.deepcopy(base_data)
        for key, value in applied:
            try:
                apply_override(scenario, key, value, base_model)
            except ScenarioError as err:
                at = f"{where}: {key} = {cut(value)}" if name_key else where
                raise ScenarioError(f"{at}: {err}") from None
        return scenario, _check_section(parse_scenario(scenario, where), command, where)

    # Each case alone, then each grid key and value alone against the base: a message that
    # names exactly that case or pair.
    for case, over in cases.items():
        variant(over.items(), f"{source}: cases: {case}", name_key=True)
    for key, values in axes.items():
        for value in values:
            variant([(key, value)], f"{source}: grid: {key} = {cut(value)}")

    # Then every combination (a value may be valid alone but not with another one). A case's
    # overrides are applied first, then the grid's.
    if cases:
        axes = {CASE_KEY: list(cases), **axes}
    keys = list(axes)
    variants, unused = [], {}
    for i, combo in enumerate(itertools.product(*(axes[k] for k in keys))):
        overrides = dict(zip(keys, combo, strict=True))
        label = ", ".join(f"{k} = {cut(v)}" for k, v in overrides.items())
        applied = [*cases.get(str(overrides.get(CASE_KEY)), {}).items(),
                   *((k, v) for k, v in overrides.items() if k != CASE_KEY)]
        scenario, lines = variant(applied, f"{source}: grid: variant {label}")
        unused.update(dict.fromkeys(lines))
        variants.append(Variant(i, overrides, scenario))
    return Sweep(name=spec.name or default_name, command=command, source=source, text=text,
                 base_source=base_source, base_text=base_text, grid=axes, cases=cases,
                 seeds=spec.seeds, seed_start=spec.seed_start, metrics=tuple(metrics),
                 variants=tuple(variants), warnings=tuple(unused))


def _check_section(sc, command: str, where: str) -> list[str]:
    """The checks a run of the command makes first (:func:`gcalign.app.preflight.preflight`:
    the section's own ``check``, times against the data, the cost of one run); the keys
    that cannot matter to it (``Scenario.unused``)."""
    from gcalign.app.preflight import preflight

    section = getattr(sc, command, None)
    if section is None and command != "align":
        raise ScenarioError(f"{where}: {command}: missing; command {cut(command)} needs a "
                            f"'{command}' section in the base scenario")
    try:
        preflight(sc, command, read_recorded=False)
    except ScenarioError as err:
        raise ScenarioError(f"{where}: {err}") from None
    return sc.unused(command)


def apply_sets(data: dict, sets: Sequence[tuple[str, Any]], base_model: Any = None,
               grid_keys: Iterable[str] = ()) -> None:
    """The command line's ``--set KEY=VALUE`` items written into a scenario mapping, in
    place; a key the grid (or a case) also sets is refused: it would be overridden."""
    taken = set(grid_keys)
    for key, value in sets:
        if key in taken:
            raise ScenarioError(f"--set {key}: also set by the sweep's grid or cases; "
                                "give it once")
        try:
            apply_override(data, key, value, base_model)
        except ScenarioError as err:
            raise ScenarioError(f"--set {key}: {err}") from None


#: The pseudo grid key of a batch over a list of scenario files: each file is a variant.
FILE_KEY = "scenario"


def sweep_from_files(paths: list[Path], command: str | None = None, seeds: int = 1,
                     seed_start: int = 1, metrics: list[str] | None = None,
                     sets: Sequence[tuple[str, Any]] = ()) -> Sweep:
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
    datas, models, texts = [], [], []
    for path in paths:
        data = read_yaml(path)
        if isinstance(data, dict) and "base" in data:
            raise ScenarioError(f"{path}: a sweep file (it has 'base'); a batch takes one "
                                "sweep file, or a list of scenario files")
        absolute_paths(data, path.parent)  # workers may run elsewhere
        model = parse_scenario(copy.deepcopy(data), str(path))
        if sets and isinstance(data, dict):
            apply_sets(data, sets, model)
            model = parse_scenario(copy.deepcopy(data), str(path))
        datas.append(data)
        models.append(model)
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
    if sets:
        spec["set"] = dict(sets)
    stems = [p.name.split(".")[0] for p in paths]
    name = "+".join(stems) if len(stems) <= 3 else f"{stems[0]}+{len(stems) - 1}-more"
    unused: dict[str, None] = {}
    for path, model in zip(paths, models, strict=True):  # each file refused by its own name
        unused.update(dict.fromkeys(f"{path}: {line}"
                                    for line in _check_section(model, command, str(path))))
    # The checks of seeds, seed_start and metrics are the sweep's (one variant: file 1).
    sweep = sweep_from_mapping({"name": name, "base": copy.deepcopy(datas[0]),
                                "command": command, "seeds": seeds, "seed_start": seed_start,
                                "metrics": spec["metrics"]}, "batch")
    variants = [Variant(i, {FILE_KEY: label}, data)
                for i, (label, data) in enumerate(zip(labels, datas, strict=True))]
    return dataclasses.replace(
        sweep, source="batch of " + ", ".join(map(str, paths)),
        text=yaml.safe_dump(spec, sort_keys=False), base_source=", ".join(map(str, paths)),
        base_text="".join(f"# --- {p}\n{t}\n" for p, t in zip(paths, texts, strict=True)),
        grid={FILE_KEY: labels}, variants=tuple(variants), warnings=tuple(unused))
