"""The architecture as a test: imports go one way, the numerical core uses no I/O or UI
library, and the commands that run no kernel do not load numba (DESIGN.md "Architecture")."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "gcalign"
CORE = ("nav", "sim", "estimation", "align", "northfind", "modulate", "realtime", "calibrate")
# Each layer may import itself and what is listed (plus the leaf modules units, errors,
# limits).
ALLOWED = {
    "core": set(CORE),
    "io": set(CORE) | {"io"},
    "app": set(CORE) | {"io", "app"},
    "cli": set(CORE) | {"io", "app", "cli"},
    "api": set(CORE) | {"io", "app", "api"},  # the Python API: never the command line
}
CORE_FORBIDDEN = {"typer", "rich", "yaml", "pydantic", "h5py", "matplotlib"}


def layer(module: str) -> str:
    top = module.split(".")[1] if module.count(".") else ""
    return "core" if top in CORE else top


def imports(path: Path):
    """(module imported, line) of every import in a file, absolute names."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    pkg = ".".join(path.relative_to(PKG.parent).with_suffix("").parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.rsplit(".", node.level - 1)[0] if node.level > 1 else pkg
                yield f"{base}.{node.module}" if node.module else base, node.lineno
            elif node.module:
                yield node.module, node.lineno


@pytest.mark.slow
def test_imports_go_one_way():
    bad = []
    for path in PKG.rglob("*.py"):
        module = ".".join(path.relative_to(PKG.parent).with_suffix("").parts)
        here = layer(module)
        if here not in ALLOWED:
            continue  # gcalign/__init__, units, errors, limits
        for name, line in imports(path):
            root = name.split(".")[0]
            if here == "core" and root in CORE_FORBIDDEN:
                bad.append(f"{module}:{line} imports {name} (the core takes and returns arrays)")
            if root != "gcalign" or name.count(".") == 0:
                continue
            target = name.split(".")[1]
            if target in ("units", "errors", "limits", "__init__"):
                continue
            target_layer = "core" if target in CORE else target
            allowed = ALLOWED[here]
            if target_layer == "core":
                ok = target in allowed or "core" in allowed
            else:
                ok = target_layer in allowed
            if not ok:
                bad.append(f"{module}:{line} imports {name} ({here} must not reach {target})")
    assert not bad, "\n".join(bad)


@pytest.mark.slow
def test_the_check_sees_a_violation(tmp_path):
    """The scanner reports an upward import (so the test above can fail)."""
    f = PKG / "nav" / "_probe_layout.py"
    try:
        f.write_text("from gcalign.app import registry\nimport h5py\n")
        with pytest.raises(AssertionError, match="nav._probe_layout:1 imports gcalign.app"):
            test_imports_go_one_way()
    finally:
        f.unlink()


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
