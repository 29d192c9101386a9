"""Dotted-key overrides (``align.stages.0.t_z_s``) checked against the scenario schema.

A sweep's grid sets values deep inside the base scenario; :func:`apply_override` walks the
path along :class:`gcalign.io.scenario.Scenario` (not only along the mapping), so a misspelt key
or a missing list index is an error that names what exists.
"""

from __future__ import annotations

from typing import Any, get_args, get_origin

from gcalign.errors import ScenarioError
from gcalign.io.scenario.walk import is_model as _is_model
from gcalign.io.scenario.walk import kind_arm
from gcalign.io.scenario.walk import unwrap as _unwrap


def _arm(tp, node):
    """The member of a union of models (the motion kinds) that `node`'s ``kind`` names."""
    arm = kind_arm(tp, node.get("kind")) if isinstance(node, dict) else None
    return tp if arm is None else arm


def _dump(value):
    """A model value as plain YAML types (only what the user set, so defaults stay defaults)."""
    from pydantic import BaseModel

    if isinstance(value, BaseModel):
        return value.model_dump(mode="json", exclude_unset=True)
    if isinstance(value, (list, tuple)):
        return [_dump(v) for v in value]
    return value


def apply_override(data: dict, key: str, value, base_model=None) -> None:
    """Set ``data[a][b][0][c] = value`` for ``key = "a.b.0.c"``, in place.

    The path is checked against the scenario schema (:class:`gcalign.io.scenario.Scenario`), not
    only against `data`: a key the schema does not have is an error even where the parent
    section is optional, and a list index must exist (``align.stages.5`` with one stage is
    an error that says which indices exist). A section or list the base leaves to its
    default is filled in from the validated `base_model` (``align.stages.0.t_z_s`` works on
    a base that gives no stages). ScenarioError on a bad path.
    """
    from gcalign.io.scenario import Scenario

    parts = key.split(".")
    if any(not p for p in parts):
        raise ScenarioError(f"{key}: not a dotted key (e.g. align.stages.0.t_z_s)")
    node: Any = data
    tp: Any = Scenario
    model_val = base_model
    for depth, part in enumerate(parts):
        here = ".".join(parts[:depth]) or "the scenario"
        path = ".".join(parts[: depth + 1])
        tp = _arm(tp, node)
        if _is_model(tp):
            fields = tp.model_fields
            if part not in fields:
                raise ScenarioError(f"{path}: unknown key; {here} has: {', '.join(fields)}")
            if not isinstance(node, dict):
                raise ScenarioError(f"{path}: {here} is {node!r}, not a mapping")
            child_tp = _unwrap(fields[part].annotation)
            child_val = getattr(model_val, part, None) if model_val is not None else None
            slot: Any = part
            child = node.get(part)
        elif get_origin(tp) in (list, tuple):
            if not isinstance(node, list):
                raise ScenarioError(f"{path}: {here} is {node!r}, not a list")
            n = len(node)
            have = "no items" if n == 0 else (
                f"{n} item(s): index 0" + (f" .. {n - 1}" if n > 1 else ""))
            if not part.isdigit():
                raise ScenarioError(f"{path}: {here} is a list; address an item by its index "
                                    f"({have})")
            slot = int(part)
            if slot >= n:
                raise ScenarioError(f"{path}: no item {slot}; {here} has {have}")
            args = get_args(tp)
            child_tp = _unwrap(args[0]) if args else Any
            child_val = (model_val[slot] if isinstance(model_val, (list, tuple))
                         and slot < len(model_val) else None)
            child = node[slot]
        elif get_origin(tp) is dict:
            if not isinstance(node, dict):
                raise ScenarioError(f"{path}: {here} is {node!r}, not a mapping")
            args = get_args(tp)
            child_tp = _unwrap(args[1]) if len(args) == 2 else Any
            child_val = model_val.get(part) if isinstance(model_val, dict) else None
            slot, child = part, node.get(part)
        else:
            raise ScenarioError(f"{path}: {here} is a single value, it has no keys or items")
        if depth == len(parts) - 1:
            node[slot] = value
            return
        if child is None:
            if isinstance(child_val, (list, tuple, dict)) or _is_model(type(child_val)):
                child = _dump(child_val)
            elif _is_model(child_tp) or get_origin(child_tp) is dict:
                child = {}
            elif get_origin(child_tp) in (list, tuple):
                child = []
            else:
                raise ScenarioError(f"{path + '.' + parts[depth + 1]}: {path} is a single "
                                    "value, it has no keys or items")
            node[slot] = child
        node, tp, model_val = child, child_tp, child_val
