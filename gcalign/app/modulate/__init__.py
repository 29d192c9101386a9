"""`gcalign modulate`: navigation on a turning IMU, several rotation schemes on the same data
(seed 004)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import (
    BLOCK,
    DOUBLE,
    SIMULATE_OPS,
    STRAPDOWN_OPS,
    Command,
    Cost,
    Inputs,
    Options,
    Outcome,
)
from gcalign.app.navigate import ROW_DOUBLES

MECHANISM_OPS = 100.0  #: per sample: the mechanism's C_s^b and the increments it turns


class Modulate(Command):
    name = "modulate"
    help = ("Rotation modulation: navigation on a turning IMU, schemes compared on the same "
            "data (seed 004).")
    section = "modulate"
    builtin = "seed004_modulation.yaml"
    options = Options(streams=True, batch_metrics=("max_horizontal_error_m",))

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.modulate.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.modulate.tables import modulate_table

        return modulate_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.modulate.plots import figures

        return figures(f, name)

    def check(self, inputs: Inputs) -> None:
        sc = inputs.scenario
        from gcalign.io.scenario.modulate import plan_of

        plan_of(sc)

    def cost(self, inputs: Inputs) -> Cost:
        """Each scheme simulates and navigates the plan's duration, streamed in blocks, and
        stores its series at ``output.rate_hz`` (default 1 Hz up to 4 h, 0.1 Hz beyond)."""
        sc: Any = inputs.scenario  # its section is there: the check ran first
        from gcalign.io.scenario.modulate import default_rate_hz, plan_of

        plan = plan_of(sc)
        rate = sc.imu.rate_hz
        n = plan.duration_s * rate
        schemes = len(plan.entries)
        rows = plan.duration_s * (sc.output.rate_hz or default_rate_hz(plan.duration_s, rate))
        return Cost(samples=n * schemes,
                    memory_bytes=min(n, BLOCK) * 2 * ROW_DOUBLES * DOUBLE,
                    output_bytes=schemes * rows * ROW_DOUBLES * DOUBLE,
                    work=schemes * n * (SIMULATE_OPS + MECHANISM_OPS + STRAPDOWN_OPS),
                    work_what="schemes × samples × (mechanism, simulation, strapdown)",
                    memory_what="the blocks of the stream")


COMMAND = Modulate()
