"""`gcalign simulate`: truth and IMU data of a scenario."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import Command, Cost, Inputs, Options, Outcome, streamed, stride

#: doubles stored per row: /truth t, att, v_n, pos, segment and /imu t, dtheta, dv, q_bs
ROW_DOUBLES = 26


class Simulate(Command):
    name = "simulate"
    help = "Simulate truth and IMU data."
    options = Options(streams=True)

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.simulate.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.simulate.tables import simulate_table

        return simulate_table(summary)

    def check(self, inputs: Inputs) -> None:
        sc, ext = inputs.scenario, inputs.extent
        if ext is not None:
            stride(sc, ext)

    def cost(self, inputs: Inputs) -> Cost:
        return streamed(inputs, ROW_DOUBLES, 0.0, "samples × their simulation")

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        """The truth and the IMU output (the shared figures of :mod:`gcalign.app.plots`)."""
        from gcalign.app.plots import truth_and_imu

        return truth_and_imu(f, name)


COMMAND = Simulate()
