"""Row checks shared by the aiding and reference readers: strictly increasing times, finite
fields, the declared columns; each failure one line naming the file, the row and the field."""

from __future__ import annotations

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.io.imu_files import ImuFileError


def _check_rows(name: str, t: np.ndarray, where) -> None:
    dt = np.diff(t)
    if (dt <= 0).any():
        k = int(np.argmax(dt <= 0)) + 1
        raise ImuFileError(f"{name}{where(k)}: time must increase strictly, got "
                           f"{float(t[k])!r} after {float(t[k - 1])!r}")


def _finite(name: str, a: np.ndarray, labels, where) -> None:
    bad = ~np.isfinite(a)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise ImuFileError(f"{name}{where(int(row))}: field {col + 1} ({labels[col]}) must be "
                           f"finite, got {float(a[row, col])!r}")


def _columns(columns, default, allowed_extra=("-",)) -> tuple[str, ...]:
    cols = tuple(str(c).strip().lower() for c in (columns or default))
    missing = [c for c in default if c not in cols]
    if missing or any(c not in default and c not in allowed_extra for c in cols):
        raise ScenarioError(f"columns: {list(cols)} must name each of {', '.join(default)} "
                            "once ('-' skips a column)")
    return cols
