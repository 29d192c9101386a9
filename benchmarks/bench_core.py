"""Benchmark of the navigation core (DESIGN.md "Performance"; core issue, must-show 6).

Every row is the median of ≥ 5 runs after a warm-up call; contenders that are compared are
interleaved in the same loop (ours, theirs, ours, theirs, …) so that a busy machine slows
both alike. CPU rows use process (or child) CPU time, user + system.

* strapdown kernel against pyins 1.0's numba kernel on the same 2 M samples (the seed 000
  swing, tiled; |Δθ| > 1e-4 rad so every step takes the exact rotation-vector branch), each
  in its own frames (pyins: NED, FRD, rotation-compensated Δv as ``tests/pyins_ref.py``
  feeds it), outputs preallocated. Target: ours ≥ 3× pyins.
* gyrocompass steps/s on the seed's own §5.3 data (the default ``gcalign align`` scenario:
  simulated moving base with its sensor errors, 5 passes over [10, 300] s), the passes
  alone. Target ≥ 5 M steps/s.
* ideal IMU generation: the NumPy route (400 s moving base) and the numba route (1 h on the
  seed-004 12-step mechanism), samples/s.
* ``gcalign align`` (the built-in scenario) as a subprocess with a warm JIT cache: CPU time
  of the child, and whether ``gcalign validate`` / ``gcalign show`` load numba (they must
  not). Target ≤ 1.0 s CPU.

Run: ``python benchmarks/bench_core.py`` (after one ``gcalign align``, so the cache is warm).
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # tests/pyins_ref.py: pyins in our conventions

import kernels_prev  # noqa: E402  (tests/: the kernels before their state moved to locals)
from numba import njit  # noqa: E402

from gcalign.app.data import scenario_stream  # noqa: E402
from gcalign.io.scenario import load_scenario, parse_scenario  # noqa: E402
from gcalign.nav import _kernels as K  # noqa: E402
from gcalign.nav.earth import WGS84  # noqa: E402
from gcalign.nav.rotation import euler_to_quat, quat_to_dcm  # noqa: E402
from gcalign.sim.imu import ideal_imu  # noqa: E402
from gcalign.sim.motions import Swing  # noqa: E402
from gcalign.units import DEG  # noqa: E402

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TS = 0.01
SITE = np.array([45.7796 * DEG, 126.6705 * DEG, 0.0])
N = 20_000 if SMOKE else 2_000_000
RUNS = 1 if SMOKE else 7


def cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def interleaved(fns: dict, runs: int = RUNS) -> dict:
    """Median CPU time (user + system, s) of each function, called in turn `runs` times
    after a warm-up (CPU, not wall: the machine is shared)."""
    for f in fns.values():
        f()
    times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(runs):
        for k, f in fns.items():
            t0 = cpu()
            f()
            times[k].append(cpu() - t0)
    return {k: statistics.median(v) for k, v in times.items()}


@njit(cache=True)
def locals_floor(s, dtheta, dv, ts, earth_sign, E, vertical, h_ref, out):
    """The same strapdown steps with the state in local variables and nothing else: every
    row written, a constant reference height, no stride (the bound the kernel can reach)."""
    x = (s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8], s[9], s[10])
    for k in range(dtheta.shape[0]):
        x = K.strapdown_step(x, dtheta, dv, k, ts, earth_sign, E, vertical, h_ref)
        (out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4], out[k, 5], out[k, 6],
         out[k, 7], out[k, 8], out[k, 9], out[k, 10]) = x


def strapdown_vs_pyins() -> dict:
    motion = Swing((0.0, 0.0, 30 * DEG), 400.0, (2 * DEG, 3 * DEG, 4 * DEG), (10.0, 10.0, 20.0))
    truth, imu = ideal_imu(motion, SITE, TS)
    reps = -(-N // len(imu))
    dtheta = np.ascontiguousarray(np.tile(imu.dtheta, (reps, 1))[:N])
    dv = np.ascontiguousarray(np.tile(imu.dv, (reps, 1))[:N])
    q0 = euler_to_quat(truth.att[0])
    s0 = np.zeros(K.NAV_STATE)
    s0[K.Q], s0[K.V], s0[K.P] = q0, truth.v_n[0], truth.pos[0]
    out = np.empty((N, K.NAV_STATE))
    E, vert, href = WGS84.params(), np.zeros(4), np.zeros(1)

    def ours():
        K.strapdown_block(s0.copy(), dtheta, dv, TS, 1.0, E, vert, href, 1, out)

    def floor():
        locals_floor(s0.copy(), dtheta, dv, TS, 1.0, E, vert, 0.0, out)

    def before():
        kernels_prev.strapdown_block(s0.copy(), dtheta, dv, TS, 1.0, E, vert, href, 1, out)

    fns = {"ours": ours, "floor": floor, "before": before}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            import pyins_ref as pr
            from pyins._numba_integrate import integrate as pyins_kernel
        except ImportError:
            pr = None
    if pr is not None:
        theta_p = np.ascontiguousarray(pr.vec_to_pyins(dtheta))
        dv_p = np.ascontiguousarray(pr.vec_to_pyins(dv + 0.5 * np.cross(dtheta, dv)))
        dt = np.full(N, TS)
        lla, vel, mats = np.empty((N + 1, 3)), np.empty((N + 1, 3)), np.empty((N + 1, 3, 3))

        def pyins():
            lla[0] = pr.lla_to_pyins(truth.pos[0])
            vel[0] = pr.vec_to_pyins(truth.v_n[0])
            mats[0] = pr.dcm_to_pyins(quat_to_dcm(q0))
            pyins_kernel(dt, lla, vel, mats, theta_p, dv_p, 0, True)

        fns["pyins"] = pyins
    return interleaved(fns)


def gyrocompass_on_seed_data() -> tuple[float, int]:
    """CPU time of the passes of the built-in §5.3 alignment (its 5 passes over the stored
    block), through the core's array route; the data are collected once."""
    import statistics

    import yaml

    from gcalign.align.gyrocompass import align, timeline, truth_samples
    from gcalign.app.align.run import AlignConfig, collect, settings_of
    from gcalign.cli.common import builtin_text

    sc = parse_scenario(yaml.safe_load(builtin_text("seed000_moving_full_cycle.yaml")))
    cfg = sc.align or AlignConfig()
    stream = scenario_stream(sc)
    settings = settings_of(cfg, "moving")
    tl = timeline(settings, stream.ts, stream.samples)
    data = collect(stream, tl, cfg.aiding, keep=truth_samples(settings, stream.ts,
                                                              stream.samples))

    def run():
        return align(data.dtheta, data.dv, stream.ts, stream.site, settings,
                     earth=stream.earth, position_t1=data.pos_t1, vref=data.vref,
                     vref_body=cfg.aiding.body, truth_att=data.truth, t0=stream.t0,
                     first_sample=tl.lo, samples=stream.samples).compute_s

    run()  # warm-up
    t = statistics.median(run() for _ in range(RUNS))
    return t, cfg.pass_count * (tl.i2 - tl.i1)


