"""The fuzz suite: hundreds of hostile inputs, every command, one contract.

The cases come from :mod:`fuzz_cases` (seeded: ``GCALIGN_FUZZ_SEED``, default 14, gives
the same cases in the same order, so a failure reproduces from its id). Each runs in-process
(``typer.testing.CliRunner``) in an empty folder with tight resource limits
(:data:`fuzz_cases.FUZZ_ENV`) and must keep the contract of :func:`fuzz_cases.violations`:
exit 2 or 1 with one line on stderr and no traceback, no file left behind, validate agreeing
with the run, a finite summary when it succeeds, no hang (:data:`fuzz_cases.HANG_S`; the
10 s bound per case is the fuzz report's, ``benchmarks/fuzz_report.py``, where each case
has its own process); the process stays under :data:`MAX_RSS_MB` throughout.
"""

from __future__ import annotations

import os
import resource
import time
from collections import Counter

import fuzz_cases as F
import pytest
from typer.testing import CliRunner

from gcalign.cli import app

SEED = int(os.environ.get("GCALIGN_FUZZ_SEED", "14"))
CASES = F.all_cases(SEED)
FIXED = F.fixed_cases()  # the first round's reproductions, by name
GENERATED = CASES[len(FIXED):]
MAX_RSS_MB = 3000.0  # peak resident memory of the whole test process
runner = CliRunner()


def run_case(case: F.Case, folder) -> F.Outcome:
    saved = {k: os.environ.get(k) for k, _ in case.env}
    os.environ.update(dict(case.env))
    try:
        return _run_case(case, folder)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _run_case(case: F.Case, folder) -> F.Outcome:
    argv = F.materialize(case, folder)
    before = F.snapshot(folder)
    t0 = time.perf_counter()
    res = runner.invoke(app, argv, catch_exceptions=True)
    elapsed = time.perf_counter() - t0
    note = ""
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        note = f"exception {type(res.exception).__name__}: {res.exception}"
    out = F.Outcome(res.exit_code, res.stderr, sorted(F.snapshot(folder) - before), elapsed,
                    note=note)
    if res.exit_code in (0, 1):  # 1: a batch with failed runs keeps its file
        out.summary = F.read_summary(folder, case)
    if case.validate is not None:
        check = runner.invoke(app, ["validate", case.validate])
        out.validate_exit, out.validate_stderr = check.exit_code, check.stderr
    return out


@pytest.fixture
def fuzz_env(monkeypatch, tmp_path):
    for k in list(os.environ):
        if k.startswith("GCALIGN_"):
            monkeypatch.delenv(k)
    for k, v in F.FUZZ_ENV.items():
        monkeypatch.setenv(k, v)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_enough_cases_of_every_class():
    counts = Counter(c.cls for c in CASES)
    assert len(GENERATED) >= 300  # generated, besides the named reproductions
    assert set(counts) >= {0, 1, 3, 4, 5, 6, 7, 8, 11}, counts
    assert len({c.id for c in CASES}) > 0.9 * len(CASES)  # names tell the cases apart


@pytest.mark.slow
def test_same_seed_same_cases():
    assert [c.id for c in CASES[:len(FIXED)]] == [c.id for c in FIXED]
    again = F.all_cases(SEED)
    assert [(c.id, c.argv, c.files) for c in again] == [(c.id, c.argv, c.files) for c in CASES]


def check(case: F.Case, folder, i: int | str) -> None:
    out = run_case(case, folder)
    v = F.violations(case, out, F.HANG_S)
    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    if rss_mb > MAX_RSS_MB:
        v.append(f"peak memory {rss_mb:.0f} MB")
    assert not v, (f"seed {SEED} case {i} {case.id} {list(case.argv)}: {'; '.join(v)}\n"
                   f"stderr: {out.stderr[-600:]}{out.note}")


