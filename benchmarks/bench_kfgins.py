"""Aided navigation side by side with KF-GINS: both programs on the same files of an
independent simulated land vehicle (``benchmarks/vehicle``: 30 min, 200 Hz A15-grade IMU
with KF-GINS's Gauss–Markov biases and scale factors, 1 Hz GNSS with per-epoch σ
0.05–0.5 m, the antenna 1 m above the IMU, turns, stops, a figure-eight and two 60 s
outages across U-turns), scored against the simulator's truth.

Needs a KF-GINS executable built from its public source (github.com/i2Nav-WHU/KF-GINS,
C++; built as its own README says, nothing of it is in this repository): its path in the
environment variable ``KFGINS_BIN`` or ``--kfgins PATH``. Without one the comparison is
skipped with a message saying so, and gcalign's rows are printed alone.

Rows, for each program (the errors of every output epoch: KF-GINS's and gcalign's at every
IMU sample):

* position (north, east, down), velocity and attitude RMS and max, outside and inside the
  outages;
* the 12 sensor estimates at the end, in units of the program's own final σ;
* NEES of the position at the GNSS epochs by σ bin of the epoch (< 0.1, 0.1–0.2, ≥ 0.2 m;
  3 when consistent);
* CPU (user + system, warm: one run of each discarded first) and peak memory (maximum
  resident set) from ``/usr/bin/time -v``, medians of ``--runs`` runs (default 5), the
  programs interleaved; gcalign's ``export --format i2nav-nav`` (its solution at every IMU
  sample as KF-GINS writes it) timed apart.

A third column is gcalign with its RTS smoother (``--smoother``; KF-GINS has none), scored at
the filter's epochs (1 Hz), where the smoothed solution is stored.

gcalign is run as a user runs it: ``gcalign calibrate gcalign.yaml`` (the scenario the
simulator writes beside ``kf-gins.yaml``), its solution read from ``gcalign export
--format i2nav-nav``, its σ and sensor estimates from the results file (HDF5,
``/calibrate/runs/00``: ``t``, ``sigma``, ``estimate`` at the filter's epochs). KF-GINS's
from its
``KF_GINS_Navresult.nav``, ``KF_GINS_STD.txt`` and ``KF_GINS_IMU_ERR.txt``.

The simulated files are written once to ``--data`` (default ``$GCALIGN_BENCH_DATA`` or
``/tmp/gcalign-bench-vehicle``) and written again when the simulator's sources change.

Run: ``python benchmarks/bench_kfgins.py [--kfgins PATH] [--runs 5] [--json OUT.json]``
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.vehicle import dataset, files, solution  # noqa: E402

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke
TIME = "/usr/bin/time"


#: the simulator's modules that make the files (not those that score or check them)
WRITERS = ("earth", "route", "trajectory", "imu", "gnss", "dataset", "files")


def _source_stamp() -> str:
    """A hash of the simulator's sources that make the files: the files on disk are theirs
    or are written again."""
    h = hashlib.sha256()
    for name in WRITERS:
        h.update((ROOT / "benchmarks" / "vehicle" / f"{name}.py").read_bytes())
    return h.hexdigest()[:16]


def prepare(cfg: dataset.Config, data_dir: Path) -> tuple[dataset.Dataset, dict[str, Path]]:
    """The run's files in `data_dir` (written when missing or from other sources), and the
    dataset in memory without its increments (the truth to score against)."""
    stamp = {"source": _source_stamp(), "config": repr(cfg)}
    mark = data_dir / "stamp.json"
    ds = dataset.simulate(cfg, increments=False)
    if mark.exists() and json.loads(mark.read_text()) == stamp:
        paths = files.paths(data_dir)
    else:
        print(f"simulating the drive into {data_dir} ...", flush=True)
        paths = files.write(dataset.simulate(cfg), data_dir)
        mark.write_text(json.dumps(stamp))
    return ds, paths


def timed(cmd: list[str], cwd: Path) -> dict:
    """Run `cmd` under ``/usr/bin/time -v``: CPU (user + system) s, peak RSS MB, wall s;
    RuntimeError with its output when it fails."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        proc = subprocess.run([TIME, "-v", "-o", tf.name, *cmd], cwd=cwd,
                              capture_output=True, text=True)
        report = Path(tf.name).read_text()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {proc.returncode}:\n"
                           f"{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")

    def field(name: str) -> float:
        m = re.search(rf"{re.escape(name)}: ([0-9.:]+)", report)
        assert m, (name, report)
        v = m.group(1)
        if ":" in v:  # h:mm:ss or m:ss
            parts = [float(x) for x in v.split(":")]
            return sum(x * 60**i for i, x in enumerate(reversed(parts)))
        return float(v)

    return {"cpu_s": field("User time (seconds)") + field("System time (seconds)"),
            "peak_mb": field("Maximum resident set size (kbytes)") / 1024.0,
            "wall_s": field("Elapsed (wall clock) time (h:mm:ss or m:ss)"),
            "stderr": proc.stderr}


