"""Long runs end to end: time and peak memory do not grow faster than the run (core issue,
must-show 6).

* 72 h static at 100 Hz (25.9 M samples) with the IMU on the seed-004 12-step mechanism:
  ``gcalign simulate`` then ``gcalign navigate`` (which streams the simulation again),
  each a fresh process under ``/usr/bin/time -v``. Targets: both together ≤ 20 s and each
  ≤ 600 MB peak RSS; the files ≤ 50 MB at the default output rate (1 Hz beyond an hour).
* ``gcalign align`` on a moving base (the seed 000 §5.3 segments, the cruise held) of 3000 s
  and of 30000 s, both stored at 1 Hz, runs interleaved: 30000 s ≤ 600 MB peak RSS and its
  time within 1.2× of 10 × the 3000 s case.

Medians of `--runs` (default 5) runs. Run: ``python benchmarks/bench_long.py [--runs N]``.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
ROOT = Path(__file__).resolve().parents[1]
TURN = "profile: trapezoid, accel_s: 4, const_s: 4, decel_s: 4, dwell_s: 300"
MECHANISM_72H = """\
name: seed004-12step-72h
site: {lat_deg: 45.7796, lon_deg: 126.6705, height_m: 0}
earth: seed004
imu:
  rate_hz: 100
  gyro: {bias_dph: [0.01, 0.01, 0.01]}
  accel: {bias_ug: [100, 100, 100]}
motion: {kind: static, duration_s: 259200}
mechanism:
  reference: navigation
  steps:
""" + "".join(f"    - {{axis: {a}, angle_deg: {180 if i < 6 else -180}, {TURN}}}\n"
              for i, a in enumerate("zxyyxzzxyyxz"))


def align_scenario(seconds: int) -> str:
    text = (ROOT / "configs/seed000_moving_full_cycle.yaml").read_text()
    text = re.sub(r"name: .*", f"name: align-{seconds}", text, count=1)
    text = text.replace("  duration_s: 400", f"  duration_s: {seconds}")
    text = re.sub(r"  t2_s: \d+", f"  t2_s: {seconds - 30}", text)
    text = re.sub(r"  t3_s: \d+", f"  t3_s: {seconds}", text)
    return text + "output: {rate_hz: 1}\n"


def timed(args: list[str], cwd: Path) -> tuple[float, float]:
    """(wall s, peak RSS MB) of one command in a fresh process."""
    cmd = ["/usr/bin/time", "-v", sys.executable, "-c", "from gcalign.cli import main; main()",
           *args]
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True,
                       env=dict(os.environ, TERM="dumb"))
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed:\n{r.stderr[-2000:]}")
    wall = re.search(r"Elapsed \(wall clock\) time .*: (?:(\d+):)?(\d+):([\d.]+)", r.stderr)
    assert wall is not None
    h, m, s = wall.groups()
    seconds = (int(h) if h else 0) * 3600 + int(m) * 60 + float(s)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr)
    assert rss is not None
    return seconds, int(rss.group(1)) / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=1 if SMOKE else 5)
    runs = ap.parse_args().runs
    short, long = (400, 800) if SMOKE else (3000, 30000)
    mechanism = MECHANISM_72H.replace("259200", "3600") if SMOKE else MECHANISM_72H
    hours = 1 if SMOKE else 72
    print(f"gcalign long-run benchmark: {os.cpu_count()} CPUs, load "
          f"{os.getloadavg()[0]:.1f}; medians of {runs}")
    with tempfile.TemporaryDirectory(prefix="gcalign-long-") as tmp:
        d = Path(tmp)
        (d / "mech.yaml").write_text(mechanism)
        (d / "a3000.yaml").write_text(align_scenario(short))
        (d / "a30000.yaml").write_text(align_scenario(long))
        timed(["navigate", "mech.yaml", "-o", "warm.h5", "--duration", "60"], d)  # JIT cache
        sim, nav, a3, a30 = [], [], [], []
        for _ in range(runs):
            sim.append(timed(["simulate", "mech.yaml", "-o", "sim.h5"], d))
            nav.append(timed(["navigate", "mech.yaml", "-o", "nav.h5"], d))
            a3.append(timed(["align", "a3000.yaml", "-o", "a3.h5"], d))
            a30.append(timed(["align", "a30000.yaml", "-o", "a30.h5"], d))
        size = {n: (d / n).stat().st_size / 2**20 for n in ("sim.h5", "nav.h5", "a30.h5")}

    def med(rows, i):
        return statistics.median(r[i] for r in rows)

    both = statistics.median(s[0] + n[0] for s, n in zip(sim, nav, strict=True))
    lines = [
        (f"{hours:g} h mechanism: simulate", f"{med(sim, 0):.1f} s, {med(sim, 1):.0f} MB, "
         f"file {size['sim.h5']:.1f} MB", ""),
        (f"{hours:g} h mechanism: navigate", f"{med(nav, 0):.1f} s, {med(nav, 1):.0f} MB, "
         f"file {size['nav.h5']:.1f} MB", ""),
        (f"{hours:g} h: simulate + navigate", f"{both:.1f} s", "≤ 20 s, ≤ 600 MB, ≤ 50 MB"),
        (f"align {short} s moving", f"{med(a3, 0):.2f} s, {med(a3, 1):.0f} MB", ""),
        (f"align {long} s moving", f"{med(a30, 0):.2f} s, {med(a30, 1):.0f} MB, "
         f"file {size['a30.h5']:.1f} MB", "≤ 600 MB"),
        (f"  {long} s / ({long // short} × {short} s)",
         f"{med(a30, 0) / (long // short * med(a3, 0)):.2f}", "≤ 1.2"),
    ]
    width = max(len(a) for a, _, _ in lines)
    for a, b, c in lines:
        print(f"  {a:<{width}}  {b:>36}  {('target ' + c) if c else ''}")


if __name__ == "__main__":
    main()
