"""One object per command: the registry, a command added by one line, the cost models held
against the limits before any work, and `python -m gcalign`."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from cli_checks import assert_bad_input
from rich.table import Table
from typer.testing import CliRunner

from gcalign import __version__, limits
from gcalign.app import preflight, registry
from gcalign.app.command import Command, Cost, Inputs, Outcome
from gcalign.app.registry import COMMANDS
from gcalign.cli import app
from gcalign.errors import ScenarioError
from gcalign.io.scenario import parse_scenario

runner = CliRunner()
NEW = ("calibrate", "observability", "realtime", "modulate")
SHORT = {"modulate": ["--hours", "1"]}  # a quick run if the limits failed to refuse it


def builtin(name: str, tmp_path: Path) -> Path:
    p = tmp_path / f"{name}.yaml"
    p.write_text(COMMANDS[name].builtin_text(), encoding="utf-8")
    return p


@pytest.fixture
def no_work(monkeypatch):
    """Every command's execute fails the test: a refusal must come before any work."""
    def boom(*args, **kwargs):
        raise AssertionError("the run started; the limits should have refused it first")

    for c in COMMANDS.values():
        monkeypatch.setattr(c, "execute", boom)


def test_every_command_is_one_object_of_the_protocol():
    for name, c in COMMANDS.items():
        assert isinstance(c, Command), name
        assert c.name == name and c.help
    assert set(registry.batchable()) == {"align", "northfind", "calibrate", "observability",
                                         "realtime", "modulate"}


