"""Reading scenario YAML and turning validation errors into one line per field.

Numbers follow the YAML 1.2 core schema, in files and ``--set`` values alike: ``1e-3``,
``1E5``, ``.5``, ``-2e+3`` are floats (YAML 1.1, PyYAML's default, reads the first as the
text '1e-3'), ``010`` is ten (not eight) and ``1:30`` is text (not ninety). Text is never
turned into a number: ``"0.2"`` or ``!!str 0.2`` where a number belongs is refused by the
models (:class:`gcalign.io.scenario.base.Model`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import yaml
from pydantic import ValidationError

from gcalign import limits
from gcalign.errors import ScenarioError
from gcalign.io.paths import not_a_file
from gcalign.io.scenario.base import locate
from gcalign.io.scenario.messages import CUT, cut, scenario_errors
from gcalign.io.scenario.models import Scenario


def parse_scenario(data: dict, source: str = "scenario") -> Scenario:
    """Validate a mapping (parsed YAML) as a scenario; raise ScenarioError on bad input."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: the scenario must be a YAML mapping, got "
                            f"{type(data).__name__}")
    if "base" in data:  # no scenario key: a sweep's
        raise ScenarioError(f"{source}: a sweep file (it has 'base'): run it with gcalign "
                            "batch (gcalign validate checks it)")
    try:
        sc = Scenario.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(scenario_errors(err, source, Scenario)) from None
    locate(sc)
    return sc


def _mark(node) -> str:
    m = getattr(node, "start_mark", None)
    return f"line {m.line + 1}" if m is not None else "?"


def check_nodes(root, source: str) -> None:
    """Refuse what safe_load would accept but no scenario is: a key given twice in one
    mapping, and aliases that expand past the limit (a "billion laughs" of a few hundred
    bytes expands to 10^9 values in every later walk). Sizes are counted once per node
    (anchors share nodes), so the check costs the size of the text, not of the expansion."""
    limit = limits.MAX_YAML_NODES.value()
    size: dict[int, int] = {}
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            children = _children(node)
            total = 1 + sum(size[id(c)] for c in children)
            size[key] = total
            if total > limit:
                raise ScenarioError(
                    f"{source}: {_mark(node)}: expands to more than {limits._num(limit)} "
                    f"values (YAML aliases); refused (raise the limit with "
                    f"{limits.MAX_YAML_NODES.env}=N if intended)")
            continue
        if key in size:
            continue
        size[key] = -1  # in progress
        if isinstance(node, yaml.MappingNode):
            seen: dict[tuple, yaml.Node] = {}
            for k, _ in node.value:
                if isinstance(k, yaml.ScalarNode) and k.tag != "tag:yaml.org,2002:merge":
                    ident = (k.tag, k.value)
                    if ident in seen:
                        raise ScenarioError(
                            f"{source}: {_mark(k)}: key {cut(k.value)} given twice in one "
                            f"mapping (first at {_mark(seen[ident])}); remove one")
                    seen[ident] = k
        stack.append((node, True))
        for c in _children(node):
            if size.get(id(c)) == -1:  # an ancestor: the alias is inside its own anchor
                raise ScenarioError(f"{source}: {_mark(c)}: an alias refers to the value "
                                    "that contains it (recursive YAML anchor)")
            if id(c) not in size:
                stack.append((c, False))