class KfGins:
    name = "KF-GINS"

    def __init__(self, exe: Path, paths: dict[str, Path]) -> None:
        self.exe, self.paths = exe, paths

    def run(self) -> dict:
        return timed([str(self.exe), str(self.paths["kfgins_yaml"])], self.paths["imu"].parent)

    def solution(self, ds: dataset.Dataset) -> solution.Solution:
        return solution.read_kfgins(self.paths["kfgins_out"])


class Gcalign:
    name = "gcalign"
    options: tuple[str, ...] = ()

    def __init__(self, paths: dict[str, Path], out: Path, cwd: Path = ROOT) -> None:
        self.paths, self.cwd = paths, cwd  # cwd: ``python -m gcalign`` imports from there
        stem = self.name.replace(" ", "").replace(",", "_").replace("+", "_")
        self.h5, self.nav = out / f"{stem}.h5", out / f"{stem}.nav"

    def run(self) -> dict:
        return timed([sys.executable, "-m", "gcalign", "calibrate",
                      str(self.paths["gcalign_yaml"]), *self.options, "-o", str(self.h5)],
                     self.cwd)

    def export(self) -> dict:
        return timed([sys.executable, "-m", "gcalign", "export", str(self.h5), "--format",
                      "i2nav-nav", "-o", str(self.nav)], self.cwd)

    def solution(self, ds: dataset.Dataset) -> solution.Solution:
        return solution.read_gcalign(self.h5, self.nav)


class GcalignSmoothed(Gcalign):
    """The same run with the RTS smoother (``--smoother``): its solution at the filter's
    epochs (1 Hz), scored there."""

    name = "gcalign + smoother"
    options = ("--smoother",)

    def solution(self, ds: dataset.Dataset) -> solution.Solution:
        return solution.read_gcalign(self.h5, smoothed=True)


def _median(runs: list[dict], key: str) -> float:
    return float(np.median([r[key] for r in runs]))


def _fmt(v, digits: int = 3) -> str:
    if v is None:
        return "—"
    if isinstance(v, (list, tuple)):
        return " / ".join(_fmt(x, digits) for x in v)
    return f"{v:.{digits}f}"


def report(results: dict[str, dict], ds: dataset.Dataset) -> list[tuple[str, ...]]:
    """The table's rows: (label, one cell per program)."""
    names = list(results)
    rows: list[tuple[str, ...]] = []

    def add(label: str, cell) -> None:
        rows.append((label, *[cell(results[n]) for n in names]))

    for where, title in (("out", "outside the outages"), ("in", "inside the outages")):
        for q, unit, k in (("pos", "m", 1.0), ("vel", "m/s", 1.0), ("att", "deg",
                                                                     np.degrees(1.0))):
            label = {"pos": "position N / E / D", "vel": "velocity N / E / D",
                     "att": "attitude roll / pitch / yaw"}[q]
            add(f"{label} RMS, {title} ({unit})",
                lambda r, q=q, k=k, w=where: _fmt([x * k for x in r["table"][w][q]["rms"]],
                                                  4 if q != "pos" else 3)
                if r["table"][w] else "—")
            add(f"{label} max, {title} ({unit})",
                lambda r, q=q, k=k, w=where: _fmt([x * k for x in r["table"][w][q]["max"]],
                                                  4 if q != "pos" else 3)
                if r["table"][w] else "—")
        add(f"horizontal RMS / max, {title} (m)",
            lambda r, w=where: _fmt([r["table"][w]["pos"]["rms_h"], r["table"][w]["pos"]["max_h"]])
            if r["table"][w] else "—")
    for i, (state, _, _) in enumerate(solution.SENSOR_STATES):
        add(f"{state} x / y / z at the end, (estimate − truth) / σ",
            lambda r, i=i: _fmt(r["table"]["sensors_in_sigma"][i], 2))
    for b in range(len(solution.SIGMA_BINS)):
        lo, hi = solution.SIGMA_BINS[b]
        span = f"σ < {hi:g} m" if lo == 0 else (f"σ ≥ {lo:g} m" if hi == np.inf
                                                else f"{lo:g} ≤ σ < {hi:g} m")
        add(f"position NEES at fixes, {span} (epochs; 3 when consistent)",
            lambda r, b=b: f"{r['table']['nees'][b]['nees']:.2f} "
                           f"({r['table']['nees'][b]['epochs']})")
    add("CPU, median (s)", lambda r: _fmt(r.get("cpu_s"), 2))
    add("CPU per IMU sample (µs)", lambda r: _fmt(1e6 * r["cpu_s"] / len(ds.t), 1))
    add("peak memory, median (MB)", lambda r: _fmt(r.get("peak_mb"), 1))
    add("export to i2nav-nav: CPU (s) / peak (MB)",
        lambda r: _fmt([r["export_cpu_s"], r["export_peak_mb"]], 2) if "export_cpu_s" in r
        else "—")
    return rows


