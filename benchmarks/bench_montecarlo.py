"""CPU per run of the seed 000 §5.3 Monte Carlo inside ``gcalign batch``, against the
passes-only floor; optionally against another checkout, interleaved.

One run of a batch, exactly as a pool worker executes it (``warm_up`` as the worker's
initializer does, then ``run_task``: the scenario, the sensor errors on the shared
noise-free simulation, coarse alignment, the 5 passes over [10, 300] s, the T2 → T3
compensation, the summary and the metrics), timed in CPU (user + system) per run over
consecutive seeds after a warm-up, one run after another as in a worker; then the floor of
each: the passes alone on the same block (``run_passes``, its data prepared beforehand).
Target: ≤ 25 ms CPU a run. Then the same seeds as a batch worker runs them, in chunks of 16
(``run_chunk``: the seeds of a variant in lockstep where the tree has it), CPU per run,
each chunk's metrics checked equal to the same seeds run one by one. Target ≤ 12 ms.

``--before DIR`` runs the same seeds in a second process on the checkout DIR (e.g. a
``git worktree`` of main), seed by seed in turn with this one (before, after, before, …),
so that both see the same load; each side times its own runs.

Run: ``python benchmarks/bench_montecarlo.py [--seeds 40] [--before DIR]``
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import sys
import tempfile
from importlib import resources
from pathlib import Path

from _child import Child

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TARGET_RUN_MS = 25.0
TARGET_CHUNK_MS = 12.0
CHUNK = 16  #: runs a worker takes at a time (gcalign.app.batch.engine.CHUNK_MAX)
HERE = Path(__file__).resolve()


def usage() -> tuple[float, float, int]:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime, r.ru_stime, r.ru_minflt


class Runs:
    """The sweep's tasks in this process, and a run of one seed with its floor."""

    def __init__(self, seeds: int):
        from gcalign.app.batch import runs as B
        from gcalign.app.batch.engine import _tasks
        from gcalign.app.batch.sweep import load_sweep

        self.B = B
        base = resources.files("gcalign.scenarios").joinpath("seed000_moving_full_cycle.yaml")
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "mc.yaml"
            path.write_text(f"name: mc\nbase: {Path(str(base)).resolve()}\nseeds: {seeds + 1}\n"
                            "metrics: [error_t3_deg, error_t2_deg]\n", encoding="utf-8")
            sweep = load_sweep(path)
        self.tasks = _tasks(sweep, sweep.run_keys())
        B.warm_up("align")  # what a worker's initializer does
        rec = B.run_task(self.tasks[0])  # warm-up: JIT cache, imports, the simulation
        assert rec["status"] == "ok", rec
        B.run_chunk(self.tasks[:2])  # and the chunk's kernels, if another

    def passes_of(self, task: dict):
        """The floor of a run: its passes on its block (the block prepared beforehand)."""
        import numpy as np

        from gcalign.align import kernel as AK
        from gcalign.align.cycles import Block, run_passes
        from gcalign.align.gyrocompass import timeline
        from gcalign.app.align.run import AlignConfig, collect, settings_of
        from gcalign.app.data import scenario_data, stream_of
        from gcalign.nav.rotation import euler_to_quat

        sc = self.B._scenario(task)
        cfg = sc.align or AlignConfig()
        stream = stream_of(scenario_data(sc, task["seed"], self.B.noise_free_key(sc)))
        settings = settings_of(cfg, sc.motion.kind if sc.motion else None)
        tl = timeline(settings, stream.ts, stream.samples)
        w = collect(stream, tl, cfg.aiding)
        i, j = tl.i1 - tl.lo, tl.i2 - tl.lo
        rows = (w.dtheta[i:j], w.dv[i:j], w.vref[i:j + 1], False, stream.ts)
        if "first" in Block.__dataclass_fields__:  # no array of times
            block = Block(tl.i1, 0.0, *rows)
        else:  # a checkout whose blocks carry their times
            block = Block(np.arange(tl.i1, tl.i2 + 1) * stream.ts, *rows)
        truth = w.truth.att if hasattr(w, "truth") else w.truth_att
        state0 = AK.new_state(euler_to_quat(truth[i]), w.vref[i], w.pos_t1)
        return lambda: run_passes(state0, block, settings.mode, settings.pass_count,
                                  list(settings.stages), settings.azimuth_poles,
                                  settings.level_phase_s, stream.earth)

    def run(self, k: int) -> dict:
        """Seed k's run: CPU ms, system ms, page faults, its error at T3."""
        u0, s0, f0 = usage()
        rec = self.B.run_task(self.tasks[k])
        u1, s1, f1 = usage()
        assert rec["status"] == "ok", rec
        return {"run": (u1 - u0 + s1 - s0) * 1e3, "sys": (s1 - s0) * 1e3, "faults": f1 - f0,
                "error_t3": rec["metrics"]["error_t3_deg"]}

    def chunk(self, k: int) -> dict:
        """Seeds k .. k+CHUNK-1 as one worker chunk: CPU ms per run, their metrics."""
        u0, s0, _ = usage()
        recs = self.B.run_chunk(self.tasks[k:k + CHUNK])
        u1, s1, _ = usage()
        assert all(r["status"] == "ok" for r in recs), recs
        return {"per_run": (u1 - u0 + s1 - s0) * 1e3 / len(recs),
                "metrics": [r["metrics"] for r in recs]}

    def floor(self, k: int) -> dict:
        """Seed k's passes alone (its block prepared beforehand): CPU ms."""
        if not hasattr(self, "floors"):
            self.floors = [self.passes_of(t) for t in self.tasks]
        u0, s0, _ = usage()
        self.floors[k]()
        u1, s1, _ = usage()
        return {"floor": (u1 - u0 + s1 - s0) * 1e3}


