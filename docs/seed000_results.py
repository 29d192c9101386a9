"""The seed 000 section of docs/results.md, from the sweeps in configs/sweeps/ run by the
batch engine (the numbers a user gets from ``gcalign batch SWEEP``).

Called by docs/make_results.py; writes docs/results_seed000.md and the headline figure
docs/figures/seed000_tz.png (``gcalign plot`` of the T_z sweep's batch file).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SWEEPS = ROOT / "configs" / "sweeps"
MODES = ("conventional", "full-cycle", "half-cycle")
CASES_TZ = ("ours", "seed-like", "seed-like-10")
T_Z = 280  # the configs' azimuth loop period (chosen from the T_z sweep)
LEVEL_S = 60.0  # the configs' level-first phase (3·T_xy)
LAT = math.radians(45.7796)

# Seed's numbers (deg): errors at T3 [pitch, roll, yaw].
SEED_52 = {"none": [-1.8942, -2.8555, 3.2428], "one-off": [0.0166, 0.0198, -0.0210],
           "continued": [-0.0005, -0.0140, -0.0044]}
SEED_53 = {"conventional": [-0.0044, 0.0018, 0.1845], "full-cycle": [0.0047, 0.0001, -0.0248],
           "half-cycle": [0.0044, 0.0001, -0.0373]}
SEED_62 = {"swing": (0.1349, 0.0038), "moving": (-0.1730, -0.0006)}


@dataclass
class Batch:
    """A sweep and the records of its runs."""

    sweep: object
    records: dict
    output: Path

    def values(self, metric: str, **match) -> np.ndarray:
        """Metric of every seed (rows) of the one variant whose overrides match; keys are
        override keys with '.' written '__' (``align__mode="full-cycle"``)."""
        want = {k.replace("__", "."): v for k, v in match.items()}
        hits = [v for v in self.sweep.variants
                if all(v.overrides.get(k) == x for k, x in want.items())]
        if len(hits) != 1:
            raise KeyError(f"{self.sweep.name}: {want} matches {len(hits)} variants")
        vi = hits[0].index
        rows = [self.records[(vi, s)] for s in self.sweep.seed_values]
        bad = [r for r in rows if r["status"] != "ok"]
        if bad:
            raise RuntimeError(f"{self.sweep.name}: {hits[0].label}: {bad[0]['error']}")
        return np.array([r["metrics"][metric] for r in rows], dtype=float)

    def yaw(self, **match) -> np.ndarray:
        """Yaw error at T3 of every seed (deg)."""
        if "error_t3_deg.2" in self.sweep.metrics:
            return self.values("error_t3_deg.2", **match)
        return self.values("error_t3_deg", **match)[:, 2]


def run(name: str, workers: int, runs_dir: Path, resume: bool) -> Batch:
    """Run configs/sweeps/NAME.yaml with a local pool into RUNS_DIR/<sweep>-batch.h5."""
    from gcalign.app.batch.engine import run_batch
    from gcalign.app.batch.sweep import load_sweep

    sweep = load_sweep(SWEEPS / f"{name}.yaml")
    out = runs_dir / f"{sweep.name}-batch.h5"
    res = run_batch(sweep, out, workers=workers, resume=resume)
    if res.failed:
        raise RuntimeError(f"{name}: {res.failed} run(s) failed: {res.summary['failures'][:1]}")
    return Batch(sweep, res.records, out)


def heading_fraction(t: float, t_z: float, poles: str = "double-oscillator") -> float:
    """Linear compass loop: heading error t s after the loop starts / initial error."""
    from gcalign.align.gains import azimuth_gains, heading_transient
    from gcalign.nav import earth

    g, (r_m, _) = float(earth.gravity(LAT)), earth.radii(LAT)
    return float(heading_transient(t, azimuth_gains(t_z, 0.707, g, r_m, poles), g, r_m))


def med_abs(x: np.ndarray) -> float:
    return float(np.median(np.abs(x)))


def f4(x: float) -> str:
    return f"{x:.4f}"


def stats(e: np.ndarray) -> str:
    """median [5 %, 95 %] of one component over seeds."""
    lo, hi = np.percentile(e, [5, 95])
    return f"{np.median(e):+.4f} [{lo:+.4f}, {hi:+.4f}]"


def seed_txt(v) -> str:
    return ", ".join("—" if x is None else f"{x:+.4f}" for x in v)


def section(workers: int = 2, runs_dir: Path | None = None, resume: bool = False) -> str:
    """The whole seed 000 section (markdown) and the headline figure."""
    runs_dir = Path(runs_dir or ROOT / "runs")
    runs_dir.mkdir(parents=True, exist_ok=True)
    b = {name: run(name, workers, runs_dir, resume) for name in (
        "seed000_tz", "seed000_modes", "seed000_modes_tz100", "seed000_level_phase",
        "seed000_swing", "seed000_first_tz", "seed000_two_stage_swing",
        "seed000_two_stage_moving", "seed000_ideal", "lasergyro_windows")}
    best = best_tz(b["seed000_tz"])
    if best != T_Z:
        print(f"note: the T_z sweep now fits the seed best at {best} s, the configs use {T_Z} s")
    figure(b["seed000_tz"].output, "batch_error_t3_deg_2_vs_t_z_s", "seed000_tz.png")
    figure(b["seed000_modes"].output, "batch_error_t3_deg", "batch_error_t3_deg.png")
    parts = [
        head(b),
        summary_table(b),
        tz_sweep(b["seed000_tz"]),
        modes_table(b["seed000_modes"], b["seed000_tz"]),
        modes_tz100(b["seed000_modes_tz100"]),
        ideal(b["seed000_ideal"]),
        level_phase(b["seed000_level_phase"]),
        swing(b["seed000_swing"]),
        first_tz(b["seed000_first_tz"]),
        two_stage(b["seed000_two_stage_swing"], b["seed000_two_stage_moving"]),
        typos(b["seed000_swing"]),
        real_data(b["lasergyro_windows"]),
    ]
    return "\n".join(p.rstrip() + "\n" for p in parts)


def seed_ratios(tz: Batch, t: float) -> dict[str, float]:
    """Our median |yaw| over the seed's |yaw|, per mode, case ours, at T_z = t."""
    return {mo: med_abs(tz.yaw(case="ours", align__mode=mo, align__stages__0__t_z_s=t))
            / abs(SEED_53[mo][2]) for mo in MODES}


