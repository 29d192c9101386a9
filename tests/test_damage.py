"""Damaged results files of every kind read back by plot, show, export and
``navigate --init`` (:mod:`damage_cases`): exit 2 with one line naming the file and the
dataset, or exactly what the undamaged file gives; never an internal error, a traceback,
or exit 0 having drawn less.

The default suite holds each writer's files to their kind's schema and refuses one
representative damage per kind; the slow suite runs every damage of every dataset of every
kind (the counts of docs/robustness.md)."""

from __future__ import annotations

import damage_cases as D
import pytest

from gcalign.app.checked import SCHEMAS


def test_every_dataset_a_command_writes_is_in_its_kinds_schema(results_of_every_kind):
    """The schemas name every dataset of every kind's real file, so each is checked against
    the others (a new dataset of a writer without a schema entry fails here)."""
    for kind, path in results_of_every_kind.items():
        assert D.undeclared(kind, path) == [], kind
    assert set(SCHEMAS) >= {"simulate", "navigate", "align", "northfind", "calibrate",
                            "observability", "realtime", "modulate", "batch"}


@pytest.mark.parametrize("kind", D.KINDS)
def test_a_series_replaced_by_three_zeros_with_its_units_is_refused_by_every_reader(
        kind, results_of_every_kind, tmp_path):
    """The kind's main series replaced by ``zeros(3)``, its units and frame kept (it was
    drawn, or an internal error): plot, show, export (the kind's group and the series' own)
    and --init each exit 2 with one line naming the file, the dataset and the shape the
    others give it; nothing written."""
    src = results_of_every_kind[kind]
    path = tmp_path / f"d-{kind}.h5"
    path.write_bytes(src.read_bytes())
    (tmp_path / "S.yaml").write_text((src.parent / "S.yaml").read_text())
    name = D.REPRESENTATIVE[kind]
    D.damage(path, name, "zeros(3)")
    D.index_timed_groups(kind, src)
    for command, group in D.commands(kind, name):
        r = D._run(command, path, tmp_path, kind, group)
        lines = r.stderr.strip().splitlines()
        assert r.code == 2 and len(lines) == 1, (command, r.stderr)
        assert lines[0].startswith(f"error: {path}: dataset {name} must have "), lines[0]
        assert "got (3,)" in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["S.yaml", path.name]


@pytest.mark.parametrize("kind", [k for k in D.KINDS if k not in ("northfind", "batch")])
def test_a_zeroed_time_is_refused_naming_it(kind, results_of_every_kind, tmp_path):
    """A time vector whose second half is zeroed is not a time: refused, naming it."""
    import h5py

    src = results_of_every_kind[kind]
    with h5py.File(src, "r") as f:
        names = [n for n in D.datasets(src) if n.rsplit("/", 1)[-1] in ("t", "t0")
                 and f[n].size > 2]
    path = tmp_path / "d.h5"
    path.write_bytes(src.read_bytes())
    D.damage(path, names[0], "zeroed chunk")
    r = D._run("show", path, tmp_path, kind, None)
    assert r.code == 2 and f"dataset {names[0]} " in r.stderr, r.stderr
    assert "monotonic" in r.stderr or "must increase" in r.stderr, r.stderr


@pytest.mark.parametrize("kind", [k for k in D.KINDS if k not in ("northfind", "batch")])
def test_a_time_with_a_second_column_is_refused_by_its_shape(kind, results_of_every_kind,
                                                             tmp_path):
    """A time vector stacked beside itself (two columns) is no time: refused, naming it and
    its shape, not an internal error of the check that times increase."""
    import h5py

    src = results_of_every_kind[kind]
    with h5py.File(src, "r") as f:
        name, size = next((n, f[n].size) for n in D.datasets(src)
                          if n.rsplit("/", 1)[-1] == "t" and f[n].size > 2)
    path = tmp_path / "d.h5"
    path.write_bytes(src.read_bytes())
    D.damage(path, name, "two columns")
    r = D._run("show", path, tmp_path, kind, None)
    assert r.code == 2 and f"dataset {name} must have shape" in r.stderr, r.stderr
    assert f"got ({size}, 2)" in r.stderr, r.stderr


@pytest.fixture(scope="module")
def baselines(results_of_every_kind, tmp_path_factory):
    return D.baselines(results_of_every_kind, tmp_path_factory.mktemp("baselines"))


@pytest.mark.slow  # about 1500 damaged files, four read-backs each
@pytest.mark.parametrize("kind", D.KINDS)
def test_every_damage_of_every_dataset_keeps_the_contract(kind, results_of_every_kind,
                                                          baselines, tmp_path):
    """Every dataset of the kind's file, damaged each way (``zeros(3)``, strings, NaN, a
    zeroed chunk): each read-back is ``same`` or ``refused``, and ``refused`` where the
    damage cannot be data (:func:`damage_cases.must_refuse`)."""
    files = {kind: results_of_every_kind[kind]}
    failures = []
    for case in D.cases(files):
        got = D.run_case(case, files, baselines, tmp_path)
        bad = D.broken(case, got)
        if bad:
            failures.append(f"{case.name} {case.how}: {'; '.join(bad)}")
    assert failures == [], f"{len(failures)} broken:\n" + "\n".join(failures[:40])
