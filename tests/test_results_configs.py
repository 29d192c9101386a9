"""docs/results.md takes its numbers from the sweeps in configs/sweeps/; these tests pin
that each sweep variant named there *is* the config file it stands for, so the tables are
what `gcalign align CONFIG --seed N` gives, and that the document is assembled from its
section files in a fixed order."""

from __future__ import annotations

import copy
import functools
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from gcalign.app.batch.sweep import load_sweep
from gcalign.app.data import scenario_data
from gcalign.io.scenario import load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parents[1]
CONFIGS, SWEEPS = ROOT / "configs", ROOT / "configs" / "sweeps"


@functools.cache
def _sweep(name: str):
    """A sweep of configs/sweeps/, loaded once (a load builds every variant's scenario)."""
    return load_sweep(SWEEPS / f"{name}.yaml")


def scenario_of(sweep: str, **match):
    """The scenario (model) of the one variant of a sweep whose overrides match."""
    sw = _sweep(sweep)
    want = {k.replace("__", "."): v for k, v in match.items()}
    hits = [v for v in sw.variants if all(v.overrides.get(k) == x for k, x in want.items())]
    assert len(hits) == 1, (sweep, want, len(hits))
    return parse_scenario(copy.deepcopy(hits[0].scenario), sweep)


def same(a, b) -> bool:
    da, db = a.model_dump(exclude={"name"}), b.model_dump(exclude={"name"})
    return da == db


def config(name: str):
    return load_scenario(CONFIGS / name)[0]


MODES = ("conventional", "full-cycle", "half-cycle")


@pytest.mark.parametrize("mode", MODES)
def test_section_5_3_sweeps_are_the_configs(mode):
    fn = mode.replace("-", "_")
    cfg, cfg100 = config(f"seed000_moving_{fn}.yaml"), config(f"seed000_moving_{fn}_tz100.yaml")
    assert same(scenario_of("seed000_modes", case="ours", align__mode=mode), cfg)
    assert same(scenario_of("seed000_modes_tz100", case="ours", align__mode=mode), cfg100)
    assert same(scenario_of("seed000_tz", case="ours", align__mode=mode,
                            align__stages__0__t_z_s=280), cfg)
    assert same(scenario_of("seed000_tz", case="ours", align__mode=mode,
                            align__stages__0__t_z_s=100), cfg100)
    assert cfg.align.stages[0].t_z_s == 280 and cfg100.align.stages[0].t_z_s == 100


@pytest.mark.parametrize("comp", ["none", "one-off", "continued"])
def test_section_5_2_sweep_is_the_configs(comp):
    fn = comp.replace("-", "_")
    for t_z, suffix in ((280, ""), (100, "_tz100")):
        assert same(scenario_of("seed000_swing", align__stages__0__t_z_s=t_z,
                                align__compensation=comp),
                    config(f"seed000_swing_{fn}{suffix}.yaml"))


@pytest.mark.parametrize("base", ["swing", "moving"])
def test_section_6_2_sweep_is_the_configs(base):
    """Variable: the config itself. Fixed: a second stage with T_z = 100 s is the single
    T_z = 100 s stage of the fixed config, number for number (same gains every pass)."""
    from gcalign.app.align.run import run_alignment

    variable = scenario_of(f"seed000_two_stage_{base}", case="ours",
                           align__stages__1__t_z_s=200)
    assert same(variable, config(f"seed000_two_stage_{base}_variable.yaml"))
    fixed_sweep = scenario_of(f"seed000_two_stage_{base}", case="ours",
                              align__stages__1__t_z_s=100)
    fixed = config(f"seed000_two_stage_{base}_fixed.yaml")
    data = scenario_data(fixed, 3)
    np.testing.assert_array_equal(run_alignment(fixed_sweep, data).error_t3,
                                  run_alignment(fixed, data).error_t3)


def test_results_are_assembled_from_section_files_in_order(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("make_results", ROOT / "docs/make_results.py")
    mr = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mr)
    assert mr.SECTIONS[0] == "results_intro.md" and mr.SECTIONS[1] == "results_seed000.md"
    assert set(mr.GENERATORS) <= set(mr.SECTIONS)
    monkeypatch.setattr(mr, "DOCS", tmp_path)
    for name in reversed(mr.SECTIONS[:3]):  # written in reverse: order comes from SECTIONS
        (tmp_path / name).write_text(f"# {name}\n\n")
    out = mr.assemble()
    assert out.read_text() == "\n\n".join(f"# {n}" for n in mr.SECTIONS[:3]) + "\n"


@pytest.mark.parametrize("name", sorted(p.stem for p in SWEEPS.glob("*.yaml")))
def test_every_sweep_of_the_results_has_no_key_that_cannot_matter(name):
    """A grid over a key that cannot matter would give columns that differ only by label."""
    assert _sweep(name).warnings == ()
