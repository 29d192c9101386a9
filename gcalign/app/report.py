"""Rich tables built by pure functions from plain summaries (the same dicts the JSON holds)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from rich.table import Table
from rich.text import Text


def fmt(x, digits: int = 4) -> str:
    """A number or a vector of numbers in a compact, aligned form."""
    if x is None:
        return "—"
    if isinstance(x, (list, tuple)):
        return "  ".join(fmt(v, digits) for v in x)
    if isinstance(x, float):
        if x != 0 and (abs(x) < 10 ** -(digits - 1) or abs(x) >= 1e6):
            return f"{x:.{digits - 1}e}"
        return f"{x:.{digits}f}"
    return str(x)


def kv_table(title: str, rows: Iterable[Sequence], headers: Sequence[str] = ("", "")) -> Table:
    table = Table(title=title, title_justify="left", header_style="bold")
    for i, h in enumerate(headers):
        table.add_column(h, justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*(Text(c if isinstance(c, str) else fmt(c)) for c in row))
    return table


def summary_table(kind: str, summary: dict) -> Table:
    """The table a command printed, rebuilt from its summary (for `gcalign show`)."""
    from gcalign.app.registry import COMMANDS
    from gcalign.errors import ScenarioError

    if kind not in COMMANDS:
        raise ScenarioError(f"kind: {kind!r} is not a gcalign command ({', '.join(COMMANDS)}); "
                            "a results file from another version, or a damaged one")
    try:
        return COMMANDS[kind].load().table(summary)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as err:
        raise ScenarioError(f"summary_json: not the summary of a {kind!r} run "
                            f"({type(err).__name__}: {str(err)[:60]}); a damaged results "
                            "file, or one from another version") from None
