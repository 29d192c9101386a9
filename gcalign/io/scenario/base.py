"""Shared pieces of the scenario models."""

from __future__ import annotations

import types
import typing
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, model_validator

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
NonNegVec3 = Annotated[list[Annotated[float, Field(ge=0)]], Field(min_length=3, max_length=3)]
PosVec3 = Annotated[list[Annotated[float, Field(gt=0)]], Field(min_length=3, max_length=3)]


def _takes_bool(annotation: Any) -> bool:
    """Whether a field's type admits a boolean anywhere (``bool``, ``bool | float``,
    ``Literal[True]``, ``Any``, ...)."""
    if annotation is bool or annotation is Any:
        return True
    origin = typing.get_origin(annotation)
    if origin is typing.Literal:
        return any(isinstance(a, bool) for a in typing.get_args(annotation))
    if origin is Annotated:
        return _takes_bool(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return any(_takes_bool(a) for a in typing.get_args(annotation))
    return False


def _has_bool(value: Any) -> bool:
    if isinstance(value, bool):
        return True
    if isinstance(value, list):
        return any(_has_bool(v) for v in value[:10_000])
    return False


class Model(BaseModel):
    """Strict base: unknown keys and NaN/inf are errors; assignments are validated too;
    a boolean is not a number (YAML reads ``yes``/``on``/``true`` as booleans, and pydantic
    would take them as 1)."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _no_bool_for_number(cls, data: Any) -> Any:
        if isinstance(data, dict):
            for name, value in data.items():
                field = cls.model_fields.get(name) if isinstance(name, str) else None
                if field is not None and _has_bool(value) and not _takes_bool(field.annotation):
                    raise ValueError(f"{name}: a boolean ({_yaml_bool(value)}) where a number "
                                     "or text is expected (YAML reads yes/no/on/off/true/false "
                                     "as booleans)")
        return data


def _yaml_bool(value: Any) -> str:
    """The first boolean in `value` (a boolean or nested lists holding one), as YAML."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return next(_yaml_bool(v) for v in value[:10_000] if _has_bool(v))
