"""Simulated transfer-alignment scenarios for the command-line tests (spec 006, test 1).

:func:`write_scenario` writes a case of :func:`gcalign.transfer.simulate.transfer_case` (the
wing-rock drive: 12 m/s at heading 30°, roll ±20° at 10 °/s about the body's forward axis;
μ, ε, ∇ drawn from the demo's P0; master noise 1′ and 0.02 m/s at 10 Hz) as a PSINS
``.mat`` (the slave ``mimu = [dθ dv t]``, the master ``fogavp = [att v lat lon h t]``, as
PSINS's demo file) and a scenario that aligns it with ``align.mode: transfer``: the demo's
P0, R set to the master's noise, 15 states, attitude feedback. The filter then starts from
the master's attitude, as the demo does.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.io
import yaml

from gcalign.transfer.simulate import TransferCase, transfer_case
from gcalign.units import ARCMIN


def case(seed: int, duration: float = 20.0) -> TransferCase:
    return transfer_case(np.random.default_rng(seed), duration=duration)


def write_scenario(c: TransferCase, folder: Path, name: str = "sim",
                   **transfer) -> Path:
    """The case's ``NAME.mat`` and ``NAME.yaml`` in `folder`; `transfer` keys replace the
    ``align.transfer`` section's (e.g. ``r={...}``). Returns the scenario's path."""
    m = c.master
    mat = folder / f"{name}.mat"
    scipy.io.savemat(mat, {"mimu": np.column_stack([c.dtheta, c.dv, c.t]),
                           "fogavp": np.column_stack([m.att, m.v_n, m.pos, m.t])})
    r = c.settings.r_sigma
    section = {"flexure": False, "feedback": {"bias": True, "attitude": True},
               "r": {"attitude_arcmin": r[0] / ARCMIN, "velocity_mps": r[3]}, **transfer}
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump({"name": name, "imu_file": mat.name,
                                    "align": {"mode": "transfer", "transfer": section}}))
    return path