def figure(path: Path, sols: dict[str, solution.Solution], ds: dataset.Dataset) -> None:
    """Errors against the truth over the drive (left) and around the first outage (right):
    horizontal, down and yaw, each program with its own ±3σ of position (dashed: the σ it
    states, once a second; the smoother's solution, at 1 Hz, without), the outages shaded;
    with both programs, a last row of their difference (gcalign − KF-GINS, north, east,
    down)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    both = "KF-GINS" in sols and "gcalign" in sols
    rows = 4 if both else 3
    fig, axes = plt.subplots(rows, 2, figsize=(12, 2.6 * rows + 0.6), sharex="col",
                             gridspec_kw={"width_ratios": [2.2, 1]})
    style = {"KF-GINS": {"color": "tab:orange", "lw": 2.4, "alpha": 0.55},
             "gcalign": {"color": "tab:blue", "lw": 0.8, "alpha": 1.0},
             "gcalign + smoother": {"color": "tab:green", "lw": 0.8, "alpha": 1.0}}
    a0, b0 = ds.fixes.outages[0]
    zoom = (float(a0) - 20.0, float(b0) + 20.0)
    pos = {}
    for name, sol in sols.items():
        e = solution.errors(sol, ds)
        t = sol.t - ds.config.sow0
        pos[name] = (np.round(sol.t, 4), e["pos"])
        k = slice(None, None, max(1, int(round(0.1 / np.median(np.diff(t))))))  # ≤ 10 Hz
        series = (np.hypot(e["pos"][:, 0], e["pos"][:, 1]), e["pos"][:, 2],
                  np.degrees(e["att"][:, 2]))
        ts = sol.sigma_t - ds.config.sow0
        step = max(1, int(round(1.0 / np.median(np.diff(ts)))))  # σ once a second
        sig_h = np.hypot(sol.sigma_pos_ned[::step, 0], sol.sigma_pos_ned[::step, 1])
        st = style.get(name, {})
        for row, (y, sg) in enumerate(zip(series, (sig_h, sol.sigma_pos_ned[::step, 2], None),
                                          strict=True)):
            for col in (0, 1):
                ax = axes[row, col]
                ax.plot(t[k], y[k], label=name, **st)
                if sg is not None and name != "gcalign + smoother":
                    for sign in ((1,) if row == 0 else (1, -1)):
                        ax.plot(ts[::step], sign * 3 * sg, color=st.get("color"),
                                lw=0.9 if name == "KF-GINS" else 0.6,
                                ls="--" if name == "KF-GINS" else ":",
                                label=f"{name} 3σ" if sign == 1 else None)
    if both:
        (tk, ek), (tg, eg) = pos["KF-GINS"], pos["gcalign"]
        _, ik, ig = np.intersect1d(tk, tg, return_indices=True)
        d = eg[ig] - ek[ik]
        td = tk[ik] - ds.config.sow0
        for col in (0, 1):
            for j, (lab, c) in enumerate(zip("NED", ("tab:green", "tab:purple", "k"),
                                             strict=True)):
                axes[3, col].plot(td[::20], d[::20, j], color=c, lw=0.7, label=lab)
        axes[3, 0].set_ylabel("gcalign − KF-GINS\nposition (m)")
        axes[3, 0].legend(loc="upper right", fontsize=8, ncol=3)
    for ax in axes.ravel():
        for a, b in ds.fixes.outages:
            ax.axvspan(a, b, color="0.88", zorder=0)
        ax.grid(alpha=0.3)
    for ax in axes[:, 1]:
        ax.set_xlim(*zoom)
    for row, lab in enumerate(("horizontal error (m)", "down error (m)", "yaw error (deg)")):
        axes[row, 0].set_ylabel(lab)
    axes[0, 0].set_ylim(0, None)
    axes[0, 1].set_ylim(0, None)
    axes[-1, 0].set_xlabel("time from the start (s); shaded: GNSS outages")
    axes[-1, 1].set_xlabel(f"around the first outage ({a0:g}-{b0:g} s)")
    axes[0, 0].legend(loc="upper right", fontsize=8, ncol=2)
    minutes = (ds.t[-1] - ds.t[0]) / 60.0
    fig.suptitle(f"Simulated vehicle ({minutes:.3g} min, A15 IMU at {ds.config.imu_rate_hz:g} Hz, "
                 "1 Hz GNSS σ 0.05-0.5 m): errors against the truth", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def print_table(rows: list[tuple[str, ...]], names: list[str]) -> None:
    print("| | " + " | ".join(names) + " |")
    print("| --- |" + " --- |" * len(names))
    for r in rows:
        print("| " + " | ".join(r) + " |")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kfgins", type=Path, default=os.environ.get("KFGINS_BIN"),
                    help="KF-GINS executable (default: $KFGINS_BIN)")
    ap.add_argument("--data", type=Path, default=Path(os.environ.get(
        "GCALIGN_BENCH_DATA", "/tmp/gcalign-bench-vehicle")))
    ap.add_argument("--runs", type=int, default=1 if SMOKE else 5)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--route", choices=sorted(dataset.ROUTES), default="standard",
                    help="standard: the 30 min drive; hour: it twice over (CPU for an hour)")
    ap.add_argument("--json", type=Path, help="write the figures here")
    ap.add_argument("--figure", type=Path, help="draw the errors over the drive here (PNG)")
    args = ap.parse_args()
    if not Path(TIME).exists():
        print(f"skipped: {TIME} (GNU time) is needed for CPU and peak memory")
        return 0
    cfg = (dataset.Config(route="short", duration_s=150.0, seed=args.seed) if SMOKE
           else dataset.Config(route=args.route, seed=args.seed))
    data = args.data / f"{cfg.route}-seed{cfg.seed}" / ("smoke" if SMOKE else "full")
    ds, paths = prepare(cfg, data)
    exe = args.kfgins
    contenders: list = [Gcalign(paths, data), GcalignSmoothed(paths, data)]
    if exe is None or not Path(exe).is_file() or not os.access(exe, os.X_OK):
        why = "no KFGINS_BIN or --kfgins given" if exe is None else f"{exe} is not executable"
        print(f"KF-GINS skipped ({why}): gcalign's rows alone, nothing compared")
    else:
        contenders.insert(0, KfGins(Path(exe), paths))
    runs: dict[str, list[dict]] = {c.name: [] for c in contenders}
    exports: list[dict] = []
    warm = 0 if SMOKE else 1
    for i in range(warm + args.runs):  # interleaved: A B A B ...; the first of each is warm-up
        for c in contenders:
            r = c.run()
            if i >= warm:
                runs[c.name].append(r)
            if type(c) is Gcalign:
                e = c.export()
                if i >= warm:
                    exports.append(e)
    results: dict[str, dict] = {}
    sols = {c.name: c.solution(ds) for c in contenders}
    for c in contenders:
        res = {"cpu_s": _median(runs[c.name], "cpu_s"),
               "peak_mb": _median(runs[c.name], "peak_mb"),
               "cpu_runs_s": [r["cpu_s"] for r in runs[c.name]],
               "peak_runs_mb": [r["peak_mb"] for r in runs[c.name]],
               "table": solution.table(sols[c.name], ds)}
        if type(c) is Gcalign:
            res["export_cpu_s"] = _median(exports, "cpu_s")
            res["export_peak_mb"] = _median(exports, "peak_mb")
        results[c.name] = res
    load = os.getloadavg()
    f = ds.fixes
    print(f"{cfg.route} drive, seed {cfg.seed}: {len(ds.t)} IMU samples at "
          f"{cfg.imu_rate_hz:g} Hz, {len(f.t)} fixes, outages "
          f"{[(float(ds.sow(a)), float(ds.sow(b))) for a, b in f.outages]} s of week; "
          f"{args.runs} runs each (medians), load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print_table(report(results, ds), list(results))
    if "KF-GINS" in results:
        k, g = results["KF-GINS"]["table"], results["gcalign"]["table"]
        for w in ("out", "in"):
            if k[w] and g[w]:
                ratio = np.array(g[w]["pos"]["rms"]) / np.array(k[w]["pos"]["rms"])
                print(f"gcalign / KF-GINS position RMS N, E, D {w}side the outages: "
                      f"{_fmt(ratio.tolist(), 2)}")
    if args.figure:
        figure(args.figure, sols, ds)
    if args.json:
        args.json.write_text(json.dumps({"config": repr(cfg), "load": load,
                                         "results": results}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
