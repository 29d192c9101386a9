"""Collection rules for the whole checkout (tests/, the package's doctests, README.md).

Doctests are collected only from modules whose source holds an example (``>>>``): the
package's, and the helper modules beside the tests (``tests/pyins_ref.py``,
``tests/fuzz_cases.py``, ...). Importing a module to find none would load numba and the
kernels of every command, pyins, pandas and scipy: most of the collection time.
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent
PACKAGE, TESTS = ROOT / "gcalign", ROOT / "tests"


def _doctest_only(path: Path) -> bool:
    """A module pytest would import only to look for doctests."""
    if path.is_relative_to(PACKAGE):
        return True
    return (path.is_relative_to(TESTS) and not path.name.startswith("test_")
            and path.name != "conftest.py")


def pytest_ignore_collect(collection_path: Path, config) -> bool | None:
    if (collection_path.suffix == ".py" and _doctest_only(collection_path)
            and ">>>" not in collection_path.read_text(encoding="utf-8")):
        return True
    return None
