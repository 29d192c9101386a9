"""`gcalign example`: list the built-in scenarios, or print one to start a scenario from.

``gcalign example align > mine.yaml`` writes the scenario `gcalign align` runs without a
file; edit it and run ``gcalign align mine.yaml``.
"""

from __future__ import annotations

import re
import sys

import typer

from gcalign.app.registry import COMMANDS
from gcalign.cli.base import app, consoles, emit_json
from gcalign.errors import ScenarioError


def first_comment(text: str) -> str:
    """The first sentence of a scenario file's leading comment: what it is."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("# ").strip())
    words = " ".join(lines)
    return re.split(r"\.\s+(?=[A-Z])", words)[0].rstrip(".") if words else ""


@app.command()
def example(
    name: str | None = typer.Argument(
        None, help="A command with a built-in scenario; without it, the list."),
    as_json: bool = typer.Option(False, "--json", help="The list as one JSON object."),
):
    """Print a built-in scenario (YAML) to start your own from, or list them."""
    known = {cmd: c for cmd, c in COMMANDS.items() if c.builtin}
    if name is None:
        from gcalign.app.report import kv_table

        rows = [(cmd, c.builtin, first_comment(c.builtin_text())) for cmd, c in known.items()]
        consoles(as_json).print(kv_table(
            "built-in scenarios: `gcalign example NAME > mine.yaml`, then "
            "`gcalign NAME mine.yaml`", [(cmd, what) for cmd, _, what in rows],
            ("name", "what"), ("left", "left")))
        if as_json:
            emit_json({"examples": {cmd: {"file": f, "what": w} for cmd, f, w in rows}})
        return
    if name not in known:
        raise ScenarioError(f"example: {name!r} has no built-in scenario; built-in: "
                            f"{', '.join(known)}")
    sys.stdout.write(known[name].builtin_text())
