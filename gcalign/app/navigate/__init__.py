"""`gcalign navigate`: strapdown navigation of simulated or recorded data."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import (
    DOUBLE,
    SIMULATE_OPS,
    STRAPDOWN_OPS,
    Command,
    Cost,
    Inputs,
    Options,
    Outcome,
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
        from gcalign.io.scenario.navigation import NavigationConfig

        cfg = sc.navigation or NavigationConfig()
        if int(round(cfg.start_s / ext.ts)) >= ext.samples:
            raise ScenarioError(f"navigation.start_s: {cfg.start_s:g} s is past the end of the "
                                f"data ({ext.samples * ext.ts:g} s)")
        stride(sc, ext)

    def cost(self, inputs: Inputs) -> Cost:
        sc, ext = inputs.scenario, inputs.extent
        if ext is None:
            return Cost()
        n = float(ext.samples)
        ops = STRAPDOWN_OPS + (0.0 if ext.recorded else SIMULATE_OPS)
        return Cost(samples=n, memory_bytes=min(n, 1 << 16) * ROW_DOUBLES * DOUBLE,
                    output_bytes=n / stride(sc, ext) * ROW_DOUBLES * DOUBLE,
                    work=n * ops, work_what="strapdown steps")


COMMAND = Navigate()
