"""Scenario values that cannot be, refused by their keys before any work, and a recording's
scenario that runs as the recording alone does: an initial pitch of 100°, a velocity of
1e9 m/s and a transfer lever arm of 1e9 m (accepted, then a diverged run or an internal
error); a MAT variable on a CSV reference (ignored); NaN assigned in the Python API
(pydantic's error); a scenario with ``imu_file`` and no ``align`` section (the simulated
default coarse alignment 'given', which needs truth)."""

from __future__ import annotations

import json
import math

import pytest
import yaml
from cli_checks import assert_bad_input
from typer.testing import CliRunner

import gcalign
from conftest import LASERGYRO_XZ, ROOT
from gcalign.cli import app
from gcalign.errors import ScenarioError

runner = CliRunner()
MAT = ROOT / "tests" / "data" / "transfer_align_fog_mems.mat"


@pytest.mark.parametrize("initial, message", [
    ({"att_deg": [100, 0, 0]}, "initial.att_deg: pitch must be within (-90, 90) deg, got 100"),
    ({"att_deg": [1, 0, 400]}, "initial.att_deg: roll and yaw must be within [-360, 360] deg"),
    ({"att_deg": [1, 0, -90], "v_enu_mps": [1e9, 0, 0]},
     "initial.v_enu_mps: must be within [-10000, 10000] m/s"),
])
def test_an_initial_state_no_vehicle_has_is_refused(tmp_path, initial, message):
    out = tmp_path / "n.h5"
    args = ["navigate", "--imu-file", str(LASERGYRO_XZ), "--set",
            f"initial={json.dumps(initial)}", "-o", str(out)]
    assert_bad_input(runner.invoke(app, args), out, message)


def test_a_transfer_lever_arm_past_any_vehicle_is_refused(tmp_path):
    out = tmp_path / "t.h5"
    res = runner.invoke(app, ["validate", str(ROOT / "configs" / "psins_transfer_fog_mems.yaml"),
                              "--set", "align.transfer.lever_arm_m=[1e9, 0, 0]"])
    assert_bad_input(res, out, "align.transfer.lever_arm_m: must be within [-500, 500] m")


@pytest.mark.parametrize("reference, message", [
    ({"format": "csv", "variable": "fogavp"},
     "reference.variable: names an array of a MAT file; format 'csv' has none"),
    ({"format": "i2nav-nav", "variable": "fogavp"}, "reference.variable:"),
    ({"format": "psins-mat", "columns": ["t", "ve", "vn", "vu"]},
     "reference.columns: names the columns of a CSV file; format 'psins-mat' fixes its own"),
])
def test_a_key_the_reference_format_cannot_use_is_refused(tmp_path, reference, message):
    (tmp_path / "ref.csv").write_text("t,pitch,roll,yaw,ve,vn,vu,lat,lon,h\n")
    out = tmp_path / "n.h5"
    ref = {"path": str(tmp_path / "ref.csv"), **reference}
    res = runner.invoke(app, ["navigate", "--imu-file", str(MAT), "--set",
                              f"reference={json.dumps(ref)}", "-o", str(out)])
    assert_bad_input(res, out, message)


def test_a_velocity_aiding_file_refuses_a_mat_variable_too():
    from gcalign.io.recorded.aiding import read_velocity_aiding

    with pytest.raises(ScenarioError, match="aiding.variable: names an array of a MAT file"):
        read_velocity_aiding(MAT, "velocity-enu", variable="fogavp")


@pytest.mark.parametrize("key, value, message", [
    ("align.t2_s", math.nan, "align.t2_s: Input should be a finite number, got nan"),
    ("imu.gyro.bias_dph", [math.nan, 0, 0], "imu.gyro.bias_dph.0: Input should be a finite"),
    ("align.stages.0.xi", 2.0, "align.stages.0.xi: Input should be less than 1, got 2"),
    # a section's own check and a union name the key as a file's error does
    ("align.t2_s", 5.0, "align.t2_s: must be greater than t1_s (10.0 s), got 5.0"),
    ("align.t3_s", math.nan, "align.t3_s: Input should be a finite number or Input should be "
     "'measured', got nan"),
    ("output.rate_hz", -2, "output.rate_hz: must be > 0 or 'full', got -2"),
])
def test_an_assignment_in_the_python_api_is_refused_as_a_scenario_error(key, value, message):
    sc = gcalign.load(ROOT / "configs" / "seed000_moving_conventional.yaml")
    *parents, last = key.split(".")
    obj = sc
    for p in parents:
        obj = obj[int(p)] if p.isdigit() else getattr(obj, p)
    with pytest.raises(ScenarioError) as err:
        setattr(obj, last, value)
    assert str(err.value).startswith(message), str(err.value)
    assert "\n" not in str(err.value)


def test_a_recording_scenario_without_its_section_runs_as_the_recording_alone(tmp_path):
    (tmp_path / "lg.yaml").write_text(yaml.safe_dump({"name": "lg",
                                                      "imu_file": str(LASERGYRO_XZ)}))
    by_file = runner.invoke(app, ["align", str(tmp_path / "lg.yaml"), "--json", "-o",
                                  str(tmp_path / "a.h5")])
    alone = runner.invoke(app, ["align", "--imu-file", str(LASERGYRO_XZ), "--json", "-o",
                                str(tmp_path / "b.h5")])
    assert by_file.exit_code == 0 and alone.exit_code == 0, (by_file.output, alone.output)
    a, b = json.loads(by_file.stdout), json.loads(alone.stdout)
    assert a["attitude_t3_deg"] == b["attitude_t3_deg"]
    assert a["attitude_t3_deg"][2] == pytest.approx(-90.6, abs=0.05)  # DESIGN: −90.58…−90.62°


def test_the_messages_know_the_tag_of_every_motion_kind():
    """The formatter drops the motion union's tag from an error's location
    (``motion.duration_s``, not ``motion.static.duration_s``): it must know every kind."""
    from typing import get_args

    from gcalign.io.scenario.messages import MOTION_KINDS
    from gcalign.io.scenario.motion import MotionModel

    arms = get_args(get_args(MotionModel)[0])
    assert MOTION_KINDS == tuple(get_args(a.model_fields["kind"].annotation)[0] for a in arms)