def _children(node) -> list:
    if isinstance(node, yaml.MappingNode):
        return [x for pair in node.value for x in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with the YAML 1.2 core schema's integers and floats."""


_INT, _FLOAT = "tag:yaml.org,2002:int", "tag:yaml.org,2002:float"
_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag not in (_INT, _FLOAT)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
# Integers first: the float pattern also matches "12".
_Loader.add_implicit_resolver(_INT, re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$"),
                              list("-+0123456789"))
_Loader.add_implicit_resolver(
    _FLOAT, re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                       r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
    list("-+.0123456789"))


def _constructor(convert, what: str):
    """A constructor of scalars read by `convert`; a text it refuses is a YAML error at its
    line, ``not WHAT: TEXT``."""
    def construct(loader: yaml.SafeLoader, node: yaml.ScalarNode):
        text = loader.construct_scalar(node)
        try:
            return convert(text)
        except ValueError:
            raise yaml.constructor.ConstructorError(
                None, None, f"not {what}: {cut(text)}", node.start_mark) from None
    return construct


_SPECIAL = {".inf": math.inf, "+.inf": math.inf, "-.inf": -math.inf, ".nan": math.nan}
_Loader.add_constructor(_INT, _constructor(
    lambda t: int(t, 0) if t[:2] in ("0o", "0x") else int(t, 10), "an integer"))
_Loader.add_constructor(_FLOAT, _constructor(
    lambda t: _SPECIAL[t.lower()] if t.lower() in _SPECIAL else float(t), "a number"))


MAX_DEPTH = 200  #: nesting of flow collections ([ {) refused beyond this


def _flow_depth(text: str) -> int:
    """Deepest nesting of flow brackets outside quoted strings (PyYAML's scanner is
    quadratic in it: 20000 levels take seconds before its own recursion error)."""
    bare = re.sub(r'"(?:[^"\\]|\\.)*"|\'[^\']*\'|#[^\n]*', "", text)
    depth = deepest = 0
    for c in re.sub(r"[^\[\]{}]", "", bare):
        depth = depth + 1 if c in "[{" else max(0, depth - 1)
        deepest = max(deepest, depth)
    return deepest


def loads(text: str, source: str):
    """Parse YAML text safely (safe tags only, YAML 1.2 numbers, checked by
    :func:`check_nodes`); ScenarioError names the source and the line."""
    if _flow_depth(text) > MAX_DEPTH:
        raise ScenarioError(f"{source}: YAML nested more than {MAX_DEPTH} levels deep")
    loader = _Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        check_nodes(node, source)
        return loader.construct_document(node)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ScenarioError(f"{source}: YAML syntax error{where}: {problem[:CUT]}") from None
    except RecursionError:
        raise ScenarioError(f"{source}: YAML nested too deeply") from None
    finally:
        loader.dispose()


def with_overrides(text: str, what: str, overrides: dict[str, object]) -> str:
    """Scenario `text` with `overrides` recorded after it as YAML keys, under a comment
    naming `what` was overridden: the text a results file stores, which must read back. A
    document in flow style (``{...}``) cannot take keys after it, and a key the text already
    records (an override of a run this one read) must not be given twice: then the text is
    written out in block style first, without those keys."""
    dumped: str = yaml.safe_dump(overrides, sort_keys=False)
    tail = f"\n# command-line overrides{what}:\n" + dumped
    try:
        loads(text + tail, "scenario")
        return text + tail
    except ScenarioError:
        kept = {k: v for k, v in loads(text, "scenario").items() if k not in overrides}
        block: str = yaml.safe_dump(kept, sort_keys=False)
        return block + tail


def parse_override(item: str, option: str = "--set") -> tuple[str, object]:
    """``KEY=VALUE`` -> (key, value), VALUE read as a scenario file is (:func:`loads`: YAML
    1.2 numbers, no key twice, nesting limited); ScenarioError names the option and key.
    ``KEY=null`` is the key written ``null`` in the file (an optional key's default); an
    empty VALUE is refused, being more likely a slip than a null."""
    key, sep, text = item.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ScenarioError(f"{option}: expected KEY=VALUE (e.g. align.mode=conventional), "
                            f"got {cut(item)}")
    if not text.strip():
        raise ScenarioError(f"{option} {key}: give a value (KEY=VALUE; KEY=null for the "
                            "key's default where it has one)")
    return key, loads(text, f"{option} {key}")


def read_yaml(path: Path) -> dict:
    """YAML text of a file as a mapping; ScenarioError names the file and the line."""
    path = Path(path)
    if path.is_dir():
        raise ScenarioError(f"{path}: is a directory, expected a YAML file")
    if not path.is_file():
        raise ScenarioError(f"{path}: {not_a_file(path)}")
    try:
        size = path.stat().st_size
        limits.MAX_YAML_MB.check(size / 2**20, str(path))
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        raise ScenarioError(f"{path}: not a text file (expected YAML)") from None
    except OSError as err:
        raise ScenarioError(f"{path}: cannot read ({err.strerror or err})") from None
    data = loads(text, str(path))
    if data is None:
        raise ScenarioError(f"{path}: empty; expected a YAML mapping of keys and values")
    return data


def load_scenario(path: Path) -> tuple[Scenario, str]:
    """Scenario model and its YAML text (stored verbatim in results files).

    Relative file paths (`imu_file`, `reference.path`) are taken from the scenario file's
    folder.
    """
    path = Path(path)
    data = read_yaml(path)
    scenario = parse_scenario(data, str(path))
    scenario.resolve_paths(path.parent)
    return scenario, path.read_text(encoding="utf-8")
