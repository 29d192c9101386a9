"""The architecture as a test: imports go one way through the layers (units/errors/limits →
nav → sim, estimation → the capabilities → io → app → cli, api), the numerical core uses no
I/O or UI library, and the commands that run no kernel do not load numba (DESIGN.md
"Architecture")."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "gcalign"
# The packages in layers, lowest first. A module may import its own layer and the layers
# below it, never one above, at the top of a file or inside a function alike.
LAYERS = (
    ("units", "errors", "limits", "gaps", "_version", "schema", "choices"),
    ("nav",),
    ("sim", "estimation"),
    ("align", "northfind", "calibrate", "realtime", "modulate", "transfer",  # capabilities
     "allan"),
    ("io",),
    ("app",),
    ("cli", "api", "__main__"),
)
RANK = {name: i for i, names in enumerate(LAYERS) for name in names}
CORE = {name for names in LAYERS[1:4] for name in names}
CORE_FORBIDDEN = {"typer", "rich", "yaml", "pydantic", "h5py", "matplotlib"}
# Not layered: the package's own __init__ (version and the lazy Python API) and the
# built-in scenario files (package data).
UNLAYERED = {"__init__", "scenarios"}


def top(module: str) -> str:
    """The package of ``gcalign.<top>...`` (``__init__`` for gcalign itself)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def imports(path: Path, text: str):
    """(module imported, line) of every import in `text`, the source of the package file at
    `path`, absolute names; ``from gcalign import units`` counts as ``gcalign.units`` when it
    names a module."""
    tree = ast.parse(text)
    pkg = ".".join(path.relative_to(PKG.parent).with_suffix("").parts[:-1])
    for node in ast.walk(tree):  # every node: imports inside functions count too
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.rsplit(".", node.level - 1)[0] if node.level > 1 else pkg
                module = f"{base}.{node.module}" if node.module else base
            else:
                module = node.module or ""
            if module == "gcalign":
                for a in node.names:
                    sub = PKG / a.name
                    named = sub.is_dir() or sub.with_suffix(".py").is_file()
                    yield (f"gcalign.{a.name}" if named else "gcalign"), node.lineno
            else:
                yield module, node.lineno


def file_violations(path: Path, text: str) -> list[str]:
    """The layering rules broken by `text` as the package file at `path`."""
    module = ".".join(path.relative_to(PKG.parent).with_suffix("").parts)
    here = top(module)
    if here in UNLAYERED:
        return []
    if here not in RANK:
        return [f"{module}: package {here!r} is in no layer (add it to LAYERS)"]
    bad = []
    for name, line in imports(path, text):
        root = name.split(".")[0]
        if here in CORE and root in CORE_FORBIDDEN:
            bad.append(f"{module}:{line} imports {name} (the core takes and returns arrays)")
        if root != "gcalign" or name == "gcalign":
            continue
        target = top(name)
        if target in UNLAYERED:
            continue
        if target not in RANK:
            bad.append(f"{module}:{line} imports {name}: package {target!r} is in no layer")
        elif RANK[target] > RANK[here]:
            bad.append(f"{module}:{line} imports {name} (upward: {here} is in layer "
                       f"{RANK[here]}, {target} in layer {RANK[target]})")
    return bad


def violations() -> list[str]:
    return [v for path in sorted(PKG.rglob("*.py"))
            for v in file_violations(path, path.read_text(encoding="utf-8"))]


@pytest.mark.slow
def test_imports_go_one_way():
    bad = violations()
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize(("where", "text", "expected"), [
    ("nav", "from gcalign.app import registry\n",
     "nav._probe_layout:1 imports gcalign.app (upward: nav is in layer 1, app in layer 5)"),
    ("nav", "def f():\n    from gcalign.sim import motions\n    return motions\n",
     "nav._probe_layout:2 imports gcalign.sim (upward: nav is in layer 1, sim in layer 2)"),
    ("sim", "import gcalign.align.gains\n",
     "sim._probe_layout:1 imports gcalign.align.gains (upward: sim is in layer 2, align in"),
    ("estimation", "from gcalign import calibrate\n",
     "estimation._probe_layout:1 imports gcalign.calibrate (upward: estimation is in layer 2"),
    ("align", "from ..io import results\n",
     "align._probe_layout:1 imports gcalign.io (upward: align is in layer 3, io in layer 4)"),
    ("calibrate", "import h5py\n", "calibrate._probe_layout:1 imports h5py (the core"),
])
def test_the_check_sees_a_violation(where, text, expected):
    """An upward import in a file of the package is reported (so the test above can fail):
    top-level, inside a function, relative, and a forbidden library. The probe is checked
    as the file it would be, not written into the package."""
    found = file_violations(PKG / where / "_probe_layout.py", text)
    assert any(v.startswith("gcalign." + expected) for v in found), found


