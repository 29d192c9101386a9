"""Damaged results files of every kind, and what reading them back must do.

:func:`make_files` writes one small real results file of every kind (each command's
output: simulate, navigate, align in gyrocompass and in transfer mode, northfind,
calibrate, observability, realtime, modulate, batch). :func:`cases` damages each of their
datasets in each of four ways (:data:`DAMAGES`):

* ``zeros(3)``: the dataset replaced by three zeros, its attributes (units, frame, ...)
  kept;
* ``strings``: replaced by two strings, attributes kept;
* ``NaN``: every value NaN (text: a NaN array);
* ``zeroed chunk``: its second half along axis 0 set to zero (text: empty strings).

Each damaged file is read back by plot, show, export (the kind's group, and the damaged
dataset's own time series group where that differs) and, for a gyrocompass alignment,
``navigate --init``; :func:`outcome` classes what each did against the undamaged file:

* ``same``: what the undamaged file gives (the same figures, the same columns and rows,
  the same table, the same exit code and message);
* ``refused``: exit 2, one line ``error: ...`` naming the file and the dataset;
* ``less``: exit 0 but fewer or other figures, columns or rows (silently drawn less);
* ``vague``: exit 2, one line, but the dataset is not named;
* ``internal``, ``traceback``, ``other``: an internal error, a traceback, anything else.

The contract (:func:`broken`): ``same`` or ``refused`` only, and ``refused`` where the
damage cannot be data: text where numbers were written, a shape other than the one
written, NaN in a dataset that never holds NaN, a zeroed time or quaternion.

``python tests/damage_cases.py [--only KIND]`` counts the outcomes (docs/robustness.md).
"""

from __future__ import annotations

import io
import json
import os
import shutil
import sys
from collections import Counter
from contextlib import redirect_stderr
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_cases as F  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TRANSFER_MAT = ROOT / "tests" / "data" / "transfer_align_fog_mems.mat"
DAMAGES = ("zeros(3)", "strings", "NaN", "zeroed chunk")
#: datasets that store NaN by design: a north-finding closed form that does not exist, a
#: failed run's metrics and wall time in a batch, and its statistics over no run
MAY_BE_NAN = ("/northfind/*/error_pred", "/northfind/*/std_pred", "/batch/runs/metrics/*",
              "/batch/runs/wall_s", "/batch/aggregate/*")
#: the kinds whose files are made, by label: (command line, scenario)
KINDS = ("simulate", "navigate", "align", "transfer", "northfind", "calibrate",
         "observability", "realtime", "modulate", "batch")
#: a representative damage per kind: the main series of the kind replaced by zeros(3)
REPRESENTATIVE = {
    "simulate": "/imu/dtheta", "navigate": "/navigate/att", "align": "/align/pass_01/att",
    "transfer": "/align/transfer/estimate", "northfind": "/northfind/coordinate/error",
    "calibrate": "/calibrate/runs/00/estimate", "observability": "/observability/eta",
    "realtime": "/realtime/cases/00/latched", "modulate": "/modulate/fixed/error/pos",
    "batch": "/batch/runs/metrics/error_t3_deg"}


def _cli(argv: list[str]):
    from typer.testing import CliRunner

    from gcalign.cli import app

    return CliRunner().invoke(app, [str(a) for a in argv], catch_exceptions=True)


def _transfer_scenario(folder: Path) -> Path:
    """The PSINS FOG/MEMS file's first 20 s as a file of its own (slave and master), with
    the demo configuration: a transfer alignment in a second."""
    import scipy.io
    import yaml

    d = scipy.io.loadmat(TRANSFER_MAT)
    t0 = d["mimu"][0, -1]
    keep = {"mimu": d["mimu"][d["mimu"][:, -1] < t0 + 20.0],
            "fogavp": d["fogavp"][d["fogavp"][:, -1] < t0 + 20.0]}
    keep.update({k: d[k] for k in ("eb0", "db0", "mu0") if k in d})
    scipy.io.savemat(folder / "tr.mat", keep)
    cfg = yaml.safe_load((ROOT / "configs" / "psins_transfer_fog_mems.yaml").read_text())
    cfg["imu_file"] = "tr.mat"
    (folder / "TR.yaml").write_text(yaml.safe_dump(cfg))
    return folder / "TR.yaml"


