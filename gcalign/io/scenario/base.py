"""Shared pieces of the scenario models."""

from __future__ import annotations

import types
import typing
from pathlib import PurePath
from typing import Annotated, Any

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    model_validator,
)

from gcalign.errors import ScenarioError, clip

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
NonNegVec3 = Annotated[list[Annotated[float, Field(ge=0)]], Field(min_length=3, max_length=3)]
PosVec3 = Annotated[list[Annotated[float, Field(gt=0)]], Field(min_length=3, max_length=3)]


#: Where a scenario names a file: a path, or a mapping whose ``path`` is one (``align.aiding``
#: is always a mapping); a relative path is taken from the scenario file's folder.
FILE_KEYS = ("imu_file", "reference", "align.aiding", "calibrate.files.velocity",
             "calibrate.files.position")


def is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def broadcast(x: Any) -> Any:
    """One number stands for all three axes."""
    return [x, x, x] if is_number(x) else x


#: A bias, a scale-factor error, an angle: one number for all three axes, or one per axis.
PerAxis = Annotated[Vec3, BeforeValidator(broadcast)]
Pos3 = Annotated[PosVec3, BeforeValidator(broadcast)]  #: positive, one number or three
NonNeg3 = Annotated[NonNegVec3, BeforeValidator(broadcast)]  #: ≥ 0, one number or three


def span(v: list[float] | None) -> list[float] | None:
    """A τ span ``[lo, hi]`` in s (None: none)."""
    if v is not None and (len(v) != 2 or not 0 < v[0] < v[1]):
        raise ValueError(f"must be [lo, hi] in s with 0 < lo < hi, got {v}")
    return v


def one_of(names: tuple[str, ...], what: str) -> AfterValidator:
    """A text among `names`: ``'TEXT' is not a WHAT; allowed: NAMES`` otherwise."""
    def check(v: str) -> str:
        if v not in names:
            raise ValueError(f"{v!r} is not a {what}; allowed: {', '.join(names)}")
        return v
    return AfterValidator(check)


def vector(value: float | tuple[float, float, float] = 0.0, **field: Any) -> Any:
    """A field of three numbers whose default is `value` (one number: on all three axes)."""
    values = list(value) if isinstance(value, tuple) else [value] * 3
    return Field(default_factory=lambda: list(values), **field)


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


def _takes(annotation: Any, kinds: tuple[type, ...]) -> bool:
    """Whether a field's type admits one of `kinds` anywhere (in a union, a list, a tuple,
    a mapping's values); ``Any`` admits everything."""
    if annotation is Any:
        return True
    if isinstance(annotation, type):
        return issubclass(annotation, kinds) and annotation is not bool
    return any(_takes(a, kinds) for a in typing.get_args(annotation)
               if a is not Ellipsis and not isinstance(a, (str, int, float)))


def _number_text(value: Any) -> str | None:
    """The first text in `value` (nested lists and mappings) that reads as a number."""
    if isinstance(value, str):
        try:
            float(value)
        except ValueError:
            return None
        return value
    items = value[:10_000] if isinstance(value, list) else (
        list(value.values())[:10_000] if isinstance(value, dict) else [])
    return next((t for t in map(_number_text, items) if t is not None), None)


def _first_bool(value: Any) -> bool | None:
    """The first boolean in `value` (a boolean, or nested lists holding one), or None."""
    if isinstance(value, bool):
        return value
    if isinstance(value, list):
        return next((b for b in map(_first_bool, value[:10_000]) if b is not None), None)
    return None


class Model(BaseModel):
    """Strict base: unknown keys and NaN/inf are errors; assignments are validated too;
    a boolean is not a number (YAML reads ``yes``/``on``/``true`` as booleans, and pydantic
    would take them as 1), nor is text (``"0.2"`` or ``!!str 0.2``, which pydantic would
    convert) where the field takes numbers and no text."""

    # defer_build: a model's validator is built when it first validates, as part of the
    # scenario's (one schema, not one per model at import: a start-up cost of every command)
    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False,
                              defer_build=True)
    _where: str = PrivateAttr(default="")  #: the dotted key of this section (locate)

    def __setattr__(self, name: str, value: Any) -> None:
        """An assignment that does not validate (``sc.align.t2_s = nan`` in the Python
        API) is a ScenarioError naming the dotted key, as a bad key of a file is, not
        pydantic's ValidationError."""
        if name.startswith("_"):
            super().__setattr__(name, value)
            return
        try:
            super().__setattr__(name, value)
        except ValidationError as err:
            from gcalign.io.scenario.messages import scenario_errors  # imports the models

            raise ScenarioError(scenario_errors(err, at=self._where).replace("\n", "; ")
                                ) from None
        locate(getattr(self, name), prefix_of(self._where, name))

    @model_validator(mode="before")
    @classmethod
    def _no_bool_for_number(cls, data: Any) -> Any:
        for name, value in data.items() if isinstance(data, dict) else ():
            field = cls.model_fields.get(name) if isinstance(name, str) else None
            if field is None:
                continue
            found = _first_bool(value)
            if found is not None and not _takes_bool(field.annotation):
                raise ValueError(f"{name}: a boolean ({'true' if found else 'false'}) where a "
                                 "number or text is expected (YAML reads yes/no/on/off/true/false "
                                 "as booleans)")
            text = _number_text(value) if _takes(field.annotation, (int, float)) and not _takes(
                field.annotation, (str, PurePath)) else None
            if text is not None:
                raise ValueError(f"{name}: a number written as text ({clip(text, 40)!r}, quoted "
                                 "or tagged !!str in the YAML); write the number itself")
        return data


def prefix_of(where: str, name: str) -> str:
    return f"{where}.{name}" if where else name


def locate(value: Any, where: str = "") -> None:
    """Tell every section of a scenario its dotted key (``imu.gyro``), so that an assignment
    that fails names it (:meth:`Model.__setattr__`)."""
    if isinstance(value, Model):
        value._where = where
        for name in type(value).model_fields:
            locate(getattr(value, name), prefix_of(where, name))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            if isinstance(item, Model):
                locate(item, prefix_of(where, str(i)))
