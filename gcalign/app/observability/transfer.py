"""`gcalign observability` on a transfer-alignment scenario (``align.mode: transfer``, spec
006): the filter's run for the scenario's matching (``align.transfer.matching``,
``--matching``) gives F, H and the covariance; :func:`gcalign.transfer.observability.
transfer_observability` gives the PWCS/SVD table of its windows.

The summary keeps the command's usual shape (``segments`` and ``cumulative`` per window with
``degree`` and ``covariance_degree``, ``rank_final``, ``degree_final``), plus per state the
separation, σ0 and σ at the end, the unobservable states and the weakest combination. The
results file: ``/observability`` as for a flight (windows in place of segments; ``eta``
over the 15 PWCS states, ``cov_degree`` over all the filter's states, named by the
``states`` and ``covariance_states`` attributes) and the filter's σ against time.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import h5py
import numpy as np

from gcalign.app.align.transfer import DECIMALS, GROUP_ENDS, display, write_display
from gcalign.app.command import DOUBLE, Cost, Outcome
from gcalign.errors import ScenarioError
from gcalign.schema import stored

PWCS_N = 15
PIECE_OPS = 40.0 * PWCS_N**3  #: per PWCS piece: Φ = expm(F T), the observability matrix, QR


@dataclass(frozen=True)
class SigmaSeries:
    """What ``/observability`` of a transfer run holds beside the table
    (:class:`~gcalign.transfer.observability.TransferObservability`): the filter's σ per
    master epoch, for its σ/σ0 figure."""

    t: np.ndarray = field(metadata=stored("s", description="master epochs, from the start"))
    sigma: np.ndarray = field(metadata=stored(
        "SI", description="the filter's sigma per epoch, 'covariance_states' order"))


def cost(sc) -> Cost:
    """One filter run (:func:`gcalign.app.align.transfer.cost`) and the PWCS pieces, at
    most one per master epoch (the bound: the files' headers give no times), each F, Φ, R
    and its observability matrix (6·15 rows of 15) held at once."""
    from gcalign.app.align import transfer

    run = transfer.cost(sc)
    _, K, n = transfer.sizes(sc)
    pieces = float(K)
    per_piece = 4 * PWCS_N**2 + 6 * PWCS_N * PWCS_N
    return Cost(samples=run.samples,
                memory_bytes=run.memory_bytes + pieces * per_piece * DOUBLE,
                output_bytes=K * n * DOUBLE + run.output_bytes,
                work=run.work + pieces * PIECE_OPS,
                work_what=f"{run.work_what} + PWCS pieces × 40 · 15³",
                memory_what=run.memory_what)


def execute(sc, seed: int | None = None, cache_key: str | None = None,
            progress: Any = None, recording: Any = None) -> Outcome:
    """The filter's run and its table (no randomness: the seed only names the run)."""
    from gcalign.app.align.transfer import run_filter
    from gcalign.io.scenario.calibrate import ObservabilityConfig
    from gcalign.transfer.observability import transfer_observability

    cfg = sc.observability or ObservabilityConfig()
    if progress is not None:
        progress(0, 2, f"transfer filter ({sc.align.transfer.matching})")
    result, _, _, filter_s = run_filter(sc, recording)
    start = time.process_time()
    if progress is not None:
        progress(1, 2, "PWCS + SVD table")
    obs = transfer_observability(result, cfg.piece_s, cfg.window_s, cfg.scaling,
                                 cfg.rank_rtol, cfg.null_tol)
    if progress is not None:
        progress(2, 2, "PWCS + SVD table")
    warnings = tuple(result.health_warnings())
    out = summary(sc, obs, filter_s + time.process_time() - start)
    out["warnings"] = list(warnings)
    return Outcome(out, lambda f: write(f, obs, result), None, None, warnings, result=obs)


def summary(sc, obs, compute_s: float) -> dict:
    """Plain numbers: the JSON contract of ``gcalign observability`` on a transfer run."""
    from gcalign.app.observability.run import per_state, table_rows
    from gcalign.calibrate.data import Span
    from gcalign.schema import placed, summary_of

    tab, pw, names = obs.table, obs.pwcs, obs.names
    spans = [Span(w, float(a), float(b)) for w, a, b in zip(obs.windows, obs.t0, obs.t1,
                                                            strict=True)]
    segs, cum = table_rows(tab, spans, obs.condition, pw,
                           (names, obs.cov_degree_segment, obs.cov_degree))
    return placed(summary_of(obs), {  # how the table was made, from its fields
        "measure": {"scenario": sc.name, "mode": "transfer"},
        "scaling": {"matching": obs.matching}}, {
        "pieces": obs.pieces,
        "states": list(pw),
        "covariance_states": list(names),
        "segments": segs,
        "cumulative": cum,
        "rank_final": int(tab.rank_cum[-1]),
        "tom_rank_final": int(tab.tom_rank_cum[-1]),
        "degree_final": [float(v) for v in tab.eta_cum[-1]],
        "separation": per_state(pw, obs.separation),
        "singular_values": [float(v) for v in obs.singular_values],
        "unobservable": [n for n, z in zip(pw, obs.unobservable, strict=True) if z],
        "weakest": {"ratio": obs.weakest_ratio, "vector": per_state(pw, obs.weakest)},
        "sigma0": per_state(names, obs.sigma0),
        "sigma_final": per_state(names, obs.sigma_end[-1]),
        "covariance_degree_final": per_state(names, obs.cov_degree[-1]),
        **display(names),
        "compute_s": compute_s,
    })


def write(f: h5py.File, obs, result) -> None:
    """``/observability`` (module docstring) as the table's fields say
    (:class:`~gcalign.transfer.observability.TransferObservability`), the states' display
    units, and the filter's σ per epoch."""
    from gcalign.io.stored import write_fields

    g = f.create_group("observability")
    g.attrs["mode"] = "transfer"
    write_display(g, obs.names)
    write_fields(g, obs)
    write_fields(g, SigmaSeries(result.t - result.t0, result.sigma))


# -- table and figures (rich and matplotlib loaded by the caller's import of this module) --

def _ratio(x: float) -> str:
    """σ0/σ with one decimal (1.0: nothing learnt), scientific from 10⁴."""
    return f"{x:.1f}" if x < 1e4 else f"{x:.1e}"


def table(s: dict):
    """One row per state: σ0, σ at the end (display units), σ0/σ, the whole run's degree η
    and separation."""
    from gcalign.app.observability.tables import margin
    from gcalign.app.report import DASH, titled

    last = s["cumulative"][-1]
    t = titled(f"gcalign observability: {s['scenario']} — transfer alignment, "
               f"{s['matching']} matching, scaling {s['scaling']}, {s['pieces']} pieces of "
               f"{s['piece_s']:g} s in {len(s['segments'])} windows of {s['window_s']:g} s",
               ("state", "unit"), ("σ0", "σ end", "σ0/σ", "η", "sep."))
    unobs = set(s["unobservable"])
    for name in s["covariance_states"]:
        k, unit = s["display_scale"][name], s["display_units"][name]
        d = DECIMALS[unit]
        eta = last["degree"].get(name)
        sep = s["separation"].get(name)
        eta_text = (DASH if eta is None else "n/a" if eta == 0 and name not in unobs
                    else "0" if eta == 0 else f"{eta:.1e}")
        t.add_row(name + (" ·" if name in unobs else ""), unit,
                  f"{s['sigma0'][name] * k:.{d}f}", f"{s['sigma_final'][name] * k:.{d}f}",
                  _ratio(s["covariance_degree_final"][name]), eta_text,
                  DASH if sep is None else f"{sep:.1e}", end_section=name in GROUP_ENDS)
    w = s["weakest"]
    parts = sorted(((v, n) for n, v in w["vector"].items() if abs(v) >= 0.05),
                   key=lambda p: -abs(p[0]))
    combo = " ".join(f"{v:+.2f} {n}" for v, n in parts)
    conditions = sum(seg["condition"] for seg in s["segments"])
    notes = [
        f"whole run: SOM rank {last['rank']} (margin {margin(last.get('rank_margin'))}), "
        f"TOM rank {s['tom_rank_final']} of {len(s['states'])}; the null-space condition "
        f"of seed eq. 12 holds in {conditions} of {len(s['segments'])} windows",
        ("· unobservable (zero TOM column: in no measurement and no path to one): "
         + ", ".join(s["unobservable"])) if unobs else "no state with a zero TOM column",
        f"weakest combination, in units of the scaled states (σ_min/σ_max of the others "
        f"{w['ratio']:.1e}): {combo}",
        "σ0/σ: the filter's own covariance reduction (PSINS kfstat; 1 = nothing learnt). "
        "η: SVD degree σ_(k)/σ_0 of the whole run's SOM (seed eq. 17, σ_0 of the measured "
        "φ or δv; n/a: no singular vector has its largest part on the state, though its "
        "column is not zero). sep.: distance of the state's TOM column from the span of the others "
        "(0: a combination of them; unchanged by P0 and units). θ, ω (flexure, a "
        "noise-driven Markov process): σ only.",
        f"Per window and cumulative: --json, the results file, gcalign plot. Compute "
        f"{s['compute_s']:.2f} s; output {s.get('output') or DASH}",
    ]
    t.caption = "\n".join(notes)
    return t


def figures(f, name: str) -> dict:
    """The cumulative degree η per window (heat map, windows × 15 states), the covariance
    degree σ0/σ likewise (all states), and σ/σ0 against time per state group."""
    from gcalign.app.align.transfer import COLOURS, GROUPS, state_groups
    from gcalign.app.observability.plots import heat_map
    from gcalign.app.plots import finish, new_figure
    from gcalign.io.stored import read_fields
    from gcalign.transfer.observability import TransferObservability

    g = f["observability"]
    for ds in ("t", "sigma"):  # beside the table, outside its checks
        if not isinstance(g.get(ds), h5py.Dataset):
            raise ScenarioError(f"{f.filename}: dataset {g.name}/{ds} missing (a results "
                                "file of a transfer run has it)")
    obs, run = read_fields(g, TransferObservability), read_fields(g, SigmaSeries)
    how = f"{obs.matching} matching, scaling {obs.scaling}"
    figs = {
        "observability_cumulative": heat_map(
            obs.table.eta_cum, [f"to {w}" for w in obs.windows], list(obs.pwcs),
            f"{name}: cumulative degree η from the start (transfer alignment, {how}; grey ·: "
            "0, unobservable)", "log10 η", "·"),
        "covariance_degree": heat_map(
            obs.cov_degree, [f"after {w}" for w in obs.windows], list(obs.names),
            f"{name}: covariance degree σ(0)/σ(t) at the end of each window ({how})",
            "log10 σ(0)/σ(t)", exponents=False),
    }
    groups = state_groups(obs.names)
    fig, axes = new_figure(len(groups), width=9.0, height=1.6 * len(groups) + 1.2)
    for ax, (_, idx) in zip(axes, groups, strict=True):
        ratio = run.sigma[:, idx] / obs.sigma0[idx]
        for c, i, y in zip(COLOURS, idx, ratio.T, strict=True):
            ax.plot(run.t, y, color=c, linewidth=1.0, label=obs.names[i])
        if ratio.max() > 10 * ratio.min():  # decades: log; within one, linear reads better
            ax.set_yscale("log")
        ax.axhline(1.0, color="0.5", linewidth=0.8, linestyle=":", label="_P0")
    figs["sigma_reduction"] = finish(
        fig, axes, "time from the start of the run (s)",
        f"{name}: the filter's σ / σ0 ({how}); 1 = nothing learnt",
        [f"{GROUPS[gr].split()[0]} σ/σ0" for gr, _ in groups])  # its symbol
    return figs
