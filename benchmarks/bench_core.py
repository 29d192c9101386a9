"""Benchmark of the navigation core: strapdown kernel, pyins side by side, IMU generation,
and `gcalign simulate` end to end (DESIGN.md "Performance").

Rows (every timing after a warm-up call, so JIT compilation or cache loading is excluded
except where the row says it is included):

* strapdown kernel: ``kernels.strapdown_block`` on 2 M samples (the seed 000 swing,
  400 s, tiled 50 times: |Δθ| > 1e-4 rad, so every step takes the exact rotation-vector
  branch), outputs preallocated; best of 5. Target ≥ 5 M steps/s on one core.
* ``strapdown.navigate`` on the same data: the public function (allocation included).
* pyins 1.0 numba kernel (``pyins._numba_integrate.integrate``) on the same data in its
  frames (NED, FRD; rotation-compensated Δv as ``tests/pyins_ref.py`` feeds it),
  preallocated; best of 3. And pyins's public path (``tests/pyins_ref.pyins_integrate``:
  pandas DataFrames + ``Integrator``) on the 400 s moving scenario.
* ``imu.ideal_imu``: truth + ideal increments of the seed 000 moving base, 400 s at
  100 Hz; best of 5. Target ≤ 0.15 s. And with the error model applied (``apply_errors``).
* ``gcalign simulate`` of the seed 000 moving scenario (with IMU errors) as a subprocess:
  interpreter start, imports, simulation, HDF5 written to a temp dir; one warm-up run
  fills the JIT/OS caches, then best of 3. Target ≤ 3 s.

``margin`` is how many times better than its target a row is (rate/target for rates,
target/time for times): ≥ 1 meets the target. All kernels are single-threaded, so the
numbers do not depend on NUMBA_NUM_THREADS.

Run: ``python benchmarks/bench_core.py``
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from gcalign.nav._kernels import empty_states, strapdown_block
from gcalign.nav.rotation import euler_to_quat, quat_to_dcm
from gcalign.nav.strapdown import NavState, navigate
from gcalign.sim.imu import ImuErrors, SensorErrors, apply_errors, ideal_imu
from gcalign.sim.motions import Moving, Segment, Swing
from gcalign.units import DEG, DPH, DPSH, UG, UGPSHZ

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # tests/pyins_ref.py: pyins in our conventions

TS = 0.01
SITE = np.array([45.7796 * DEG, 126.6705 * DEG, 0.0])
TARGET_STEPS = 5e6  # strapdown steps/s on one core
TARGET_IMU_S = 0.15  # truth + IMU, 400 s moving at 100 Hz
TARGET_E2E_S = 3.0  # gcalign simulate, wall time incl. interpreter start
N_STEPS = 2_000_000

SCENARIO_YAML = """\
# Seed 000 §5.3 moving base (bench_core.py end-to-end row).
name: bench-moving
site: {lat_deg: 45.7796, lon_deg: 126.6705, height_m: 0}
imu:
  rate_hz: 100
  seed: 1
  gyro:  {bias_dph: [0.01, 0.01, 0.01], arw_dprh: 0.001}
  accel: {bias_ug: [50, 50, 50], vrw_ugrhz: 10}
motion:
  kind: moving
  attitude_deg: [0, 0, 30]
  duration_s: 400
  segments:
    - {duration_s: 10}
    - {duration_s: 10, accel_mps2: 1.0}
    - {duration_s: 10, rate_dps: [0, 0, -1]}
    - {duration_s: 10, rate_dps: [0, 0, 1]}
    - {duration_s: 280}
    - {duration_s: 10, rate_dps: [0, 0, -1]}
    - {duration_s: 10}
