"""Walking the scenario schema by a path of keys: which model a dotted key lands in, and
which keys that model has. Shared by the loader's error lines (an unknown key lists the
keys its mapping has), the dotted overrides of sweeps and ``--set``, and the generated
reference of the documentation."""

from __future__ import annotations

import types
from typing import Annotated, Union, get_args, get_origin


def unwrap(tp):
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


def is_model(tp) -> bool:
    from pydantic import BaseModel

    return isinstance(tp, type) and issubclass(tp, BaseModel)


def kind_arm(tp, kind):
    """The member of a union of models (the motion kinds) whose ``kind`` is `kind`, or
    None."""
    if get_origin(tp) not in (Union, types.UnionType):
        return None
    for arm in get_args(tp):
        field = getattr(arm, "model_fields", {}).get("kind")
        if field is not None and kind in get_args(field.annotation):
            return arm
    return None


def keys_at(loc, root: type) -> list[str] | None:
    """The keys of the mapping at `loc` in the model `root` (a pydantic error location
    without its last part: ``("initial",)``, ``("motion", "moving", "segments", 0)`` in
    :class:`~gcalign.io.scenario.Scenario`), or None where the schema has no single mapping
    there."""
    tp = root
    for part in loc:
        tp = unwrap(tp)
        arm = kind_arm(tp, part)
        if arm is not None:  # pydantic names the union member it tried by its tag
            tp = arm
            continue
        if is_model(tp):
            field = tp.model_fields.get(str(part))
            if field is None:
                return None
            tp = field.annotation
        elif get_origin(tp) in (list, tuple) and get_args(tp):
            tp = get_args(tp)[0]
        elif get_origin(tp) is dict and len(get_args(tp)) == 2:
            tp = get_args(tp)[1]
        else:
            return None
    tp = unwrap(tp)
    return list(tp.model_fields) if is_model(tp) else None
