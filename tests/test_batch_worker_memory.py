"""A batch worker keeps the memory a run frees for the next run (glibc's mallopt): runs of
the same sizes do not fault their pages in again (the default trims the heap above twice
the largest block freed, and a §5.3 run has about 15 MB of arrays of 1 MB)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

ROUNDS = """
import json, resource
import numpy as np
from gcalign.app.batch.runs import keep_freed_memory
def run():  # twenty 1 MB arrays alive at once, then all freed: a run's pattern
    arrays = [np.ones(131072) for _ in range(20)]
    return sum(float(a[0]) for a in arrays)
def faults_per_round():
    run()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(10):
        run()
    return (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / 10
default = faults_per_round()
took = keep_freed_memory()
print(json.dumps({"default": default, "took": took, "kept": faults_per_round()}))
"""


@pytest.mark.slow  # a fresh interpreter (its allocator untouched by this one)
def test_kept_memory_is_reused_without_page_faults():
    out = json.loads(subprocess.run([sys.executable, "-c", ROUNDS], capture_output=True,
                                    text=True, check=True).stdout)
    assert out["took"] is True
    # 20 MB freed a round: the default hands most back and faults ~4000 pages in again
    assert out["default"] > 1000, out
    assert out["kept"] < 50, out
