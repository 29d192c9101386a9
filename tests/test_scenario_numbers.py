"""Numbers in scenarios are read strictly (gcalign.io.scenario.loader, base.Model): YAML 1.2
numbers in files and ``--set`` values alike, text never turned into a number, and ``--set``
values checked like files (a key given twice, nesting depth)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.errors import ScenarioError
from gcalign.io.scenario.loader import load_scenario, loads, parse_override

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "configs" / "seed000_moving_full_cycle.yaml"
runner = CliRunner()


def _one_line_error(res) -> str:
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output and "RecursionError" not in res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), res.output
    return lines[0]


def _validate(*args: str):
    return runner.invoke(app, ["validate", *args])


def _with_bias(tmp_path: Path, text: str) -> Path:
    """The base scenario with ``imu.gyro.bias_dph`` written as `text` in the file."""
    base = BASE.read_text(encoding="utf-8")
    gyro = "  gyro:  {bias_dph: [0.01, 0.01, 0.01], arw_dprh: 0.001, scale_ppm: [0, 0, 0]}\n"
    assert gyro in base
    block = f"  gyro:\n    bias_dph: {text}\n    arw_dprh: 0.001\n"
    p = tmp_path / "s.yaml"
    p.write_text(base.replace(gyro, block), encoding="utf-8")
    return p


YAML12_FLOATS = [("1e-3", 1e-3), ("1E5", 1e5), (".5", 0.5), ("-2e+3", -2e3), ("5.", 5.0),
                 ("+1.5e-2", 1.5e-2)]
#: gyro biases in °/h written so (within the bias bound of ±3.6e4 °/h)
BIASES = [("1e-3", 1e-3), ("1E3", 1e3), (".5", 0.5), ("-2e+3", -2e3)]


@pytest.mark.parametrize(("text", "value"), YAML12_FLOATS)
def test_yaml_1_2_floats(text, value):
    """The YAML 1.2 core schema's floats; YAML 1.1 (PyYAML's default) reads 1e-3, 1E5 and
    -2e+3 as text."""
    v = loads(f"x: {text}", "t")["x"]
    assert type(v) is float and v == value


@pytest.mark.parametrize(("text", "value"), [("010", 10), ("0o10", 8), ("0x1F", 31),
                                             ("-7", -7), ("+3", 3)])
def test_yaml_1_2_integers(text, value):
    """``010`` is ten (YAML 1.1: octal eight); octal and hex need 0o and 0x."""
    v = loads(f"x: {text}", "t")["x"]
    assert type(v) is int and v == value


@pytest.mark.parametrize("text", ["1:30", "1_000", "1e3.5", "e5", "."])
def test_not_numbers_in_yaml_1_2_stay_text(text):
    """YAML 1.1 makes 1:30 ninety (base 60) and 1_000 a thousand; 1.2 keeps them text."""
    assert loads(f"x: {text}", "t")["x"] == text


@pytest.mark.parametrize(("text", "value"), BIASES)
def test_a_scenario_file_reads_yaml_1_2_floats(tmp_path, text, value):
    sc, _ = load_scenario(_with_bias(tmp_path, text))
    assert sc.imu.gyro.bias_dph == [value] * 3  # a scalar bias is the same on every axis


@pytest.mark.parametrize(("text", "value"), BIASES)
def test_set_reads_yaml_1_2_floats(text, value):
    """``--set imu.gyro.bias_dph=1e-3`` was refused ("should be a valid list, got '1e-3'")."""
    res = _validate(str(BASE), "--set", f"imu.gyro.bias_dph={text}", "--json")
    assert res.exit_code == 0, res.output
    got = json.loads(res.stdout)["values"]["imu.gyro.bias_dph"]["value"]
    assert got == "[" + ", ".join([f"{value:g}"] * 3) + "] °/h"


@pytest.mark.parametrize("text", ['"0.2"', "'0.2'", "!!str 0.2", "[0.2, '0.1', 0.3]",
                                  '" 45 "'])
def test_a_number_written_as_text_is_refused_in_a_file(tmp_path, text):
    """pydantic would convert '0.2' to 0.2: text where a number belongs is refused."""
    line = _one_line_error(_validate(str(_with_bias(tmp_path, text))))
    assert "imu.gyro.bias_dph: a number written as text" in line
    assert "write the number itself" in line


@pytest.mark.parametrize("text", ['"0.2"', "!!str 0.2"])
def test_a_number_written_as_text_is_refused_in_set(text):
    line = _one_line_error(_validate(str(BASE), "--set", f"imu.gyro.bias_dph={text}"))
    assert "imu.gyro.bias_dph: a number written as text ('0.2'" in line


def test_text_fields_still_take_digits():
    """A name made of digits is a name: only fields that take numbers and no text refuse."""
    res = _validate(str(BASE), "--set", "name='2026'", "--json")
    assert res.exit_code == 0, res.output


def test_set_refuses_a_key_given_twice():
    """``--set 'site={lat_deg: 45, lon_deg: 126, lat_deg: 46}'`` was accepted (the last
    value won), as a file with the key twice is not."""
    line = _one_line_error(_validate(str(BASE), "--set",
                                     "site={lat_deg: 45, lon_deg: 126, lat_deg: 46}"))
    assert line.startswith("error: --set site: ")
    assert "key 'lat_deg' given twice in one mapping" in line


@pytest.mark.parametrize("value", ["[" * 5000 + "]" * 5000, "{a: " * 5000 + "1" + "}" * 5000])
def test_set_refuses_a_value_nested_5000_deep(value):
    """It hit RecursionError; now one line naming the key, as for files (200 levels)."""
    line = _one_line_error(_validate(str(BASE), "--set", f"site={value}"))
    assert line == "error: --set site: YAML nested more than 200 levels deep"


def test_set_block_yaml_nested_deep_is_one_line():
    """Block style (indentation, no brackets) nested past Python's recursion limit."""
    value = "\n" + "".join(" " * i + "a:\n" for i in range(5000)) + " " * 5000 + "1"
    with pytest.raises(ScenarioError) as err:
        parse_override(f"site={value}")
    assert str(err.value) == "--set site: YAML nested too deeply"


