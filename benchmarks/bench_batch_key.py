"""What keying a batch's recording by its content costs: the variant keys of a sweep over a
large recorded file (``Sweep.keys``: one SHA-256 of the file, read in 1 MiB chunks, then a
hash per variant), against the keys of the same variants by path (the scenario mappings
hashed as they are) and against one reading of the file by the recorded-data reader (what
each worker does once per variant).

The file: ``tests/data/lasergyro.imu.xz`` (PSINS text) with its rows repeated to ``--mb``
MB; the sweep: ``configs/sweeps/lasergyro_windows.yaml``'s 12 windows. The three are timed
in turn ``--repeats`` times (medians; the page cache warm: the reader too reads a file the
system has just read); the load average is printed with them.

Run: ``python benchmarks/bench_batch_key.py [--mb 100] [--repeats 7]``
"""

from __future__ import annotations

import argparse
import dataclasses
import lzma
import os
import statistics
import tempfile
import time
from pathlib import Path

import yaml

from gcalign.app.batch.sweep import _hash, load_sweep
from gcalign.io.recorded.imu import read_recording

ROOT = Path(__file__).resolve().parents[1]


def big_recording(path: Path, mb: float) -> None:
    """lasergyro.imu with its data rows repeated to `mb` MB (header kept: 14 lines)."""
    lines = lzma.decompress((ROOT / "tests/data/lasergyro.imu.xz").read_bytes()).splitlines(
        keepends=True)
    head, rows = b"".join(lines[:14]), b"".join(lines[14:])
    with open(path, "wb") as f:
        f.write(head)
        for _ in range(max(1, round((mb * 1e6 - len(head)) / len(rows)))):
            f.write(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mb", type=float, default=100)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        big_recording(folder / "big.imu", args.mb)
        base = yaml.safe_load((ROOT / "configs/lasergyro_align.yaml").read_text())
        base["imu_file"] = "big.imu"
        (folder / "base.yaml").write_text(yaml.safe_dump(base))
        sweep = yaml.safe_load((ROOT / "configs/sweeps/lasergyro_windows.yaml").read_text())
        (folder / "sweep.yaml").write_text(yaml.safe_dump({**sweep, "base": "base.yaml"}))
        size = (folder / "big.imu").stat().st_size

        sw = load_sweep(folder / "sweep.yaml")

        def by_content() -> None:  # a copy of the sweep: its keys not yet computed
            dataclasses.replace(sw).keys  # noqa: B018 - the property is the work

        def by_path() -> None:
            [_hash(sw.command, list(sw.metrics), v.scenario) for v in sw.variants]

        def reader() -> None:
            read_recording(folder / "big.imu")

        times: dict[str, list[float]] = {"keys by path": [], "keys by content": [],
                                         "one reading": []}
        for _ in range(args.repeats):
            for name, f in (("keys by path", by_path), ("keys by content", by_content),
                            ("one reading", reader)):
                t0 = time.perf_counter()
                f()
                times[name].append(time.perf_counter() - t0)
    print(f"{size / 1e6:.1f} MB recording, {len(sw.variants)} variants, medians of "
          f"{args.repeats}, load {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    median = {name: statistics.median(ts) for name, ts in times.items()}
    for name, t in median.items():
        print(f"  {name:16s} {t * 1e3:9.1f} ms")
    ratio = median["keys by content"] / median["one reading"]
    print(f"  keys by content / one reading: {ratio:.4f}")


if __name__ == "__main__":
    main()