def test_python_m_gcalign_runs_the_command_line():
    r = subprocess.run([sys.executable, "-m", "gcalign", "--version"], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout == f"gcalign {__version__}\n"


# ---------------------------------------------------------------------- a toy command


class Count(Command):
    """A small command: counts the samples of the scenario's motion; its check refuses a
    motion shorter than 1 s, its cost is one operation per sample."""

    name = "count"
    help = "Count the samples of the motion (a toy)."
    layout = ("count",)

    def check(self, inputs: Inputs) -> None:
        ext = inputs.extent
        if ext is None or ext.samples * ext.ts < 1.0:
            raise ScenarioError("motion.duration_s: count needs at least 1 s of data")

    def cost(self, inputs: Inputs) -> Cost:
        ext = inputs.extent
        assert ext is not None
        return Cost(samples=ext.samples, memory_bytes=8.0, work=float(ext.samples),
                    work_what="samples")

    def execute(self, sc, seed=None, cache_key=None, **options) -> Outcome:
        n = int(round(sc.motion.duration() / sc.imu.ts))

        def write(f):
            f.create_group("count").create_dataset("n", data=n)

        return Outcome({"scenario": sc.name, "samples": n}, write, seed=seed)

    def accepts(self, option: str) -> bool:
        return False

    def table(self, summary: dict) -> Table:
        t = Table(title=summary["scenario"])
        t.add_column("samples")
        t.add_row(str(summary["samples"]))
        return t


@pytest.fixture
def toy(monkeypatch):
    monkeypatch.setitem(COMMANDS, "count", Count())  # what registry.register does
    return COMMANDS["count"]


SCENARIO = {"name": "toy", "site": {"lat_deg": 45.0, "lon_deg": 126.0},
            "motion": {"kind": "static", "duration_s": 2.5}}


def test_a_registered_command_runs_end_to_end(toy, tmp_path, monkeypatch):
    """check, cost, execute, table, results file and `show`, with no line of gcalign changed."""
    import h5py

    from gcalign.app.runner import run_command
    from gcalign.io import results

    sc = parse_scenario(dict(SCENARIO), "toy")
    out = tmp_path / "count.h5"
    summary = run_command("count", sc, json.dumps(SCENARIO), 7, out)
    assert summary["samples"] == 250  # 2.5 s at the default 100 Hz
    kind, stored, attrs = results.read_summary(out)
    assert kind == "count" and stored["samples"] == 250 and int(attrs["seed"]) == 7
    with h5py.File(out) as f:
        assert f["count/n"][()] == 250
    res = runner.invoke(app, ["show", str(out)])
    assert res.exit_code == 0, res.output
    assert "250" in res.output and "toy" in res.output
    # its check and its cost are the preflight's
    short = parse_scenario({**SCENARIO, "motion": {"kind": "static", "duration_s": 0.5}}, "t")
    with pytest.raises(ScenarioError, match="motion.duration_s: count needs"):
        run_command("count", short, "", 1, tmp_path / "short.h5")
    monkeypatch.setenv("GCALIGN_MAX_WORK", "100")
    with pytest.raises(ScenarioError, match=r"count: needs 250 operations.*GCALIGN_MAX_WORK"):
        run_command("count", sc, "", 1, tmp_path / "big.h5")
    assert not (tmp_path / "short.h5").exists() and not (tmp_path / "big.h5").exists()


# ---------------------------------------------------------------------- the cost models


@pytest.mark.parametrize("name", NEW)
def test_a_memory_limit_refuses_the_new_commands_before_work(name, tmp_path, monkeypatch,
                                                             no_work):
    monkeypatch.setenv("GCALIGN_MAX_MEMORY_MB", "1e-300")
    out = tmp_path / "out.h5"
    res = runner.invoke(app, [name, *SHORT.get(name, []), "-o", str(out)])
    assert_bad_input(res, out, f"{name}: needs", "GCALIGN_MAX_MEMORY_MB=N")


@pytest.mark.parametrize("name", [c for c in COMMANDS if c != "batch"])
def test_a_limit_that_is_not_a_number_is_refused_everywhere(name, tmp_path, monkeypatch,
                                                            no_work):
    monkeypatch.setenv("GCALIGN_MAX_MEMORY_MB", "abc")
    out = tmp_path / "out.h5"
    args = [str(builtin("align", tmp_path))] if name in ("simulate", "navigate", "allan") else []
    res = runner.invoke(app, [name, *args, "-o", str(out)])
    assert_bad_input(res, out, "GCALIGN_MAX_MEMORY_MB: must be a number, got 'abc'")


def test_modulate_honours_the_output_limit(tmp_path, monkeypatch, no_work):
    monkeypatch.setenv("GCALIGN_MAX_OUTPUT_MB", "1e-9")
    out = tmp_path / "out.h5"
    res = runner.invoke(app, ["modulate", "--hours", "1", "-o", str(out)])
    assert_bad_input(res, out, "modulate: needs", "of stored series",
                     "GCALIGN_MAX_OUTPUT_MB=N")


def test_observability_on_millisecond_pieces_is_refused_before_work(tmp_path, monkeypatch,
                                                                    no_work):
    """``piece_s: 0.001`` on the built-in 590 s flight reached 7.1 GB and kept growing:
    the estimate is at least that, and a machine with 8 GB to spare refuses it."""
    sc = parse_scenario(yaml.safe_load(COMMANDS["observability"].builtin_text()), "b")
    sc.observability = sc.observability.model_copy(update={"piece_s": 0.001})
    cost = COMMANDS["observability"].cost(preflight.load(sc))
    assert cost.memory_bytes > 7.1e9
    monkeypatch.setenv("GCALIGN_MAX_MEMORY_MB", "8192")
    out = tmp_path / "out.h5"
    res = runner.invoke(app, ["observability", "--set", "observability.piece_s=0.001",
                              "-o", str(out)])
    assert_bad_input(res, out, "observability: needs", "GCALIGN_MAX_MEMORY_MB=N",
                     "observability.piece_s")


def test_realtime_with_fifty_thousand_taps_is_refused_by_the_work_limit(tmp_path, no_work,
                                                                         monkeypatch):
    # 13 cases × 12 s × 5 kHz × 3 channels × (5.3e3 operations a sample through FFTs + 5)
    monkeypatch.setenv("GCALIGN_MAX_WORK", "1e10")
    out = tmp_path / "out.h5"
    res = runner.invoke(app, ["realtime", "--set", "realtime.filter.nav_order=50000",
                              "-o", str(out)])
    assert_bad_input(res, out, "realtime: needs", "operations", "FIR operations × samples",
                     "GCALIGN_MAX_WORK=N")


def test_a_long_fir_is_costed_as_the_ffts_it_runs_through():
    """Up to DIRECT_TAPS the chain convolves directly (taps operations a sample); above, three
    FFTs of N = chunk + 2 taps a chunk: 5e4 taps on 1 s chunks at 5 kHz cost about a tenth of
    their direct sum."""
    from gcalign.realtime.filters import DIRECT_TAPS, fir_ops_per_sample

    assert fir_ops_per_sample(41, 5000) == 41
    assert fir_ops_per_sample(DIRECT_TAPS, 5000) == DIRECT_TAPS
    N = 5000 + 2 * 50001
    assert fir_ops_per_sample(50001, 5000) == pytest.approx(15 * N * math.log2(N) / 5000)
    assert fir_ops_per_sample(50001, 5000) < 0.11 * 50001


def test_realtime_with_a_million_taps_on_a_short_case_is_refused_at_once(tmp_path, no_work):
    """An FIR longer than the case (1e6 taps at 5 kHz: 200 s, on a 2 s case) ran for minutes
    within the work limit; its output would be the filter's start-up transient only."""
    import fuzz_cases as F

    (tmp_path / "rt.yaml").write_text(F.emit(F.REALTIME))
    out = tmp_path / "out.h5"
    res = runner.invoke(app, ["realtime", str(tmp_path / "rt.yaml"), "--set",
                              "realtime.filter.nav_order=1000000", "-o", str(out)])
    assert_bad_input(res, out, "realtime.filter.nav_order: an FIR of order 1000000 spans "
                     "200 s", "longer than case 'r5' (2 s)", "at most 9999")


@pytest.mark.parametrize("name, sets, env, same", [
    ("observability", ["observability.piece_s=0.001"], {"GCALIGN_MAX_MEMORY_MB": "8192"}, True),
    ("realtime", ["realtime.filter.nav_order=50000"], {"GCALIGN_MAX_WORK": "1e10"}, True),
    ("realtime", [], {"GCALIGN_MAX_MEMORY_MB": "abc"}, True),
    # validate costs every section: the simulation of the motion is refused first
    ("modulate", ["modulate.hours=1"], {"GCALIGN_MAX_OUTPUT_MB": "1e-9"}, False),
    ("calibrate", [], {"GCALIGN_MAX_MEMORY_MB": "1e-300"}, False),
])
def test_validate_reports_the_same_refusals(name, sets, env, same, tmp_path, monkeypatch,
                                            no_work):
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    path = builtin(name, tmp_path)
    args = [a for s in sets for a in ("--set", s)]
    run = runner.invoke(app, [name, str(path), *args, "-o", str(tmp_path / "o.h5")])
    check = runner.invoke(app, ["validate", str(path), *args])
    assert run.exit_code == check.exit_code == 2, (run.output, check.output)
    variable = next(iter(env), "GCALIGN_MAX_WORK")
    assert variable in run.output and variable in check.output
    if same:
        assert check.output == run.output, (run.output, check.output)


def test_the_realtime_and_northfind_sample_caps_name_their_variables(tmp_path, monkeypatch):
    monkeypatch.setenv("GCALIGN_MAX_REALTIME_SAMPLES", "1000")
    res = runner.invoke(app, ["validate", str(builtin("realtime", tmp_path))])
    assert_bad_input(res, tmp_path / "none.h5", "realtime.cases: needs 7.8e+05 sensor samples",
                     "GCALIGN_MAX_REALTIME_SAMPLES=N")
    monkeypatch.setenv("GCALIGN_MAX_NORTHFIND_SAMPLES", "1000")
    res = runner.invoke(app, ["validate", str(builtin("northfind", tmp_path)), "--set",
                              "northfind.samples=true"])
    assert_bad_input(res, tmp_path / "none.h5", "northfind.samples: needs",
                     "simulated samples per sensor", "GCALIGN_MAX_NORTHFIND_SAMPLES=N")
    monkeypatch.delenv("GCALIGN_MAX_REALTIME_SAMPLES")
    monkeypatch.delenv("GCALIGN_MAX_NORTHFIND_SAMPLES")
    assert limits.MAX_REALTIME_SAMPLES.value() == 5e7
    assert limits.MAX_NORTHFIND_SAMPLES.value() == 2e8


def test_the_built_in_scenarios_fit_the_default_limits():
    """What the cost models say of every built-in run: well inside the defaults."""
    for name, c in COMMANDS.items():
        if not c.builtin:
            continue
        sc = parse_scenario(yaml.safe_load(c.builtin_text()), name)
        cost = preflight.budget(preflight.load(sc), c)
        assert 0 < cost.memory_bytes < 2**30, name
        assert 0 < cost.work < limits.MAX_WORK.value() / 10, name


@pytest.mark.parametrize("name, keys", [("northfind", "positions, dwell_s"),
                                        ("realtime", "cases or a turntable motion")])
def test_a_required_section_that_is_missing_is_one_line_naming_it(tmp_path, name, keys):
    from gcalign.cli import app

    path = tmp_path / "s.yaml"
    path.write_text("name: x\nsite: {lat_deg: 40, lon_deg: 116}\n")
    res = CliRunner().invoke(app, [name, str(path), "-o", str(tmp_path / "o.h5")])
    assert res.exit_code == 2 and not (tmp_path / "o.h5").exists()
    assert res.stderr.strip().startswith(
        f"error: {name}: missing; the scenario needs a '{name}' section ({keys}")
