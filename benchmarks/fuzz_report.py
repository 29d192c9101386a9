"""Run the fuzz cases in child processes and count violations per class.

Each case runs ``gcalign`` in a new process, in an empty folder, under a time limit and an
address-space limit, so that a version without the fixes (hangs, memory blow-ups) can be
measured too::

    python benchmarks/fuzz_report.py --seed 14 [--src DIR] [--timeout 60] [--json out.json]

``--src`` puts another checkout's ``gcalign`` first on the path (e.g. an export of main:
``git archive main | tar -x -C /tmp/main``), to count before and after the fixes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import fuzz_cases as F  # noqa: E402

SMOKE = os.environ.get("GCALIGN_BENCH_SMOKE") == "1"  #: python -m benchmarks --smoke: tiny sizes


def run(case: F.Case, src: str | None, timeout: float, mem_gb: float) -> F.Outcome:
    env = {k: v for k, v in os.environ.items() if not k.startswith("GCALIGN_")}
    env.update(F.FUZZ_ENV)
    env.update(dict(case.env))
    if src:
        env["PYTHONPATH"] = src
    cmd = [sys.executable, "-c", "import sys; from gcalign.cli import main; "
           "sys.argv[0] = 'gcalign'; main()"]

    def limit():
        lim = int(mem_gb * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (lim, lim))

    with tempfile.TemporaryDirectory() as d:
        argv = F.materialize(case, d)
        before = F.snapshot(d)
        t0 = time.perf_counter()
        try:
            p = subprocess.run(cmd + argv, cwd=d, env=env, capture_output=True,
                               timeout=timeout, preexec_fn=limit, stdin=subprocess.DEVNULL)
            code, err, note = p.returncode, p.stderr.decode("utf-8", "replace"), ""
            if code < 0:
                code, note = None, f"killed by signal {-code}"
            elif "MemoryError" in err:
                note = "exception MemoryError"
        except subprocess.TimeoutExpired as exc:
            code, note = None, f"hang: no answer within {timeout:g} s"
            err = (exc.stderr or b"").decode("utf-8", "replace")
        elapsed = time.perf_counter() - t0
        new = sorted(F.snapshot(d) - before)
        out = F.Outcome(code, err, new, elapsed, note=note)
        if code in (0, 1):
            out.summary = F.read_summary(d, case)
        if case.validate is not None and code is not None:
            try:
                v = subprocess.run(cmd + ["validate", case.validate], cwd=d, env=env,
                                   capture_output=True, timeout=timeout, preexec_fn=limit)
                out.validate_exit = v.returncode
                out.validate_stderr = v.stderr.decode("utf-8", "replace")
            except subprocess.TimeoutExpired:
                out.validate_exit = None
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--src", default=None)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--mem-gb", type=float, default=4.0)
    ap.add_argument("--json", default=None)
    ap.add_argument("--only", default=None, help="substring of the case ids to run")
    args = ap.parse_args()
    cases = F.all_cases(args.seed)
    if args.only:
        cases = [c for c in cases if args.only in c.id]
    if SMOKE:
        cases = cases[:: len(cases) // 4][:4]  # a few, spread over the classes
    total, bad = Counter(), Counter()
    rows = []
    for i, case in enumerate(cases):
        out = run(case, args.src, args.timeout, args.mem_gb)
        v = F.violations(case, out)
        total[case.cls] += 1
        bad[case.cls] += bool(v)
        rows.append({"i": i, "id": case.id, "cls": case.cls, "exit": out.exit_code,
                     "violations": v, "elapsed_s": round(out.elapsed_s, 2),
                     "stderr": out.stderr.strip()[-300:], "new_files": out.new_files,
                     "validate_exit": out.validate_exit, "note": out.note,
                     "non_finite": F._non_finite(out.summary)})
        print(f"{i:4d} {'FAIL' if v else 'ok  '} {out.elapsed_s:6.1f}s {case.id[:90]}"
              + (f"  <- {'; '.join(v)}" if v else ""), flush=True)
    print("\nclass  cases  broken")
    for c in sorted(total):
        print(f"{c:5d}  {total[c]:5d}  {bad[c]:6d}")
    print(f"  all  {sum(total.values()):5d}  {sum(bad.values()):6d}")
    if args.json:
        Path(args.json).write_text(json.dumps({"total": total, "broken": bad, "rows": rows},
                                              indent=1))


if __name__ == "__main__":
    main()