def ideal_rates() -> dict:
    moving, _ = load_scenario(ROOT / "configs/seed000_moving_full_cycle.yaml")
    mech = parse_scenario({
        "name": "mech", "earth": "seed004", "site": {"lat_deg": 45.7796, "lon_deg": 126.6705},
        "motion": {"kind": "static", "duration_s": 3600},
        "mechanism": {"reference": "navigation", "steps": [
            {"axis": a, "profile": "trapezoid", "angle_deg": 180 * (1 if i < 6 else -1),
             "accel_s": 4, "const_s": 4, "decel_s": 4, "dwell_s": 300}
            for i, a in enumerate("zxyyxzzxyyxz")]}})

    def run(sc):
        return lambda: sum(len(b.t) for b in scenario_stream(sc).blocks())

    t = interleaved({"moving": run(moving), "mechanism": run(mech)}, runs=min(RUNS, 5))
    return {"moving": 40000 / t["moving"], "mechanism": 360000 / t["mechanism"]}


def read_lasergyro_s() -> float:
    """Median wall time of reading the real recording (tests/data, 1 h at 100 Hz)."""
    import lzma

    from gcalign.io.imu_files import read_imu_file

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "lasergyro.imu"
        path.write_bytes(lzma.decompress((ROOT / "tests/data/lasergyro.imu.xz").read_bytes()))
        read_imu_file(path)
        times = []
        for _ in range(min(RUNS, 5)):
            t0 = time.perf_counter()
            read_imu_file(path)
            times.append(time.perf_counter() - t0)
    return statistics.median(times)


