"""Shared fixtures. The real recording ships with the repository (tests/data/, xz), so no
real-data test skips in a plain clone."""

from __future__ import annotations

import lzma
import re
import subprocess
import sys
from pathlib import Path

import pytest
import typer.testing

# Byte code is written, whatever PYTHONDONTWRITEBYTECODE says (this conftest is loaded
# before any test module or package module is imported, in every xdist worker): without
# it each process rewrote the asserts of every test module and compiled every module of
# the package from source at each run, 1.7 of its 3.3 s CPU of collection. The files go
# to __pycache__ as any import's do (the clean-checkout check below ignores them).
sys.dont_write_bytecode = False

ROOT = Path(__file__).resolve().parents[1]
#: The PSINS lasergyro.imu recording, compressed (tests/data/README.md).
LASERGYRO_XZ = ROOT / "tests" / "data" / "lasergyro.imu.xz"


@pytest.fixture(scope="session")
def lasergyro(tmp_path_factory) -> Path:
    """The plain lasergyro.imu (decompressed once per test session), for the readers and
    for anything that needs the file itself."""
    path = tmp_path_factory.mktemp("data") / "lasergyro.imu"
    path.write_bytes(lzma.decompress(LASERGYRO_XZ.read_bytes()))
    return path


@pytest.fixture(scope="session", autouse=True)
def one_click_command_per_app():
    """typer's CliRunner converts the Typer app into its click command on every invoke
    (about 20 ms: the signature and type hints of every option of every command); the
    command line does it once per process, and so do the tests here: once per app and set
    of registered commands."""
    build = typer.testing._get_command
    built: dict = {}

    def cached(app):
        # the objects themselves (hashed by identity, kept alive): no id reused
        key = (app, tuple(app.registered_commands), tuple(app.registered_groups),
               app.registered_callback)
        if key not in built:
            built[key] = build(app)
        return built[key]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(typer.testing, "_get_command", cached)
        yield


@pytest.fixture(scope="session")
def results_of_every_kind(tmp_path_factory) -> dict[str, Path]:
    """One small real results file of every kind, by kind (``transfer``: align in transfer
    mode), made once per session (:func:`damage_cases.make_files`); the scenarios beside
    them (``S.yaml``: the alignment's)."""
    import damage_cases

    return damage_cases.make_files(tmp_path_factory.mktemp("kinds"))


def _untracked() -> set[str] | None:
    """Files of the checkout that git does not track (ignored ones included: runs/ is), or
    None outside a git checkout."""
    try:
        out = subprocess.run(["git", "ls-files", "--others", "-z"], cwd=ROOT,
                             capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return {p for p in out.decode().split("\0") if p and not _BUILD_PRODUCT.search(p)}


#: What running Python and the tools leave by design: byte code and caches.
_BUILD_PRODUCT = re.compile(r"(^|/)(__pycache__|\.pytest_cache|\.ruff_cache|\.mypy_cache|"
                            r"\.benchmarks|\.venv|[^/]*\.egg-info)(/|$)|\.nbi$|\.nbc$")


@pytest.fixture(scope="session", autouse=True)
def checkout_stays_clean():
    """No test leaves a file in the checkout (a results file in runs/, a plot, a journal):
    the session fails at its end naming the files that appeared."""
    before = _untracked()
    yield
    after = _untracked()
    if before is not None and after is not None and after - before:
        new = sorted(after - before)
        pytest.fail(f"the tests left {len(new)} file(s) in the checkout: {new[:10]}",
                    pytrace=False)
