"""What an alignment keeps in the results file, each field saying how (:mod:`gcalign.schema`):
every pass's attitude along it (:class:`PassRows`, ``/align/pass_NN``) and the attitude at
T1, T2 and T3 (:class:`AlignmentAt`, ``/align/result``), with the truth, errors and
misalignment where there is truth. :class:`gcalign.align.gyrocompass.Alignment` gives them
(``pass_rows()``, ``at_times()``); apart from it, so that the checks of a results file read
back take these fields without loading the loops' kernels."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.schema import ATT_FRAME, PHI_FRAME, stored

#: the frame of an attitude error (Euler angles)
EULER_ERROR = "Euler differences est - true, yaw wrapped"
#: the names of a pass's ten loop gains
GAIN_NAMES = "K_E1, K_E2, K_E3, K_N1, K_N2, K_N3, K_U1, K_U2, K_U3, K_U4"


@dataclass(frozen=True)
class PassRows:
    """One pass (its `index` from 0) at the rows it stored: data time `t` (processing
    order), attitude `att`, and without truth None for the Euler error and misalignment."""

    index: int
    direction: str = field(metadata=stored(None, attr=True))
    kind: str = field(metadata=stored(None, attr=True))
    stage: int = field(metadata=stored("1", attr=True))  # numbered from 1
    t: np.ndarray = field(metadata=stored("s", dims="N", description="data time, processing "
                                          "order (decreasing in a reverse pass)"))
    att: np.ndarray = field(metadata=stored("rad", frame=ATT_FRAME, dims="N 3"))
    gains: np.ndarray = field(metadata=stored("SI", names=GAIN_NAMES, dims="10",
                                              optional=True))
    error: np.ndarray | None = field(metadata=stored("rad", frame=EULER_ERROR, dims="N 3",
                                                     optional=True))
    phi: np.ndarray | None = field(metadata=stored("rad", frame=PHI_FRAME, dims="N 3",
                                                   optional=True))


def _at(label: str, frame: str, optional: bool = True) -> dict:
    return stored("rad", frame=frame, dims="3", optional=optional, summary="deg", label=label)


@dataclass(frozen=True)
class AlignmentAt:
    """The attitude (rad) at T1 (coarse), T2 and T3, the truth there, the Euler error and
    the misalignment φ (None without truth); the passes' compute time and the data length
    they amount to (s). Summarised in degrees in this order."""

    coarse_att: np.ndarray = field(metadata=_at("coarse_attitude", ATT_FRAME, False))
    att_t2: np.ndarray = field(metadata=_at("attitude_t2", ATT_FRAME, False))
    truth_t2: np.ndarray | None = field(metadata=_at("truth_t2", ATT_FRAME))
    error_t2: np.ndarray | None = field(metadata=_at("error_t2", EULER_ERROR))
    att_t3: np.ndarray = field(metadata=_at("attitude_t3", ATT_FRAME, False))
    truth_t3: np.ndarray | None = field(metadata=_at("truth_t3", ATT_FRAME))
    error_t3: np.ndarray | None = field(metadata=_at("error_t3", EULER_ERROR))
    phi_t2: np.ndarray | None = field(metadata=_at("misalignment_t2", PHI_FRAME))
    phi_t3: np.ndarray | None = field(metadata=_at("misalignment_t3", PHI_FRAME))
    compute_s: float = field(metadata=stored("s", attr=True))
    equivalent_s: float = field(metadata=stored("s", attr=True))
