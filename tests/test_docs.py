"""Every example of the README and the documentation runs, and the reference says what the
command line does.

* YAML blocks are read by the scenario models (or as sweep files) in the fast suite; a
  block marked ``same-as=PATH`` must say what that file says.
* Shell, Python (doctest) and YAML-file blocks of a page run in order in one folder (a
  copy of ``configs/``, the real recordings of ``tests/data/``), as a reader would type
  them: in the slow suite, since each ``gcalign`` there is a process of seconds.
* The few blocks that cannot run are marked in the page, with the reason
  (``<!-- example: skip: REASON -->`` on the line before the block).
* Every option and argument ``gcalign COMMAND --help`` shows is in the generated CLI
  reference (``docs/reference_pages.py``), under that command.

Markers (an HTML comment on the line before a block): ``skip: REASON``; ``file=NAME``
(a YAML block written to NAME in the folder, for the blocks after it); ``same-as=PATH``
(a copy of a file of the repository).
"""

from __future__ import annotations

import doctest
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from conftest import ROOT

DOCS = ROOT / "docs"
#: docs/results.md is assembled from the results_*.md section files (docs/make_results.py),
#: whose blocks are run once, from the sections.
ASSEMBLED = {DOCS / "results.md"}
PAGES = [ROOT / "README.md"] + sorted(p for p in DOCS.rglob("*.md") if p not in ASSEMBLED)
SHELL = {"bash", "sh", "shell", "console"}
FENCE = re.compile(r"^(?P<indent> *)```(?P<lang>[\w-]*)[^\n]*\n(?P<body>.*?)^(?P=indent)```",
                   re.M | re.S)
MARK = re.compile(r"<!--\s*example:\s*(?P<mark>.*?)\s*-->\s*\n\s*$")


@dataclass(frozen=True)
class Block:
    page: Path
    line: int
    lang: str
    body: str
    mark: str

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    @property
    def skip(self) -> str | None:
        return self.mark.split(":", 1)[1].strip() if self.mark.startswith("skip") else None

    def option(self, key: str) -> str | None:
        m = re.search(rf"\b{key}=(\S+)", self.mark)
        return m.group(1) if m else None


def blocks(page: Path) -> list[Block]:
    text = page.read_text(encoding="utf-8")
    out = []
    for m in FENCE.finditer(text):
        before = MARK.search(text[max(0, m.start() - 300):m.start()])
        lang = m.group("lang").lower()
        if lang == "python" or (lang == "" and ">>> " in m.group("body")):
            lang = "python"
        out.append(Block(page, text.count("\n", 0, m.start()) + 1, lang, m.group("body"),
                         before.group("mark") if before else ""))
    return out


ALL = [b for p in PAGES for b in blocks(p)]
RUNNABLE = [b for b in ALL if b.lang in SHELL | {"yaml", "python"}]
YAML = [b for b in RUNNABLE if b.lang == "yaml"]


def test_every_runnable_block_runs_or_says_why_not():
    """The count of examples, and a reason for every block that does not run."""
    skipped = [b for b in RUNNABLE if b.skip is not None]
    for b in skipped:
        assert len(b.skip) > 15, f"{b.where}: a skipped example needs its reason"
    assert len(RUNNABLE) - len(skipped) >= 40, [b.where for b in RUNNABLE]
    assert len(skipped) <= 11, [b.where for b in skipped]


def sandbox(tmp: Path) -> Path:
    """A folder laid out like the repository for the examples: configs/ copied (a block may
    write a sweep beside the others), the recordings and benchmarks/ (the simulators) linked,
    runs/ empty."""
    shutil.copytree(ROOT / "configs", tmp / "configs")
    (tmp / "tests").mkdir()
    (tmp / "tests" / "data").symlink_to(ROOT / "tests" / "data")
    (tmp / "benchmarks").symlink_to(ROOT / "benchmarks")
    (tmp / "runs").mkdir()
    return tmp


@pytest.mark.parametrize("block", YAML, ids=lambda b: b.where)
def test_yaml_block_is_read_by_the_models(block, tmp_path):
    from gcalign.app.batch.sweep import load_sweep
    from gcalign.io.scenario.loader import parse_scenario

    if block.skip is not None:
        pytest.skip(block.skip)
    data = yaml.safe_load(block.body)
    same = block.option("same-as")
    if same is not None:
        assert data == yaml.safe_load((ROOT / same).read_text()), f"{block.where} != {same}"
        return
    if isinstance(data, dict) and ("grid" in data or "base" in data):
        folder = sandbox(tmp_path)
        path = folder / (block.option("file") or "configs/sweeps/example.yaml")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(block.body)
        load_sweep(path)
    else:
        parse_scenario(data, block.where)


