"""Reading scenario YAML and turning validation errors into one line per field."""

from __future__ import annotations

import re
from pathlib import Path

import yaml
from pydantic import ValidationError

from gcalign.errors import ScenarioError
from gcalign.io.scenario.models import Scenario
from gcalign.io.scenario.motion import MOTION_KINDS

# Model-level checks name their field at the start of the message ("segments: ..."),
# since pydantic gives them the model's location only.
_FIELD_PREFIX = re.compile(r"^([a-z_0-9]+(?:\.[a-z_0-9]+)*): ")


# Location parts that name a member of a union type, not a key the user wrote (also the
# tags of the discriminated motion union).
_UNION_TAG = re.compile(r"^(float|int|str|bool|constrained-\w+|\w+\[.*\]|"
                        + "|".join(MOTION_KINDS) + r")$")


def scenario_errors(err: ValidationError, source: str = "") -> str:
    """One line per invalid field: ``source: field: what is wrong, got VALUE``.

    Pydantic reports every failed member of a union (``float | 'measured'``) separately;
    those become one line whose alternatives are joined by "or".
    """
    by_field: dict[str, list[str]] = {}
    got_of: dict[str, str] = {}
    for e in err.errors():
        loc = [str(x) for x in e["loc"] if not _UNION_TAG.match(str(x))]
        msg = e["msg"].removeprefix("Value error, ")
        m = _FIELD_PREFIX.match(msg)
        if m:
            if not loc or loc[-1] != m.group(1):  # a field validator names its own field
                loc.append(m.group(1))
            msg = msg[m.end() :]
        where = ".".join(loc) or "scenario"
        if e["type"] == "extra_forbidden":
            msg = "unknown key (check the spelling; see README 'Scenario format')"
        elif e["type"] in ("union_tag_invalid", "union_tag_not_found"):
            ctx = e.get("ctx", {})
            key = str(ctx.get("discriminator", "kind")).strip("'")
            where = ".".join([*loc, key])
            allowed = str(ctx.get("expected_tags", "")).replace("'", "") or ", ".join(
                MOTION_KINDS)
            msg = (f"allowed: {allowed}, got {ctx['tag']!r}" if "tag" in ctx
                   else f"missing; allowed: {allowed}")
            by_field.setdefault(where, [])
            if msg not in by_field[where]:
                by_field[where].append(msg)
            continue
        elif e["type"] not in {"missing", "model_type", "value_error"}:
            got_of[where] = f", got {e.get('input')!r}"
        by_field.setdefault(where, [])
        if msg not in by_field[where]:
            by_field[where].append(msg)
    lines = [
        f"{where}: {' or '.join(msgs)}{got_of.get(where, '')}" for where, msgs in by_field.items()
    ]
    return "\n".join(f"{source}: {line}" if source else line for line in lines)


def parse_scenario(data: dict, source: str = "scenario") -> Scenario:
    """Validate a mapping (parsed YAML) as a scenario; raise ScenarioError on bad input."""
    if not isinstance(data, dict):
        raise ScenarioError(
            f"{source}: the scenario must be a YAML mapping, got {type(data).__name__}"
        )
    try:
        return Scenario.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(scenario_errors(err, source)) from None


def read_yaml(path: Path) -> dict:
    """YAML text of a file as a mapping; ScenarioError names the file and the line."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: file not found")
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ScenarioError(f"{path}: YAML syntax error{where}: {problem}") from None
    except UnicodeDecodeError:
        raise ScenarioError(f"{path}: not a text file (expected YAML)") from None
    return data if data is not None else {}


def load_scenario(path: Path) -> tuple[Scenario, str]:
    """Scenario model and its YAML text (stored verbatim in results files).

    A relative `imu_file` is taken relative to the scenario file.
    """
    path = Path(path)
    data = read_yaml(path)
    scenario = parse_scenario(data, str(path))
    if scenario.imu_file is not None and not scenario.imu_file.is_absolute():
        scenario.imu_file = (path.parent / scenario.imu_file).resolve()
    return scenario, path.read_text(encoding="utf-8")