"""


def moving_motion() -> Moving:
    right, left = (0.0, 0.0, -DEG), (0.0, 0.0, DEG)
    segments = (
        Segment(10.0),
        Segment(10.0, 1.0),
        Segment(10.0, rate=right),
        Segment(10.0, rate=left),
        Segment(280.0),
        Segment(10.0, rate=right),
        Segment(10.0),
    )
    return Moving((0.0, 0.0, 30.0 * DEG), 400.0, segments)


def swing_motion() -> Swing:
    return Swing((0.0, 0.0, 30.0 * DEG),
        400.0,
        amplitude=(2 * DEG, 3 * DEG, 4 * DEG),
        period=(10.0, 10.0, 20.0),
    )


def best_of(fn, repeat: int) -> float:
    """Best wall time (s) of `repeat` calls of fn(), after one warm-up call."""
    fn()
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def bench_strapdown(dtheta, dv, start: NavState):
    q, v, p = empty_states(len(dtheta))
    q0, v0, p0 = (np.asarray(x, float) for x in (start.q_nb, start.v_n, start.pos))

    def kernel():
        strapdown_block(q0, v0, p0, dtheta, dv, TS, 1.0, q, v, p)

    t_kernel = best_of(kernel, 5)
    assert np.all(np.isfinite(q[-1])) and np.all(np.isfinite(p[-1]))
    t = TS * np.arange(1, len(dtheta) + 1)
    t_nav = best_of(lambda: navigate(t, dtheta, dv, TS, start), 3)
    return t_kernel, t_nav


def bench_pyins(dtheta, dv, start: NavState, moving_imu, moving_truth):
    """pyins's bare kernel on the same 2 M samples, and its public path on 40 k samples."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import pyins_ref as pr
        from pyins._numba_integrate import integrate as pyins_kernel

    n = len(dtheta)
    theta_p = np.ascontiguousarray(pr.vec_to_pyins(dtheta))
    dv_p = np.ascontiguousarray(pr.vec_to_pyins(dv + 0.5 * np.cross(dtheta, dv)))
    dt = np.full(n, TS)
    lla = np.empty((n + 1, 3))
    vel = np.empty((n + 1, 3))
    mats = np.empty((n + 1, 3, 3))

    def kernel():
        lla[0] = pr.lla_to_pyins(start.pos)
        vel[0] = pr.vec_to_pyins(start.v_n)
        mats[0] = pr.dcm_to_pyins(quat_to_dcm(start.q_nb))
        pyins_kernel(dt, lla, vel, mats, theta_p, dv_p, 0, True)

    t_kernel = best_of(kernel, 3)
    assert np.all(np.isfinite(lla[-1]))

    tr, imu = moving_truth, moving_imu

    def adapter():
        pr.pyins_integrate(
            0.0,
            TS,
            imu.dtheta,
            imu.dv,
            tr.pos[0],
            tr.att[0],
            tr.v_n[0],
            compensation="rotation",
            with_altitude=False,
        )

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t_adapter = best_of(adapter, 3)
    return t_kernel, t_adapter, pr.PYINS_VERSION


def bench_imu():
    motion = moving_motion()
    t_ideal = best_of(lambda: ideal_imu(motion, SITE, TS), 5)
    errors = ImuErrors(
        SensorErrors(bias=np.full(3, 0.01 * DPH), noise=np.full(3, 0.001 * DPSH)),
        SensorErrors(bias=np.full(3, 50 * UG), noise=np.full(3, 10 * UGPSHZ)),
    )

    def with_errors():
        _, ideal = ideal_imu(motion, SITE, TS)
        apply_errors(ideal, errors, np.random.default_rng(1))

    return t_ideal, best_of(with_errors, 5)


def bench_simulate():
    exe = shutil.which("gcalign") or str(Path(sys.executable).with_name("gcalign"))
    with tempfile.TemporaryDirectory(prefix="gcalign-bench-") as tmp:
        scen = Path(tmp) / "moving.yaml"
        scen.write_text(SCENARIO_YAML, encoding="utf-8")
        out = Path(tmp) / "moving.h5"
        cmd = [exe, "simulate", str(scen), "-o", str(out)]
        env = dict(os.environ, TERM="dumb")

        def run():
            r = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
            if r.returncode != 0:
                raise RuntimeError(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr}")

        t0 = time.perf_counter()
        run()  # warm-up: fills the numba cache, byte-code cache, OS file cache
        t_first = time.perf_counter() - t0
        t_best = best_of(run, 3)  # best_of's own warm-up call is a 2nd warm run
        size = out.stat().st_size
    return t_first, t_best, size


