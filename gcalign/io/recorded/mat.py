"""PSINS MATLAB files (``psins-mat``): the one place that opens them.

A PSINS ``.mat`` (MATLAB v5/v7, what ``save`` writes by default) holds plain numeric arrays:
an IMU ``[wm(3) vm(3) t]`` (:mod:`.imu`), an ``avp`` ``[att(3) v(3) lat lon h t]``
(:mod:`.reference`), and whatever else the user saved (PSINS's demos store their own
end-of-run estimates ``eb0``, ``db0``, ``mu0``: :func:`read_vectors`). Every reader of the
format takes its arrays from :func:`arrays`, so a damaged or v7.3 file is refused in one
wording wherever it is read; :func:`shapes` lists the variables without reading their
data (a cost estimate before a run).
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Callable
from typing import TypeVar

import numpy as np

from gcalign.io.imu_files import ImuFileError, read_bytes

__all__ = ["arrays", "read_vectors", "shapes"]

T = TypeVar("T")


def arrays(name: str, data: bytes) -> dict[str, np.ndarray]:
    """The numeric arrays of a MAT file's content `data` (`name` for messages), by variable
    name; ImuFileError (one line naming the file) for what ``scipy.io.loadmat`` cannot read."""
    import scipy.io

    from gcalign import limits

    if b"\x00" not in data[:128]:  # a MAT file's header holds binary fields by byte 128
        what = ("an empty file" if not data.strip() else "text" if _is_text(data[:4096])
                else "its first 128 bytes are not a MAT header")
        raise ImuFileError(f"{name}: {what}, not a MATLAB file; format psins-mat reads the MAT "
                           "v5/v7 files MATLAB's save writes (a text table: format csv)")
    # the arrays' sizes from their headers first: compressed ones can be huge
    found = _parsed(name, lambda: scipy.io.whosmat(io.BytesIO(data)))
    held = sum(8.0 * math.prod(int(n) for n in shape) for _, shape, _ in found)
    limits.MAX_INPUT_MB.check(held / 2**20, f"{name} (its arrays)", "read a part of it")
    mat = _parsed(name, lambda: scipy.io.loadmat(io.BytesIO(data)))
    return {k: v for k, v in mat.items() if not k.startswith("__")
            and isinstance(v, np.ndarray) and v.dtype.kind in "fiu"}


def _is_text(head: bytes) -> bool:
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return all(c.isprintable() or c in "\r\n\t" for c in text)


def read_vectors(path, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The variables of `names` that the file holds as 3-vectors (any of 3×1, 1×3, (3,)),
    as float (3,) arrays; the others are left out (a file need not store them)."""
    name, data = read_bytes(os.fspath(path))
    found = arrays(name, data)
    return {k: np.asarray(found[k], dtype=float).ravel() for k in names
            if k in found and found[k].size == 3}


def shapes(path) -> dict[str, tuple[int, ...]]:
    """The shape of every variable of the MAT file at `path`, from its headers only
    (``scipy.io.whosmat``: no data read); ImuFileError as :func:`arrays`."""
    import scipy.io

    name = os.fspath(path)
    return {k: tuple(int(n) for n in shape)
            for k, shape, _ in _parsed(name, lambda: scipy.io.whosmat(name))}


def _parsed(name: str, parse: Callable[[], T]) -> T:
    """``parse()``, scipy reading the MAT file `name`; what it cannot read, in one line
    naming the file."""
    try:
        return parse()
    except MemoryError:
        raise
    except NotImplementedError:  # scipy's word for a v7.3 (HDF5) file
        raise ImuFileError(f"{name}: a MAT v7.3 (HDF5) file; save it with save(..., '-v7') "
                           "for format psins-mat") from None
    except Exception as exc:  # noqa: BLE001 - scipy's parser of a damaged file raises anything
        why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ImuFileError(f"{name}: not a MATLAB file that scipy.io.loadmat reads ({why})"
                           ) from None
