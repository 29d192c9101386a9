"""Collection rules for the whole checkout (tests/, the package's doctests, README.md).

Doctests are collected only from modules whose source holds an example (``>>>``): the
package's, and the helper modules beside the tests (``tests/pyins_ref.py``,
``tests/fuzz_cases.py``, ...). And they are collected from the source text: pytest's own
doctest collector imports each module to find its docstrings, which loads numba and the
kernels of every command (``gcalign.align.gyrocompass``, ``gcalign.nav.navigate``, ...),
pyins, pandas and scipy before a test has run. Here the docstrings are read with
:mod:`ast` (the module, its classes, their functions and methods: what
:class:`doctest.DocTestFinder` finds) and the module is imported when its doctest runs;
the examples run in a copy of the module's namespace, as pytest's run them.
"""

from __future__ import annotations

import ast
import doctest
import gc
import importlib
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from _pytest.doctest import (
    DoctestItem,
    DoctestModule,
    DoctestTextfile,
    _get_checker,
    _get_continue_on_failure,
    _get_runner,
    get_optionflags,
)

ROOT = Path(__file__).resolve().parent
PACKAGE, TESTS = ROOT / "gcalign", ROOT / "tests"


def _doctest_only(path: Path) -> bool:
    """A module pytest would import only to look for doctests."""
    if path.is_relative_to(PACKAGE):
        return True
    return (path.is_relative_to(TESTS) and not path.name.startswith("test_")
            and path.name != "conftest.py")


def pytest_configure(config) -> None:
    gc.disable()  # until the collection is done: see pytest_collection_finish


def pytest_collection_finish(session) -> None:
    """The imported modules and the collected items live as long as the session: moved out
    of the cyclic garbage collector's way (gc.freeze) so that its full collections during
    the tests, and the five pytest makes at the end of the session, do not walk them again;
    the collector runs from here on."""
    gc.freeze()
    gc.enable()


def pytest_ignore_collect(collection_path: Path, config) -> bool | None:
    if (collection_path.suffix == ".py" and _doctest_only(collection_path)
            and ">>>" not in collection_path.read_text(encoding="utf-8")):
        return True
    return None


@pytest.hookimpl(hookwrapper=True)
def pytest_collect_file(file_path: Path, parent):
    """pytest's doctest collector of a doctest-only module, replaced by the text one."""
    outcome = yield
    if file_path.suffix == ".py" and _doctest_only(file_path):
        outcome.force_result([
            SourceDoctestModule.from_parent(parent, path=file_path)
            if isinstance(c, DoctestModule) else c for c in outcome.get_result()])


def _module_name(path: Path) -> tuple[str, Path]:
    """The dotted name of the module at `path` and the folder it is imported from (above its
    outermost package), as pytest's default import mode finds them."""
    parts = [] if path.name == "__init__.py" else [path.stem]
    folder = path.parent
    while (folder / "__init__.py").is_file():
        parts.insert(0, folder.name)
        folder = folder.parent
    return ".".join(parts), folder


def _docstrings(tree: ast.Module, name: str) -> Iterator[tuple[str, str, int]]:
    """(qualified name, docstring, 0-based line of the docstring) of the module, its classes
    and their nested classes, its functions and the classes' functions (methods, properties,
    static and class methods): the objects :class:`doctest.DocTestFinder` searches."""

    def visit(node, qualname: str, inside: bool):
        doc = ast.get_docstring(node, clean=False)
        if doc is not None:
            yield qualname, doc, node.body[0].lineno - 1
        if inside:
            for child in node.body:
                if isinstance(child, ast.ClassDef):
                    yield from visit(child, f"{qualname}.{child.name}", True)
                elif isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                    yield from visit(child, f"{qualname}.{child.name}", False)

    yield from visit(tree, name, True)


class SourceDoctestModule(DoctestTextfile):
    """The doctests of a Python module, found in its source text, not in the imported module."""

    def collect(self) -> Iterator[DoctestItem]:
        name, self.import_root = _module_name(self.path)
        self.module_name = name
        tree = ast.parse(self.path.read_text(encoding="utf-8"), filename=str(self.path))
        runner = _get_runner(verbose=False, optionflags=get_optionflags(self.config),
                             checker=_get_checker(),
                             continue_on_failure=_get_continue_on_failure(self.config))
        parser = doctest.DocTestParser()
        for qualname, doc, lineno in sorted(_docstrings(tree, name)):
            test = parser.get_doctest(doc, {}, qualname, str(self.path), lineno)
            if test.examples:
                yield SourceDoctestItem.from_parent(self, name=test.name, runner=runner,
                                                    dtest=test)


class SourceDoctestItem(DoctestItem):
    def setup(self) -> None:
        module: SourceDoctestModule = self.parent  # type: ignore[assignment]
        if str(module.import_root) not in sys.path:
            sys.path.insert(0, str(module.import_root))
        self.dtest.globs.update(importlib.import_module(module.module_name).__dict__)
        super().setup()