def main() -> None:
    t_all = time.perf_counter()
    print(
        f"gcalign core benchmark (python {sys.version.split()[0]}, numpy {np.__version__}, "
        f"{os.cpu_count()} CPUs; single-threaded kernels)"
    )

    # Data: the seed 000 swing, 400 s, tiled to 2 M samples (periodic: 20 swing periods).
    truth_s, imu_s = ideal_imu(swing_motion(), SITE, TS)
    reps = -(-N_STEPS // len(imu_s))
    dtheta = np.ascontiguousarray(np.tile(imu_s.dtheta, (reps, 1))[:N_STEPS])
    dv = np.ascontiguousarray(np.tile(imu_s.dv, (reps, 1))[:N_STEPS])
    start = NavState(euler_to_quat(truth_s.att[0]), truth_s.v_n[0].copy(), truth_s.pos[0].copy())
    truth_m, imu_m = ideal_imu(moving_motion(), SITE, TS)

    t_kernel, t_nav = bench_strapdown(dtheta, dv, start)
    try:
        py_kernel, py_adapter, py_version = bench_pyins(dtheta, dv, start, imu_m, truth_m)
    except ImportError:
        py_kernel = py_adapter = py_version = None
    t_imu, t_imu_err = bench_imu()
    t_first, t_e2e, size = bench_simulate()

    rows = []  # (what, value, unit, target text, margin)
    ours = N_STEPS / t_kernel
    rows.append(
        ("strapdown kernel (2 M steps)", ours / 1e6, "M steps/s", "≥ 5", ours / TARGET_STEPS)
    )
    rows.append(("strapdown.navigate (2 M steps)", N_STEPS / t_nav / 1e6, "M steps/s", "", None))
    if py_kernel is not None:
        theirs = N_STEPS / py_kernel
        rows.append(
            (f"pyins {py_version} numba kernel (same data)", theirs / 1e6, "M samples/s", "", None)
        )
        rows.append(("  ours / pyins (kernel vs kernel)", ours / theirs, "x", "", None))
        rows.append(
            (
                "pyins public path (pandas, 40 k)",
                len(imu_m) / py_adapter / 1e6,
                "M samples/s",
                "",
                None,
            )
        )
        ratio = (N_STEPS / t_nav) / (len(imu_m) / py_adapter)
        rows.append(("  ours navigate / pyins public", ratio, "x", "", None))
    else:
        rows.append(("pyins", float("nan"), "not installed", "", None))
    rows.append(
        ("ideal_imu, moving 400 s @ 100 Hz", t_imu * 1e3, "ms", "≤ 150", TARGET_IMU_S / t_imu)
    )
    rows.append(("  + apply_errors (bias, noise)", t_imu_err * 1e3, "ms", "", None))
    rows.append(("gcalign simulate, end to end (warm)", t_e2e, "s", "≤ 3", TARGET_E2E_S / t_e2e))
    rows.append(("  first run (cold caches)", t_first, "s", "", None))

    w = max(len(r[0]) for r in rows)
    print(f"\n{'':<{w}}  {'value':>10}  {'unit':<12}{'target':>8}  {'margin':>7}")
    for what, value, unit, target, margin in rows:
        m = "" if margin is None else f"{margin:6.2f}{' ' if margin >= 1 else '!'}"
        print(f"{what:<{w}}  {value:>10.3f}  {unit:<12}{target:>8}  {m:>7}")
    print(
        f"\n(margin = rate/target or target/time: ≥ 1 meets the target; '!' misses it. "
        f"HDF5 written: {size / 1e6:.1f} MB. Benchmark wall time "
        f"{time.perf_counter() - t_all:.1f} s)"
    )


if __name__ == "__main__":
    main()