def best_tz(tz: Batch) -> float:
    """The T_z whose worst ratio ours/seed over the three modes is closest to 1."""
    return min(tz.sweep.grid["align.stages.0.t_z_s"],
               key=lambda t: max(abs(math.log(r)) for r in seed_ratios(tz, t).values()))


def figure(batch_file: Path, name: str, png: str) -> None:
    """docs/figures/PNG: figure NAME of a batch file, as `gcalign plot` draws it."""
    from gcalign.app.plots import DPI
    from gcalign.app.readback import figures_for

    figures_for(batch_file)[name].savefig(ROOT / "docs" / "figures" / png, dpi=DPI)


def head(b) -> str:
    n = b["seed000_tz"].sweep.seeds
    return f"""## Gyrocompass alignment (seed 000)

Every number below comes from a sweep in `configs/sweeps/`, run by `gcalign batch` exactly
as a user would: medians (and 5-95 %) over seeds {b["seed000_tz"].sweep.seed_start}-{n}, the
same seeds for every variant, or one run where nothing is random. Each sweep's variants are
the scenarios of the `configs/seed000_*.yaml` files named beside them
(`tests/test_results_configs.py`). Errors are estimate − truth in degrees, yaw wrapped, at
T3 unless stated.

**Settings.** *Ours*: gyro bias 0.01 °/h and ARW 0.001 °/√h, accelerometer bias 50 µg and
VRW 10 µg/√Hz per axis, odometer (speed along body y) with 0.01 m/s white noise, coarse
error given (1, 1, 10)°, 60 s level-first phase. *Seed-like*: the seed's §5.3 as it states
it — biases only, an ideal speed reference, analytic coarse alignment on the 10 s of static
data before T1. *Seed-like-10*: biases only and an ideal speed reference, with the
(1, 1, 10)° coarse error of the seed's §6.2. The seed states no IMU errors, and no T_z for
§5.2-5.3.
"""


