"""Resource limits: what one run may cost before gcalign refuses it (docs: Reference, Limits).

Every limit has a default that fits this project's machines and can be raised (or lowered)
explicitly with an environment variable of the same name, e.g.::

    GCALIGN_MAX_SAMPLES=5e9 gcalign simulate long.yaml

A run whose estimated cost exceeds a limit is refused before it starts, with one line that
names the estimate, the limit and the variable (exit 2). Memory defaults to half of the
memory available when the command starts.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass

from gcalign.errors import ScenarioError

SEED_MAX = 2**63 - 1  #: seeds are stored as signed 64-bit integers (HDF5, numpy)


@dataclass(frozen=True)
class Limit:
    env: str
    default: float | Callable[[], float]
    what: str  # "IMU samples", ...
    unit: str = ""

    def value(self) -> float:
        text = os.environ.get(self.env)
        if text is None or not text.strip():
            return self.default() if callable(self.default) else self.default
        try:
            v = float(text)
        except ValueError:
            raise ScenarioError(f"{self.env}: must be a number, got {text[:40]!r}") from None
        if not v > 0:
            raise ScenarioError(f"{self.env}: must be > 0, got {text[:40]!r}")
        return v

    def check(self, estimate: float, where: str, hint: str = "") -> None:
        """ScenarioError (one line) if `estimate` exceeds the limit."""
        limit = self.value()
        if estimate > limit:
            hint = f"; {hint}" if hint else ""
            raise ScenarioError(
                f"{where}: needs {_num(estimate)}{self.unit} {self.what}, more than the limit "
                f"{_num(limit)}{self.unit}{hint} (raise it with {self.env}=N if intended)")


def _num(x: float) -> str:
    return f"{x:.3g}" if x >= 1e5 or x != int(x) else f"{int(x)}"


def _half_available_mb() -> float:
    """Half the memory available now (MemAvailable), in MB; 4096 where it is unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) / 1024 / 2
    except OSError:
        pass
    return 4096.0


MAX_SAMPLES = Limit("GCALIGN_MAX_SAMPLES", 2e9, "IMU samples")
MAX_MEMORY_MB = Limit("GCALIGN_MAX_MEMORY_MB", _half_available_mb, "of memory", " MB")
MAX_OUTPUT_MB = Limit("GCALIGN_MAX_OUTPUT_MB", 20_000, "of stored series", " MB")
#: Input files held in memory at once (a recording, an aiding or reference file), after
#: decompression: checked from the size on disk before reading, and while decompressing.
MAX_INPUT_MB = Limit("GCALIGN_MAX_INPUT_MB", 1024, "of input data", " MB")
MAX_RUNS = Limit("GCALIGN_MAX_RUNS", 1e6, "runs")
MAX_VARIANTS = Limit("GCALIGN_MAX_VARIANTS", 20_000, "variants")
MAX_YAML_NODES = Limit("GCALIGN_MAX_YAML_NODES", 1e6, "YAML values after expanding aliases")
MAX_YAML_MB = Limit("GCALIGN_MAX_YAML_MB", 4, "of YAML", " MB")
MAX_WORKERS = Limit("GCALIGN_MAX_WORKERS", float(2 * (os.cpu_count() or 1)), "worker processes")
#: Arithmetic of one run, as its command's cost model counts it (multiply-adds: filter
#: taps × samples, PWCS pieces × 21³, strapdown steps × their operations); 1e12 is about a
#: quarter of an hour on one core of this project's machines.
MAX_WORK = Limit("GCALIGN_MAX_WORK", 1e12, "operations")
#: realtime holds every sensor sample of its cases at once (its pulses are drawn from them).
MAX_REALTIME_SAMPLES = Limit("GCALIGN_MAX_REALTIME_SAMPLES", 5e7,
                             "sensor samples of all realtime cases together")
#: northfind with ``samples: true`` simulates every sample of every dwell.
MAX_NORTHFIND_SAMPLES = Limit("GCALIGN_MAX_NORTHFIND_SAMPLES", 2e8,
                              "simulated samples per sensor")
#: northfind keeps azimuths × repeats × positions dwell readings (its result arrays).
MAX_NORTHFIND_READINGS = Limit("GCALIGN_MAX_NORTHFIND_READINGS", 2e6, "dwell readings")
