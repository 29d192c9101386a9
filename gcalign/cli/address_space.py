"""The command line under an address-space limit (``ulimit -v``, ``RLIMIT_AS``).

NumPy and SciPy each carry a copy of OpenBLAS, and each copy maps a buffer of 33 MB per
thread on its first call. When that mapping is refused, OpenBLAS neither returns nor
raises: it prints its own message and calls ``exit(1)`` ("Memory allocation still failed
after 10 retries, giving up"), or retries without end, so the run's temporary file stays
and the last line is not ours. Under a limit, therefore (:func:`prepare`, before NumPy is
imported):

* one OpenBLAS thread (each further thread of each copy maps its own buffer and a stack,
  40 MB), unless ``OPENBLAS_NUM_THREADS``, ``GOTO_NUM_THREADS`` or ``OMP_NUM_THREADS`` is
  set;
* each copy's buffer taken when the library is loaded (a 2 × 2 LAPACK solve, whose buffer
  later products reuse: NumPy's when NumPy is imported, SciPy's when ``scipy.linalg`` is),
  after checking that the room is there; later calls reuse it, so a later shortage is a
  MemoryError of NumPy, which the command line reports as its one ``out of memory`` line
  (:mod:`gcalign.cli`).

:mod:`gcalign.cli` imports this module first, and importing it prepares the process.
"""

from __future__ import annotations

import importlib.abc
import os
import resource
import sys

THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")
#: room an OpenBLAS buffer needs: 33 MB mapped, and what the call itself allocates
BUFFER_BYTES = 48 * 2**20


def address_limit() -> int | None:
    """The soft limit of the address space in bytes, or None without one."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    return None if soft == resource.RLIM_INFINITY else int(soft)


def mapped_bytes() -> int:
    """The process's mapped address space (Linux ``/proc/self/statm``; 0 elsewhere)."""
    try:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def warm(library: str) -> None:
    """Make `library`'s OpenBLAS (``numpy`` or ``scipy``) take its buffer now; MemoryError
    when the limit leaves no room for it (OpenBLAS would end the process instead)."""
    limit = address_limit()
    if limit is not None and limit - mapped_bytes() < BUFFER_BYTES:
        raise MemoryError(f"the address-space limit (ulimit -v, {limit >> 20} MB) leaves "
                          f"{(limit - mapped_bytes()) >> 20} MB, {library}'s OpenBLAS needs "
                          f"{BUFFER_BYTES >> 20} MB")
    import numpy as np

    # A LAPACK solve, not a product: a product's buffer is not the one LAPACK takes, and a
    # first solve late in a run (realtime's lfilter_zi at 520 MB) still ended the process.
    a = np.eye(2)
    if library == "numpy":
        np.linalg.solve(a, a)
    else:
        from scipy.linalg import lapack

        lapack.dgesv(a, a)


class _WarmScipy(importlib.abc.MetaPathFinder):
    """Finds ``scipy.linalg`` through the other finders and gives it a loader that warms
    SciPy's OpenBLAS once the package has run."""

    def find_spec(self, name, path, target=None):
        if name != "scipy.linalg":
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(name, path, target)
            if spec is not None and spec.loader is not None:
                spec.loader = _WarmingLoader(spec.loader)
                sys.meta_path.remove(self)  # once
                return spec
        return None


class _WarmingLoader(importlib.abc.Loader):
    def __init__(self, inner):
        self._inner = inner

    def create_module(self, spec):
        return self._inner.create_module(spec)

    def exec_module(self, module) -> None:
        self._inner.exec_module(module)
        warm("scipy")

    def __getattr__(self, name: str):  # get_filename, get_resource_reader, ...
        return getattr(self._inner, name)


def prepare() -> None:
    """Before NumPy is imported: under an address-space limit, one OpenBLAS thread and
    the buffers taken when the libraries load (module docstring). SystemExit(1) with the
    one ``out of memory`` line when not even NumPy's fits."""
    if address_limit() is None:
        return
    if not any(v in os.environ for v in THREAD_VARIABLES):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"
    if "scipy.linalg" not in sys.modules:
        sys.meta_path.insert(0, _WarmScipy())
    try:
        warm("numpy")
    except (MemoryError, ImportError, OSError) as err:  # a library that cannot be mapped
        reason = (str(err).strip().splitlines() or [type(err).__name__])[0][:160]
        sys.stderr.write(f"error: out of memory: {reason}\n")
        sys.stderr.flush()
        raise SystemExit(1) from None


prepare()