@pytest.mark.parametrize("base", [*F.BASES, *F.LATE_BASES])
def test_every_base_is_valid_and_runs(base, fuzz_env):
    """The scenarios the generator mutates run as given (exit 0): a base that a change of
    the scenario schema made invalid would turn every mutation of it into a trivial exit 2."""
    data, command = (F.BASES | F.LATE_BASES)[base]
    case = F.Case(0, f"{base} as given", (command, "case.yaml", "-o", "out.h5"),
                  (("case.yaml", F.emit(data).encode()),), frozenset({0}), validate="case.yaml")
    check(case, fuzz_env, base)


@pytest.mark.parametrize("case", FIXED, ids=lambda c: f"c{c.cls}-{c.name}")
def test_reproduction(case, fuzz_env):
    """Each named reproduction (robustness classes 1, 3, 4, 5, 6, 8, 11) keeps the contract."""
    check(case, fuzz_env, case.name)


def _case_id(i: int) -> str:
    """Index, class and the start of the name: the crafted files, journals and options
    (recorded_cases, journal_cases, ...) include the first round's reproductions by name."""
    c = GENERATED[i]
    name = "".join(ch if ch.isprintable() and ch not in "[]:" else "_" for ch in c.name[:60])
    return f"{i}-c{c.cls}-{name}"


#: The default run takes every FAST_EVERY-th generated case (all classes are spread over the
#: list) but those of class 1 (resources: alias bombs and numbers scaled up run to a bound,
#: up to 10 s each; the named reproductions of class 1 stay in the default run); the rest is
#: the slow suite's.
FAST_EVERY = 5


def _fast(i: int) -> bool:
    return i % FAST_EVERY == 0 and GENERATED[i].cls != 1


@pytest.mark.parametrize("i", [i if _fast(i) else pytest.param(i, marks=pytest.mark.slow)
                               for i in range(len(GENERATED))], ids=_case_id)
def test_contract(i, fuzz_env):
    """Generated case i of seed SEED keeps the contract."""
    check(GENERATED[i], fuzz_env, i)


def test_an_unexpected_exception_is_one_line_and_exit_1(fuzz_env, monkeypatch):
    """A bug (any exception gcalign does not expect) is one line, exit 1, not a traceback:
    the handler once named an exception class typer no longer has, so every unexpected
    exception escaped as AttributeError."""
    import gcalign.app.preflight

    def boom(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(gcalign.app.preflight, "preflight", boom)  # validate's checks
    (fuzz_env / "a.yaml").write_bytes(F.emit(F.S).encode())
    res = runner.invoke(app, ["validate", "a.yaml"], catch_exceptions=True)
    assert res.exit_code == 1 and isinstance(res.exception, SystemExit), res.exception
    assert res.stderr.strip().splitlines() == [
        "error: internal error, RuntimeError: boom (a bug in gcalign; GCALIGN_TRACEBACK=1 "
        "shows where)"]


BY_NAME = {c.name: c for c in CASES}


@pytest.mark.parametrize("name, expected", [
    ("CSV 90 s gap", r"d\.csv:1002: time jumps from 10(\.0)? to 100\.01 s"),
    ("PSINS header latitude 90", r"d\.imu: header row 2 field 1 \(latitude, deg\)"),
    ("navigate on results file: NaN rows", r"d\.h5: /imu: row 101: dtheta must be finite"),
    ("navigate on results file: ts 0",
     r"d\.h5: /imu attribute 'ts' \(sample interval, s\) must be a positive number, got 0\.0$"),
    ("navigate on results file: ts missing",
     r"d\.h5: /imu attribute 'ts' \(sample interval, s\) must be a positive number, got nothing$"),
    ("navigate on results file: ts 1e300", r"d\.h5: /imu: sample interval must lie in"),
    ("long bad value", r"align\.mode: .*got 'm{60,90}\.\.\.'$"),
    ("--seed -5", r"--seed: must be a whole number within \[0, 2\^63\), got -5$"),
])
def test_messages_name_the_file_row_and_value(name, expected, fuzz_env):
    """Recorded data are blamed by file and row (not the alignment window that used to be
    blamed); bad values are echoed cut at about 80 characters (robustness classes 6, 11)."""
    import re

    out = run_case(BY_NAME[name], fuzz_env)
    assert out.exit_code == 2, out.stderr
    line = out.stderr.strip()
    assert re.search(expected, line), line
    assert "align.coarse" not in line


def _one_line(res) -> str:
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), res.stderr
    assert "internal error" not in lines[0] and "Traceback" not in res.stderr
    return lines[0]


