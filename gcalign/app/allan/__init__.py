"""`gcalign allan`: the Allan deviation of a static recording (or a simulation) and the IMU
noise terms fitted to it, named as the scenario's ``imu`` keys."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import Command, Cost, Inputs, Options, Outcome

#: operations per sample and axis: the running sum and allantools' second differences at
#: every cluster time (about 10 a decade over 5 decades)
OPS_PER_SAMPLE = 6 * 50.0


class Allan(Command):
    name = "allan"
    help = ("Allan deviation of IMU data at rest and the noise terms fitted to it (ARW, "
            "bias instability, ...).")
    section = "allan"
    options = Options(recorded=True)

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.allan.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.allan.tables import allan_table

        return allan_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.allan.plots import figures

        return figures(f, name)

    def check(self, inputs: Inputs) -> None:
        sc, ext = inputs.scenario, inputs.extent
        if ext is not None and sc.allan is not None:
            from gcalign.app.allan.run import window

            window(sc.allan, ext.samples, ext.ts)  # a start past the data's end

    def cost(self, inputs: Inputs) -> Cost:
        ext = inputs.extent
        if ext is None:
            return Cost()
        n = float(ext.samples)
        return Cost(samples=n, memory_bytes=n * 8 * 10, work=n * OPS_PER_SAMPLE,
                    work_what="samples × cluster times")


COMMAND = Allan()