def make_files(folder: Path, kinds=KINDS) -> dict[str, Path]:
    """One small real results file of each of `kinds` in `folder` (made in-process; the
    scenarios are the fuzz suite's bases)."""
    folder = Path(folder)
    here = os.getcwd()
    os.chdir(folder)
    try:
        for name, data in (("S", F.S), ("FL", F.FLIGHT), ("NF", F.NORTHFIND),
                           ("CAL", F.CALIBRATE), ("RT", F.REALTIME), ("MO", F.MODULATE)):
            Path(f"{name}.yaml").write_text(F.emit(data))
        Path("SW.yaml").write_text(F.emit(F.SWEEP))
        argv = {"simulate": ["simulate", "FL.yaml"], "navigate": ["navigate", "FL.yaml"],
                "align": ["align", "S.yaml"], "northfind": ["northfind", "NF.yaml"],
                "calibrate": ["calibrate", "CAL.yaml"],
                "observability": ["observability", "CAL.yaml"],
                "realtime": ["realtime", "RT.yaml"], "modulate": ["modulate", "MO.yaml"],
                "batch": ["batch", "SW.yaml", "-w", "1"]}
        out = {}
        for kind in kinds:
            line = ["align", _transfer_scenario(folder)] if kind == "transfer" else argv[kind]
            res = _cli([*line, "-o", f"{kind}.h5"])
            assert res.exit_code == 0, (kind, res.stderr)
            out[kind] = folder / f"{kind}.h5"
    finally:
        os.chdir(here)
    return out


def datasets(path: Path) -> list[str]:
    """Every dataset of a results file, by name, in file order."""
    import h5py

    names: list[str] = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: names.append(o.name) if isinstance(o, h5py.Dataset) else None)
    return names


_SCALE_ATTRS = ("CLASS", "NAME", "REFERENCE_LIST", "DIMENSION_LIST")  # HDF5's bookkeeping


