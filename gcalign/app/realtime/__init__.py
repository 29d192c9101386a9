"""`gcalign realtime`: attitude at external sync pulses, filter delay and prediction
(seed 003)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import DOUBLE, Command, Cost, Inputs, Options, Outcome

NOTCH_OPS = 5.0  #: a second-order IIR section per sample
SOLUTION_DOUBLES = 24  #: per attitude solution: truth, output and each predictor's error


class Realtime(Command):
    name = "realtime"
    help = "Attitude at sync pulses: filter delay and prediction (seed 003)."
    section = "realtime"
    builtin = "seed003_table1.yaml"
    options = Options(self_contained=True,
                      batch_metrics=("cases.0.after_max_arcsec.kalman-ls",))
    section_keys = "cases or a turntable motion, filter, sensor, tracker, pulses"

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.realtime.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.realtime.tables import realtime_table

        return realtime_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.realtime.plots import figures

        return figures(f, name)

    def cost(self, inputs: Inputs) -> Cost:
        """Three gyro channels through the chain's FIR (as it is applied: directly or
        through FFTs) and notch; the attitude solutions held for the pulses."""
        from gcalign.realtime.filters import fir_ops_per_sample

        sc: Any = inputs.scenario  # its section is there: the check ran first
        cfg = sc.realtime
        s = cfg.to_settings()
        f = s.filter
        n = float(cfg.samples(sc))
        taps = (f.nav_order if f.chain == "navigation" else f.align_order) + 1.0
        chunk = min(n, s.chunk_s * f.fs_hz)
        solutions = n / f.fs_hz * s.solution_hz
        return Cost(samples=n,
                    memory_bytes=(chunk * 3 * 6 + taps * 3 * 2) * DOUBLE
                    + solutions * SOLUTION_DOUBLES * DOUBLE,
                    output_bytes=solutions * SOLUTION_DOUBLES * DOUBLE,
                    work=3 * n * (fir_ops_per_sample(taps, chunk) + NOTCH_OPS),
                    work_what="3 channels × FIR operations × samples",
                    memory_what="the attitude solutions")


COMMAND = Realtime()