@pytest.mark.parametrize("argv, expected", [
    (["modulate", "M.yaml", "--dwell", "0"],
     "modulate.compare: fixed with the mechanism's timing: mechanism.dwell_s: the fixed "
     "scheme needs a dwell > 0 s"),
    (["modulate", "M.yaml", "--dwell", "1e-300"],
     "mechanism.dwell_s: the cycle of fixed lasts 1e-300 s, shorter than 10 IMU samples"),
    (["realtime", "R.yaml", "--set", "realtime.filter.window=boxcar2"],
     "realtime.filter.window: 'boxcar2' is not a scipy.signal window"),
    (["modulate", "M.yaml", "--hours", "2e-7"],  # found by the limited generator
     "modulate.hours: 2e-07 h holds fewer than 2 IMU samples at 10 Hz"),
    (["realtime", "R.yaml", "--set", "realtime.filter.nav_cutoff_hz=1e9"],
     "realtime.filter.nav_cutoff_hz: must be in (0, 2500) Hz"),
])
def test_bad_settings_of_a_run_are_exit_2_naming_the_key_and_validate_agrees(
        argv, expected, fuzz_env):
    """Settings that the run's set-up (the scheme's timing, the filter design) would refuse
    are refused as bad input naming the key, by the run and by validate alike; they were
    'internal error' (a pydantic dump, NumPy's array limit, scipy's ValueError)."""
    (fuzz_env / "M.yaml").write_text(F.emit(F.MODULATE))
    (fuzz_env / "R.yaml").write_text(F.emit(F.REALTIME))
    res = runner.invoke(app, [*argv, "-o", "out.h5"])
    assert res.exit_code == 2 and expected in _one_line(res), res.stderr
    assert not (fuzz_env / "out.h5").exists()
    key = {"--dwell": "mechanism.dwell_s", "--hours": "modulate.hours"}.get(argv[2])
    check = runner.invoke(app, ["validate", argv[1], *argv[2:]] if key is None
                          else ["validate", argv[1], "--set", f"{key}={argv[3]}"])
    assert check.exit_code == 2 and expected.split(":")[0] in _one_line(check)


def test_a_value_error_of_a_check_is_exit_2_naming_the_section(fuzz_env, monkeypatch):
    """A check or cost model that meets a value it cannot take (ValueError, TypeError) is bad
    input of its section, exit 2, not an internal error."""
    from gcalign.app.modulate import Modulate

    def refuse(self, inputs):
        raise ValueError("period: cannot be negative")

    monkeypatch.setattr(Modulate, "check", refuse)
    (fuzz_env / "M.yaml").write_text(F.emit(F.MODULATE))
    res = runner.invoke(app, ["modulate", "M.yaml", "-o", "out.h5"])
    assert res.exit_code == 2
    assert _one_line(res) == "error: modulate: period: cannot be negative"


def test_latitude_is_reported_with_the_digits_given(fuzz_env):
    res = runner.invoke(app, ["align", "--lat", "89.99999", "--lon", "1", "-o", "out.h5"])
    assert res.exit_code == 2
    assert "got 89.99999°" in _one_line(res)  # was "got 90.0000°"


@pytest.mark.parametrize("given, missing", [("--lat", "--lon"), ("--lon", "--lat")])
def test_lat_without_lon_is_refused(given, missing, fuzz_env):
    res = runner.invoke(app, ["align", given, "45", "-o", "out.h5"])
    assert res.exit_code == 2
    assert _one_line(res) == (f"error: {missing}: missing beside {given} "
                              f"(site.{missing[2:]}_deg); give both (and --height if it "
                              "matters) or neither")
    assert not (fuzz_env / "out.h5").exists()


