"""Results files of two source trees compared dataset by dataset and attribute by attribute.

``python benchmarks/results_identity.py run SRC OUT`` writes one results file per run of
:data:`RUNS` (the built-in scenarios, configs/ and the recorded-data runs) with the gcalign
of the source tree SRC (``git archive`` of a commit, or a worktree) into OUT, plus each
file's ``show`` text read back by that tree; ``... compare A B`` counts what differs between
the files of two such folders: the objects present, each dataset's dtype, shape, values
(NaN equal to NaN), compression, its options, shuffle, chunks and maxshape, every attribute
(type and value), and the summary JSON key by key; timings (``*compute_s``, ``wall_s``,
``created_utc``) aside, and the source folder's path replaced by ``<src>``.
``... reread SRC A OUT`` reads the files of folder A back with the tree SRC (``show``),
so that files written before are shown to read the same. ``show`` texts are compared
without timings, dates, folders and line breaks; give both trees names of one length (their
paths wrap the tables alike). A batch over a recording keys its variants by the recording's
content (trees before 2026-12-04 by its absolute path: their ``fingerprint`` and ``vkey``
differ from any other folder's).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

#: (file name, command line after ``gcalign``; ``{c}`` is the source tree's configs folder)
RUNS = [
    ("simulate", "simulate {c}/static.yaml"),
    ("align", "align"), ("northfind", "northfind"),
    ("calibrate", "calibrate"), ("observability", "observability"), ("realtime", "realtime"),
    ("modulate", "modulate --set motion.duration_s=7200"), ("allan", "allan {c}/static.yaml"),
    ("static_navigate", "navigate {c}/static.yaml"), ("static_align", "align {c}/static.yaml"),
    ("lasergyro_align", "align {c}/lasergyro_align.yaml"),
    ("lasergyro_navigate", "navigate {c}/lasergyro_align.yaml"),
    ("lasergyro_allan", "allan {c}/lasergyro_align.yaml --duration 600"),
    ("lasergyro_calibrate", "calibrate {c}/lasergyro_calibrate.yaml"),
    ("mems_fog_navigate", "navigate {c}/mems_fog.yaml"),
    ("mems_fog_align", "align {c}/mems_fog.yaml"),
    ("mems_fog_calibrate", "calibrate {c}/mems_fog_calibrate.yaml"),
    ("transfer_align", "align {c}/psins_transfer_fog_mems.yaml"),
    ("transfer_observability", "observability {c}/psins_transfer_fog_mems.yaml"),
    ("seed002_conventional", "calibrate {c}/seed002_conventional.yaml"),
    ("seed002_observability", "observability {c}/seed002_conventional.yaml"),
    ("calibrate_compare", "calibrate --compare"),
    ("seed001_table", "northfind {c}/seed001_table_experiment.yaml"),
    ("seed003_async", "realtime {c}/seed003_rate20_async.yaml"),
    ("realtime_beyond", "realtime {c}/realtime_beyond_seed.yaml"),
    ("batch_tilt", "batch {c}/sweeps/seed001_tilt.yaml --seeds 2 -w 1"),
    ("batch_windows", "batch {c}/sweeps/lasergyro_windows.yaml -w 1"),
] + [(p[:-5], f"align {{c}}/{p}") for p in sorted(
    x.name for x in (Path(__file__).resolve().parents[1] / "configs").glob("seed000_*.yaml"))]

TIMINGS = re.compile(r"(^|_)(compute|wall)(_s)?$|^created_utc$|^command_line$|^output$")


def gcalign(src: Path, args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(src))
    return subprocess.run([sys.executable, "-m", "gcalign", *args], cwd=cwd, env=env,
                          capture_output=True, text=True)


def run(src: Path, out: Path, only: list[str]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for name, line in RUNS:
        if only and name not in only:
            continue
        args = line.format(c=src / "configs").split() + ["-o", str(out / f"{name}.h5")]
        res = gcalign(src, args, out)
        (out / f"{name}.rc").write_text(f"{res.returncode}\n{res.stderr[-2000:]}")
        print(name, res.returncode, flush=True)
        if res.returncode == 0:
            show = gcalign(src, ["show", str(out / f"{name}.h5")], out)
            (out / f"{name}.show").write_text(show.stdout + show.stderr)


def _norm(v, srcs):
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    if isinstance(v, str):
        for s in srcs:
            v = v.replace(str(s), "<src>")
        return v
    return v


def _json_diff(a, b, where, srcs, out):
    if isinstance(a, dict) and isinstance(b, dict):
        if list(a) != list(b):
            out.append(f"{where}: keys {list(a)} != {list(b)}")
        for k in a:
            if k in b and not TIMINGS.search(str(k)):
                _json_diff(a[k], b[k], f"{where}.{k}", srcs, out)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _json_diff(x, y, f"{where}[{i}]", srcs, out)
    elif _norm(a, srcs) != _norm(b, srcs) or type(a) is not type(b):
        out.append(f"{where}: {a!r:.80} != {b!r:.80}")


def _same(x, y) -> bool:
    import numpy as np

    x, y = np.asarray(x), np.asarray(y)
    if x.dtype != y.dtype or x.shape != y.shape:
        return False
    if x.dtype.kind == "f":
        return bool(np.array_equal(x, y, equal_nan=True))
    if x.dtype.kind == "O":
        return [_norm(v, ()) for v in x.ravel()] == [_norm(v, ()) for v in y.ravel()]
    return bool(np.array_equal(x, y))


def _attrs(a, b, where, srcs, out) -> None:
    import h5py

    if list(a.attrs) != list(b.attrs):
        out.append(f"{where}: attributes {list(a.attrs)} != {list(b.attrs)}")
    for k in a.attrs:
        if k not in b.attrs or TIMINGS.search(k):
            continue
        x, y = a.attrs[k], b.attrs[k]
        if k == "summary_json":
            _json_diff(json.loads(x), json.loads(y), f"{where}@summary_json", srcs, out)
        elif k in ("DIMENSION_LIST", "REFERENCE_LIST"):  # references: compared by target
            if str(a.attrs.get_id(k).dtype) != str(b.attrs.get_id(k).dtype):
                out.append(f"{where}@{k}: type differs")
        elif isinstance(x, (str, bytes)) or isinstance(y, (str, bytes)):
            if type(x) is not type(y) or _norm(x, srcs) != _norm(y, srcs):
                out.append(f"{where}@{k}: {x!r:.60} != {y!r:.60}")
            elif a.attrs.get_id(k).dtype != b.attrs.get_id(k).dtype:
                out.append(f"{where}@{k}: type {a.attrs.get_id(k).dtype} != "
                           f"{b.attrs.get_id(k).dtype}")
        elif not _same(x, y) or h5py.check_string_dtype(a.attrs.get_id(k).dtype) != \
                h5py.check_string_dtype(b.attrs.get_id(k).dtype):
            out.append(f"{where}@{k}: {x!r:.60} != {y!r:.60}")


def compare_files(pa: Path, pb: Path, srcs) -> list[str]:
    import h5py

    out: list[str] = []
    with h5py.File(pa, "r") as a, h5py.File(pb, "r") as b:
        names_a, names_b = [], []
        a.visit(names_a.append)
        b.visit(names_b.append)
        if names_a != names_b:
            out.append(f"objects: only before {sorted(set(names_a) - set(names_b))}, only "
                       f"after {sorted(set(names_b) - set(names_a))}"
                       + ("" if set(names_a) != set(names_b) else ", order differs"))
        _attrs(a, b, "/", srcs, out)
        for n in names_a:
            if n not in b:
                continue
            x, y = a[n], b[n]
            if type(x) is not type(y):
                out.append(f"{n}: {type(x).__name__} != {type(y).__name__}")
                continue
            _attrs(x, y, n, srcs, out)
            if isinstance(x, h5py.Dataset):
                for prop in ("dtype", "shape", "compression", "compression_opts", "shuffle",
                             "chunks", "maxshape", "fletcher32", "scaleoffset"):
                    if getattr(x, prop) != getattr(y, prop):
                        out.append(f"{n}: {prop} {getattr(x, prop)} != {getattr(y, prop)}")
                if x.dtype == y.dtype and x.shape == y.shape and not TIMINGS.search(
                        n.rsplit("/", 1)[-1]) and not _same(x[()], y[()]):
                    out.append(f"{n}: values differ")
    return out


def compare(da: Path, db: Path, srcs) -> int:
    total = 0
    for name, _ in RUNS:
        fa, fb = da / f"{name}.h5", db / f"{name}.h5"
        ra = (da / f"{name}.rc").read_text().split("\n")[0] if (da / f"{name}.rc").exists() \
            else "-"
        rb = (db / f"{name}.rc").read_text().split("\n")[0] if (db / f"{name}.rc").exists() \
            else "-"
        if ra != rb:
            print(f"{name}: exit {ra} before, {rb} after")
            total += 1
            continue
        if not fa.exists() or not fb.exists():
            print(f"{name}: no file (exit {ra})")
            continue
        diffs = compare_files(fa, fb, srcs + [da, db])
        sa, sb = (da / f"{name}.show"), (db / f"{name}.show")
        if sa.exists() and sb.exists():
            # words joined first: a timing whose unit wrapped onto the next line is one too
            ta, tb = (" ".join(re.sub(r"\d+(\.\d+)? (m?s|min)\b|\S*/|\d{4}-\d\d-\d\dT\S+", "",
                                      " ".join(p.read_text().split())).split())
                      for p in (sa, sb))
            if ta != tb:
                diffs.append("show text differs")
        total += len(diffs)
        print(f"{name}: {len(diffs)} differences")
        for d in diffs[:20]:
            print("   ", d)
    print(f"total: {total} differences over {len(RUNS)} runs")
    return total


if __name__ == "__main__":
    what, *rest = sys.argv[1:]
    if what == "run":
        run(Path(rest[0]).resolve(), Path(rest[1]).resolve(), rest[2:])
    elif what == "compare":
        srcs = [Path(s).resolve() for s in rest[2:]]
        sys.exit(1 if compare(Path(rest[0]), Path(rest[1]), srcs) else 0)
    elif what == "reread":
        src, folder, out = (Path(x).resolve() for x in rest[:3])
        out.mkdir(parents=True, exist_ok=True)
        for name, _ in RUNS:
            f = folder / f"{name}.h5"
            if f.exists():
                res = gcalign(src, ["show", str(f)], out)
                (out / f"{name}.show").write_text(res.stdout + res.stderr)
                (out / f"{name}.rc").write_text(f"{res.returncode}\n")
