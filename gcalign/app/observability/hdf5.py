"""The /observability group of a results file (seed 002 §4): degrees per segment and
cumulative, ranks, the null-space condition, the covariance degree.

Layout::

    /observability        attrs: measure, scaling, rank_rtol, piece_s, states (names)
        segment_name (S,), t0, t1 (S,) s
        eta, eta_cum, sigma_state (S, 21); rank, tom_rank, rank_cum, tom_rank_cum (S,)
        null_residual (S,), condition (S,) bool
        cov_degree, cov_degree_segment (S, 21) sigma(0)/sigma(t_end), sigma(t0)/sigma(t_end)
"""

from __future__ import annotations

import h5py
import numpy as np

from gcalign.io.results import put, write_segments
from gcalign.io.stored import write_fields


def put_rows(g: h5py.Group, tab, names, t0, t1, condition, *, shape: str, row: str,
             t0_description: str | None = None) -> None:
    """The rows of an observability table (a segment or a window each) and their ranks: the
    datasets every /observability group has, the seed-002 flight's and a transfer run's."""
    g.create_dataset("segment_name", data=np.array(names, dtype=h5py.string_dtype()))
    put(g, "t0", t0, "s", **({} if t0_description is None else
                             {"description": t0_description}))
    put(g, "t1", t1, "s")
    put(g, "eta", tab.eta, "1", shape=shape, description=f"seed eq. 17 per {row}")
    put(g, "eta_cum", tab.eta_cum, "1", shape=shape, description="from the start of the run")
    put(g, "sigma_state", tab.sigma_state, "SOM units", shape=shape)
    for name in ("rank", "tom_rank", "rank_cum", "tom_rank_cum", "null_residual"):
        put(g, name, getattr(tab, name), "1")
    put(g, "condition", condition.astype(np.int8), "1",
        description="null(O_j) in null(F_j) for every piece (seed eq. 12)")


def write_observability(f: h5py.File, tab, truth, spans) -> None:
    """/observability: the table as its fields say
    (:class:`gcalign.calibrate.observability.ObservabilityTable`), and each
    segment's start and end."""
    write_segments(f, truth, spans)
    g = f.create_group("observability")
    write_fields(g, tab)
    put(g, "t0", [s.start for s in spans], "s")
    put(g, "t1", [s.end for s in spans], "s")
