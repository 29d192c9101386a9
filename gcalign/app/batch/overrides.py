"""Dotted-key overrides (``align.stages.0.t_z_s``) checked against the scenario schema.

A sweep's grid sets values deep inside the base scenario; :func:`apply_override` walks the
path along :class:`gcalign.io.scenario.Scenario` (not only along the mapping), so a misspelt key
or a missing list index is an error that names what exists.
"""

from __future__ import annotations

import types
from typing import Annotated, Any, Union, get_args, get_origin

from gcalign.errors import ScenarioError


def _unwrap(tp):
    """Strip Annotated[...] and Optional[...] from a pydantic field annotation."""
    while True:
        origin = get_origin(tp)
        if origin is Annotated:
            tp = get_args(tp)[0]
        elif origin in (Union, types.UnionType):
            args = [a for a in get_args(tp) if a is not type(None)]
            if len(args) != 1:
                return tp  # e.g. float | Literal["measured"]: a single value
            tp = args[0]
        else:
            return tp


def _is_model(tp) -> bool:
    from pydantic import BaseModel

    return isinstance(tp, type) and issubclass(tp, BaseModel)


def _arm(tp, node):
    """The member of a union of models (the motion kinds) that `node`'s ``kind`` names."""
    if get_origin(tp) not in (Union, types.UnionType) or not isinstance(node, dict):
        return tp
    for arm in get_args(tp):
        field = getattr(arm, "model_fields", {}).get("kind")
        if field is not None and node.get("kind") in get_args(field.annotation):
            return arm
    return tp


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
