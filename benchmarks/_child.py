"""A benchmark script serving runs from another process, one question per line.

The script is started again with ``--serve --seeds N`` under the checkout `tree` (its
``PYTHONPATH`` and working folder), prints ``ready``, then answers each ``WHAT K`` line with
one line of JSON: two checkouts served side by side are timed in turns, in one process each.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path


class Child:
    def __init__(self, script: Path, tree: Path, seeds: int):
        env = dict(os.environ, PYTHONPATH=str(tree))
        self.p = subprocess.Popen([sys.executable, str(script), "--serve", "--seeds", str(seeds)],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                  env=env, cwd=tree)
        assert self.p.stdout is not None and self.p.stdout.readline().strip() == "ready"

    def ask(self, what: str, k: int) -> dict:
        assert self.p.stdin is not None and self.p.stdout is not None
        self.p.stdin.write(f"{what} {k}\n")
        self.p.stdin.flush()
        return json.loads(self.p.stdout.readline())

    def close(self) -> None:
        assert self.p.stdin is not None
        self.p.stdin.close()
        self.p.wait()
