"""What the commands share: scenario loading with overrides, the common options, default
output names, progress, warnings, saving and showing.

Every command of the registry gets the same habits here, not by hand:

* ``--seed``, ``-o/--output``, ``--json``, ``--set KEY=VALUE`` (any scenario key,
  dotted as in a sweep's grid) and the recorded-data options (``--imu-file``, ``--format``,
  ``--axes``, ``--reference``, ``--lat``, ``--lon``, ``--height``) are declared once, as
  annotated types in :mod:`gcalign.cli.options`, that each command names in its signature;
  the recorded-data ones reach :func:`load_with_overrides` as one value (:func:`recorded`).
* :func:`load_with_overrides` applies the options and the ``--set`` items and returns what
  it loaded (:class:`Loaded`), which :func:`run_and_show` takes.
* A default results file named after every override that changes the result
  (:func:`output_name`), and a warning when it replaces a run of other inputs.
* A progress bar on stderr for long runs (:class:`ProgressBar`; a command whose ``execute``
  takes ``progress=`` reports to it), keys that cannot matter as warnings (stderr, table,
  JSON), the wall time beside what ``compute`` measured.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import os
import re
import shutil
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from gcalign.app.command import loading
from gcalign.app.registry import COMMANDS, builtin_text
from gcalign.cli.base import consoles, emit_json
from gcalign.errors import ScenarioError
from gcalign.io.paths import not_a_file

if TYPE_CHECKING:  # loaded by the functions that use them: `gcalign --help` needs neither
    from gcalign.io.scenario import Scenario

# --------------------------------------------------------------------------- options


@dataclass(frozen=True)
class Recorded:
    """The recorded-data options a command was given (:func:`recorded`)."""

    imu_file: Path | None = None
    imu_layout: dict = field(default_factory=dict)  # --format, --axes
    reference: Path | None = None  # --reference
    site: dict = field(default_factory=dict)  # lat_deg, lon_deg, height_m given as options


def recorded(imu_file: Path | None = None, imu_format: str | None = None,
             imu_axes: str | None = None, reference: Path | None = None,
             lat: float | None = None, lon: float | None = None,
             height: float | None = None) -> Recorded:
    """The recorded-data options (:mod:`gcalign.cli.options`: ``ImuFile``, ``ImuFormat``,
    ``ImuAxes``, ``Reference``, ``Lat``, ``Lon``, ``Height``) as one value; ScenarioError
    for --lat without --lon or the reverse."""
    site = {k: v for k, v in (("lat_deg", lat), ("lon_deg", lon), ("height_m", height))
            if v is not None}
    if (lat is None) != (lon is None):
        given, missing = ("--lat", "--lon") if lon is None else ("--lon", "--lat")
        raise ScenarioError(f"{missing}: missing beside {given} (site.{missing[2:]}_deg); "
                            "give both (and --height if it matters) or neither")
    layout = {k: v for k, v in (("format", imu_format), ("axes", imu_axes)) if v is not None}
    return Recorded(imu_file, layout, reference, site)


@dataclass(frozen=True)
class Loaded:
    """A scenario as a command line loaded it (:func:`load_with_overrides`): the validated
    scenario, the text stored in its results file and the options that were applied (key,
    value; in order: the results file's default name records them)."""

    scenario: Scenario
    text: str
    applied: list[tuple[str, object]] = field(default_factory=list)


def install(app: typer.Typer) -> None:
    """The command list shows each registry command's line (its ``help``)."""
    for info in app.registered_commands:
        name = info.name or (info.callback.__name__ if info.callback else "")
        cmd = COMMANDS.get(name)
        if cmd is not None and info.help is None and info.short_help is None:
            info.short_help = cmd.help


# --------------------------------------------------------------------------- loading


def _apply_sets(data: dict, sets: list[str], taken: set[str], source: str,
                applied: list) -> None:
    if not sets:  # nothing to apply: no scenario validated for them
        return
    from gcalign.app.batch.overrides import apply_override
    from gcalign.io.scenario import parse_scenario
    from gcalign.io.scenario.loader import parse_override

    try:
        base = parse_scenario(copy.deepcopy(data), source)
    except ScenarioError:
        base = None  # the file may need the --set to become valid
    for item in sets:
        key, value = parse_override(item)
        if key in taken:
            raise ScenarioError(f"--set {key}: also given by an option; give it once")
        try:
            apply_override(data, key, value, base)
        except ScenarioError as err:
            raise ScenarioError(f"--set {key}: {err}") from None
        taken.add(key)
        applied.append((key, value))


def _apply_recorded(data: dict, inv: Recorded, applied: list) -> None:
    """--imu-file replaces the motion, the mechanism and the site (the file's header, or
    --lat/--lon/--height, gives it); --lat/--lon/--height replace the site."""
    if inv.imu_file is not None:
        path = Path(inv.imu_file)
        if not path.is_file():
            raise ScenarioError(f"--imu-file: {path}: {not_a_file(path)}")
        for key in ("motion", "mechanism", "site", "imu"):  # the simulation it replaces
            data.pop(key, None)
        data["imu_file"] = str(path.resolve())
        applied.append(("imu_file", path))
    if inv.imu_layout:  # --format, --axes describe the recording
        from gcalign.io.scenario.recording import with_layout

        data["imu_file"] = with_layout(data.get("imu_file"), inv.imu_layout)
        applied.extend((f"imu_file.{k}", v) for k, v in inv.imu_layout.items())
    if inv.reference is not None:  # --reference: a reference solution, format from its suffix
        from gcalign.io.recorded.reference import reference_format_of

        if not Path(inv.reference).is_file():
            raise ScenarioError(f"--reference: {inv.reference}: file not found")
        data["reference"] = {"path": str(Path(inv.reference).resolve()),
                             "format": reference_format_of(inv.reference)}
        applied.append(("reference", inv.reference))
    if inv.site:
        data["site"] = {**(data["site"] if isinstance(data.get("site"), dict) else {}), **inv.site}
        applied.extend((f"site.{k}", v) for k, v in inv.site.items())


def read_source(path: Path | None, builtin: str) -> tuple[dict, str, str]:
    """The scenario mapping of the file `path` (without it, of the built-in scenario
    `builtin`), its text and its source name."""
    with loading():  # yaml and the scenario models (pydantic builds each as it loads)
        import yaml

        from gcalign.io.scenario.loader import read_yaml

    if path is None:
        text = builtin_text(builtin)
        return yaml.safe_load(text), text, f"<built-in {builtin}>"
    return read_yaml(path), Path(path).read_text(encoding="utf-8"), str(path)


def load_with_overrides(
    command: str | None,
    path: Path | None,
    overrides: dict | None = None,
    adjust: Callable[[dict, dict], None] | None = None,
    data: dict | None = None,
    text: str | None = None,
    sets: Sequence[str] | None = None,
    recorded: Recorded | None = None,
) -> Loaded:
    """The scenario of `command` (the file, the registry's built-in one, or a given mapping
    `data` with its `text`), its text and its source name, with the options that were given
    written into the command's section before validation, so that a bad option is reported
    like a bad key in the file; then the ``--set KEY=VALUE`` items `sets` and the
    recorded-data options `recorded` (``--imu-file``, site: :func:`recorded`).
    `adjust(section, given)` may drop keys of the section that a given option replaces, and
    may take options out of `given` that it wrote elsewhere in the section. The text stored
    in results files records the overrides.
    """
    cmd = COMMANDS.get(command or "")
    builtin, section = (cmd.builtin or "", cmd.section or "") if cmd else ("", "")
    inv = recorded or Recorded()
    with loading():  # yaml and the scenario models (pydantic builds each as it loads)
        import yaml

        from gcalign.io.scenario import parse_scenario
        from gcalign.io.scenario.loader import with_overrides

    if data is not None:
        source = str(path) if path is not None else f"<built-in {builtin}>"
        text = text or yaml.safe_dump(data, sort_keys=False)
    elif path is None and inv.imu_file is not None:
        from gcalign.io.scenario.recording import recorded_scenario  # a recording alone

        data = recorded_scenario(section, inv.imu_file)
        text, source = yaml.safe_dump(data, sort_keys=False), f"--imu-file {inv.imu_file}"
    else:
        data, text, source = read_source(path, builtin)
    given = {k: v for k, v in (overrides or {}).items() if v is not None}
    named = dict(given)  # what the file name and the stored text record
    done: list = []
    if isinstance(data, dict):
        if given:
            current = data.get(section)
            merged = dict(current) if isinstance(current, dict) else {}
            if adjust is not None:
                adjust(merged, given)
            merged.update(given)
            data[section] = merged
        _apply_recorded(data, inv, done)
        _apply_sets(data, list(sets or []), {f"{section}.{k}" for k in given} | {
            k for k, _ in done}, source, done)
    sc = parse_scenario(data, source)
    if path is not None:
        sc.resolve_paths(Path(path).parent)  # imu_file, reference.path
    applied = [(f"{section}.{k}", v) for k, v in named.items()] + done
    if applied:
        text = with_overrides(text, "", {k: (str(v) if isinstance(v, Path) else v)
                                         for k, v in applied})
    return Loaded(sc, text, applied)


# --------------------------------------------------------------------------- output names


#: Units at the end of a key, left out of a file name (``t2_s=300`` -> ``t2_300``).
_UNIT = re.compile(r"_(deg|s|dph|dprh|ug|ugrhz|ppm|hz|m|mps|mps2|dps|arcsec|ms|us)$")
_UNSAFE = re.compile(r"[^A-Za-z0-9_.+-]+")
MAX_TAG = 60


def _word(value) -> str:
    if isinstance(value, Path):
        return value.stem
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        return "+".join(_word(v) for v in value)
    if isinstance(value, dict):
        return "_".join(f"{k}{_word(v)}" for k, v in value.items())
    return str(value)


_DATA_SUFFIXES = (".h5", ".hdf5", ".imu", ".csv", ".txt", ".gz", ".xz", ".yaml")


def _pathlike(value) -> bool:
    return isinstance(value, Path) or (isinstance(value, str) and (
        "/" in value or value.lower().endswith(_DATA_SUFFIXES)))


def tag(key: str, value) -> str:
    """One override as a file-name word: a word value alone (``conventional``, ``one-off``,
    ``coordinate+vector``), a file by its stem (``imu-lasergyro``), otherwise the key's
    last part without its unit and the value (``passes7``, ``t2_300``, ``tilt5``,
    ``sweep_0-360-5``)."""
    parts = key.split(".")
    tail = _UNIT.sub("", parts[-1])
    if len(parts) > 2 and not parts[-2].isdigit():  # imu.gyro.bias_dph: gyro_bias
        tail = f"{parts[-2]}_{tail}"
    if isinstance(value, bool):
        word = tail if value else f"no-{tail}"
    elif _pathlike(value):
        word = f"{tail.removesuffix('_file')}-{Path(str(value)).name.split('.')[0]}"
    elif isinstance(value, str) and not re.fullmatch(r"[-+0-9.eE]+", value):
        word = value
    elif isinstance(value, (list, tuple)) and value and all(isinstance(v, str) for v in value):
        word = "+".join(value)
    elif isinstance(value, dict):
        word = f"{tail}_" + "-".join(_word(v) for v in value.values())
    else:
        v = _word(value)
        word = tail + ("_" if tail[-1:].isdigit() and v[:1].isdigit() else "") + v
    return _UNSAFE.sub("_", word).strip("_") or "x"


def output_name(name: str, kind: str, seed: int | None,
                overrides: Sequence[tuple[str, object]] = ()) -> Path:
    """``runs/NAME-COMMAND[-OVERRIDES][-rngN].h5``: every override that changes the result
    is in the name (too many: the first ones and a hash of all), the random seed last."""
    words = "-".join(tag(k, v) for k, v in overrides)
    if len(words) > MAX_TAG:
        digest = hashlib.sha256(repr(list(overrides)).encode()).hexdigest()[:8]
        words = words[:MAX_TAG - 9].rstrip("-_") + "-" + digest
    parts = [name, kind] + ([words] if words else []) + (
        [f"rng{seed}"] if seed is not None else [])
    return Path("runs") / ("-".join(parts) + ".h5")


def _replaced_other(out: Path, kind: str, text: str, seed: int | None) -> str | None:
    """A warning if `out` exists and holds a run of other inputs."""
    if not out.is_file():
        return None
    from gcalign.io import results

    try:
        _, _, attrs = results.read_summary(out)
    except (ScenarioError, KeyError, ValueError):
        return f"replaced {out}, which was not a gcalign results file"
    same = (attrs.get("kind") == kind and attrs.get("scenario_yaml") == text
            and int(attrs.get("seed", -1)) == (-1 if seed is None else seed))
    if same:
        return None
    return (f"replaced {out}, a run of other inputs (scenario text, options or seed); "
            "give -o FILE to keep both")


# --------------------------------------------------------------------------- progress


class ProgressBar:
    """A transient rich progress bar on stderr for a run's ``progress(done, total, what)``
    reports. It appears only on a terminal and once a run has taken more than `delay_s`
    (short runs stay quiet), also while no report comes (a first run's numba compile): a
    stage not yet begun shows the time since it started. ``GCALIGN_PROGRESS=always`` forces
    it at once (also into a pipe or a log, where it stays), ``never`` turns it off."""

    def __init__(self, title: str, delay_s: float = 1.0):
        mode = os.environ.get("GCALIGN_PROGRESS", "auto").lower()
        self.enabled = mode == "always" or (mode == "auto" and sys.stderr.isatty())
        self.force = mode == "always"
        self.title, self.delay = title, 0.0 if self.force else delay_s
        self.t0 = time.perf_counter()
        self.bar = None
        self.tasks: dict[str, int] = {}
        self.lock = threading.Lock()
        self.pending: tuple[float, float, str] | None = None
        self.timer: threading.Timer | None = None
        self.closed = False
        self.notes: list[str] = []

    def _start(self):
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TaskProgressColumn, TextColumn
        from rich.table import Column

        # one line of at most 80 columns (a pipe or a log has no width): what, how far, how
        # long; a description too long for it is shortened with "…" (_update), not wrapped
        self.width = min(80, shutil.get_terminal_size((80, 24)).columns)
        self.bar = Progress(
            TextColumn(f"[bold]{self.title}[/bold] {{task.description}}",
                       table_column=Column(no_wrap=True)),
            BarColumn(bar_width=16), TaskProgressColumn(),
            TextColumn("{task.completed:.0f}/{task.total:.0f}"), _time_column(),
            console=Console(stderr=True, force_terminal=self.force or None, width=self.width),
            transient=not self.force,
            # sys.stdout and sys.stderr left as they are: a module imported during the run
            # (colorama's init) must not keep rich's wrapper of them
            redirect_stdout=False, redirect_stderr=False)
        self.bar.start()
        for text in self.notes:
            self.bar.console.print(text, highlight=False)

    def __call__(self, done: float, total: float, what: str = "") -> None:
        if not self.enabled or total <= 0:
            return
        with self.lock:
            if self.closed:
                return
            if self.bar is None:
                wait = self.delay - (time.perf_counter() - self.t0)
                if wait > 0 and done < total:  # a report before the delay: shown after it
                    self.pending = (done, total, what)
                    if self.timer is None:
                        self.timer = threading.Timer(wait, self._late_start)
                        self.timer.daemon = True
                        self.timer.start()
                    return
                self._start()
            self._update(done, total, what)

    def note(self, text: str) -> None:
        """A line above the bar (it stays when the bar goes), where the bar is shown."""
        if not self.enabled:
            return
        with self.lock:
            if self.bar is not None:
                self.bar.console.print(text, highlight=False)
            elif not self.closed:
                self.notes.append(text)

    def _late_start(self) -> None:
        with self.lock:
            if self.bar is None and not self.closed and self.pending is not None:
                self._start()
                self._update(*self.pending)

    def _update(self, done: float, total: float, what: str) -> None:
        assert self.bar is not None
        if what not in self.tasks:
            for other in self.tasks.values():  # a new stage: the earlier ones are done
                task = self.bar.tasks[other]
                self.bar.update(other, completed=task.total)
            # the rest of the line: title, bar 16, "100%", done/total, "0:00:00 so far" and
            # the spaces between them
            rest = len(self.title) + 1 + 16 + 4 + 2 * len(f"{total:.0f}") + 1 + 14 + 4
            room = max(8, self.width - rest)
            shown = what if len(what) <= room else what[:room - 1] + "…"
            self.tasks[what] = self.bar.add_task(shown, total=total)
        self.bar.update(self.tasks[what], completed=min(done, total), total=total)

    def close(self) -> None:
        with self.lock:
            self.closed = True
            if self.timer is not None:
                self.timer.cancel()
            if self.bar is not None:
                self.bar.stop()
                self.bar = None

    def __enter__(self) -> ProgressBar:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


COMPILING = ("compiling gcalign's numerical kernels (numba): once, on a first run or after "
             "an upgrade; later runs load them from the cache")


@contextlib.contextmanager
def compile_note(bar: ProgressBar):
    """While a command runs with a progress bar, say once above it (:data:`COMPILING`)
    when numba compiles a kernel instead of loading it from its cache: a first run takes
    tens of seconds more, which the bar alone would leave unexplained."""
    if not bar.enabled:
        yield
        return
    from numba.core import event

    class _Note(event.Listener):
        said = False

        def on_start(self, ev) -> None:
            if not self.said:
                self.said = True
                bar.note(COMPILING)

        def on_end(self, ev) -> None:
            pass

    listener = _Note()
    event.register("numba:compile", listener)
    try:
        yield
    finally:
        event.unregister("numba:compile", listener)


def _time_column():
    """A rich column (made when a bar is drawn, so that rich loads only then): the time
    left, or, before any of the stage is done, the time it has run."""
    from rich.progress import ProgressColumn
    from rich.text import Text

    class TimeColumn(ProgressColumn):
        def render(self, task) -> Text:
            def clock(s: float | None) -> str:
                if s is None:
                    return "-:--:--"
                s = int(s)
                return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"

            if task.completed <= 0 and not task.finished:
                return Text(f"{clock(task.elapsed)} so far", style="progress.elapsed")
            return Text(f"{clock(task.time_remaining)} left", style="progress.remaining")

    return TimeColumn()


# --------------------------------------------------------------------------- run and show


def run_and_show(name: str, loaded: Loaded, seed: int | None, output: Path | None,
                 as_json: bool, on_summary: Callable[[dict], None] | None = None,
                 stdout_free: bool = False, **options) -> None:
    """Run command `name` on a `loaded` scenario (its preflight, then its execute), write the
    results file and show its table. Default file name: :func:`output_name` with the
    overrides of the command line (and `options`, e.g. ``--init``). A streaming command
    writes its series into the (temporary) file while it runs; `options` go to its
    ``execute``, a progress bar to a command that reports progress
    (:func:`gcalign.app.runner.run_command`). Keys that cannot matter become warnings.
    `on_summary` hears of the summary stored; `stdout_free` keeps stdout for the command's
    own output (the table goes to stderr, as under --json, without the JSON)."""
    from gcalign.app.runner import run_command

    sc, text = loaded.scenario, loaded.text
    recorded = sc.imu_file is not None
    run_seed = None if recorded else (sc.imu.seed if seed is None else seed)
    given = [*loaded.applied, *((k, v) for k, v in options.items()
                                if v is not None and v is not False)]  # a flag not given
    out = output or output_name(sc.name, name, run_seed, given)
    notes: list[str] = []
    if recorded and seed is not None:
        notes.append("--seed: cannot matter with recorded data (no random numbers are drawn)")
    if output is None:
        replaced = _replaced_other(out, name, text, run_seed)
        if replaced:
            notes.append(replaced)
    with ProgressBar(name) as bar, compile_note(bar):  # the scenario's name heads the table
        summary = run_command(name, sc, text, seed, out, progress=bar, notes=notes,
                              before_write=bar.close, **options)
    if on_summary is not None:
        on_summary(summary)
    warn(summary["warnings"], as_json or stdout_free)
    sys.stderr.write(f"wrote {out}\n")  # where the file went, also under --json
    show(name, summary, as_json, stdout_free)


def warn(warnings: Sequence[str], as_json: bool) -> None:
    """The warnings on stderr, one line each, unless the table that lists them is shown on
    the same screen (a terminal); under --json the table on stderr leaves them out
    (:func:`show`): each is said once where it is read."""
    if not as_json and sys.stdout.isatty():
        return
    for line in warnings:
        sys.stderr.write(f"warning: {line}\n")


def show(kind: str, summary: dict, as_json: bool, stdout_free: bool = False) -> None:
    """Print a command's table with its warnings under it and, under --json, the table on
    stderr without the warnings (one line each beside it: :func:`warn`) and the summary;
    `stdout_free`: the table on stderr as under --json, and no JSON."""
    from gcalign.app.readback import summary_table

    aside = as_json or stdout_free
    shown = {**summary, "warnings": []} if aside else summary  # said above (warn)
    consoles(aside).print(summary_table(kind, shown))
    if as_json:
        emit_json(summary)