def test_a_fifo_or_a_symlink_loop_is_named_for_what_it_is(fuzz_env):
    os.mkfifo(fuzz_env / "pipe.imu")
    (fuzz_env / "a.imu").symlink_to("b.imu")
    (fuzz_env / "b.imu").symlink_to("a.imu")
    for name, what in (("pipe.imu", "is a FIFO (named pipe), expected a regular file"),
                       ("a.imu", "is a symbolic link loop, expected a file")):
        for argv in (["navigate", name], ["calibrate", "--imu-file", name],
                     ["show", name]):
            res = runner.invoke(app, [*argv, "--lat", "45", "--lon", "126"]
                                if argv[0] != "show" else argv)
            assert res.exit_code == 2 and f"{name}: {what}" in _one_line(res), argv


def test_navigate_refuses_to_write_over_its_own_input(fuzz_env):
    (fuzz_env / "S.yaml").write_text(F.emit(F.S))
    assert runner.invoke(app, ["align", "S.yaml", "-o", "a.h5"]).exit_code == 0
    before = (fuzz_env / "a.h5").read_bytes()
    res = runner.invoke(app, ["navigate", "S.yaml", "--init", "a.h5", "-o", "a.h5"])
    assert res.exit_code == 2
    assert _one_line(res).startswith("error: --output: a.h5 is --init of this run")
    assert (fuzz_env / "a.h5").read_bytes() == before


def test_numpy_warnings_do_not_print_before_the_error_line(fuzz_env, monkeypatch):
    """A RuntimeWarning on the way to a refusal (an overflow in a cost estimate, say) would
    print its lines before the one error line."""
    import numpy as np

    from gcalign.app.modulate import Modulate
    from gcalign.errors import ScenarioError

    def overflowing(self, inputs):
        np.float64(1e200) * np.float64(1e200)  # RuntimeWarning: overflow
        raise ScenarioError("modulate.hours: too long")

    monkeypatch.setattr(Modulate, "check", overflowing)
    (fuzz_env / "M.yaml").write_text(F.emit(F.MODULATE))
    res = runner.invoke(app, ["modulate", "M.yaml", "-o", "out.h5"])
    assert res.exit_code == 2 and _one_line(res) == "error: modulate.hours: too long"


def test_the_python_api_refuses_bad_arguments_as_scenario_errors():
    import gcalign
    from gcalign.errors import ScenarioError

    sc = gcalign.example("modulate")
    for call, expected in (
            (lambda: gcalign.run("calibrate", sc, measure="velocity"),
             "run: calibrate takes no option 'measure'"),
            (lambda: gcalign.example("calibrate", [1, 2]), "overrides: must map dotted keys"),
            (lambda: gcalign.load(5), "load: the scenario must be a file name"),
            (lambda: gcalign.run("navigate", sc, zz=1), "run: navigate takes no option 'zz'; "
             "its options: init")):
        with pytest.raises(ScenarioError, match=expected.replace("(", r"\(")):
            call()


@pytest.fixture(scope="module")
def results_of_kinds(results_of_every_kind):
    """The folder of small valid results files of every kind (``calibrate.h5``, ...) and
    their scenarios (``S.yaml``: the alignment's)."""
    return results_of_every_kind["align"].parent


def _first_series(f, kind: str) -> str:
    import h5py

    names: list[str] = []
    f[kind].visititems(lambda n, o: names.append(o.name) if isinstance(o, h5py.Dataset)
                       and o.dtype.kind == "f" and o.size > 3 and not o.is_scale
                       and o.name.rsplit("/", 1)[-1] not in ("t", "t0", "t1") else None)
    return names[0]


def _first_time(f, kind: str) -> str:
    import h5py

    names: list[str] = []
    f[kind].visititems(lambda n, o: names.append(o.name) if isinstance(o, h5py.Dataset)
                       and o.name.rsplit("/", 1)[-1] in ("t", "t0") and o.size > 2 else None)
    return names[0]