def summary_table(b) -> str:
    tz, modes = b["seed000_tz"], b["seed000_modes"]
    m = {mode: med_abs(modes.yaw(case="ours", align__mode=mode)) for mode in MODES}
    t100 = b["seed000_modes_tz100"]
    m100 = {mode: med_abs(t100.yaw(case="ours", align__mode=mode)) for mode in MODES}
    sw = b["seed000_swing"]
    none = np.median(sw.values("error_t3_deg", align__stages__0__t_z_s=T_Z,
                               align__compensation="none"), axis=0)
    comp = med_abs(sw.yaw(align__stages__0__t_z_s=T_Z, align__compensation="continued"))
    comp100 = med_abs(sw.yaw(align__stages__0__t_z_s=100, align__compensation="continued"))
    ft = b["seed000_first_tz"]
    h_a = ft.values("error_t2_deg.2", case="level-first",
                    align__azimuth_poles="double-oscillator",
                    align__coarse__error_deg=[1, 1, 10])[0] / 10
    ts, tm = b["seed000_two_stage_swing"], b["seed000_two_stage_moving"]
    idl = b["seed000_ideal"]
    i300 = {mo: idl.yaw(align__stages__0__t_z_s=300, align__level_s=0, align__mode=mo)[0]
            for mo in MODES}
    s10 = {mo: med_abs(tz.yaw(case="seed-like-10", align__mode=mo, align__stages__0__t_z_s=T_Z))
           for mo in MODES}

    def fv(bb, case):
        return (med_abs(bb.yaw(case=case, align__stages__1__t_z_s=100)),
                med_abs(bb.yaw(case=case, align__stages__1__t_z_s=200)))

    sf, sv = fv(ts, "ours")
    mf, mv = fv(tm, "ours")
    _, sva = fv(ts, "accel-bias")
    _, mva = fv(tm, "accel-bias")
    flat = [med_abs(tz.yaw(case="seed-like", align__mode=mo, align__stages__0__t_z_s=t))
            for mo in MODES for t in tz.sweep.grid["align.stages.0.t_z_s"]]
    rows = [
        ["§5.2: without compensation the T2 attitude is wrong at T3 by the swing's motion",
         "(−1.894, −2.856, +3.243)°",
         f"always: ({none[0]:+.3f}, {none[1]:+.3f}, {none[2]:+.3f})°", "—",
         "pure kinematics over the 13 s"],
        ["§5.2: one-off and continued compensation both repair it",
         "\\|yaw\\| 0.021°, 0.004°", f"T_z = {T_Z} s: {comp:.3f}° (both)",
         f"sizes at T_z = 100 s ({comp100:.3f}°); the seed's 0.02° gap between the two "
         "methods",
         "both integrate the same gyro data exactly (agree to 1e-6°); the residual is the "
         "heading at T2, which a slower loop averages better"],
        ["§5.3: cycles beat conventional (0.18° ≫ 0.025°, 0.037°)",
         "0.1845°, −0.0248°, −0.0373°",
         f"T_z ≈ 260-400 s, a (1, 1, 10)° start: at T_z = {T_Z} s "
         f"{m['conventional']:.3f}°, {m['full-cycle']:.3f}°, {m['half-cycle']:.3f}°",
         f"T_z = 100 s ({m100['conventional']:.3f}°, {m100['full-cycle']:.3f}°, "
         f"{m100['half-cycle']:.3f}°); the seed-like setting at any T_z "
         f"({min(flat):.3f}-{max(flat):.3f}°)",
         "cycling lets a loop too slow for one pass converge; a T_z = 100 s loop forgets its "
         "start within one pass, and an analytic coarse alignment on noise-free data starts "
         "the loop on its own steady state, leaving nothing to converge"],
        ["§5.3: half-cycle worse than full-cycle", "0.037° vs 0.025°",
         f"ideal IMU, T_z = 300 s, no level phase: {i300['half-cycle']:+.4f}° vs "
         f"{i300['full-cycle']:+.4f}°",
         f"our IMU at T_z = {T_Z} s, {modes.sweep.seeds} seeds: half-cycle slightly better "
         "(Wilcoxon, §5.3 table); biases only: half-cycle better "
         f"({s10['half-cycle']:.4f}° vs {s10['full-cycle']:.4f}°)",
         "the half-cycle runs the loop on 3 of the 5 passes and keeps part of a slow loop's "
         "transient; whether that residual adds to the sensor floor or cancels part of it "
         "decides which mode wins"],
        ["§6.1: at the first T_z the heading falls to 4-6 % of its start", "4-6 %",
         f"as an upper bound: {100 * h_a:+.2f} % (linear loop −0.99 %)", "as a value",
         "4-6 % is the first overshoot (−6.2 % at 0.70 T_z); at T_z the linear loop gives "
         "1.0 % (method a), 0.19 % (method b)"],
        ["§6.2: variable parameters (T_z 100 → 200 s) beat fixed (100 s)",
         "swing 0.1349° vs 0.0038°, moving −0.1730° vs −0.0006°",
         f"direction, our IMU: swing {sf:.4f}° vs {sv:.4f}°, moving {mf:.4f}° vs "
         f"{mv:.4f}°",
         "the sizes; the ratios (36×, 288×)",
         "no error source gains more than a factor 5 from the longer T_z (200 seeds); the "
         "seed's variable numbers have the size of an accelerometer-bias-only IMU "
         f"({sva:.4f}°, {mva:.4f}°); its persistent 0.13-0.17° fixed error is unexplained"],
    ]
    return "### What reproduces, where, and why\n\n" + table(
        ["seed claim", "seed", "reproduces where (ours there)", "does not reproduce", "why"],
        rows)


def table(header: list[str], rows: list[list[str]]) -> str:
    """A markdown table."""
    lines = [header, ["---"] * len(header), *rows]
    return "\n".join("| " + " | ".join(r) + " |" for r in lines) + "\n"