def test_set_null_is_the_key_written_null_in_the_file(tmp_path):
    """An optional key's null is its default; a key that must have a value says so."""
    assert parse_override("align.level_s=null") == ("align.level_s", None)
    assert parse_override("reference=~") == ("reference", None)
    data = yaml.safe_load(BASE.read_text())
    data["align"]["level_s"] = 30
    given = tmp_path / "given.yaml"
    given.write_text(yaml.safe_dump(data))
    del data["align"]["level_s"]
    (tmp_path / "omitted.yaml").write_text(yaml.safe_dump(data))
    nulled = json.loads(_validate(str(given), "--set", "align.level_s=null", "--json").stdout)
    omitted = json.loads(_validate(str(tmp_path / "omitted.yaml"), "--json").stdout)
    assert nulled["values"] == omitted["values"] != json.loads(
        _validate(str(given), "--json").stdout)["values"]
    line = _one_line_error(_validate(str(BASE), "--set", "align.t3_s=null"))
    assert "align.t3_s: Input should be a valid number" in line and "got None" in line, line


def test_parse_override_keeps_its_messages():
    assert parse_override("align.t3_s=measured") == ("align.t3_s", "measured")
    assert parse_override("imu.gyro.bias_dph=[1e-3, .5]") == ("imu.gyro.bias_dph", [1e-3, 0.5])
    for item, message in (("align.mode", "--set: expected KEY=VALUE"),
                          ("=3", "--set: expected KEY=VALUE"),
                          ("align.mode=", "--set align.mode: give a value"),
                          ("align.mode=[1, 2", "--set align.mode: YAML syntax error")):
        with pytest.raises(ScenarioError, match="^" + message.replace("[", r"\[")):
            parse_override(item)
