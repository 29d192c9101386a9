"""What a command loads at start-up (DESIGN.md "Performance": warm ``gcalign align`` ≤ 1 s
CPU): each command imports the heavy libraries it uses and no others, and the collector is
paused over the loads of a one-shot command only. No timings here (benchmarks/
bench_startup.py measures them); each check is the set of modules a fresh interpreter holds."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gcalign.app import command

ROOT = Path(__file__).resolve().parents[1]
#: Libraries that cost a tenth of a second or more to import.
HEAVY = ("numpy", "numba", "scipy", "pydantic", "h5py", "yaml", "rich", "matplotlib", "dask",
         "distributed", "pandas")


def modules_after(code: str) -> set[str]:
    """The top-level packages of HEAVY, and the submodules named in it, that a fresh
    interpreter holds after running `code` (with this checkout first on the path)."""
    probe = (f"{code}\nimport json, sys\n"
             "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in "
             f"{HEAVY!r})))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         cwd=ROOT, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def tops(modules: set[str]) -> set[str]:
    return {m.split(".")[0] for m in modules}


def test_importing_the_command_line_loads_no_heavy_library():
    """``import gcalign.cli`` builds every command's options and help (typer), nothing else:
    the scenario models, the results file, tables and kernels load with the command that
    uses them."""
    assert tops(modules_after("import gcalign.cli")) == set()


def test_help_loads_no_heavy_library():
    code = ("import sys\nfrom typer.testing import CliRunner\nfrom gcalign.cli import app\n"
            "r = CliRunner().invoke(app, ['--help'])\nassert r.exit_code == 0, r.output\n"
            "assert 'align' in r.output\n")
    assert tops(modules_after(code)) == set()


@pytest.mark.slow
def test_the_align_path_loads_no_plotting_no_scipy_linalg_no_dask():
    """Everything `gcalign align` imports (scenario, run, writer, table) but not matplotlib,
    dask or pandas; of scipy only the top package numba asks for its version, not
    scipy.linalg (numba's BLAS probe would import it: gcalign.nav._kernels answers it, and
    a cached load does not run it)."""
    code = ("import gcalign.cli.align, gcalign.cli.common, gcalign.app.runner\n"
            "import gcalign.app.align.run, gcalign.io.stored, gcalign.app.align.tables\n"
            "import numpy as np\nfrom gcalign.sim._noise import normals\n"
            "normals(np.random.default_rng(1), 3)\n")  # a first kernel call: cached or compiled
    loaded = modules_after(code)
    assert {"numpy", "numba", "pydantic", "h5py", "yaml", "rich"} <= tops(loaded)
    assert not tops(loaded) & {"matplotlib", "dask", "distributed", "pandas"}
    assert "scipy.linalg" not in loaded, sorted(m for m in loaded if m.startswith("scipy"))


@pytest.mark.slow
def test_validate_loads_neither_numba_nor_h5py():
    scenario = ROOT / "configs" / "seed000_moving_full_cycle.yaml"
    code = ("from typer.testing import CliRunner\nfrom gcalign.cli import app\n"
            f"r = CliRunner().invoke(app, ['validate', {str(scenario)!r}])\n"
            "assert r.exit_code == 0, r.output\n")
    loaded = tops(modules_after(code))
    assert {"numpy", "pydantic", "yaml"} <= loaded
    assert not loaded & {"numba", "h5py", "matplotlib", "scipy"}


@pytest.fixture
def unfrozen():
    """Leave the collector as it was: enabled, nothing frozen by the test."""
    frozen = gc.get_freeze_count()
    yield
    gc.enable()
    if gc.get_freeze_count() > frozen:
        gc.unfreeze()


def test_loading_changes_nothing_outside_a_one_shot_process(unfrozen, monkeypatch):
    """The API, a test's CliRunner, a batch worker: the collector runs as usual."""
    monkeypatch.setattr(command, "ONE_SHOT", None)
    frozen = gc.get_freeze_count()
    with command.loading():
        assert gc.isenabled()
    assert gc.isenabled() and gc.get_freeze_count() == frozen


def test_loading_in_a_one_shot_process_pauses_then_freezes(unfrozen, monkeypatch):
    """The gcalign script's process: no collection while the modules load, what they made
    left out of later collections, and the collector back on for the run itself."""
    monkeypatch.setattr(command, "ONE_SHOT", os.getpid())
    before = gc.get_freeze_count()
    with command.loading():
        assert not gc.isenabled()
    assert gc.isenabled(), "a long run needs the collector back"
    assert gc.get_freeze_count() > before


def test_loading_gives_the_collector_back_when_the_load_fails(unfrozen, monkeypatch):
    monkeypatch.setattr(command, "ONE_SHOT", os.getpid())
    with pytest.raises(ImportError), command.loading():
        raise ImportError("a module that is not there")
    assert gc.isenabled()


def test_a_forked_process_is_not_the_one_shot_process(unfrozen, monkeypatch):
    """A batch's forked workers run many runs: loading changes nothing in them."""
    monkeypatch.setattr(command, "ONE_SHOT", os.getpid() + 1)  # the parent's id, say
    with command.loading():
        assert gc.isenabled()