def tz_sweep(tz: Batch) -> str:
    grid = tz.sweep.grid["align.stages.0.t_z_s"]
    rows = []
    for t in grid:
        cells = [f4(med_abs(tz.yaw(case=c, align__mode=mo, align__stages__0__t_z_s=t)))
                 for c in CASES_TZ for mo in MODES]
        pred = 10.0 * abs(heading_fraction(330.0 - 10.0 - LEVEL_S, t))
        rows.append(f"| {t} | " + " | ".join(cells) + f" | {pred:.4f} |")
    hdr = " | ".join(f"{c} {mo}" for c in CASES_TZ for mo in MODES)
    o = {mo: med_abs(tz.yaw(case="ours", align__mode=mo, align__stages__0__t_z_s=100))
         for mo in MODES}
    pred_zero = next(t for t in range(200, 300) if heading_fraction(260.0, t) < 0)
    return f"""### §5.3: the azimuth loop period decides

Sweep: `configs/sweeps/seed000_tz.yaml`.

![median |yaw at T3| against T_z](figures/seed000_tz.png)

Median |yaw error at T3 = 330 s| over {tz.sweep.seeds} seeds for the three modes, T_z =
{grid[0]}-{grid[-1]} s, ξ = 0.707 (`gcalign plot` of the sweep's batch file; band 25-75 %
of the seeds). What the figure says:

- **At T_z = 100 s cycling cannot matter.** The loop's decay rate σ = 2π/T_z
  (ξ = 0.707) is 0.063 s⁻¹: within one 290 s pass the start is forgotten (e^−σ·230 s ≈
  5e-7), so every forward pass ends in the same state and full- and half-cycle give the
  same T3 error ({o["full-cycle"]:.4f}° against conventional {o["conventional"]:.4f}°:
  equal within the noise). Whatever the IMU, the modes agree; a quieter IMU only lowers all
  three together (ideal IMU: 3e-4° or less, tables below).
- **At T_z ≳ 260 s the pattern of the seed appears** (case *ours*, and *seed-like-10*):
  the conventional loop is still in its transient at T3, the cycles (5 passes = 1450 s of
  loop time, 3.6-5.6 T_z) are not. The conventional error at T3 is the linear compass loop's
  response to the 10° start after 260 s of compass loop (330 s − T1 − 60 s level phase),
  10°·|h(260 s)| (last column; `gcalign.align.gains.heading_transient`): it crosses zero
  near T_z = {pred_zero} s, which is the dip of the conventional curve, and is 0.23° at
  280 s, 0.37° at 300 s. The sensor noise adds to it; the cycles sit on the noise floor.
- **The seed-like setting, as the seed states its §5.3, shows nothing at any T_z**: with
  biases only, the analytic coarse alignment has exactly the loop's steady-state errors
  (φ_E = −∇_N/g, φ_N = ∇_E/g, φ_U = −ε_E/(ω_ie cos L) + φ_N tan L), so the loop starts
  converged and all modes sit on the bias floor (≈ 0.019° here, from the east gyro bias
  and the yaw-dependent projection; `tests/test_align_seeds.py`,
  `test_analytic_coarse_starts_on_the_steady_state_so_no_mode_differs`).
  With our noisy IMU the 10 s analytic coarse heading is within ≈ 0.1°, still too little
  to separate the modes (next section, case `analytic-coarse`). The seed's 0.18°
  conventional error needs a start of degrees, such as the (1, 1, 10)° its §6.2 states.

| T_z (s) | {hdr} | 10°·\\|h(260 s)\\| |
| --- | {" | ".join("---" for _ in range(len(CASES_TZ) * len(MODES)))} | --- |
""" + "\n".join(rows) + "\n"


