"""Benchmark of `gcalign modulate` (seed 004, must-show 6).

Rows:

* ``gcalign modulate`` end to end, the built-in case: 72 h at 100 Hz, four schemes (fixed,
  seed-12, four-position-12, dual-16-improved), results file written. A subprocess under
  ``/usr/bin/time -v`` (wall time and peak RSS; interpreter start, imports, JIT cache load,
  simulation, navigation, linear models, HDF5 included). Targets: ≤ 60 s, ≤ 800 MB.
* one 72 h scheme (``--scheme seed-12``), the same way. Target: ≤ 20 s.
* the stages of one 72 h seed-12 scheme in process (after a warm-up): ideal increments
  (``gcalign.sim._kernels.fixed_site_block``), sensor errors, strapdown
  (``Navigator.run``), errors against truth (``_kernels.error_block``), in M samples/s.

The end-to-end rows are interleaved (four schemes, one scheme, four, one, …) and quote the
median of ``--runs`` (default 5) runs; one warm-up run fills the JIT and OS caches first.
All kernels are single-threaded. ``margin`` = target / measured (≥ 1 meets the target).

Run: ``python benchmarks/bench_modulate.py [--runs 5] [--skip-e2e]``
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
HOURS = 0.1 if SMOKE else 72.0  #: of the end-to-end runs and of the stages
TARGET_ALL_S, TARGET_ONE_S, TARGET_RSS_MB = 60.0, 20.0, 800.0


def _gcalign(args: list[str], out: Path) -> tuple[float, float]:
    """Wall time (s) and peak RSS (MB) of one `gcalign` subprocess."""
    cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "gcalign", *args, "-o", str(out),
           "--json"]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True,
                         env=dict(os.environ, NUMBA_NUM_THREADS="1"))
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise RuntimeError(res.stderr[-2000:])
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", res.stderr)
    return wall, (int(rss.group(1)) / 1024 if rss else float("nan"))


def end_to_end(runs: int) -> None:
    cases = {"four schemes (built-in)": [], "one scheme (seed-12)": ["--scheme", "seed-12"]}
    targets = {"four schemes (built-in)": TARGET_ALL_S, "one scheme (seed-12)": TARGET_ONE_S}
    wall: dict[str, list[float]] = {k: [] for k in cases}
    rss: dict[str, list[float]] = {k: [] for k in cases}
    with tempfile.TemporaryDirectory() as tmp:
        _gcalign(["modulate", "--hours", "1"], Path(tmp) / "warm.h5")
        for i in range(runs):
            for name, extra in cases.items():
                w, r = _gcalign(["modulate", *extra, "--hours", str(HOURS)],
                                Path(tmp) / f"{i}.h5")
                wall[name].append(w)
                rss[name].append(r)
    print(f"gcalign modulate end to end, {HOURS:g} h at 100 Hz, median of {runs} (interleaved)")
    print(f"{'case':<26}{'median s':>10}{'min s':>8}{'max s':>8}{'target s':>10}"
          f"{'margin':>8}{'peak RSS MB':>13}{'RSS margin':>12}")
    for name in cases:
        m, r = statistics.median(wall[name]), max(rss[name])
        print(f"{name:<26}{m:>10.1f}{min(wall[name]):>8.1f}{max(wall[name]):>8.1f}"
              f"{targets[name]:>10.0f}{targets[name] / m:>8.2f}{r:>13.0f}"
              f"{TARGET_RSS_MB / r:>12.2f}")


def stage_times(hours: float) -> tuple[int, dict[str, float]]:
    """Samples and seconds per stage of one seed-12 run of `hours` (the streamed run's
    blocks, driven here stage by stage)."""
    import yaml

    from gcalign.app.modulate.run import variant
    from gcalign.cli.common import builtin_text
    from gcalign.io.scenario import parse_scenario
    from gcalign.io.scenario.modulate import plan_of
    from gcalign.nav import _kernels as K
    from gcalign.nav.strapdown import Navigator, NavState, Vertical
    from gcalign.sim.errors import ErrorStream
    from gcalign.sim.ideal import ideal_blocks

    d = yaml.safe_load(builtin_text("seed004_modulation.yaml"))
    d["modulate"] = {"compare": ["seed-12"], "hours": hours}
    sc = parse_scenario(d, "bench")
    plan = plan_of(sc)
    v = variant(sc, plan.entries[0], plan)
    assert v.motion is not None and v.site is not None and v.mechanism is not None
    motion, site, ts = v.motion.to_motion(), v.site.to_si(), v.imu.ts
    earth = v.earth_model
    E = earth.params()
    n = int(round(motion.duration / ts))
    t = dict.fromkeys(("ideal increments", "sensor errors", "strapdown",
                       "errors against truth"), 0.0)
    errs = ErrorStream(v.imu.errors(), ts, np.random.default_rng(1), n)
    nav = Navigator(NavState(np.array([1.0, 0, 0, 0]), np.zeros(3), site), ts, earth,
                    Vertical("hold"))
    acc = np.zeros((9, 3))
    gen = ideal_blocks(motion, site, ts, earth, v.mechanism.to_mechanism(v.motion.attitude_deg))
    while True:
        c0 = time.perf_counter()
        b = next(gen, None)
        t["ideal increments"] += time.perf_counter() - c0
        if b is None:
            return n, t
        c0 = time.perf_counter()
        dth, dv = errs.apply(b.dtheta, b.dv)
        c1 = time.perf_counter()
        states = nav.run(dth, dv)
        c2 = time.perf_counter()
        out = np.empty((len(states) // 1000 + 1, 21))
        K.error_block(states, np.ascontiguousarray(b.q_bs), True, b.att, b.q_nb, b.v_n,
                      b.pos, True, E, site, b.k0, 1000, acc, out)
        c3 = time.perf_counter()
        t["sensor errors"] += c1 - c0
        t["strapdown"] += c2 - c1
        t["errors against truth"] += c3 - c2


def stages(hours: float = HOURS) -> None:
    stage_times(0.05)  # warm-up (JIT cache)
    n, t = stage_times(hours)
    total = sum(t.values())
    print(f"\none scheme (seed-12), {hours:g} h at 100 Hz = {n / 1e6:.1f} M samples, "
          "in process")
    print(f"{'stage':<24}{'s':>8}{'M samples/s':>13}{'share':>8}")
    for k, s in t.items():
        print(f"{k:<24}{s:>8.2f}{n / s / 1e6:>13.2f}{100 * s / total:>7.0f}%")
    print(f"{'total':<24}{total:>8.2f}{n / total / 1e6:>13.2f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=1 if SMOKE else 5)
    ap.add_argument("--skip-e2e", action="store_true", help="only the in-process stages")
    args = ap.parse_args()
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    if not args.skip_e2e:
        end_to_end(args.runs)
    stages()


if __name__ == "__main__":
    main()
