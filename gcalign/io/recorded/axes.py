"""Declared body axes of a recording, and the rotation to gcalign's x right, y forward, z up.

Syntax (``axes:`` in a scenario, ``--axes`` on the command line): three letters, one per
axis of the *file*, x then y then z, each saying where that axis points on the vehicle:

====  =========  ====================================================
F  B  forward    backward
R  L  right      left
U  D  up         down
====  =========  ====================================================

``RFU`` is gcalign's (and PSINS's) own; ``FRD`` is KF-GINS / OB_GINS / gnss-ins-sim's;
``FLU`` is ROS's. The navigation-frame letters are accepted for a vehicle heading north
(``N`` = F, ``S`` = B, ``E`` = R, ``W`` = L), so ``ENU`` = RFU and ``NED`` = FRD. Case,
blanks and commas do not matter (``f, r, d``). A mounting that is not a signed permutation
is given as a 3×3 rotation matrix ``C`` with ``v_rfu = C @ v_file`` (rows: our x, y, z).

Each letter pair must appear once and the three axes must form a right-handed frame
(a proper rotation, det +1): ``FRU`` (left-handed) and ``FFU`` are refused, naming why.

>>> C = rotation_to_rfu("FRD")
>>> C.astype(int).tolist()     # our x (right) = file y; our y = file x; our z = -file z
[[0, 1, 0], [1, 0, 0], [0, 0, -1]]
>>> describe(C)
'FRD'
>>> try:
...     rotation_to_rfu("FRU")
... except ValueError as err:
...     print(str(err).split(":")[1].strip())
'FRU' is not a rotation
"""

from __future__ import annotations

import numpy as np

from gcalign.errors import ScenarioError

__all__ = ["AXES_HELP", "rotation_to_rfu", "describe", "axes_text"]

#: Where each letter points, in gcalign's body frame (x right, y forward, z up).
_DIRECTIONS = {
    "R": (0, 1.0), "L": (0, -1.0), "F": (1, 1.0), "B": (1, -1.0), "U": (2, 1.0),
    "D": (2, -1.0), "E": (0, 1.0), "W": (0, -1.0), "N": (1, 1.0), "S": (1, -1.0),
}
_WORDS = {"R": "right", "L": "left", "F": "forward", "B": "backward", "U": "up", "D": "down",
          "E": "right", "W": "left", "N": "forward", "S": "backward"}
_PAIRS = ("R/L", "F/B", "U/D")

AXES_HELP = ("three letters, the file's x, y, z axes: F/B (forward/backward), R/L "
             "(right/left), U/D (up/down), one of each pair, right-handed, e.g. RFU (ours), "
             "FRD, FLU; or a 3x3 rotation matrix C with v_rfu = C v_file")


def rotation_to_rfu(axes) -> np.ndarray:
    """``C`` (3, 3) with ``v_rfu = C @ v_file`` for declared `axes` (see the module
    docstring); ScenarioError naming the string and what is allowed when it is not one."""
    if isinstance(axes, str):
        return _from_letters(axes)
    try:
        C = np.asarray(axes, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"axes: {axes!r} is neither letters nor a 3x3 matrix; give "
                            f"{AXES_HELP}") from None
    if C.shape != (3, 3) or not np.isfinite(C).all():
        raise ScenarioError(f"axes: a matrix must be 3x3 and finite, got shape {C.shape}; "
                            f"give {AXES_HELP}")
    if np.abs(C @ C.T - np.eye(3)).max() > 1e-6:
        raise ScenarioError(f"axes: the matrix {C.tolist()} is not orthonormal (C C^T != I "
                            "within 1e-6), so it is not a rotation")
    if np.linalg.det(C) < 0:
        raise ScenarioError(f"axes: the matrix {C.tolist()} is a reflection (determinant -1),"
                            " not a rotation: flip the sign of one row")
    return C


def _from_letters(text: str) -> np.ndarray:
    letters = "".join(ch for ch in text.upper() if not ch.isspace() and ch != ",")
    if len(letters) != 3 or any(ch not in _DIRECTIONS for ch in letters):
        raise ScenarioError(f"axes: {text!r} is not a rotation: expected {AXES_HELP}")
    C = np.zeros((3, 3))
    for j, ch in enumerate(letters):
        i, sign = _DIRECTIONS[ch]
        if C[i].any():
            raise ScenarioError(f"axes: {text!r} is not a rotation: two axes point "
                                f"{_PAIRS[i]} and none the other ways; use each of R/L, F/B, "
                                "U/D once")
        C[i, j] = sign
    if np.linalg.det(C) < 0:
        words = ", ".join(f"{'xyz'[j]} {_WORDS[ch]}" for j, ch in enumerate(letters))
        raise ScenarioError(f"axes: {text!r} is not a rotation: {words} is a left-handed "
                            "frame (determinant -1); flip one axis (FRD, FLU, BRU) or give a "
                            "right-handed matrix")
    return C


def describe(C: np.ndarray) -> str:
    """Letters of a signed-permutation ``C`` (``'FRD'``), else the matrix as text."""
    C = np.asarray(C, float)
    names = ("RL", "FB", "UD")
    out = ""
    for j in range(3):
        col = C[:, j]
        i = int(np.argmax(np.abs(col)))
        if abs(abs(col[i]) - 1.0) > 1e-12 or np.count_nonzero(np.abs(col) > 1e-12) != 1:
            return np.array2string(C, precision=6, separator=", ").replace("\n", "")
        out += names[i][0 if col[i] > 0 else 1]
    return out


def axes_text(axes) -> str:
    """The declared axes as written in a record: letters upper-cased, a matrix as text."""
    if isinstance(axes, str):
        return "".join(ch for ch in axes.upper() if ch.isalpha())
    return describe(np.asarray(axes, float))