def _run_page(page: Path, folder: Path) -> int:
    """Run the page's blocks in order in `folder`; the count run."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
           "GCALIGN_PROGRESS": "never", "COLUMNS": "100"}
    globs: dict = {}
    ran = 0
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        for b in blocks(page):
            if b.skip is not None or b.lang not in SHELL | {"yaml", "python"}:
                continue
            if b.lang == "python" and page.name == "README.md":
                continue  # doctested by the fast suite (--doctest-glob=README.md)
            if b.lang == "yaml":
                name = b.option("file")
                if name is not None:
                    (folder / name).write_text(b.body)
                ran += 1
            elif b.lang == "python":
                test = doctest.DocTestParser().get_doctest(b.body, globs, b.where, str(page),
                                                           b.line)
                runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
                runner.run(test, clear_globs=False)
                assert runner.failures == 0, f"{b.where}: a doctest failed (output above)"
                ran += 1
            else:
                res = subprocess.run(["bash", "-euo", "pipefail", "-c", b.body], cwd=folder,
                                     env=env, capture_output=True, text=True, timeout=900)
                assert res.returncode == 0, (f"{b.where} exited {res.returncode}:\n"
                                             f"{res.stdout[-2000:]}\n{res.stderr[-3000:]}")
                ran += 1
    finally:
        os.chdir(cwd)
    return ran


RUN_PAGES = [p for p in PAGES if any(b.lang in SHELL | {"python"} and b.skip is None
                                     for b in blocks(p))]


@pytest.mark.slow
@pytest.mark.parametrize("page", RUN_PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_page_examples_run(page, tmp_path):
    assert _run_page(page, sandbox(tmp_path)) > 0


# --------------------------------------------------------------------------- CLI reference


def _reference():
    sys.path.insert(0, str(DOCS))
    try:
        import reference_pages
    finally:
        sys.path.remove(str(DOCS))
    return reference_pages


def _help_options(command: str | None) -> set[str]:
    """Every option and argument ``gcalign [COMMAND] --help`` prints: the first column of
    its Arguments and Options sections (``--output``, ``-o``, ``scenario``)."""
    from gcalign.cli import app

    res = CliRunner().invoke(app, ([command] if command else []) + ["--help"],
                             prog_name="gcalign", env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    names: set[str] = set()
    for title, body in re.findall(r"^(Arguments|Options):\n(.*?)(?:\n\n|\Z)", res.output,
                                  re.M | re.S):
        for first in re.findall(r"^  (\S.*?)(?: {2,}|$)", body, re.M):
            if title == "Arguments":
                names.add(first.split()[0])
            else:
                names |= {t.rstrip(",") for t in first.split() if t.startswith("-")}
    return names


def test_cli_reference_has_every_option_of_every_help():
    ref = _reference()
    page = ref.cli_page()
    parts = re.split(r"^## gcalign (\S+)$", page, flags=re.M)
    top, sections = parts[0], dict(zip(parts[1::2], parts[2::2], strict=True))
    _, commands = ref.cli_commands()
    assert set(sections) == set(commands)
    for name in ["", *commands]:
        body = sections[name] if name else top
        options = _help_options(name or None)
        assert options, name
        documented = {t.strip(",/") for first in re.findall(r"^`([^`]+)`$", body, re.M)
                      for t in first.split()}
        missing = sorted(options - documented)
        assert not missing, f"gcalign {name} --help shows {missing}, not in the CLI reference"


def test_scenario_reference_has_every_key():
    """Every key of every mapping of a scenario appears in the scenario reference, in the
    section of its mapping."""
    ref = _reference()
    page = ref.scenario_page()
    for path, model in ref.scenario_sections():
        title = path or "top level"
        section = page.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]
        for key, field in model.model_fields.items():
            if not field.exclude:
                assert f"`{key}`" in section, f"{title}: {key}"


def test_results_reference_has_every_kind():
    from gcalign.app.checked import SCHEMAS

    page = _reference().results_page()
    for kind, blocks_ in SCHEMAS.items():
        assert f"\n## {kind}\n" in page
        for block in blocks_:
            assert f"`/{block.where}`" in page


def test_quick_start_is_what_ci_runs():
    """The README's two quick-start lines are run as they stand by CI (.ci/run), and the
    getting-started page shows the same install line."""
    quick = next(b for b in blocks(ROOT / "README.md") if b.lang in SHELL)
    ci = (ROOT / ".ci" / "run").read_text()
    lines = [ln.strip() for ln in quick.body.splitlines() if ln.strip()]
    assert lines == ['pip install -e ".[dev]" && gcalign align', "python -m pytest"]
    for line in lines:
        assert f"\n{line}\n" in ci, line
    started = next(b for b in blocks(DOCS / "getting-started.md") if b.lang in SHELL)
    assert started.body.strip() == lines[0]


# --------------------------------------------------------------------------- the site's pages


def _nav_files(items) -> set[str]:
    out: set[str] = set()
    for item in items:
        target = next(iter(item.values())) if isinstance(item, dict) else item
        out |= _nav_files(target) if isinstance(target, list) else {target}
    return out


def test_every_page_is_in_the_site_and_every_link_resolves():
    """What `mkdocs build --strict` (CI) would refuse, said in the fast suite: a page of
    docs/ missing from the nav of mkdocs.yml, a nav entry without its page, a relative link
    to a file that does not exist."""
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    sys.path.insert(0, str(DOCS))
    try:
        import hooks
    finally:
        sys.path.remove(str(DOCS))
    nav = _nav_files(config["nav"])
    generated = {"reference/cli.md", "reference/scenario.md", "reference/results-file.md",
                 "reference/limits.md", "explanation/decisions.md"}
    pages = {str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")} - {"results.md"}
    pages = {p for p in pages if not p.startswith("decisions/")}
    assert not pages - nav, f"pages not in the nav of mkdocs.yml: {sorted(pages - nav)}"
    absent = nav - pages - generated - hooks.OPTIONAL
    assert not absent, f"nav entries of mkdocs.yml without a page: {sorted(absent)}"
    link = re.compile(r"\]\(([^)#\s]+\.md)(?:#[^)]*)?\)")
    for page in [ROOT / "README.md", *DOCS.rglob("*.md")]:
        for target in link.findall(page.read_text(encoding="utf-8")):
            if "://" in target:
                continue
            assert (page.parent / target).resolve().exists() or target.startswith(
                ("reference/", "../reference/", "explanation/", "../explanation/")), \
                f"{page.relative_to(ROOT)}: link to {target}, no such file"
