"""Results files read back (plot, show, export, ``navigate --init``): the summary, and the
groups of the command that wrote it checked against that command's layout."""

from __future__ import annotations

from pathlib import Path

from gcalign.app.registry import COMMANDS
from gcalign.io import results

#: kinds whose every dataset has units and finite values when written (north-finding stores
#: NaN for a prediction it cannot make, a batch for a failed run's metrics, navigation for
#: errors without truth; /imu and /truth have readers of their own)
STRICT = frozenset({"align", "calibrate", "observability", "realtime", "modulate"})


def read_checked(path: Path) -> tuple[str, dict, dict]:
    """``(kind, summary, root attributes)`` of a results file whose command's groups
    (:attr:`gcalign.app.command.Command.layout`) are present and undamaged
    (:func:`gcalign.io.results.check_layout`); ScenarioError (one line) otherwise."""
    kind, summary, attrs = results.read_summary(path)
    if kind in COMMANDS:
        results.check_layout(Path(path), kind, COMMANDS[kind].layout, kind in STRICT)
    return kind, summary, attrs
