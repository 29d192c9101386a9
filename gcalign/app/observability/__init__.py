"""`gcalign observability`: the PWCS/SVD observability table of a flight (seed 002 §4), or of
a transfer-alignment run (``align.mode: transfer``, spec 006, :mod:`.transfer`): one command,
its check, cost, run, table and figures chosen by the scenario's mode."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.align import Align
from gcalign.app.calibrate import COMMAND as CALIBRATE
from gcalign.app.calibrate import SIMULATION_DOUBLES, STEP_DOUBLES, Calibrate, steps
from gcalign.app.command import DOUBLE, KALMAN_OPS, Command, Cost, Inputs, Options, Outcome, config

N = 21  #: states
PIECE_OPS = 40.0 * N**3  #: per PWCS piece: Φ = expm(F T), the observability matrix, its QR


def transfer_mode(sc) -> bool:
    """A transfer-alignment scenario (its table is the transfer filter's, spec 006)."""
    return sc.align is not None and sc.align.mode == "transfer"


class Observability(Command):
    name = "observability"
    help = "PWCS/SVD observability table of a flight (seed 002) or a transfer alignment."
    section = "observability"
    builtin = "seed002_designed.yaml"
    options = Options(batch_metrics=("rank_final",))

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.observability.run import execute

        return execute

    def execute(self, sc: Any, seed: int | None = None, cache_key: str | None = None,
                *, recording: Any = None, **options: Any) -> Outcome:
        if transfer_mode(sc):
            from gcalign.app.observability import transfer

            return transfer.execute(sc, seed, cache_key, recording=recording, **options)
        return super().execute(sc, seed, cache_key, recording=recording, **options)

    def table(self, summary: dict[str, Any]) -> Any:
        if summary.get("mode") == "transfer":
            from gcalign.app.observability.transfer import table

            return table(summary)
        from gcalign.app.observability.tables import observability_table

        return observability_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        if "observability" in f and f["observability"].attrs.get("mode") == "transfer":
            from gcalign.app.observability.transfer import figures as transfer_figures

            return transfer_figures(f, name)
        from gcalign.app.observability.plots import figures

        return figures(f, name)

    read_own = Align.read_own  # a transfer scenario's slave and master

    def check(self, inputs: Inputs) -> None:
        super().check(inputs)
        if transfer_mode(inputs.scenario):  # the run's inputs: the align command's check
            from gcalign.app.align import transfer

            transfer.check(inputs.scenario, inputs.recording)

    def cost(self, inputs: Inputs) -> Cost:
        """Per PWCS piece F, Φ, R and the stacked observability matrix (measurements × 21
        rows of 21) held at once, and their products; the flight at the navigation rate;
        the covariance run's epochs."""
        sc, ext = inputs.scenario, inputs.extent
        if transfer_mode(sc):
            from gcalign.app.observability import transfer

            return transfer.cost(sc)
        cfg = config(sc, "observability")
        n, nav, epochs = steps(sc, ext)
        segments = len(sc.motion.segments) if sc.motion is not None and hasattr(
            sc.motion, "segments") else 1
        pieces = (0.0 if ext is None else ext.samples * ext.ts) / cfg.piece_s + segments
        measured = 6 if cfg.measure == "both" else 3
        per_piece = 4 * N * N + N * measured * N
        covariance = epochs * KALMAN_OPS if cfg.covariance else 0.0
        return Cost(samples=n,
                    memory_bytes=(pieces * per_piece + n * SIMULATION_DOUBLES
                                  + nav * STEP_DOUBLES) * DOUBLE,
                    output_bytes=(segments * 4 * N + nav * STEP_DOUBLES / 10) * DOUBLE,
                    work=pieces * PIECE_OPS + covariance,
                    work_what="PWCS pieces × 40 · 21³",
                    memory_what="the PWCS pieces (observability.piece_s)")

    components = Calibrate.components  # the 21 states

    def warm_up(self) -> None:
        CALIBRATE.warm_up()


COMMAND = Observability()
