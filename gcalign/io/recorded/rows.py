"""What the aiding and reference readers share: their columns read with strictly increasing
times, the declared columns; each failure one line naming the file, the row and the field."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.io.imu_files import _increasing
from gcalign.io.recorded.imu import _table_of


def _read_columns(name: str, data: bytes, cols: tuple[str, ...], keep: tuple[str, ...]
                  ) -> tuple[dict[str, np.ndarray], Callable[[int], str]]:
    """The columns `keep` of the text table `data` whose columns are `cols` (every field
    finite, the time ``t`` strictly increasing), and where(k), the file line of row k."""
    rows, (_, where) = _table_of(name, data, len(cols), cols)
    c = {k: rows[:, cols.index(k)] for k in keep}
    _increasing(name, c["t"], where, got="")
    return c, where


def _columns(columns, default, allowed_extra=("-",)) -> tuple[str, ...]:
    cols = tuple(str(c).strip().lower() for c in (columns or default))
    missing = [c for c in default if c not in cols]
    if missing or any(c not in default and c not in allowed_extra for c in cols):
        raise ScenarioError(f"columns: {list(cols)} must name each of {', '.join(default)} "
                            "once ('-' skips a column)")
    return cols
