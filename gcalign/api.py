"""The Python API: load a scenario, run any command on it, read a results file back.

:func:`run` runs a command of the registry (:mod:`gcalign.app.registry`: ``simulate``,
``navigate``, ``align``, ``northfind``, ``realtime``, …) exactly as the command line does,
writes the same results file and returns a :class:`Result`; :func:`read` gives the same
object back from the file.

Examples
--------
>>> import gcalign
>>> sc = gcalign.example("northfind", {"northfind.sweep": None, "northfind.azimuth_deg": 48})
>>> res = gcalign.run("northfind", sc, seed=3)
>>> res.kind, res.seed, res["shape"]
('northfind', 3, [1, 1])
>>> abs(res["methods"]["coordinate"]["errors_deg"][0]) < 0.1   # deg, 24 positions × 60 s
True
>>> gcalign.read(res.path) == res
True
"""

from __future__ import annotations

import atexit
import copy
import os
import shutil
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from gcalign.errors import ScenarioError

#: Suffixes read as recorded IMU data rather than as a scenario (``load("x.imu.xz")``).
DATA_SUFFIXES = (".imu", ".csv", ".txt", ".mat", ".h5", ".hdf5", ".hdf")


@dataclass(frozen=True)
class Result:
    """What a run produced: the command (``kind``), its summary (plain numbers, degrees and
    seconds: the JSON of ``--json``), the random seed (None for recorded data), the
    warnings and the results file (``path``). ``res["error_t3_deg"]`` reads the summary.

    ``value`` is the capability's typed result in SI, as its function on arrays returns it
    (``align``: :class:`gcalign.align.gyrocompass.Alignment`, ``navigate``:
    :class:`gcalign.nav.navigate.Navigation`; None for a command without one), from
    :func:`run` only: a Result read back from its file has None there. It takes no part in
    ``==`` (the file holds the same numbers)."""

    kind: str
    summary: dict
    seed: int | None
    path: Path
    warnings: tuple[str, ...] = field(default=())
    value: Any = field(default=None, compare=False, repr=False)

    def __getitem__(self, key: str):
        return self.summary[key]

    def table(self):
        """The rich table the command prints."""
        from gcalign.app.readback import summary_table

        return summary_table(self.kind, self.summary)

    def figures(self) -> dict:
        """The figures ``gcalign plot`` writes, as matplotlib Figures, by name."""
        from gcalign.app.readback import figures_for

        return figures_for(self.path)

    def open(self):
        """The results file, open for reading (h5py.File; use it in a ``with``)."""
        from gcalign.io.results import open_results

        return open_results(self.path)

    def truth(self):
        """The full truth stored in the file (:class:`gcalign.sim.motions.Truth`: attitude,
        velocity and position at every sample), or None when the file holds none: recorded
        data, ``navigate`` and ``modulate`` (their errors against truth are in their own
        series), and ``align``, which stores the true attitude only (``series("truth")``
        reads it). ScenarioError when the full truth is there but damaged."""
        from gcalign.io.results import open_results, read_truth

        with open_results(self.path) as f:
            g = f.get("truth")
            if g is None or not all(k in g for k in ("t", "att", "v_n", "pos")):
                return None
        return read_truth(self.path)

    def imu(self):
        """The IMU increments stored by ``simulate`` (:class:`gcalign.sim.imu.ImuData`)."""
        from gcalign.io.results import read_imu

        return read_imu(self.path)

    def series(self, group: str | None = None) -> dict:
        """The time series of a group of the results file (default: the command's own),
        ``{name: (array, units)}`` in SI, ``t`` first."""
        from gcalign.io.results import series

        return series(self.path, group or self.kind)

    def dataframe(self, group: str | None = None):
        """The same series as a pandas DataFrame indexed by ``t`` (needs pandas)."""
        from gcalign.io.results import dataframe

        return dataframe(self.path, group or self.kind)

    def save(self, path: str | Path) -> Result:
        """A copy of the results file at `path`; the Result read from there."""
        shutil.copyfile(self.path, path)
        return read(path)


def _mapping(source) -> tuple[dict, str, Path | None]:
    """(mapping, source name, folder of relative paths) of a scenario source."""
    from gcalign.io.scenario.loader import read_yaml

    if isinstance(source, dict):
        return copy.deepcopy(source), "scenario", None
    if not isinstance(source, (str, os.PathLike)):
        raise ScenarioError(f"load: the scenario must be a file name, a path or a mapping, "
                            f"got {type(source).__name__}")
    path = Path(source)
    names = path.name.lower().split(".")
    if len(names) > 1 and ("." + names[-1] in DATA_SUFFIXES or (
            names[-1] in ("gz", "xz") and len(names) > 2)):
        return {"name": names[0] or "data", "imu_file": str(path.resolve())}, str(path), None
    return read_yaml(path), str(path), path.parent


