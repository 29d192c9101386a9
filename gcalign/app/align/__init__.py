"""`gcalign align`: gyrocompass alignment with forward/reverse passes (seed 000), and in
``align.mode: transfer`` a slave IMU aligned against a master INS (spec 006,
:mod:`gcalign.app.align.transfer`: its own check and cost, the same command)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from gcalign.app.command import (
    DOUBLE,
    SIMULATE_OPS,
    STRAPDOWN_OPS,
    Command,
    Cost,
    Extent,
    Inputs,
    Options,
    Outcome,
    config,
    stride,
    warm_scenario,
)
from gcalign.errors import ScenarioError

MAX_LAT_DEG = 85.0  #: gyrocompassing needs the horizontal earth rate
HELD_DOUBLES = 24  #: per sample of the window: increments, reference velocity, truth rows
ROW_DOUBLES = 12  #: per stored row of a pass
GYROCOMPASS_OPS = 2 * STRAPDOWN_OPS  #: a strapdown step and the loops

WARM_SCENARIO = {  # a tiny align scenario: every align kernel, in milliseconds
    "name": "warm-up",
    "site": {"lat_deg": 45.0, "lon_deg": 126.0},
    "imu": {"gyro": {"bias_dph": [0.01, 0.01, 0.01]}, "accel": {"bias_ug": [50, 50, 50]}},
    "motion": {"kind": "moving", "attitude_deg": [0, 0, 30], "duration_s": 3,
               "segments": [{"duration_s": 1}, {"duration_s": 2, "accel_mps2": 0.5}]},
    "align": {"t1_s": 1, "t2_s": 2, "t3_s": 2.5, "stages": [{"passes": 3}], "level_s": 0.1,
              "aiding": {"source": "odometer"}},
}


def window(sc, ext: Extent) -> tuple[int, int]:
    """First and last sample the alignment reads; ScenarioError for a time past the end."""
    cfg = config(sc, "align")
    his = []
    for field in ("start_s", "t1_s", "t2_s", "t3_s"):
        t = 0.0 if field == "start_s" else getattr(cfg, field)
        if t == "measured":
            continue
        k = int(round((cfg.start_s + t) / ext.ts))
        if k > ext.samples:
            fix = ("the recording is that long: choose earlier times (--t1, --t2, --t3)"
                   if getattr(sc, "imu_file", None) is not None
                   else "lengthen motion.duration_s or choose an earlier time")
            raise ScenarioError(
                f"align.{field}: {t} s (+ start_s {cfg.start_s} s) is past the end of the data "
                f"({ext.samples * ext.ts:.2f} s); {fix}")
        his.append(k)
    return int(round(cfg.start_s / ext.ts)), max(his)


class Align(Command):
    name = "align"
    help = "Gyrocompass alignment (seed 000)."
    section = "align"
    builtin = "seed000_moving_full_cycle.yaml"
    options = Options(recorded=True, batch_metrics=("error_t3_deg",))

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.align.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.align.tables import align_table

        return align_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.align.plots import figures

        return figures(f, name)

    def read_own(self, sc) -> Any:
        """In mode transfer the slave and the master (:func:`transfer.load_inputs`)."""
        if config(sc, "align").mode != "transfer":
            return None
        from gcalign.app.align.transfer import load_inputs

        return load_inputs(sc)

    def check(self, inputs: Inputs) -> None:
        """The latitude (the scenario's site, else the data file's), what needs truth, the
        times against the data, the stored-row stride; in mode transfer its files, settings
        and the master's cover of the run."""
        sc, ext = inputs.scenario, inputs.extent
        cfg = config(sc, "align")
        if cfg.mode == "transfer":
            from gcalign.app.align import transfer

            transfer.check(sc, inputs.recording)
            return
        lat = sc.site.lat_deg if sc.site is not None else (
            None if ext is None or ext.lat is None else math.degrees(ext.lat))
        if lat is not None and abs(lat) > MAX_LAT_DEG:
            raise ScenarioError(f"site.lat_deg: gyrocompassing needs |latitude| < "
                                f"{MAX_LAT_DEG:g}°, got {lat:.10g}° (the horizontal earth "
                                "rate vanishes)")
        if ext is None:
            return
        if not ext.has_truth:
            if cfg.aiding.source in ("odometer", "nav"):
                raise ScenarioError(f"align.aiding.source: {cfg.aiding.source!r} needs a "
                                    "simulated motion (truth); recorded data take 'file' (a "
                                    "velocity, odometer or reference file) or 'none'")
            if cfg.coarse.method == "given":
                raise ScenarioError("align.coarse.method: 'given' needs truth; use 'analytic' "
                                    "or 'inertial' for recorded data")
        window(sc, ext)
        stride(sc, ext)

    def cost(self, inputs: Inputs) -> Cost:
        sc, ext = inputs.scenario, inputs.extent
        if config(sc, "align").mode == "transfer":
            from gcalign.app.align import transfer

            return transfer.cost(sc)
        if ext is None:
            return Cost()
        lo, hi = window(sc, ext)
        passes = config(sc, "align").pass_count
        ops = passes * (hi - lo) * GYROCOMPASS_OPS + (0 if ext.recorded else hi * SIMULATE_OPS)
        return Cost(samples=float(hi), memory_bytes=(hi - lo) * HELD_DOUBLES * DOUBLE,
                    output_bytes=passes * (hi - lo) / stride(sc, ext) * ROW_DOUBLES * DOUBLE,
                    work=ops, work_what="passes × samples × a gyrocompass step",
                    memory_what="the alignment window")

    def components(self, metric: str, k: int) -> list[str]:
        """Attitude triples are pitch, roll, yaw."""
        if k == 3 and metric.endswith("_deg"):
            return ["pitch", "roll", "yaw"]
        return [str(i) for i in range(k)]

    def label(self, metric: str) -> str:
        """One component of an attitude triple by its name (``error_t3_deg.2`` ->
        ``error_t3_deg yaw``)."""
        head, _, tail = metric.rpartition(".")
        if head.endswith("_deg") and tail in ("0", "1", "2"):
            return f"{head} {self.components(head, 3)[int(tail)]}"
        return metric

    def warm_up(self) -> None:
        """A tiny run alone and two seeds in lockstep (a batch worker's two routes)."""
        self.execute(warm_scenario(WARM_SCENARIO), 1)
        from gcalign.app.align.run import summaries_of_seeds

        summaries_of_seeds(warm_scenario(WARM_SCENARIO), [1, 2], None)


COMMAND = Align()