def _damage(kind: str, how: str):
    import numpy as np

    def zeros3(f):  # its attributes kept: units do not make a series of three zeros valid
        name = _first_series(f, kind)
        attrs = {k: v for k, v in f[name].attrs.items() if k != "DIMENSION_LIST"}
        del f[name]
        f[name] = np.zeros(3)
        f[name].attrs.update(attrs)
        return name

    def strings(f):
        name = _first_series(f, kind)
        units = f[name].attrs["units"]
        del f[name]
        f[name] = np.array([b"a", b"b"])
        f[name].attrs["units"] = units
        return name

    def nan(f):
        name = _first_series(f, kind)
        a = f[name][()]
        a.flat[1] = np.nan
        f[name][...] = a
        return name

    def zeroed_time(f):
        name = _first_time(f, kind)
        a = f[name][()]
        a[len(a) // 2:] = 0.0
        f[name][...] = a
        return name

    def no_group(f):
        del f[kind]
        return f"/{kind} group"

    def relabelled(f):
        f.attrs["kind"] = "modulate" if kind != "modulate" else "calibrate"
        return "/modulate group" if kind != "modulate" else "/calibrate group"

    return {"zeros(3)": zeros3, "strings": strings, "NaN": nan, "zeroed time": zeroed_time,
            "no group": no_group, "relabelled": relabelled}[how]


@pytest.mark.parametrize("how", ["zeros(3)", "strings", "NaN", "zeroed time", "no group",
                                 "relabelled"])
@pytest.mark.parametrize("kind", ["calibrate", "observability", "realtime", "modulate",
                                  "align"])
def test_damaged_results_files_are_refused_by_plot_show_export_and_init(
        kind, how, results_of_kinds, fuzz_env):
    """Each results kind is read through its check (its command's groups present; numbers
    with units, finite, time not going backwards): plot, show, export and navigate --init
    refuse a damaged file with one line naming the dataset or the group, exit 2. They were
    internal errors, or (a missing or relabelled group) exit 0 with only the trajectory."""
    import shutil

    import h5py

    shutil.copy(results_of_kinds / f"{kind}.h5", fuzz_env / "d.h5")
    with h5py.File(fuzz_env / "d.h5", "a") as f:
        where = _damage(kind, how)(f)
    for argv in (["plot", "d.h5", "-o", "figs"], ["show", "d.h5"],
                 ["export", "d.h5", "--format", "csv"],
                 ["navigate", "--init", "d.h5", str(results_of_kinds / "S.yaml"),
                  "-o", "n.h5"]):
        res = runner.invoke(app, argv)
        assert res.exit_code == 2, (argv, res.stderr)
        line = _one_line(res)
        assert "d.h5" in line and where.split()[0] in line, (argv, line)
    assert not (fuzz_env / "figs").exists() or not list((fuzz_env / "figs").iterdir())
    assert not (fuzz_env / "n.h5").exists()


def test_plot_interrupted_midway_leaves_no_figure_and_no_temporary_folder(
        results_of_kinds, fuzz_env, monkeypatch):
    """plot draws into a temporary folder and renames: a SIGTERM (here raised by the second
    figure's save) leaves neither a truncated PNG under a figure's name nor the folder."""
    from matplotlib.figure import Figure

    from gcalign.app import readback

    saved = []
    real = Figure.savefig

    def savefig(self, p, **kw):
        if saved:
            raise KeyboardInterrupt
        saved.append(p)
        real(self, p, **kw)

    monkeypatch.setattr(Figure, "savefig", savefig)
    with pytest.raises(KeyboardInterrupt):
        readback.plot_file(results_of_kinds / "calibrate.h5", fuzz_env / "figs")
    assert saved and list((fuzz_env / "figs").iterdir()) == []
    assert [p.name for p in fuzz_env.iterdir() if p.name != "figs"] == []