def load(source, overrides: dict | None = None):
    """A scenario (:class:`gcalign.io.scenario.Scenario`) from a YAML file, a mapping, or
    a recorded data file (``.imu``, CSV, gcalign HDF5, ``.gz``/``.xz``; it stands for
    ``imu_file: SOURCE``), with `overrides` (dotted key -> value, as ``--set`` and a
    sweep's grid: ``{"align.mode": "conventional"}``; None removes a key). ScenarioError
    names a bad field. The model validates assignments too (``sc.align.t2_s = 200``)."""
    from gcalign.app.batch.overrides import apply_override
    from gcalign.io.scenario import parse_scenario

    data, name, folder = _mapping(source)
    if overrides is not None and not (isinstance(overrides, dict)
                                      and all(isinstance(k, str) for k in overrides)):
        raise ScenarioError("overrides: must map dotted keys to values ({'align.mode': "
                            f"'conventional'}}), got {type(overrides).__name__}")
    if overrides:
        base = parse_scenario(copy.deepcopy(data), name)
        for key, value in overrides.items():
            if value is None:
                _remove(data, key)
            else:
                apply_override(data, key, value, base)
    model = parse_scenario(data, name)
    if folder is not None:
        model.resolve_paths(folder)
    return model


def scenario_text(sc) -> str:
    """The YAML a results file stores for a scenario run from Python: the keys it sets
    (defaults stay defaults), as it is at run time."""
    return yaml.safe_dump(sc.model_dump(mode="json", exclude_unset=True), sort_keys=False)


def _remove(data: dict, key: str) -> None:
    *head, last = key.split(".")
    node = data
    for part in head:
        node = node[int(part)] if isinstance(node, list) else node.get(part, {})
    if isinstance(node, dict):
        node.pop(last, None)


def example(command: str, overrides: dict | None = None):
    """The built-in scenario of `command` (``gcalign example COMMAND``), with `overrides`."""
    from gcalign.app.registry import COMMANDS

    c = COMMANDS.get(command)
    if c is None or not c.builtin:
        have = ", ".join(n for n, x in COMMANDS.items() if x.builtin)
        raise ScenarioError(f"example: {command!r} has no built-in scenario; built-in: {have}")
    from gcalign.io.scenario.loader import loads

    return load(loads(c.builtin_text(), f"example {command}"), overrides)


_TEMP: list[str] = []


def _scratch() -> Path:
    """A folder for results files nobody asked to keep (removed when Python exits)."""
    if not _TEMP:
        _TEMP.append(tempfile.mkdtemp(prefix="gcalign-"))
        atexit.register(shutil.rmtree, _TEMP[0], True)
    return Path(_TEMP[0])


def run(command: str, scenario, seed: int | None = None, output: str | Path | None = None,
        progress=None, **options) -> Result:
    """Run `command` (a registry name) on `scenario` (a scenario model, or anything
    :func:`load` takes) as the command line does, write the results file (`output`, or a
    temporary file kept while Python runs) and return its :class:`Result`, with the typed
    result in ``value``. `options` are the
    command's own (``navigate``: ``init="align.h5"``); `progress(done, total, what)`
    hears of long runs."""
    from gcalign.app.registry import COMMANDS
    from gcalign.app.runner import run_command

    if command not in COMMANDS or command == "batch":
        raise ScenarioError(f"run: {command!r} is not a command that runs a scenario; "
                            f"commands: {', '.join(c for c in COMMANDS if c != 'batch')}")
    import inspect

    from gcalign.io.scenario import Scenario

    own = [p for p in inspect.signature(COMMANDS[command].runner()).parameters
           if p not in _RUN_PARAMETERS]
    unknown = [k for k in options if k not in own]
    if unknown:
        raise ScenarioError(f"run: {command} takes no option {unknown[0]!r}; "
                            + (f"its options: {', '.join(own)}" if own else "it has none")
                            + " (settings go into the scenario: load(..., {'"
                            + f"{COMMANDS[command].section or command}.KEY': value}}))")
    sc = scenario if isinstance(scenario, Scenario) else load(scenario)
    out = Path(output) if output is not None else Path(tempfile.mkstemp(
        suffix=".h5", prefix=f"{sc.name}-{command}-", dir=_scratch())[1])
    if options.get("init") is not None:
        options["init"] = str(options["init"])
    outcomes: list = []
    run_command(command, sc, scenario_text(sc), seed, out, progress=progress,
                on_outcome=outcomes.append, **options)
    return replace(read(out), value=outcomes[0].result)


#: parameters of a command's ``execute`` that run() fills itself
_RUN_PARAMETERS = ("sc", "seed", "cache_key", "sink", "progress")


def read(path: str | Path) -> Result:
    """The :class:`Result` of a results file (any command's), from the file alone."""
    from gcalign.io.results import read_summary

    kind, summary, attrs = read_summary(Path(path))
    seed = int(attrs.get("seed", -1))
    return Result(kind, summary, None if seed < 0 else seed, Path(path),
                  tuple(summary.get("warnings") or ()))


def commands() -> list[str]:
    """The commands that run a scenario (each is also a function of the package)."""
    from gcalign.app.registry import COMMANDS

    return [c for c in COMMANDS if c != "batch"]
