"""`gcalign navigate`: strapdown navigation of simulated or recorded data."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import (
    STRAPDOWN_OPS,
    Command,
    Cost,
    Inputs,
    Options,
    Outcome,
    config,
    streamed,
    stride,
)
from gcalign.errors import ScenarioError

#: doubles stored per row (t, att, v_n, pos, their errors, phi, ...)
ROW_DOUBLES = 30


class Navigate(Command):
    name = "navigate"
    help = "Strapdown navigation of simulated or recorded data."
    section = "navigation"
    options = Options(recorded=True, streams=True)

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.navigate.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.navigate.tables import navigate_table

        return navigate_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.navigate.plots import figures

        return figures(f, name)

    def check(self, inputs: Inputs) -> None:
        sc, ext = inputs.scenario, inputs.extent
        if ext is None:
            return
        cfg = config(sc, "navigation")
        if int(round(cfg.start_s / ext.ts)) >= ext.samples:
            raise ScenarioError(f"navigation.start_s: {cfg.start_s:g} s is past the end of the "
                                f"data ({ext.samples * ext.ts:g} s)")
        stride(sc, ext)

    def cost(self, inputs: Inputs) -> Cost:
        return streamed(inputs, ROW_DOUBLES, STRAPDOWN_OPS, "strapdown steps")


COMMAND = Navigate()
