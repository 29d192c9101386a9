"""The `allan` section of a scenario: how ``gcalign allan`` computes the Allan deviation of
the data (simulated, or a recording) and over which window."""

from __future__ import annotations

from pydantic import Field, field_validator

from gcalign.io.scenario.base import Model


class AllanConfig(Model):
    per_decade: int = Field(10, ge=2, le=100, description="cluster times per decade of τ")
    min_clusters: int = Field(
        4, ge=2, le=1000, description="fewest clusters at the longest τ (its 1σ interval is "
        "1/√(2(K−1)): 41 % at K = 4)")
    start_s: float = Field(0.0, ge=0, description="data time at which the window starts")
    duration_s: float | None = Field(None, gt=0, description="default: to the end of the "
                                     "data")
    fit_tau_s: list[float] | None = Field(
        None, description="[lo, hi] s: fit the noise terms on these τ only (the curve is "
        "drawn whole): where the sensor, not a swaying base, shapes σ(τ)")

    @field_validator("fit_tau_s")
    @classmethod
    def _span(cls, v):
        if v is not None and (len(v) != 2 or not 0 < v[0] < v[1]):
            raise ValueError(f"must be [lo, hi] in s with 0 < lo < hi, got {v}")
        return v
