"""The choice lists of the command line's help are the code's own tuples
(:mod:`gcalign.choices`), which the code that acts on the choice uses: a new mode or format
appears in the help without a hand edit, and a list cannot drift from what is accepted."""

from __future__ import annotations

import re

import pytest
import typer.main

from gcalign.align.compensate import METHODS
from gcalign.align.cycles import MODES
from gcalign.app.export import FORMATS as EXPORTS
from gcalign.cli import app
from gcalign.estimation.ins_error import MEASUREMENTS
from gcalign.io.recorded.imu import FORMAT_NAMES
from gcalign.io.scenario.align import AlignConfig
from gcalign.io.scenario.calibrate import CalibrateConfig, ObservabilityConfig
from gcalign.io.scenario.navigation import NavigationConfig
from gcalign.io.scenario.northfind import MethodName
from gcalign.io.scenario.realtime import PredictorName
from gcalign.io.scenario.transfer import TransferConfig
from gcalign.nav.strapdown import VERTICAL_MODES
from gcalign.northfind.estimate import METHODS as AZIMUTH_METHODS
from gcalign.realtime.settings import PREDICTORS
from gcalign.transfer.filter import MATCHINGS

CLICK = typer.main.get_command(app)


def choices(command: str, option: str) -> tuple[str, ...]:
    """The ``a | b | c`` list in the help of `option` of `command`."""
    param = next(p for p in CLICK.commands[command].params  # type: ignore[attr-defined]
                 if option in p.opts)
    lists = re.findall(r"[\w+-]+(?: \| [\w+-]+)+", param.help)
    assert len(lists) == 1, param.help
    return tuple(lists[0].split(" | "))


@pytest.mark.parametrize(("command", "option", "code"), [
    ("align", "--mode", (*MODES, "transfer")),
    ("align", "--compensation", METHODS),
    ("align", "--format", FORMAT_NAMES),
    ("navigate", "--format", FORMAT_NAMES),
    ("validate", "--format", FORMAT_NAMES),
    ("export", "--format", tuple(EXPORTS)),
    ("navigate", "--vertical", ("auto", *VERTICAL_MODES)),
    ("calibrate", "--measure", MEASUREMENTS),
    ("observability", "--measure", MEASUREMENTS),
    ("calibrate", "--truth", ("scenario", "draw")),
    ("observability", "--matching", MATCHINGS),
    ("northfind", "--method", (*AZIMUTH_METHODS, "vector_literal")),
    ("realtime", "--predictor", PREDICTORS),
])
def test_each_help_choice_list_is_the_codes_tuple(command, option, code):
    assert choices(command, option) == tuple(code)


def test_the_scenario_models_take_the_same_choices():
    """The scenario's keys (pydantic Literals) accept exactly the listed names."""
    fields = AlignConfig.model_fields
    assert fields["mode"].annotation.__args__ == (*MODES, "transfer")  # type: ignore[union-attr]
    assert fields["compensation"].annotation.__args__ == METHODS  # type: ignore[union-attr]
    literals = [(NavigationConfig, "vertical", ("auto", *VERTICAL_MODES)),
                (CalibrateConfig, "measure", MEASUREMENTS),
                (ObservabilityConfig, "measure", MEASUREMENTS),
                (CalibrateConfig, "truth", choices("calibrate", "--truth")),
                (TransferConfig, "matching", MATCHINGS)]
    for model, name, code in literals:
        annotation = model.model_fields[name].annotation
        assert annotation.__args__ == code, (model, name)  # type: ignore[union-attr]
    assert MethodName.__args__ == (*AZIMUTH_METHODS, "vector_literal")  # type: ignore[attr-defined]
    assert PredictorName.__args__ == PREDICTORS  # type: ignore[attr-defined]
