"""Shared pieces of the scenario models."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
NonNegVec3 = Annotated[list[Annotated[float, Field(ge=0)]], Field(min_length=3, max_length=3)]
PosVec3 = Annotated[list[Annotated[float, Field(gt=0)]], Field(min_length=3, max_length=3)]


class Model(BaseModel):
    """Strict base: unknown keys and NaN/inf are errors; assignments are validated too."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)
