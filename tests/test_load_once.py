"""A run's inputs are loaded once (:class:`gcalign.app.command.Inputs`): the recorded file
is parsed once per run, by whichever command reads it, and nothing keeps it between runs
(a second run parses it again: no cache answers for the reader). The reader's parser is
counted, not timed."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.io.recorded import imu as reader

runner = CliRunner()


@pytest.fixture
def short_recording(lasergyro, tmp_path) -> Path:
    """The first 80 s of lasergyro.imu (PSINS text: its header, then 100 Hz rows)."""
    lines = lasergyro.read_text(encoding="utf-8").splitlines(keepends=True)
    path = tmp_path / "short.imu"
    path.write_text("".join(lines[:8000]), encoding="utf-8")
    return path


@pytest.fixture
def parses(monkeypatch) -> list[str]:
    """The files the recorded-data reader parses, one entry per parse."""
    calls: list[str] = []
    parse = reader._read

    def counted(name, layout):
        calls.append(name)
        return parse(name, layout)

    monkeypatch.setattr(reader, "_read", counted)
    return calls


ALIGN = ["--t1", "20", "--t2", "60", "--t3", "60", "--set", "align.level_s=10"]
RUNS = {  # command line after the file; each a short run on the 80 s recording
    "align": ["align", *ALIGN],
    "navigate": ["navigate", "--init", "header", "--duration", "10"],
    "allan": ["allan"],
}


@pytest.mark.parametrize("command", [pytest.param(c, marks=[pytest.mark.slow] * (c == "allan"))
                                     for c in RUNS])
def test_a_recorded_file_is_parsed_once_per_run(command, short_recording, parses, tmp_path):
    """Preflight (extent, consistency checks), the run and the results file's record of
    what the reader assumed all use the one reading; two runs in one process parse twice."""
    name, *rest = RUNS[command]
    for i in (1, 2):
        res = runner.invoke(app, [name, "--imu-file", str(short_recording), *rest,
                                  "-o", str(tmp_path / f"{i}.h5"), "--json"])
        assert res.exit_code == 0, res.output
        assert json.loads(res.stdout)["source"] == str(short_recording)
        assert parses == [str(short_recording)] * i, f"run {i}: {parses}"


def test_transfer_alignment_parses_its_slave_once(parses, tmp_path):
    """align and observability in mode transfer: the preflight's reading of the slave
    recording serves the check (the master's cover of the run) and the run."""
    from conftest import ROOT

    config = ROOT / "configs" / "psins_transfer_fog_mems.yaml"
    for i, command in enumerate(("align", "observability"), 1):
        res = runner.invoke(app, [command, str(config), "-o", str(tmp_path / f"{i}.h5")])
        assert res.exit_code == 0, res.output
        assert len(parses) == i, f"{command}: {parses}"


def test_validate_parses_the_recording_once(short_recording, parses, tmp_path):
    """``gcalign validate``: the preflight of every section and the rows of what the reader
    assumed come from one reading."""
    p = tmp_path / "rec.yaml"
    p.write_text(f"imu_file: {short_recording}\n"
                 "align: {t1_s: 20, t2_s: 60, t3_s: 60, level_s: 10, coarse: {method: inertial}}\n",
                 encoding="utf-8")
    res = runner.invoke(app, ["validate", str(p), "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    assert values["imu_file.format"]["value"] == "psins"
    assert parses == [str(short_recording)]


def test_a_batch_variant_reads_its_file_once_for_its_seeds(short_recording, parses):
    """A batch's runs of one variant pass its reading along (the worker holds the last
    variant's); each new variant reads it once."""
    from gcalign.app.batch import runs as B
    from gcalign.io.scenario import parse_scenario

    B._RECORDING.clear()
    sc = parse_scenario({"imu_file": str(short_recording),
                         "align": {"t1_s": 20, "t2_s": 60, "t3_s": 60, "level_s": 10,
                                   "coarse": {"method": "inertial"},
                                   "aiding": {"source": "none"}}}, "test")
    first = [B.run_summary("align", sc, seed, vkey="a") for seed in (1, 2, 3)]
    assert parses == [str(short_recording)]
    other = B.run_summary("align", sc, 1, vkey="b")
    assert parses == [str(short_recording)] * 2
    assert first[0]["attitude_t3_deg"] == first[2]["attitude_t3_deg"] == \
        other["attitude_t3_deg"]
    B._RECORDING.clear()