def modes_table(modes: Batch, tz: Batch) -> str:
    rows = []
    meds = {}
    for mo in MODES:
        e = modes.values("error_t3_deg", case="ours", align__mode=mo)
        meds[mo] = med_abs(e[:, 2])
        ratio = meds[mo] / abs(SEED_53[mo][2])
        rows.append([f"{mo} (`seed000_moving_{mo.replace('-', '_')}.yaml`)",
                     seed_txt(SEED_53[mo]), *(stats(e[:, j]) for j in range(3)),
                     f"{meds[mo]:.4f}", f"{ratio:.2f}"])
    full = np.abs(modes.yaw(case="ours", align__mode="full-cycle"))
    half = np.abs(modes.yaw(case="ours", align__mode="half-cycle"))
    ana = {mo: med_abs(modes.yaw(case="analytic-coarse", align__mode=mo)) for mo in MODES}
    d = half - full
    lo, hi = np.percentile(d, [5, 95])
    worse = int(np.sum(d > 0))
    n = len(d)
    # Wilcoxon signed-rank test of |half| − |full| (paired by seed: common random numbers)
    from scipy.stats import wilcoxon

    p = float(wilcoxon(half, full).pvalue)
    ci = ratio_intervals(modes)
    r = seed_ratios(tz, T_Z)
    c260, c300 = (med_abs(tz.yaw(case="ours", align__mode="conventional",
                                 align__stages__0__t_z_s=t)) for t in (260, 300))
    return f"""### §5.3 at T_z = {T_Z} s: the configs

Sweep: `configs/sweeps/seed000_modes.yaml`.

`configs/seed000_moving_{{conventional,full_cycle,half_cycle}}.yaml` at T_z = {T_Z} s: of the
swept values, the one whose worst ratio of our median |yaw| to the seed's, over the three
modes, is closest to 1 ({min(r.values()):.2f}-{max(r.values()):.2f}; at 260 s and 300 s one
mode is off by about a factor 2). Median and [5 %, 95 %] over {modes.sweep.seeds} seeds;
last column: our median |yaw| over the seed's |yaw|.

""" + table(["variant", "seed (pitch, roll, yaw)", "ours pitch", "ours roll", "ours yaw",
             "median \\|yaw\\|", "ours / seed"], rows).rstrip() + f"""

- Conventional is {meds["conventional"] / meds["full-cycle"]:.1f}× full-cycle
  [{ci["full-cycle"][0]:.1f}, {ci["full-cycle"][1]:.1f}] and
  {meds["conventional"] / meds["half-cycle"]:.1f}× half-cycle
  [{ci["half-cycle"][0]:.1f}, {ci["half-cycle"][1]:.1f}] (ratio of medians over
  {n} seeds, 95 % bootstrap interval over the seeds; the seed: 7.4× and 4.9×). From 20
  seeds these read 8.3× and 7.8×; seeds 7001-7200 give 7.0× [6.0, 8.6] and
  7.0× [6.3, 8.7] (`gcalign batch configs/sweeps/seed000_modes.yaml --seed-start 7001`).
  The signs are not the seed's (ours: conventional −, cycles +; the seed's: the reverse):
  the conventional value is the sign of a transient at one instant, which changes with
  T_z, and the cycles' is the sign of the bias floor, which depends on bias directions the
  seed does not state. The conventional value is a snapshot of a transient: at 260 s and
  300 s it is {c260:.3f}° and {c300:.3f}° (table above); the cycle modes hardly move with
  T_z.
- **Half-cycle against full-cycle, measured:** |half| − |full| per seed has median
  {np.median(d):+.4f}° [{lo:+.4f}, {hi:+.4f}]; half-cycle is worse on {worse} of {n} seeds
  (Wilcoxon signed-rank, two-sided, p = {p:.2g}; seeds 7001-7200: worse on 87 of 200,
  p = 0.033). With our IMU at T_z = {T_Z} s the half-cycle is, if anything, slightly
  *better* (by a few thousandths of a degree, a tenth of the spread): the seed's "half-cycle
  worse" (0.037° against 0.025°) does not reproduce; it is one draw of this spread.
  Without noise the half-cycle is the one that keeps a residual (it runs the loop on 3 of
  the 5 passes): ideal IMU, T_z = 300 s, no level phase, half-cycle −0.036° against
  full-cycle 0.0000° (table below). With biases only (*seed-like-10* above) that residual
  cancels part of the bias floor instead, and the half-cycle comes out better.
- **With the seed's stated coarse alignment** (analytic, on the 10 s of static data; case
  `analytic-coarse`) and our IMU the pattern is gone: conventional {ana["conventional"]:.4f}°,
  full-cycle {ana["full-cycle"]:.4f}°, half-cycle {ana["half-cycle"]:.4f}°. The 10 s
  analytic heading is off by only ≈ 0.1° (the ARW averaged over 10 s: 0.019 °/h, i.e.
  0.10° of heading at 45.8°N), a start the loop sheds within the pass.
- Pitch and roll (0.003°) are the accelerometer-bias floor ∇/g in every mode, as the
  seed's (0.004°).
- The cycles use the 290 s block 5 times (equivalent 1460 s with the 10 s coarse
  alignment; the seed says 1500 s).
"""


def median_ratio_interval(a: np.ndarray, b: np.ndarray, draws: int = 5000) -> tuple[float, float]:
    """95 % bootstrap interval (seeded; the seeds resampled, a and b paired by seed) of
    median(a) / median(b)."""
    rng = np.random.default_rng(0)
    idx = rng.integers(0, len(a), (draws, len(a)))
    r = np.median(a[idx], axis=1) / np.median(b[idx], axis=1)
    lo, hi = np.percentile(r, [2.5, 97.5])
    return float(lo), float(hi)


def ratio_intervals(modes: Batch) -> dict[str, tuple[float, float]]:
    """median |conventional| / median |mode| for the two cycle modes: 95 % intervals."""
    conv = np.abs(modes.yaw(case="ours", align__mode="conventional"))
    return {mo: median_ratio_interval(conv, np.abs(modes.yaw(case="ours", align__mode=mo)))
            for mo in ("full-cycle", "half-cycle")}


