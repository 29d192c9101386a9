"""Benchmark of `gcalign realtime`: the seed's full Table 1 (must-show 6).

Twelve cases of 12 s each at 5 kHz (60 000 samples of the gyro triad, 12 000 attitude
solutions and pulses per case), the default noise model, three predictors (none, taylor,
kalman-ls), both error metrics. Rows, each the median of 7 warm runs (after a warm-up call
that loads the numba cache), contenders interleaved:

* ``core``: :func:`gcalign.realtime.table1` + ``summarise`` (the chain on the core);
* ``ideal_blocks``: the core's ideal increments alone for the same 12 cases (its share);
* ``command``: what ``gcalign realtime`` does in-process — the built-in scenario (the 12
  cases and the 13th asynchronous one) through the command's ``execute``, the results file
  written (per-pulse arrays, compressed) and the table rendered;
* ``CLI``: ``gcalign realtime`` as a new process (median of 3; imports and cache loads).

Target: ≤ 5 s warm end to end. Run: ``python benchmarks/bench_realtime.py``
"""

from __future__ import annotations

import io
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml
from rich.console import Console

from gcalign.app.realtime import COMMAND
from gcalign.cli.common import builtin_text
from gcalign.io import results
from gcalign.io.scenario import parse_scenario
from gcalign.realtime import TABLE1, Settings, summarise, table1
from gcalign.realtime.chain import SITE
from gcalign.sim.ideal import ideal_blocks

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TARGET_S = 5.0
RUNS = 1 if SMOKE else 7


def _core(settings: Settings, seed: int) -> None:
    rows = [summarise(r) for r in table1(settings, np.random.default_rng(seed))]
    assert len(rows) == len(TABLE1)


def _ideal() -> None:
    for c in TABLE1:
        for _ in ideal_blocks(c.motion(), np.asarray(SITE), 2e-4, block=5000):
            pass


def _command(sc, out: Path) -> None:
    with results.atomic_h5(out) as f:
        outcome = COMMAND.execute(sc, None)
        results.write_header(f, "realtime", "", outcome.seed, outcome.summary)
        outcome.write(f)
    Console(file=io.StringIO(), width=160).print(COMMAND.table(outcome.summary))


def main() -> None:
    s = Settings()
    sc = parse_scenario(yaml.safe_load(builtin_text("seed003_table1.yaml")), "built-in")
    tmp = Path(tempfile.mkdtemp())
    out = tmp / "rt.h5"
    _core(s, 0)  # warm-up: numba cache, scipy imports
    _command(sc, out)
    times: dict[str, list[float]] = {"core": [], "ideal_blocks": [], "command": []}
    for k in range(RUNS):
        for name in times:
            t0 = time.perf_counter()
            if name == "core":
                _core(s, k + 1)
            elif name == "ideal_blocks":
                _ideal()
            else:
                _command(sc, out)
            times[name].append(time.perf_counter() - t0)
    cli = []
    for _ in range(1 if SMOKE else 3):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "from gcalign.cli import main; main()",
                        "realtime", "-o", str(out)], check=True, capture_output=True)
        cli.append(time.perf_counter() - t0)
    times["CLI"] = cli
    size = out.stat().st_size / 1e6
    print("gcalign realtime benchmark: seed 003 Table 1, 12 cases × 12 s at 5 kHz, "
          "3 predictors (command: + the 13th case, HDF5, table)")
    print(f"{'row':>14}{'runs':>6}{'median [s]':>12}{'min [s]':>10}{'max [s]':>10}"
          f"{'time/target':>13}")
    for name, v in times.items():
        med = statistics.median(v)
        print(f"{name:>14}{len(v):>6}{med:>12.3f}{min(v):>10.3f}{max(v):>10.3f}"
              f"{med / TARGET_S:>13.2f}")
    share = statistics.median(times["ideal_blocks"]) / statistics.median(times["core"])
    print(f"ideal_blocks share of the core: {share:.0%}; results file {size:.1f} MB")


if __name__ == "__main__":
    main()
