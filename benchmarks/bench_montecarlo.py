"""CPU per run of the seed 000 §5.3 Monte Carlo inside ``gcalign batch``, against the
passes-only floor.

One run of a batch, exactly as a pool worker executes it (``run_task``: the scenario, the
sensor errors on the shared noise-free simulation, coarse alignment, the 5 passes over
[10, 300] s, the T2 → T3 compensation, the summary and the metrics), timed in CPU (user +
system) per run over consecutive seeds after a warm-up; and, interleaved with it, the
floor: the passes alone on the same block (``run_passes``). Target: ≤ 25 ms CPU a run.

Run: ``python benchmarks/bench_montecarlo.py [--seeds 40]``
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import tempfile
from importlib import resources
from pathlib import Path

import numpy as np

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TARGET_RUN_MS = 25.0


def cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main() -> None:
    from gcalign.align import kernel as AK
    from gcalign.align.cycles import Block, run_passes
    from gcalign.align.gyrocompass import timeline
    from gcalign.app import batch as B
    from gcalign.app.align.run import AlignConfig, collect, settings_of
    from gcalign.app.data import scenario_data, stream_of
    from gcalign.nav.rotation import euler_to_quat

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3 if SMOKE else 40)
    seeds = ap.parse_args().seeds
    base = resources.files("gcalign.scenarios").joinpath("seed000_moving_full_cycle.yaml")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "mc.yaml"
        path.write_text(f"name: mc\nbase: {Path(str(base)).resolve()}\nseeds: {seeds + 1}\n"
                        "metrics: [error_t3_deg, error_t2_deg]\n", encoding="utf-8")
        sweep = B.load_sweep(path)
    tasks = B._tasks(sweep, sweep.run_keys())

    def passes_of(task: dict):
        """The floor of a run: its passes on its block (the block prepared beforehand)."""
        sc = B.runs._scenario(task)
        cfg = sc.align or AlignConfig()
        stream = stream_of(scenario_data(sc, task["seed"], B.runs.noise_free_key(sc)))
        settings = settings_of(cfg, sc.motion.kind if sc.motion else None)
        tl = timeline(settings, stream.ts, stream.samples)
        w = collect(stream, tl, cfg.aiding)
        i, j = tl.i1 - tl.lo, tl.i2 - tl.lo
        block = Block(t=np.arange(tl.i1, tl.i2 + 1) * stream.ts, dtheta=w.dtheta[i:j],
                      dv=w.dv[i:j], vref=w.vref[i:j + 1], vref_body=False, ts=stream.ts)
        state0 = AK.new_state(euler_to_quat(w.truth_att[i]), w.vref[i], w.pos_t1)
        return lambda: run_passes(state0, block, settings.mode, settings.pass_count,
                                  list(settings.stages), settings.azimuth_poles,
                                  settings.level_phase_s, stream.earth)

    rec = B.run_task(tasks[0])  # warm-up: JIT cache, imports, the noise-free simulation
    assert rec["status"] == "ok", rec
    floor_fns = [passes_of(t) for t in tasks[1:]]
    runs_ms, floor_ms = [], []
    for task, floor in zip(tasks[1:], floor_fns, strict=True):
        c0 = cpu()
        rec = B.run_task(task)
        c1 = cpu()
        floor()
        c2 = cpu()
        assert rec["status"] == "ok", rec
        runs_ms.append((c1 - c0) * 1e3)
        floor_ms.append((c2 - c1) * 1e3)
    run, flo = statistics.median(runs_ms), statistics.median(floor_ms)
    print(f"§5.3 Monte Carlo run inside gcalign batch, {len(runs_ms)} seeds, CPU per run "
          f"(medians; load {os.getloadavg()[0]:.1f}, {os.cpu_count()} CPUs, python "
          f"{sys.version.split()[0]}):")
    print(f"  one run (run_task)   {run:7.1f} ms   target ≤ {TARGET_RUN_MS:g} ms  "
          f"{'OK' if run <= TARGET_RUN_MS else 'MISSED'}")
    print(f"  the passes alone     {flo:7.1f} ms   (the floor)")
    print(f"  run / floor          {run / flo:7.2f}")


if __name__ == "__main__":
    main()