def damage(path: Path, name: str, how: str) -> None:
    """Damage dataset `name` of the file `path` in place (:data:`DAMAGES`)."""
    import h5py

    with h5py.File(path, "a") as f:
        ds = f[name]
        is_text = h5py.check_string_dtype(ds.dtype) is not None or ds.dtype.kind == "O"
        attrs = {k: v for k, v in ds.attrs.items() if k not in _SCALE_ATTRS}
        if how == "zeroed chunk":
            a = ds[()]
            if is_text:
                a = np.array(a, dtype=object)
            if a.ndim == 0:
                a = "" if is_text else 0
            else:
                a[len(a) // 2:] = b"" if is_text else 0
        elif how == "NaN":
            a = np.full(ds.shape, np.nan)
        elif how == "two columns":  # the dataset stacked beside itself
            a = np.stack([ds[()]] * 2, axis=-1)
        else:
            a = np.zeros(3) if how == "zeros(3)" else np.array([b"a", b"b"])
        del f[name]
        if is_text and how == "zeroed chunk":
            f.create_dataset(name, data=a, dtype=h5py.string_dtype())
        else:
            f[name] = a
        for k, v in attrs.items():
            f[name].attrs[k] = v


def undeclared(kind: str, path: Path) -> list[str]:
    """The datasets of a results file of `kind` that no entry of its kind's schema
    (:data:`gcalign.app.checked.SCHEMAS`) names."""
    import h5py

    from gcalign.app import checked

    named: set[str] = set()
    with h5py.File(path, "r") as f:
        for block in checked.SCHEMAS[f.attrs["kind"]]:
            for g in checked._Tree(f).matches(block.where, h5py.Group):
                tree = checked._Tree(g)
                for rel in block.items:
                    named.update(d.name for d in tree.matches(rel.rstrip("?")))
    return [n for n in datasets(path) if n not in named]


@dataclass(frozen=True)
class Result:
    """What one command did: exit code, stderr, and its output reduced to what is
    compared (figure names, export header and row count, show's text)."""

    code: int
    stderr: str
    output: tuple


def _run(command: str, path: Path, folder: Path, kind: str, group: str | None) -> Result:
    for p in ("figs", "out.csv", "n.h5"):
        q = folder / p
        shutil.rmtree(q) if q.is_dir() else q.unlink(missing_ok=True)
    err = io.StringIO()
    if command == "plot":
        argv = ["plot", path, "-o", folder / "figs"]
    elif command == "show":
        argv = ["show", path]
    elif command == "export":
        argv = ["export", path, "--format", "csv", "-o", folder / "out.csv"]
        argv += ["--group", group] if group else []
    else:  # init
        argv = ["navigate", path.parent / "S.yaml", "--init", path, "-o", folder / "n.h5"]
    with redirect_stderr(err):
        res = _cli(argv)
    stderr = res.stderr
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        import traceback

        stderr += "".join(traceback.format_exception(res.exception))
    output: tuple = ()
    if res.exit_code == 0:
        if command == "plot":
            figs = folder / "figs"
            output = tuple(sorted((p.name, p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
                                   and p.stat().st_size > 1000) for p in figs.iterdir()))
        elif command == "export":
            lines = (folder / "out.csv").read_text().splitlines()
            output = (lines[1], len(lines))
        elif command == "show":
            output = (res.stdout,)
        else:
            output = ((folder / "n.h5").is_file(),)
    return Result(res.exit_code, stderr, output)


def commands(kind: str, name: str | None = None) -> list[tuple[str, str | None]]:
    """The read-backs of a file of `kind` (damaged at dataset `name`): plot, show, export
    of the kind's group and of the group holding `name`'s series, ``--init``."""
    out: list[tuple[str, str | None]] = [("plot", None), ("show", None), ("export", None)]
    if name is not None:
        timed = timed_group(kind, name)
        if timed is not None:
            out.append(("export", timed))
    if kind == "align":
        out.append(("init", None))
    return out


_TIMED: dict[tuple[str, str], str | None] = {}


def timed_group(kind: str, name: str) -> str | None:
    """The group that exports `name` as a series (the nearest above it with a time ``t``
    of its own), if not the kind's default group."""
    return _TIMED.get((kind, name))


def index_timed_groups(kind: str, path: Path) -> None:
    import h5py

    default = {"simulate": "truth", "transfer": "align"}.get(kind, kind)
    with h5py.File(path, "r") as f:
        for name in datasets(path):
            g = f[name].parent
            while g.name != "/" and not ("t" in g and isinstance(g["t"], h5py.Dataset)):
                g = g.parent
            own = g.name.strip("/")
            _TIMED[(kind, name)] = own if own and own != default else None


def outcome(r: Result, base: Result, path: Path, name: str) -> str:
    """The class of `r`, the read-back of a file damaged at dataset `name`, against `base`,
    the same read-back of the undamaged file (module docstring)."""
    lines = r.stderr.strip().splitlines()
    if "Traceback" in r.stderr:
        return "traceback"
    if r.code == base.code and r.output == base.output and (
            r.code == 0 or lines == base.stderr.strip().splitlines()):
        return "same"
    if r.code == 0:
        return "less"
    if len(lines) == 1 and "internal error" in lines[0]:
        return "internal"
    if r.code == 2 and len(lines) == 1 and lines[0].startswith("error: "):
        return "refused" if str(path) in lines[0] and name in lines[0] else "vague"
    return "other"


def must_refuse(name: str, how: str, shape: tuple, is_text: bool) -> bool:
    """Damage that cannot be data: text where numbers were written, a shape other than
    the one written, NaN where NaN is never written, a zeroed time or quaternion."""
    import fnmatch

    leaf = name.rsplit("/", 1)[-1]
    if how == "strings":
        return not is_text or shape != (2,)
    if how == "zeros(3)":
        return is_text or shape != (3,)
    if how == "NaN":
        return is_text or not any(fnmatch.fnmatchcase(name, p) or
                                  fnmatch.fnmatchcase(name, p + "/*") for p in MAY_BE_NAN)
    return not is_text and leaf in ("t", "t0", "t1", "q", "q_bs") and (shape[0] > 1)


@dataclass(frozen=True)
class Case:
    kind: str
    name: str
    how: str
    shape: tuple
    text: bool


def cases(files: dict[str, Path]) -> list[Case]:
    """Every (kind, dataset, damage) of the files."""
    import h5py

    out = []
    for kind, path in files.items():
        index_timed_groups(kind, path)
        with h5py.File(path, "r") as f:
            for name in datasets(path):
                ds = f[name]
                is_text = h5py.check_string_dtype(ds.dtype) is not None or ds.dtype.kind == "O"
                out.extend(Case(kind, name, how, ds.shape, is_text) for how in DAMAGES)
    return out


def baselines(files: dict[str, Path], folder: Path) -> dict[tuple, Result]:
    """Every read-back of every undamaged file."""
    out = {}
    for kind, path in files.items():
        index_timed_groups(kind, path)
        groups = {None} | {timed_group(kind, n) for n in datasets(path)}
        for command in ("plot", "show", "export", "init"):
            for g in groups if command == "export" else {None}:
                if command != "init" or kind == "align":
                    out[(kind, command, g)] = _run(command, path, folder, kind, g)
    return out


def run_case(case: Case, files: dict[str, Path], base: dict, folder: Path) -> dict[str, str]:
    """The outcome of each read-back of one damaged file, by command (``export`` of the
    kind's group, ``export --group G``, ...)."""
    src = files[case.kind]
    path = folder / f"d-{case.kind}.h5"
    shutil.copy(src, path)
    (folder / "S.yaml").write_text((src.parent / "S.yaml").read_text())
    damage(path, case.name, case.how)
    out = {}
    for command, group in commands(case.kind, case.name):
        r = _run(command, path, folder, case.kind, group)
        b = base[(case.kind, command, group)]
        b = Result(b.code, b.stderr.replace(str(src), str(path)), b.output)
        label = command if group is None else f"{command} --group"
        out[label] = outcome(r, b, path, case.name)
    return out


def broken(case: Case, got: dict[str, str]) -> list[str]:
    """What breaks the contract: an outcome other than same or refused, or not refused
    where the damage cannot be data (:func:`must_refuse`)."""
    bad = [f"{c}: {o}" for c, o in got.items() if o not in ("same", "refused")]
    if must_refuse(case.name, case.how, case.shape, case.text):
        bad += [f"{c}: same, must refuse" for c, o in got.items() if o == "same"]
    return bad


def main(argv: list[str]) -> int:
    import argparse
    import tempfile
    import time

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--only", nargs="*", default=list(KINDS))
    p.add_argument("--json", type=Path, help="write every case's outcomes here")
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "files").mkdir()
        t0 = time.perf_counter()
        files = make_files(folder / "files", a.only)
        base = baselines(files, folder)
        print(f"files and baselines: {time.perf_counter() - t0:.0f} s", file=sys.stderr)
        tally: Counter = Counter()
        per_kind: dict[str, Counter] = {}
        records = []
        for i, case in enumerate(cases(files)):
            got = run_case(case, files, base, folder)
            bad = broken(case, got)
            records.append({"kind": case.kind, "dataset": case.name, "damage": case.how,
                            "outcomes": got, "broken": bad})
            per_kind.setdefault(case.kind, Counter()).update(
                {"cases": 1, "broken": int(bool(bad)), "read-backs": len(got)})
            per_kind[case.kind].update(got.values())
            tally.update(got.values())
            if i % 50 == 0:
                print(f"{i} cases, {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    if a.json:
        a.json.write_text(json.dumps(records, indent=1))
    classes = ("same", "refused", "less", "vague", "internal", "traceback", "other")
    head = ("cases", "broken", "read-backs", *classes)
    print("| kind | " + " | ".join(head) + " |")
    print("| --- | " + " | ".join("---:" for _ in head) + " |")
    total: Counter = Counter()
    for kind, c in [*per_kind.items(), ("all", None)]:
        c = total if c is None else c
        print(f"| {kind} | " + " | ".join(str(c[k]) for k in head) + " |")
        if kind != "all":
            total.update(c)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