def cli_cpu(args: list[str], cwd: Path) -> float:
    before = child_cpu()
    subprocess.run([sys.executable, "-c", "from gcalign.cli import main; main()", *args], cwd=cwd,
                   check=True,
                   capture_output=True, env=dict(os.environ, TERM="dumb"))
    return child_cpu() - before


def loads_numba(args: list[str], cwd: Path) -> bool:
    code = ("import sys, json\nfrom typer.testing import CliRunner\nfrom gcalign.cli import app\n"
            f"r = CliRunner().invoke(app, {args!r})\nassert r.exit_code == 0, r.output\n"
            "print(json.dumps('numba' in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    print(f"gcalign core benchmark: python {sys.version.split()[0]}, numpy {np.__version__}, "
          f"{os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}; medians of {RUNS}")
    rows = []
    t = strapdown_vs_pyins()
    rows.append((f"strapdown kernel, {N / 1e6:g} M steps (CPU)",
                 f"{N / t['ours'] / 1e6:.2f} M steps/s", ""))
    rows.append(("  state in an array, stride tested (before)",
                 f"{N / t['before'] / 1e6:.2f} M steps/s", ""))
    rows.append(("  same math, state in locals, nothing else",
                 f"{N / t['floor'] / 1e6:.2f} M steps/s", ""))
    rows.append(("  ours / locals", f"{t['floor'] / t['ours']:.2f}", "≥ 0.9"))
    if "pyins" in t:
        rows.append(("pyins 1.0 numba kernel, same data", f"{N / t['pyins'] / 1e6:.2f} M steps/s",
                     ""))
        rows.append(("  ours / pyins", f"{t['pyins'] / t['ours']:.2f} ×", "≥ 3.5"))
        rows.append(("  before / pyins", f"{t['pyins'] / t['before']:.2f} ×", ""))
    tg, steps = gyrocompass_on_seed_data()
    rows.append(("gyrocompass on the §5.3 data (5 passes)",
                 f"{steps / tg / 1e6:.2f} M steps/s ({tg * 1e3:.1f} ms)", "≥ 5; ≤ 50 ms"))
    r = ideal_rates()
    rows.append(("ideal IMU, NumPy route (moving base)", f"{r['moving'] / 1e6:.2f} M samples/s",
                 ""))
    rows.append(("ideal IMU, numba route (12-step mechanism)",
                 f"{r['mechanism'] / 1e6:.2f} M samples/s", ""))
    rows.append(("read lasergyro.imu (wall)", f"{read_lasergyro_s():.2f} s", "≤ 1.0"))
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "a.h5"
        cli_cpu(["align", "-o", str(out)], ROOT)  # warm the caches
        cpus = [cli_cpu(["align", "-o", str(out)], ROOT) for _ in range(min(RUNS, 5))]
        rows.append(("gcalign align (built-in), child CPU", f"{statistics.median(cpus):.2f} s",
                     "≤ 1.0"))
        v = loads_numba(["validate", "configs/seed000_moving_full_cycle.yaml"], ROOT)
        s = loads_numba(["show", str(out)], ROOT)
        rows.append(("validate / show import numba", f"{v} / {s}", "False / False"))
    width = max(len(a) for a, _, _ in rows)
    for a, b, c in rows:
        print(f"  {a:<{width}}  {b:>28}  {('target ' + c) if c else ''}")


if __name__ == "__main__":
    main()
