"""Modules a test module needs only when its tests run, not when pytest collects it.

Collection imports every test module; pyins (pandas, scipy.signal, .stats, .interpolate)
and matplotlib would cost every run, even one that selects other tests, over a second.
:func:`lazy_module` returns a stand-in that imports the module on the first use of a
public attribute (pytest's probes of a module's names, ``_``-prefixed, do not import it);
a module that is not installed skips the calling test module.
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


def lazy_module(name: str) -> Any:
    """`name`, imported on first use; the calling test module is skipped if the top-level
    package is not installed (found without importing it)."""
    if importlib.util.find_spec(name.partition(".")[0]) is None:
        pytest.skip(f"{name} is not installed", allow_module_level=True)
    return LazyModule(name)