def modes_tz100(t100: Batch) -> str:
    rows = []
    for case, what in (("ours", "ours (the `_tz100` configs)"),
                       ("ideal-odometer", "ours, ideal speed reference")):
        cells = [f4(med_abs(t100.yaw(case=case, align__mode=mo))) for mo in MODES]
        rows.append(f"| {what} | " + " | ".join(cells) + " |")
    a = {mo: med_abs(t100.yaw(case="ours", align__mode=mo)) for mo in MODES}
    b = {mo: med_abs(t100.yaw(case="ideal-odometer", align__mode=mo)) for mo in MODES}
    odo = {mo: math.sqrt(max(a[mo] ** 2 - b[mo] ** 2, 0.0)) for mo in MODES}
    return f"""### §5.3 at T_z = 100 s: where it does not reproduce

Sweep: `configs/sweeps/seed000_modes_tz100.yaml`.

Median |yaw at T3| (deg), {t100.sweep.seeds} seeds, `configs/seed000_moving_*_tz100.yaml`,
and the same with an ideal speed reference:

| setting | conventional | full-cycle | half-cycle |
| --- | --- | --- | --- |
""" + "\n".join(rows) + f"""

The modes agree in every setting: the loop converges within one pass. The 0.01 m/s odometer
noise (ours; the seed uses a vehicle speed meter of unstated quality) adds, in quadrature,
about {odo["conventional"]:.3f}° (conventional) and {odo["full-cycle"]:.3f}° (cycles) at
T_z = 100 s. With an ideal IMU all three are below 1e-3° (next table): no sensor, however
quiet, separates the modes at this T_z — the earlier explanation of the §5.3 gap ("the
heading is sensor-limited; the seed needs a quieter IMU") was wrong as its main cause.
"""


def ideal(idl: Batch) -> str:
    rows = []
    for t in idl.sweep.grid["align.stages.0.t_z_s"]:
        for lv in idl.sweep.grid["align.level_s"]:
            cells = [idl.yaw(align__stages__0__t_z_s=t, align__level_s=lv, align__mode=mo)[0]
                     for mo in MODES]
            cells = [f"{c:+.2g}" for c in cells]
            rows.append(f"| {t} | {lv} | " + " | ".join(cells) + " |")
    return """### The mechanism without sensor errors

Sweep: `configs/sweeps/seed000_ideal.yaml`.

Ideal IMU and speed reference, (1, 1, 10)° start; yaw error at T3 (deg; one run, nothing is
random):

| T_z (s) | level_s (s) | conventional | full-cycle | half-cycle |
| --- | --- | --- | --- | --- |
""" + "\n".join(rows) + """

At T_z = 100 s every mode converges. At 300 s only the full-cycle does (5 compass passes,
1450 s of loop); the half-cycle, whose reverse passes are attitude-only, keeps a residual of
a few hundredths of a degree; the conventional loop is mid-transient at T3.
`tests/test_align_seeds.py::test_cycles_converge_where_one_pass_cannot_ideal_imu_tz300` pins
this (conventional = the linear loop's 10°·h(260 s) = −0.368° within 3 %; full-cycle
< 1e-3°).
"""


def level_phase(lv: Batch) -> str:
    rows = []
    for t in lv.sweep.grid["align.stages.0.t_z_s"]:
        m0 = med_abs(lv.yaw(align__level_s=0, align__stages__0__t_z_s=t))
        m60 = med_abs(lv.yaw(align__level_s=60, align__stages__0__t_z_s=t))
        pred = 10.0 * abs(heading_fraction(330.0 - 10.0 - 60.0, t))
        rows.append([str(t), f"{m0:.4f}", f"{m60:.4f}", f"{pred:.4f}"])
    return f"""### The level-first phase: decision 002's real scope

Sweep: `configs/sweeps/seed000_level_phase.yaml`.

Conventional mode (our IMU, (1, 1, 10)° start), median |yaw at T3| (deg) over
{lv.sweep.seeds} seeds, without and with the 60 s level phase:

""" + table(["T_z (s)", "level_s 0 (the seed's loop)", "level_s 60 (our default)",
             "linear loop, 10°·\\|h(260 s)\\|"], rows).rstrip() + """

At T_z = 100 s the level phase changes nothing at T3 (the loop has converged either way).
At T_z ≥ 200 s it does, by a factor 1.5-2 (more at 240 s, where the level-first transient
happens to cross zero near T3): with it, the conventional error at T3 is the linear loop's
response to the 10° heading start (last column); without it the 1° tilt errors drive the
compass loop as well (§6.1 below).
"Converged results do not depend on the level phase" (decision 002) holds for a loop that
has converged by T3, i.e. T_z = 100 s. The full-cycle mode, which converges at any T_z here,
does not depend on it; the half-cycle's residual of a slow loop does (ideal IMU, T_z =
300 s: −0.036° without, −0.014° with it; table above).
"""