def serve(seeds: int) -> None:
    """Child mode: read "run K" or "floor K" on stdin, answer one JSON line each."""
    runs = Runs(seeds)
    print("ready", flush=True)
    for line in sys.stdin:
        what, k = line.split()
        fn = {"run": runs.run, "floor": runs.floor, "chunk": runs.chunk}[what]
        print(json.dumps(fn(int(k))), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3 if SMOKE else 80)
    ap.add_argument("--before", type=Path, help="another checkout, run interleaved")
    ap.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.serve:
        serve(args.seeds)
        return
    sides = {"after": Child(HERE, HERE.parents[1], args.seeds)}
    if args.before is not None:
        sides = {"before": Child(HERE, args.before.resolve(), args.seeds), **sides}
    # the runs one after another, as a worker runs them (nothing else allocating between),
    # then the floors; each seed on both sides in turn
    res: dict[str, list[dict]] = {k: [] for k in sides}
    for k in range(1, args.seeds + 1):
        for name, child in sides.items():
            res[name].append(child.ask("run", k))
    for k in range(1, args.seeds + 1):
        for name, child in sides.items():
            res[name][k - 1].update(child.ask("floor", k))
    chunks: dict[str, list[dict]] = {k: [] for k in sides}
    singles_of = {name: {k + 1: r["error_t3"] for k, r in enumerate(rs)}
                  for name, rs in res.items()}
    for k in range(1, args.seeds + 1, CHUNK):
        for name, child in sides.items():
            chunks[name].append(child.ask("chunk", k) | {"first": k})
    for child in sides.values():
        child.close()
    chunk_same = all(m["error_t3_deg"] == singles_of[name][c["first"] + i]
                     for name, cs in chunks.items() for c in cs
                     for i, m in enumerate(c["metrics"]))
    if "before" in res:  # the same seeds: the same numbers (the change keeps the results)
        same = all(a["error_t3"] == b["error_t3"]
                   for a, b in zip(res["before"], res["after"], strict=True))
    print(f"§5.3 Monte Carlo run inside gcalign batch, {args.seeds} seeds, CPU per run "
          f"(medians; load {os.getloadavg()[0]:.1f}, {os.cpu_count()} CPUs, python "
          f"{sys.version.split()[0]}):")

    def med(name: str, key: str) -> float:
        return statistics.median(r[key] for r in res[name])

    width = max(len(n) for n in res)
    for name in res:
        run, flo = med(name, "run"), med(name, "floor")
        print(f"  {name:<{width}}  one run {run:6.1f} ms (system {med(name, 'sys'):4.1f} ms, "
              f"{med(name, 'faults'):5.0f} page faults)   passes alone {flo:5.1f} ms   "
              f"run / passes {run / flo:4.2f}")
    for name, cs in chunks.items():
        per = statistics.median(c["per_run"] for c in cs)
        print(f"  {name:<{width}}  in chunks of {CHUNK} (as a batch worker runs them): "
              f"{per:6.1f} ms a run (median of {len(cs)} chunks)")
    per = statistics.median(c["per_run"] for c in chunks["after"])
    print(f"  target: a run in a chunk ≤ {TARGET_CHUNK_MS:g} ms: "
          f"{'OK' if per <= TARGET_CHUNK_MS else 'MISSED'}; each chunk's error at T3 that of "
          f"the same seed run alone: {'yes' if chunk_same else 'NO'}")
    run = med("after", "run")
    print(f"  target: one run ≤ {TARGET_RUN_MS:g} ms: {'OK' if run <= TARGET_RUN_MS else 'MISSED'}"
          + ("" if "before" not in res else
             f"; error at T3 the same in every run: {'yes' if same else 'NO'}"))


if __name__ == "__main__":
    main()
