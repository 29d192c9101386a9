"""The filter's navigation solution at every navigation sample, as the run goes: stored at
the output rate in ``/calibrate/runs/NN/navigation`` and compared with the truth or the
reference at every sample, the errors summed apart inside and outside the outages.

Memory stays flat in the run's length: a block of rows at a time, the file's chunked
series (:class:`gcalign.io.results.Series`) and a few sums.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gcalign.calibrate.fixes import Outage, inside
from gcalign.estimation.calibration import Errors as ErrorSeries
from gcalign.io.recorded.reference import Reference, reference_at
from gcalign.nav.earth import EarthModel
from gcalign.nav.navigate import position_error_enu
from gcalign.nav.rotation import attitude_error, quat_to_euler

QUANTITIES = ("position", "velocity", "attitude")
SPLIT = ("outside_outages", "in_outages")  #: the rows outside and inside the outages
BLOCK_ROWS = 4096  #: rows held before they are compared and stored
#: the unit each quantity's summary keys end in (``position_rms_m``, ``velocity_max_mps``)
UNITS = {"position": "m", "velocity": "mps", "attitude": "deg"}


@dataclass
class ErrorStats:
    """Sums of squares, maxima and counts of 3-component errors (ENU m, ENU m/s, Euler
    differences rad), and of the horizontal position error."""

    n: int = 0
    sq: dict[str, np.ndarray] = field(default_factory=lambda: {q: np.zeros(3)
                                                               for q in QUANTITIES})
    peak: dict[str, np.ndarray] = field(default_factory=lambda: {q: np.zeros(3)
                                                                 for q in QUANTITIES})
    h_sq: float = 0.0
    h_peak: float = 0.0

    def add(self, errors: dict[str, np.ndarray]) -> None:
        """Rows (k, 3) of each quantity's error."""
        k = len(errors["position"])
        if not k:
            return
        self.n += k
        for q in QUANTITIES:
            e = errors[q]
            self.sq[q] += np.sum(e * e, axis=0)
            self.peak[q] = np.maximum(self.peak[q], np.abs(e).max(axis=0))
        h = np.hypot(errors["position"][:, 0], errors["position"][:, 1])
        self.h_sq += float(h @ h)
        self.h_peak = max(self.h_peak, float(h.max()))

    def summary(self) -> dict | None:
        """RMS and maximum of each quantity (attitude in degrees), or None without rows."""
        if not self.n:
            return None
        out: dict = {"samples": self.n}
        for q in QUANTITIES:
            k = np.degrees(1.0) if q == "attitude" else 1.0
            out[f"{q}_rms_{UNITS[q]}"] = (np.sqrt(self.sq[q] / self.n) * k).tolist()
            out[f"{q}_max_{UNITS[q]}"] = (self.peak[q] * k).tolist()
        out["horizontal_rms_m"] = float(np.sqrt(self.h_sq / self.n))
        out["horizontal_max_m"] = self.h_peak
        return out