def swing(sw: Batch) -> str:
    rows = []
    for t in (T_Z, 100):
        for comp in ("none", "one-off", "continued"):
            e = sw.values("error_t3_deg", align__stages__0__t_z_s=t, align__compensation=comp)
            suffix = "" if t == T_Z else "_tz100"
            rows.append(f"| {comp}, T_z {t} s (`seed000_swing_{comp.replace('-', '_')}{suffix}"
                        f".yaml`) | {seed_txt(SEED_52[comp])} | "
                        + " | ".join(stats(e[:, j]) for j in range(3))
                        + f" | {med_abs(e[:, 2]):.4f} |")
    return """### §5.2: compensation of the computing latency, swing base

Sweep: `configs/sweeps/seed000_swing.yaml`.

One forward compass pass over [10, 800] s, then the attitude carried to T3 = 813 s. Truth at
813 s (1.9021, 2.8532, 26.7639)°.

| variant | seed (pitch, roll, yaw) | ours pitch | ours roll | ours yaw | median \\|yaw\\| |
| --- | --- | --- | --- | --- | --- |
""" + "\n".join(rows) + """

Reproduces at either T_z. `none` is wrong by the swing's motion over 13 s (pure kinematics,
the seed's numbers to 0.01°). `one-off` (seed eqs. 14-18) and `continued` agree to 1e-6°:
both integrate the same gyro data exactly, so the seed's 0.02° gap between them is an
artefact of its implementation. What is left is the heading at T2, which the slower loop
(T_z = 280 s) averages better.
"""


def first_tz(ft: Batch) -> str:
    rows = []
    for case in ("level-first", "no-level-phase"):
        for poles, letter in (("double-oscillator", "a"), ("oscillator-overdamped", "b")):
            lin = 100 * heading_fraction(100.0, 100.0, poles)
            for err in ([0, 0, 10], [1, 1, 10]):
                y = ft.values("error_t2_deg.2", case=case, align__azimuth_poles=poles,
                              align__coarse__error_deg=err)[0]
                rows.append(f"| {case} | {letter} ({poles}) | ({err[0]}, {err[1]}, {err[2]})° "
                            f"| {10 * y:+.2f} % | {lin:+.2f} % |")
    peak = 100 * heading_fraction(70.0, 100.0)
    return """### §6.1: the heading after the first T_z

Sweep: `configs/sweeps/seed000_first_tz.yaml`.

The seed: "with ξ = 0.707, at the first T_z the heading error generally falls to within
4-6 % of its start, or lower". Static base, ideal IMU, T_z = 100 s, heading error at T_z
after the compass loop starts, as a fraction of the 10° start (`configs/seed000_first_tz.yaml`):

| phase before the compass loop | poles | coarse error | ours | linear loop h(T_z) |
| --- | --- | --- | --- | --- |
""" + "\n".join(rows) + f"""

The loop follows its linear closed form (`gains.heading_transient`; Ω and T_z drop out, so
the fraction holds for any T_z), which is well inside "4-6 %, or lower" — but 4-6 % is not
what a linear loop gives at T_z. It is the size of method a's first overshoot,
{peak:+.1f} % at 0.70 T_z (the undamped period 2π/ω_n); the seed may have read its figures
there. Without the level phase a heading error alone behaves the same, but the 1° tilt
errors throw the loop far off: hundreds of per cent of the start at T_z, i.e. tens of
degrees, still swinging — which is why gcalign levels first (decision 002).
`tests/test_align_seeds.py::test_heading_after_the_first_tz_section_6_1` pins these numbers.
"""


