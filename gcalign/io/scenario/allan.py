"""The `allan` section of a scenario: how ``gcalign allan`` computes the Allan deviation of
the data (simulated, or a recording) and over which window."""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, Field

from gcalign.io.scenario.base import Model, span


class AllanConfig(Model):
    per_decade: int = Field(10, ge=2, le=100, description="cluster times per decade of τ")
    min_clusters: int = Field(
        4, ge=2, le=1000, description="fewest clusters at the longest τ (its 1σ interval is "
        "1/√(2(K−1)): 41 % at K = 4)")
    start_s: float = Field(0.0, ge=0, description="data time at which the window starts")
    duration_s: float | None = Field(None, gt=0, description="default: to the end of the "
                                     "data")
    fit_tau_s: Annotated[list[float] | None, AfterValidator(span)] = Field(
        None, description="[lo, hi] s: fit the noise terms on these τ only (the curve is "
        "drawn whole): where the sensor, not a swaying base, shapes σ(τ)")
