"""Collection rules for the whole checkout (tests/, the package's doctests, README.md).

The doctests of ``gcalign`` are collected only from modules whose source holds an example
(``>>>``): importing a module to find none would load numba and the kernels of every
command, which is most of the collection time.
"""

from __future__ import annotations

from pathlib import Path

PACKAGE = Path(__file__).resolve().parent / "gcalign"


def pytest_ignore_collect(collection_path: Path, config) -> bool | None:
    if (collection_path.suffix == ".py" and collection_path.is_relative_to(PACKAGE)
            and ">>>" not in collection_path.read_text(encoding="utf-8")):
        return True
    return None