class Errors:
    """Errors of solution rows against the truth (rows of a navigation-rate trajectory, in
    step with the run) or against a reference (interpolated, its gaps left out)."""

    def __init__(self, earth: EarthModel, truth=None, reference: Reference | None = None,
                 ref_gaps: tuple[Outage, ...] = ()):
        self.earth, self.truth, self.reference, self.ref_gaps = earth, truth, reference, ref_gaps
        self.against = "truth" if truth is not None else (
            "reference" if reference is not None else None)

    def of(self, rows: slice | np.ndarray | None, t_data: np.ndarray, att: np.ndarray,
           v: np.ndarray, pos: np.ndarray, tol: float = 1e-9
           ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """``(valid (n,), errors)`` of solution rows at the data times `t_data`, the rows
        `rows` of the truth (unused against a reference): position ENU m, velocity ENU m/s,
        attitude Euler differences rad, each (n, 3), NaN where nothing is compared (beyond
        the reference by more than `tol` s, or in one of its gaps)."""
        n = len(t_data)
        out = {q: np.full((n, 3), np.nan) for q in QUANTITIES}
        if self.truth is not None:
            tr = self.truth
            out["position"] = position_error_enu(pos, tr.pos[rows], self.earth)
            out["velocity"] = v - tr.v_n[rows]
            out["attitude"] = attitude_error(att, tr.att[rows])
            return np.ones(n, dtype=bool), out
        ref = self.reference
        if ref is None:
            return np.zeros(n, dtype=bool), out
        ok = (t_data >= ref.t[0] - tol) & (t_data <= ref.t[-1] + tol)
        ok &= ~inside(t_data, self.ref_gaps)
        if ok.any():
            r_att, r_v, r_pos = reference_at(ref, t_data[ok], tol=1e-6)
            out["position"][ok] = position_error_enu(pos[ok], r_pos, self.earth)
            out["velocity"][ok] = v[ok] - r_v
            if r_att is not None:
                out["attitude"][ok] = attitude_error(att[ok], r_att)
            else:
                out["attitude"][ok] = 0.0
        return ok, out


class SolutionSink:
    """``on_rows`` of :func:`gcalign.calibrate.calibrate`: stores every `stride`-th row
    (``group`` an h5py group, or None) and sums the errors (:class:`Errors`) of every row
    inside and outside `outages` (run time)."""

    def __init__(self, group, stride: int, t0: float, errors: Errors,
                 outages: tuple[Outage, ...] = (), rate_hz: float = 0.0,
                 time_origin: str = ""):
        from gcalign.io.results import ATT_FRAME, Series

        self.stride, self.t0, self.errors, self.outages = stride, t0, errors, outages
        self.k = 0  # rows processed
        self._held: list[tuple[np.ndarray, ...]] = []
        self._held_rows = 0
        self.stats = {k: ErrorStats() for k in SPLIT}
        self.series = None
        if group is not None:
            spec = {"t": (None, "s", None), "t_run": (None, "s", None),
                    "att": (3, "rad", ATT_FRAME), "v_n": (3, "m/s", "ENU"),
                    "pos": (3, "rad, rad, m", "[latitude, longitude, height]")}
            if errors.against is not None:
                spec |= {"error/t": (None, "s", None),
                         "error/att": (3, "rad", f"Euler differences est - {errors.against}"
                                                 ", roll and yaw wrapped"),
                         "error/v_n": (3, "m/s", "ENU"),
                         "error/pos": (3, "m", "ENU (east, north, up)")}
            self.series = Series(group, spec, stride=stride, rate_hz=rate_hz / stride,
                                 time_origin=time_origin or "the recording's time",
                                 description="the filter's corrected solution at every "
                                 "navigation sample (t: the recording's time base; t_run: "
                                 "s from the run's first sample)")
            if errors.against is not None:
                group.attrs["error_source"] = errors.against

    def __call__(self, t: np.ndarray, q_nb: np.ndarray, v_n: np.ndarray,
                 pos: np.ndarray) -> None:
        self._held.append((t, q_nb, v_n, pos))
        self._held_rows += len(t)
        if self._held_rows >= BLOCK_ROWS:  # whole blocks: NumPy's per-call cost, not per step
            self._process()

    def _process(self) -> None:
        if not self._held:
            return
        t, q_nb, v_n, pos = (np.concatenate(a) for a in zip(*self._held, strict=True))
        self._held, self._held_rows = [], 0
        n = len(t)
        att = quat_to_euler(q_nb)
        t_data = t + self.t0
        if self.errors.against is not None:
            ok, err = self.errors.of(slice(self.k, self.k + n), t_data, att, v_n, pos)
            add_split(self.stats, ok, inside(t, self.outages), err)
        if self.series is not None:
            keep = (self.k + np.arange(n)) % self.stride == 0
            rows = {"t": t_data[keep], "t_run": t[keep], "att": att[keep], "v_n": v_n[keep],
                    "pos": pos[keep]}
            if self.errors.against is not None:  # where compared: not in a reference's gaps
                sel = keep & ok
                rows |= {"error/t": t_data[sel], "error/att": err["attitude"][sel],
                         "error/v_n": err["velocity"][sel], "error/pos": err["position"][sel]}
            self.series.append(**rows)
        self.k += n

    def close(self) -> dict | None:
        """The series flushed; the error statistics (None without truth or reference)."""
        self._process()
        if self.series is not None:
            self.series.flush()
        if self.errors.against is None:
            return None
        return {"against": self.errors.against, **{k: s.summary() for k, s in self.stats.items()}}


def add_split(stats: dict[str, ErrorStats], ok: np.ndarray, out: np.ndarray,
              err: dict[str, np.ndarray]) -> dict[str, ErrorStats]:
    """`stats` (:data:`SPLIT`) with the errors `err` of the rows `ok` added, outside or
    inside the outages as `out` says."""
    for key, where in zip(SPLIT, (ok & ~out, ok & out), strict=True):
        stats[key].add({q: e[where] for q, e in err.items()})
    return stats


def epoch_errors(errors: Errors, t: np.ndarray, t0: float, index: np.ndarray | None,
                 att: np.ndarray, v_n: np.ndarray, pos: np.ndarray,
                 outages: tuple[Outage, ...], what: str = "", tol: float = 1e-9
                 ) -> tuple[dict[str, dict | None], ErrorSeries]:
    """A solution at the filter epochs (the forward filter's or the smoother's) against
    the truth or the reference (:meth:`Errors.of`, `tol`): its statistics inside and
    outside the outages, and the errors themselves at the epochs compared, as the results
    file keeps them (`what` they are the errors of)."""
    ok, err = errors.of(index, t + t0, att, v_n, pos, tol)
    stats = add_split({k: ErrorStats() for k in SPLIT}, ok, inside(t, outages), err)
    return ({k: s.summary() for k, s in stats.items()}, ErrorSeries(
        what, t[ok], err["attitude"][ok], err["velocity"][ok], err["position"][ok]))
