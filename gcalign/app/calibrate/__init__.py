"""`gcalign calibrate`: in-flight calibration of an airborne SINS (seed 002)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gcalign.app.command import (
    DOUBLE,
    KALMAN_OPS,
    SIMULATE_OPS,
    STRAPDOWN_OPS,
    Command,
    Cost,
    Extent,
    Inputs,
    Options,
    Outcome,
    config,
    warm_scenario,
)

SIMULATION_DOUBLES = 24  #: per IMU sample of the noise-free simulation held (truth + IMU)
RECORDED_DOUBLES = 7  #: per sample of recorded data (t, increments)
STEP_DOUBLES = 16  #: per navigation step of the flight data (increments, truth)
EPOCH_DOUBLES = 100  #: per filter epoch: estimate, σ, truth, error, state, NIS, NEES
ROW_DOUBLES = 23  #: per stored navigation row: t, t_run, att, v_n, pos and their errors
SMOOTHER_DOUBLES = 2 * 21 * 21  #: per epoch kept for the smoother: P and Φ

WARM_SCENARIO = {  # a tiny flight: every kernel of a calibration, in milliseconds
    "name": "warm-up",
    "site": {"lat_deg": 38.0, "lon_deg": 121.0},
    "imu": {"rate_hz": 20},
    "motion": {"kind": "flight", "segments": [
        {"kind": "hold", "duration_s": 1}, {"kind": "accelerate", "accel_mps2": 2,
                                            "speed_mps": 4}]},
    "calibrate": {"navigation_rate_hz": 10, "filter_rate_hz": 1},
}


def steps(sc, ext: Extent | None) -> tuple[float, float, float]:
    """(IMU samples, navigation steps, filter epochs) of the calibration window."""
    cfg = config(sc, "calibrate")
    if ext is None:
        return 0.0, 0.0, 0.0
    rate = 1.0 / ext.ts
    duration = ext.samples * ext.ts
    try:
        _, coarse_end, end = cfg.window(duration, ext.ts)
        nav = (end - coarse_end) * rate / cfg.subsamples(rate)
        epochs = nav / cfg.steps_per_update(rate)
    except Exception:  # noqa: BLE001 - the check names what does not fit; the cost is rough
        nav, epochs = float(ext.samples), float(ext.samples)
    return float(ext.samples), nav, epochs


class Calibrate(Command):
    name = "calibrate"
    help = "In-flight calibration, 21-state Kalman filter (seed 002)."
    section = "calibrate"
    builtin = "seed002_designed.yaml"
    options = Options(recorded=True, streams=True,
                      batch_metrics=("nees.final", "normalized_error"))

    def runner(self) -> Callable[..., Outcome]:
        from gcalign.app.calibrate.run import execute

        return execute

    def table(self, summary: dict[str, Any]) -> Any:
        from gcalign.app.calibrate.tables import calibrate_table

        return calibrate_table(summary)

    def figures(self, f: Any, name: str) -> dict[str, Any]:
        from gcalign.app.calibrate.plots import figures

        return figures(f, name)

    def cost(self, inputs: Inputs) -> Cost:
        """The simulation (or the recorded data) held whole, the flight at the navigation
        rate, the filter's epochs (and the smoother's P and Φ per epoch)."""
        sc, ext = inputs.scenario, inputs.extent
        n, nav, epochs = steps(sc, ext)
        cfg = config(sc, "calibrate")
        recorded = ext is not None and ext.recorded
        per_epoch = EPOCH_DOUBLES + (SMOOTHER_DOUBLES if cfg.smoother else 0)
        memory = n * (RECORDED_DOUBLES if recorded else SIMULATION_DOUBLES) + (
            nav * STEP_DOUBLES + epochs * per_epoch)
        work = (0.0 if recorded else n * SIMULATE_OPS) + nav * STRAPDOWN_OPS + (
            epochs * KALMAN_OPS * (2 if cfg.smoother else 1))
        rows = nav / max(1, cfg.output_stride(1.0 / ext.ts / cfg.subsamples(1.0 / ext.ts))
                         if ext is not None else 1)
        return Cost(samples=n, memory_bytes=memory * DOUBLE,
                    output_bytes=(epochs * EPOCH_DOUBLES + rows * ROW_DOUBLES) * DOUBLE,
                    work=work,
                    work_what="navigation steps and 21-state filter epochs",
                    memory_what="the simulation and the filter's epochs")

    def components(self, metric: str, k: int) -> list[str]:
        """Names of a batch metric's components: 21-vectors are the states."""
        from gcalign.estimation.ins_error import STATE_NAMES

        if k == len(STATE_NAMES):
            return list(STATE_NAMES)
        return [str(i) for i in range(k)]

    def warm_up(self) -> None:
        self.execute(warm_scenario(WARM_SCENARIO), 1)


COMMAND = Calibrate()
