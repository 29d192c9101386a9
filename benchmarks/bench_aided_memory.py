"""Memory and CPU of an aided-navigation run against its length: ``gcalign calibrate`` on the
first 5 min and on all 30 min of the benchmark's simulated drive (``benchmarks/vehicle``:
200 Hz IMU, 1 Hz GNSS with σ per fix, KF-GINS's text layouts), as a user runs it.

Rows, medians of ``--runs`` runs (default 5) of each length, the lengths interleaved, after
one warm-up run each (``/usr/bin/time -v``: maximum resident set, user + system CPU):

* peak memory of each length and the ratio 30 min / 5 min (the target: ≤ 1.3, memory flat
  in the run's length), as KF-GINS runs (no reference) and with the truth file as
  ``reference`` (every sample compared with it, the reference held whole);
* CPU per IMU sample of the 30 min run, less the 5 min run's per-sample cost (what a minute
  more costs, the start-up taken out), and of the whole run.

The files are written once to ``--data`` (default ``$GCALIGN_BENCH_DATA`` or
``/tmp/gcalign-bench-vehicle``, beside the KF-GINS benchmark's) and again when the
simulator's sources change.

Run: ``python benchmarks/bench_aided_memory.py [--runs 5]``
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.vehicle import dataset, files  # noqa: E402

SMOKE = bool(os.environ.get("GCALIGN_BENCH_SMOKE"))


def drive(folder: Path, seconds: float | None, route: str) -> Path:
    """The drive's first `seconds` written to `folder` (once per simulator version), and
    beside its gcalign scenario (returned) a copy with the truth as ``reference``
    (``with_reference.yaml``)."""
    stamp = folder / "SOURCES"
    sources = b"".join(p.read_bytes() for p in sorted((ROOT / "benchmarks/vehicle").glob("*.py")))
    key = f"{route} {seconds} {hashlib.sha256(sources).hexdigest()}"
    if not (stamp.exists() and stamp.read_text() == key):
        ds = dataset.simulate(dataset.Config(route=route, duration_s=seconds))
        files.write(ds, folder)
        stamp.write_text(key)
    paths = files.paths(folder)
    sc = yaml.safe_load(paths["gcalign_yaml"].read_text())
    sc["reference"] = {"path": str(paths["truth"]), "format": "i2nav-nav"}
    (folder / "with_reference.yaml").write_text(yaml.safe_dump(sc, sort_keys=False))
    return paths["gcalign_yaml"]


def measure(scenario: Path, out: Path) -> tuple[float, float]:
    """(peak RSS MB, CPU s) of one ``gcalign calibrate`` run."""
    cmd = ["/usr/bin/time", "-v", sys.executable, "-m", "gcalign", "calibrate", str(scenario),
           "-o", str(out)]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        raise SystemExit(f"gcalign calibrate {scenario} failed:\n{r.stderr[-2000:]}")
    peak = float(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr)[1])
    user = float(re.search(r"User time \(seconds\): ([\d.]+)", r.stderr)[1])
    system = float(re.search(r"System time \(seconds\): ([\d.]+)", r.stderr)[1])
    return peak / 1024.0, user + system


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1 if SMOKE else 5)
    ap.add_argument("--data", type=Path, default=Path(os.environ.get(
        "GCALIGN_BENCH_DATA", "/tmp/gcalign-bench-vehicle")))
    args = ap.parse_args()
    route = "short" if SMOKE else "standard"
    short_s, long_s = (60.0, 120.0) if SMOKE else (300.0, None)
    folders = {"short": args.data / f"memory-{route}-{short_s:g}s",
               "long": args.data / f"memory-{route}-all"}
    scen = {k: drive(f, s, route) for (k, f), s in zip(folders.items(), (short_s, long_s),
                                                        strict=True)}
    samples = {k: sum(1 for _ in open(files.paths(f)["imu"])) for k, f in folders.items()}
    rows: dict[tuple[str, str], list[tuple[float, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.runs + 1):  # the first round warms up, uncounted
            for ref in ("none", "truth"):
                for k in ("short", "long"):
                    s = scen[k] if ref == "none" else folders[k] / "with_reference.yaml"
                    m = measure(s, Path(tmp) / f"{k}-{ref}.h5")
                    if i:
                        rows.setdefault((k, ref), []).append(m)
    load = os.getloadavg()[0]
    print(f"aided-navigation memory against length: {route} drive, {samples['short']} and "
          f"{samples['long']} IMU samples (200 Hz), medians of {args.runs}, load {load:.1f}")
    for ref, what in (("none", "no reference (as KF-GINS runs)"),
                      ("truth", "the truth file as reference")):
        peak = {k: float(np.median([r[0] for r in rows[(k, ref)]])) for k in ("short", "long")}
        cpu = {k: float(np.median([r[1] for r in rows[(k, ref)]])) for k in ("short", "long")}
        marginal = (cpu["long"] - cpu["short"]) / (samples["long"] - samples["short"]) * 1e6
        print(f"  {what}: peak {peak['short']:.1f} MB / {peak['long']:.1f} MB = "
              f"{peak['long'] / peak['short']:.2f}x (target <= 1.3); CPU {cpu['short']:.2f} s / "
              f"{cpu['long']:.2f} s, {cpu['long'] / samples['long'] * 1e6:.1f} us per sample "
              f"whole, {marginal:.1f} us per added sample")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
