"""What a navigation run keeps in the results file, each field saying how
(:mod:`gcalign.schema`): its rows every `stride`-th sample (:class:`NavRows`) with their
errors against the truth or a reference (:class:`NavErrors`). Apart from
:mod:`gcalign.nav.navigate`, so that the checks of a results file read back take these
fields without loading the navigation kernels."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from gcalign.schema import ATT_FRAME, PHI_FRAME, stored

Array = NDArray[np.float64]


@dataclass(frozen=True)
class NavErrors:
    """Errors (or their largest magnitudes) per component: att (Euler differences est −
    true, roll and yaw wrapped, rad), v_n (m/s ENU), pos (m ENU), phi (misalignment, rad).
    Stored under ``error/`` of the rows (the frame names what they are against) and
    summarised in degrees, m/s and m."""

    att: Array = field(metadata=stored(
        "rad", frame="Euler differences est - {against}, roll and yaw wrapped",
        summary="deg", label="attitude", dims="N 3", optional=True))
    v_n: Array = field(metadata=stored("m/s", frame="ENU", summary="mps", label="velocity",
                                       dims="N 3", optional=True))
    pos: Array = field(metadata=stored("m", frame="ENU (east, north, up)", summary="m",
                                       label="position", dims="N 3", optional=True))
    phi: Array = field(metadata=stored("rad", frame=PHI_FRAME, summary="deg",
                                       label="misalignment", dims="N 3", optional=True))

    def stack(self) -> Array:
        """(4, 3): att, v_n, pos, phi."""
        return np.stack([self.att, self.v_n, self.pos, self.phi])


@dataclass(frozen=True)
class NavRows:
    """Stored rows: record time t (n,), body attitude att, v_n, pos (n, 3), and the
    errors against the truth (None without truth) as in :class:`NavErrors`."""

    t: Array = field(metadata=stored("s", dims="N", rule="increasing"))
    att: Array = field(metadata=stored("rad", frame=ATT_FRAME, dims="N 3", optional=True))
    v_n: Array = field(metadata=stored("m/s", frame="ENU", dims="N 3", optional=True))
    pos: Array = field(metadata=stored("rad, rad, m", frame="[latitude, longitude, height]",
                                       dims="N 3", optional=True))
    error: NavErrors | None = field(default=None, metadata=stored(""))