def test_the_layers_allow_a_downward_import():
    assert not file_violations(PKG / "calibrate" / "_probe_layout.py",
                               "def f():\n    from gcalign.sim import motions\n"
                               "    from gcalign import units\n")


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["validate", "configs/seed000_moving_full_cycle.yaml"],
                                  ["--help"]])
def test_commands_without_kernels_do_not_import_numba(argv):
    code = (
        "import sys, json\n"
        "from typer.testing import CliRunner\n"
        "from gcalign.cli import app\n"
        f"r = CliRunner().invoke(app, {argv!r})\n"
        "print(json.dumps([r.exit_code, 'numba' in sys.modules, 'scipy' in sys.modules]))\n"
    )
    root = PKG.parent
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=root, check=True)
    code_, numba, scipy = json.loads(out.stdout.strip().splitlines()[-1])
    assert code_ == 0 and not numba and not scipy


@pytest.mark.slow
def test_show_does_not_import_numba(tmp_path):
    root = PKG.parent
    out = tmp_path / "a.h5"
    res = subprocess.run([sys.executable, "-c", (
        "from typer.testing import CliRunner\nfrom gcalign.cli import app\n"
        f"r = CliRunner().invoke(app, ['navigate', 'configs/static.yaml', '-o', '{out}'])\n"
        "assert r.exit_code == 0, r.output\n")], cwd=root, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    code = (
        "import sys, json\nfrom typer.testing import CliRunner\nfrom gcalign.cli import app\n"
        f"r = CliRunner().invoke(app, ['show', '{out}'])\n"
        "print(json.dumps([r.exit_code, 'numba' in sys.modules]))\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=root, check=True)
    assert json.loads(res.stdout.strip().splitlines()[-1]) == [0, False]


def test_one_module_opens_matlab_files():
    """PSINS .mat files are opened in one place (gcalign.io.recorded.mat): the IMU, the
    reference and transfer alignment's master and stored values all read them there."""
    opened = sorted(str(p.relative_to(PKG)) for p in PKG.rglob("*.py")
                    if any(f"scipy.io.{fn}" in p.read_text(encoding="utf-8")
                           or f"import {fn}" in p.read_text(encoding="utf-8")
                           for fn in ("loadmat", "whosmat")))
    assert opened == ["io/recorded/mat.py"], opened


def module_name(path: Path) -> str:
    """``gcalign/app/align/__init__.py`` -> ``gcalign.app.align``."""
    parts = path.relative_to(PKG.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def module_graph(sources: dict[str, str]) -> dict[str, set[str]]:
    """Module -> the package modules it imports (`sources`: module name -> its text), at the
    top of a file or inside a function alike: ``from gcalign.app import registry`` imports
    the module ``gcalign.app.registry``, ``from gcalign.app.registry import COMMANDS`` it
    too. A package's ``__init__`` counts only where it is named (the parents Python runs
    first are not edges)."""
    packages = {m.rpartition(".")[0] for m in sources}
    graph: dict[str, set[str]] = {}
    for name, text in sources.items():
        pkg = name if name in packages else name.rpartition(".")[0]
        edges: set[str] = set()
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Import):
                for a in node.names:
                    m = a.name
                    while m and m not in sources:
                        m = m.rpartition(".")[0]
                    edges.add(m)
            elif isinstance(node, ast.ImportFrom):
                base = pkg
                for _ in range(max(node.level - 1, 0)):
                    base = base.rpartition(".")[0]
                module = (f"{base}.{node.module}" if node.module else base) if node.level \
                    else (node.module or "")
                for a in node.names:
                    edges.add(f"{module}.{a.name}" if f"{module}.{a.name}" in sources
                              else module)
        graph[name] = {m for m in edges if m in sources and m != name}
    return graph


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles of `graph`: its strongly connected parts of two modules or more
    (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                found.append(sorted(part))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def package_sources() -> dict[str, str]:
    return {module_name(p): p.read_text(encoding="utf-8") for p in sorted(PKG.rglob("*.py"))}


def test_no_import_circle():
    """No module of gcalign imports, through any chain, one that imports it back, counting
    the imports inside functions: commands hold references to their functions, and what
    dispatches by a command's name (the registry, ``show``, ``plot``) sits above them."""
    found = circles(module_graph(package_sources()))
    assert not found, "\n".join(", ".join(c) for c in found)


def test_the_circle_check_sees_a_function_level_circle():
    """A circle closed by an import inside a function, and one through ``from pkg import
    module``, are found (so the test above can fail)."""
    sources = package_sources()
    sources["gcalign.app.command"] += ("\n\ndef _probe():\n"
                                       "    from gcalign.app import registry\n")
    found = circles(module_graph(sources))
    assert any({"gcalign.app.command", "gcalign.app.registry"} <= set(c) for c in found), found
