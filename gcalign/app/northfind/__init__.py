"""`gcalign northfind`: multi-position north-finding with tilt compensation (seed 001)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import (
    DOUBLE,
    SIMULATE_OPS,
    Command,
    Cost,
    Inputs,
    Options,
    Outcome,
)

READING_DOUBLES = 16  #: per dwell reading: gyro and accelerometer means, per method results


class Northfind(Command):
    name = "northfind"
    help = "Multi-position north-finding (seed 001)."
    section = "northfind"
    builtin = "seed001_simulation.yaml"
    options = Options(self_contained=True,
                      batch_metrics=("methods.coordinate.rms_error_deg",))
    section_keys = "positions, dwell_s, azimuth_deg or sweep, tilt_deg, …"

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.northfind.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.northfind.tables import northfind_table

        return northfind_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.northfind.plots import figures

        return figures(f, name)

    def cost(self, inputs: Inputs) -> Cost:
        sc: Any = inputs.scenario  # its section is there: the check ran first
        cfg = sc.northfind
        readings = float(cfg.azimuths_deg().size * cfg.repeats * cfg.positions)
        per_dwell = float(round(cfg.dwell_s * sc.imu.rate_hz)) if cfg.samples else 1.0
        return Cost(samples=readings * per_dwell if cfg.samples else 0.0,
                    memory_bytes=readings * READING_DOUBLES * DOUBLE + per_dwell * 6 * DOUBLE,
                    output_bytes=readings * READING_DOUBLES * DOUBLE,
                    work=readings * per_dwell * SIMULATE_OPS,
                    work_what="dwell readings × their samples", memory_what="dwell readings")


COMMAND = Northfind()
