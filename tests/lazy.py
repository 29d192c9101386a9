"""Modules a test module needs only when its tests run, not when pytest collects it.

Collection imports every test module; pyins (pandas, scipy.signal, .stats, .interpolate),
matplotlib and scipy's submodules would cost every run, even one that selects other tests,
seconds. :func:`lazy_module` returns a stand-in that imports the module on the first use of
a public attribute (pytest's probes of a module's names, ``_``-prefixed, do not import it);
a module that is not installed skips the calling test module. :func:`lazy_attr` does the
same for one name of a module (``chi2 = lazy_attr("scipy.stats", "chi2")``): imported on
the first use of an attribute of it or the first call.
"""

from __future__ import annotations

import importlib
import importlib.util
from typing import Any

import pytest


class LazyModule:
    """Stand-in for module `name`: its public attributes, the module imported on first use."""

    def __init__(self, name: str):
        self._name = name

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("_"):  # pytest's probes (__test__, fixture markers): not us
            raise AttributeError(attr)
        return getattr(importlib.import_module(self._name), attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._name!r}>"


class LazyAttr:
    """Stand-in for `module`.`name`, imported on first use (an attribute, or a call)."""

    def __init__(self, module: str, name: str):
        self._module, self._name = module, name

    def _target(self) -> Any:
        return getattr(importlib.import_module(self._module), self._name)

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("_"):  # pytest's probes: not us
            raise AttributeError(attr)
        return getattr(self._target(), attr)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._target()(*args, **kwargs)

    def __repr__(self) -> str:
        return f"<lazy {self._module}.{self._name}>"


def lazy_attr(module: str, name: str) -> Any:
    """`module`.`name` (of an installed package), imported on first use."""
    return LazyAttr(module, name)


def lazy_module(name: str) -> Any:
    """`name`, imported on first use; the calling test module is skipped if the top-level
    package is not installed (found without importing it)."""
    if importlib.util.find_spec(name.partition(".")[0]) is None:
        pytest.skip(f"{name} is not installed", allow_module_level=True)
    return LazyModule(name)
