"""Two-stage loop parameters (seed 000 §6.1): which stage's T_xy, T_z, ξ each pass uses.

Plain data, no kernels, so that the scenario layer can check a stage list cheaply.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Stage:
    """Loop parameters for `passes` passes (None: all remaining). Periods in s."""

    t_xy: float
    t_z: float
    xi: float
    passes: int | None = None



def stage_of_passes(stages: list[Stage], passes: int) -> list[int]:
    """Stage index of each pass; the last stage without a count covers the rest."""
    out: list[int] = []
    for i, st in enumerate(stages):
        n = passes - len(out) if st.passes is None else st.passes
        out += [i] * n
    return (out + [len(stages) - 1] * passes)[:passes]
