"""Start-up of the command line (DESIGN.md "Performance": warm ``gcalign align`` end to end
≤ 1 s CPU).

Every row is a child process's CPU time (user + system, from ``getrusage``), the median of
``--runs`` (≥ 5) runs; the contenders are interleaved (align, bare, help, validate, align,
…) so that a loaded machine slows them alike, and each is also given as a multiple of the
bare ``python -c "import numpy, numba"``, the floor of any command that runs a kernel:
that ratio holds on a loaded machine, where the seconds do not.

* ``gcalign align -o TMP`` (the built-in seed-000 §5.3 scenario) with warm caches: one run
  before the timed ones writes numba's cache and the ``.pyc`` files (the children run with
  bytecode writing on, whatever ``PYTHONDONTWRITEBYTECODE`` says, as an installed package
  has its ``.pyc`` files). Target ≤ 1.0 s CPU, stretch 0.8 s.
* ``gcalign --help`` and ``gcalign validate`` (no kernel: they must not load numba).
* the modules each command loads that it does not need (matplotlib, scipy.linalg, dask for
  align; numba, h5py for validate; numba, numpy, pydantic for --help), from one extra run.

A command runs as the ``gcalign`` script does: the entry point of the tree's
``pyproject.toml`` (``[project.scripts]``) with the tree first on ``PYTHONPATH``.
``--before DIR`` interleaves the same rows for another checkout (e.g. ``git archive main |
tar -x -C DIR``), so that a change is measured before and after in one run.

Run: ``python benchmarks/bench_startup.py [--runs 7] [--before DIR]``
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes
TARGET_S, STRETCH_S = 1.0, 0.8
BARE = "import numpy, numba"
#: modules a command loads although it does not use them
UNNEEDED = {
    "align": ("matplotlib", "scipy.linalg", "scipy.stats", "dask", "distributed", "pandas"),
    "validate": ("numba", "h5py", "matplotlib", "scipy.linalg", "dask"),
    "help": ("numba", "numpy", "pydantic", "h5py", "yaml", "matplotlib", "scipy"),
}


def entry_point(tree: Path) -> str:
    """``module:function`` of the ``gcalign`` script in the tree's pyproject.toml."""
    text = (tree / "pyproject.toml").read_text(encoding="utf-8")
    m = re.search(r'^gcalign\s*=\s*"([\w.]+):(\w+)"', text, re.MULTILINE)
    if m is None:
        raise SystemExit(f"{tree}/pyproject.toml: no gcalign script in [project.scripts]")
    return f"{m.group(1)}:{m.group(2)}"


def child_env(tree: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(PYTHONPATH=os.pathsep.join(filter(None, [str(tree), env.get("PYTHONPATH")])),
               TERM="dumb", GCALIGN_PROGRESS="never")
    return env


def script(tree: Path, prologue: str = "") -> list[str]:
    """The interpreter running the tree's ``gcalign`` script (after `prologue`)."""
    module, func = entry_point(tree).split(":")
    return [sys.executable, "-c",
            f"{prologue}import sys; from {module} import {func}; sys.exit({func}())"]


def child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cpu_of(cmd: list[str], env: dict[str, str], cwd: Path) -> float:
    before = child_cpu()
    res = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"{' '.join(cmd[-4:])} failed ({res.returncode}): {res.stderr[-800:]}")
    return child_cpu() - before


def unneeded(tree: Path, args: list[str], names: tuple[str, ...], cwd: Path) -> list[str]:
    """Which of `names` the command loads (one run, its modules listed at exit)."""
    probe = ("import atexit, json, sys; atexit.register(lambda: sys.stderr.write("
             f"'\\nMODULES ' + json.dumps([n for n in {list(names)!r} if n in sys.modules])"
             " + '\\n')); ")
    res = subprocess.run([*script(tree, probe), *args], env=child_env(tree), cwd=cwd,
                         capture_output=True, text=True)
    found = re.findall(r"^MODULES (.*)$", res.stderr, re.MULTILINE)
    if res.returncode != 0 or not found:
        raise SystemExit(f"{args}: failed ({res.returncode}): {res.stderr[-800:]}")
    return list(json.loads(found[-1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1 if SMOKE else 7, help="timed runs of each")
    ap.add_argument("--before", type=Path, help="another checkout, interleaved as 'before'")
    args = ap.parse_args()
    if not SMOKE and args.runs < 5:
        ap.error("--runs: at least 5 (medians of ≥ 5 runs)")
    trees = {"": ROOT} if args.before is None else {"before": args.before.resolve(),
                                                    "after": ROOT}
    with tempfile.TemporaryDirectory() as tmp_:
        tmp = Path(tmp_)
        config = ROOT / "configs" / "seed000_moving_full_cycle.yaml"
        cases: dict[str, tuple[list[str], dict[str, str]]] = {
            "python -c 'import numpy, numba'": ([sys.executable, "-c", BARE],
                                                child_env(ROOT))}
        probes = []
        for label, tree in trees.items():
            tag = f" ({label})" if label else ""
            env = child_env(tree)
            commands = {"align": ["align", "-o", str(tmp / f"align{label}.h5")],
                        "--help": ["--help"], "validate": ["validate", str(config)]}
            for name, argv in commands.items():
                cases[f"gcalign {name}{tag}"] = ([*script(tree), *argv], env)
                probes.append((f"gcalign {name}{tag}", tree, argv,
                               UNNEEDED["help" if name == "--help" else name]))
        for cmd, env in cases.values() if not SMOKE else ():  # warm: numba's cache, .pyc
            cpu_of(cmd, env, tmp)  # files, the OS's caches (smoke: the figures mean nothing)
        load0 = os.getloadavg()
        times: dict[str, list[float]] = {k: [] for k in cases}
        for _ in range(args.runs):
            for name, (cmd, env) in cases.items():
                times[name].append(cpu_of(cmd, env, tmp))
        load1 = os.getloadavg()
        loaded = {name: unneeded(tree, argv, names, tmp) for name, tree, argv, names in probes}
    med = {k: statistics.median(v) for k, v in times.items()}
    bare = med["python -c 'import numpy, numba'"]
    print(f"gcalign start-up: python {sys.version.split()[0]}, {os.cpu_count()} CPUs; load "
          f"average {load0[0]:.2f} before the timed runs, {load1[0]:.2f} after; CPU (user + "
          f"sys) of a child, medians of {args.runs} interleaved runs")
    width = max(map(len, med))
    print(f"  {'':<{width}}  {'CPU s':>6}  {'range':>11}  {'× bare':>6}  unneeded modules loaded")
    for name, m in med.items():
        lo, hi = min(times[name]), max(times[name])
        extra = loaded.get(name)
        note = "" if extra is None else (", ".join(extra) or "none")
        print(f"  {name:<{width}}  {m:6.2f}  {lo:5.2f}–{hi:<5.2f}  {m / bare:6.2f}  {note}")
    for label in trees:
        tag = f" ({label})" if label else ""
        m = med[f"gcalign align{tag}"]
        print(f"  align{tag}: {m:.2f} s, target ≤ {TARGET_S:g} s (stretch {STRETCH_S:g}): "
              f"{'met' if m <= TARGET_S else 'not met'} here; {m / bare:.2f} × bare")
    if args.before is not None:
        b, a = med["gcalign align (before)"], med["gcalign align (after)"]
        print(f"  align after / before: {a / b:.2f} ({b - a:.2f} s less)")


if __name__ == "__main__":
    main()
