"""What the commands share: loading a scenario with option overrides, saving and showing."""

from __future__ import annotations

import sys
from collections.abc import Callable
from importlib import resources
from pathlib import Path

import yaml

from gcalign.app.registry import command
from gcalign.cli import consoles, emit_json
from gcalign.errors import ScenarioError
from gcalign.io import results
from gcalign.io.scenario import Scenario, parse_scenario
from gcalign.io.scenario.loader import read_yaml


def builtin_text(name: str) -> str:
    """YAML text of a built-in scenario (package data in gcalign/scenarios)."""
    return resources.files("gcalign.scenarios").joinpath(name).read_text(encoding="utf-8")


def load_with_overrides(
    path: Path | None,
    builtin: str,
    section: str,
    overrides: dict,
    adjust: Callable[[dict, dict], None] | None = None,
    data: dict | None = None,
    text: str | None = None,
) -> tuple[Scenario, str, str]:
    """Scenario (the file, the built-in one, or a given mapping `data` with its `text`),
    its text and its source name, with the options that were given written into `section`
    before validation, so that a bad option is reported like a bad key in the file.
    `adjust(section, given)` may drop keys that a given option replaces. The text stored in
    results files records the overrides.
    """
    if data is not None:
        source = str(path)
        text = text or yaml.safe_dump(data, sort_keys=False)
    elif path is None:
        text, source = builtin_text(builtin), f"<built-in {builtin}>"
        data = yaml.safe_load(text)
    else:
        data, source = read_yaml(path), str(path)
        text = Path(path).read_text(encoding="utf-8")
    assert text is not None
    given = {k: v for k, v in overrides.items() if v is not None}
    if isinstance(data, dict) and given:
        current = data.get(section)
        merged = dict(current) if isinstance(current, dict) else {}
        if adjust is not None:
            adjust(merged, given)
        merged.update(given)
        data[section] = merged
    sc = parse_scenario(data, source)
    if sc.imu_file is not None and path is not None and not sc.imu_file.is_absolute():
        sc.imu_file = (Path(path).parent / sc.imu_file).resolve()
    if given:
        text += f"\n# command-line overrides of {section}:\n" + yaml.safe_dump(
            {section: given}, sort_keys=False
        )
    return sc, text, source


def run_and_show(name: str, sc: Scenario, text: str, seed: int | None, output: Path | None,
                 as_json: bool, **options) -> None:
    """Run command `name` on a loaded scenario through its room, write the results file
    (default name from the scenario, command and seed) and show its table. A streaming
    command writes its series into the (temporary) file while it runs; `options` go to its
    ``execute``."""
    from gcalign.cli import default_output

    cmd = command(name)
    run_seed = None if sc.imu_file is not None else (sc.imu.seed if seed is None else seed)
    out = output or default_output(sc.name, name, run_seed)
    try:
        with results.atomic_h5(out) as f:
            if cmd.streams:
                outcome = cmd.execute(sc, seed, sink=f, **options)
            else:
                outcome = cmd.execute(sc, seed, **options)
            for line in outcome.warnings:
                sys.stderr.write(f"warning: {line}\n")
            summary = outcome.summary
            summary["output"] = str(out)
            results.write_header(f, name, text, outcome.seed, summary)
            if outcome.truth is not None:
                results.write_truth(f, outcome.truth)
            outcome.write(f)
    except OSError as err:
        raise ScenarioError(f"--output: cannot write {out}: {err.strerror or err}") from None
    show(name, summary, as_json)


def show(kind: str, summary: dict, as_json: bool) -> None:
    """Print a command's table (stderr under --json) and, under --json, the summary."""
    consoles(as_json).print(command(kind).load().table(summary))
    if as_json:
        emit_json(summary)