def two_stage(ts: Batch, tm: Batch) -> str:
    out = ["### §6.2: two-stage loop parameters", "",
           "Sweeps: `configs/sweeps/seed000_two_stage_{swing,moving}.yaml`.", "",
           "Full-cycle, 3 forward + 2 reverse compass passes, coarse error (1, 1, 10)°;\n"
           "stage 1 (first forward pass) T_z = 100 s, stage 2 T_z = 100 s (*fixed*:\n"
           "`seed000_two_stage_*_fixed.yaml`) or 200 s (*variable*: `…_variable.yaml`), the\n"
           f"T_z the seed states. Median |yaw at T3| (deg), {ts.sweep.seeds} seeds, one sensor\n"
           "error at a time; the ratio of the medians with its 95 % bootstrap interval over\n"
           "the seeds (paired):",
           "",
           "| setting | swing fixed | swing variable | ratio | moving fixed | moving variable "
           "| ratio |",
           "| --- | --- | --- | --- | --- | --- | --- |",
           "| **seed** | " + " | ".join(
               f"{abs(f):.4f} | {abs(v):.4f} | {f / v:.0f}×" for f, v in SEED_62.values())
           + " |"]
    cases = list(tm.sweep.cases)

    def cell(bb, case):
        if case not in bb.sweep.cases:
            return "— | — | —"
        fa = np.abs(bb.yaw(case=case, align__stages__1__t_z_s=100))
        va = np.abs(bb.yaw(case=case, align__stages__1__t_z_s=200))
        f, v = float(np.median(fa)), float(np.median(va))
        if max(f, v) < 1e-3:  # nothing to compare: no error source
            return f"{f:.1e} | {v:.1e} | —"
        lo, hi = median_ratio_interval(fa, va)
        return f"{f:.4f} | {v:.4f} | {f / v:.1f}× [{lo:.1f}, {hi:.1f}]"

    what = {"ours": "ours (the configs)", "ours-no-level-phase": "ours, no level phase",
            "biases": "biases only", "accel-bias":
            "accelerometer bias only", "gyro-bias": "gyro bias only", "arw": "gyro ARW only",
            "vrw": "accelerometer VRW only", "odometer": "odometer noise only",
            "ideal": "ideal IMU"}
    for case in cases:
        out.append(f"| {what.get(case, case)} | {cell(ts, case)} | {cell(tm, case)} |")
    out += ["", """The direction reproduces with our IMU and with every velocity-type error
alone (VRW, odometer noise, accelerometer bias: 2.0-4.9×, every interval above 2): the
second stage's longer T_z averages them over a longer time ((1 + K_U2) ∝ 1/T_z², so the
velocity-noise gain drops four-fold from 100 s to 200 s). Gyro errors care less (gyro
bias 1.0×; ARW 1.3-1.5×, intervals from 1.1; biases together: 0.9×, slightly reversed).
The sizes do not reproduce: no error source gives more than a factor 5 (the odometer
noise's interval ends at 6), against the seed's 36× and 288×. A constant gyro bias sets a
floor ε_E/(ω_ie cos L) that no T_z removes (0.01 °/h → 0.055° before the yaw-dependent
projection, 0.02° here); the seed's variable-parameter numbers (0.0038°, 0.0006°) have the
size of an IMU with accelerometer bias only. The seed's persistent 0.13-0.17°
fixed-parameter error ("keeps oscillating slightly with more passes") is unexplained: a
fixed T_z = 100 s loop converges within one pass in our kernel, with every error source
above, with or without the level phase (< 1e-4° with an ideal IMU)."""]
    return "\n".join(out) + "\n"


def typos(sw: Batch) -> str:
    return """### The seed's typos and inconsistencies

- **§5.2, truth yaw at 813 s.** Printed 26.7693°; the seed's own columns give 26.7639°
  (continued: 26.7595 + 0.0044; none: 30.0065 − 3.2428 = 26.7637), and so does its swing
  (yaw 30° + 4° sin(2π·813 s/20 s) = 26.7639°, our truth).
- **§5.2, the one-off yaw row.** Attitude 26.7963° with error −0.0210° does not fit the
  truth 26.7639° (it would be +0.0324°); its pitch and roll entries are consistent.
- **§5.3, "300 s of data used as 1500 s".** The stored block is [T1, T2] = [10, 300] s:
  290 s, 5 passes = 1450 s of loop time (1460 s with the 10 s coarse alignment, our
  `equivalent_s`).
- **§5.3, signs.** Half-cycle: final attitude 20.0382° against the truth 20.0009° is an
  error of +0.0373°, printed −0.0373°. The 300 s rows imply two different truths for the
  same instant (full-cycle 29.9763 − 0.0244 = 29.9519°, half-cycle 30.0383 − 0.0357 =
  30.0026°), and their pitch errors (−0.0042°, −0.0041°) have the opposite sign of the
  final ones (+0.0047°, +0.0044°) with an unchanged pitch estimate.
- **§2.2, method b gains.** The printed closed form does not place the designed poles
  (short by 2ω_n³(1 − ξ) in the s¹ coefficient); `gcalign/align/gains.py` solves the
  coefficient equations exactly.
"""


def real_data(lg: Batch) -> str:
    rows = []
    for start in lg.sweep.grid["align.start_s"]:
        for off in lg.sweep.grid["align.coarse.offset_deg"]:
            c = lg.values("coarse_attitude_deg", align__start_s=start,
                          align__coarse__offset_deg=off)[0]
            p, r, y = lg.values("attitude_t2_deg", align__start_s=start,
                                align__coarse__offset_deg=off)[0]
            rows.append(f"| {start:.0f} | {off[2]:+.0f} | {c[2]:.3f} | {p:.3f} | {r:.3f} | "
                        f"{y:.3f} |")
    return """### Real data: `lasergyro.imu` (`configs/sweeps/lasergyro_windows.yaml`)

Inertial-frame coarse alignment on [0, 60 s] of each window, an added yaw offset, then a
conventional gyrocompass (60 s level phase, T_z = 100 s, method b) to T2 = 400 s. Known:
yaw ≈ −90.6°, pitch ≈ 0.9°, roll ≈ 0.2-0.4° (data README).

| window start (s) | yaw offset (deg) | coarse yaw (deg) | pitch | roll | yaw at T2 |
| --- | --- | --- | --- | --- | --- |
""" + "\n".join(rows) + """

The gyrocompass lands at −90.58…−90.63° for every window and offset; the 60 s coarse
alignment alone scatters by ±0.5°. A T_z = 100 s loop forgets its ±5° start long before T2
(280 s of compass loop after the 60 s level phase), so the offset does not show.
"""
