"""A result written and read back from what its fields say (gcalign.schema,
gcalign.io.stored): the observability table of the seed-002 flight as ``gcalign
observability`` stores it, read back field for field; a new field of a result is one line
in its dataclass, and the file has it."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import h5py
import numpy as np
import pytest

from gcalign.calibrate.observability import DEGREE, ObservabilityTable
from gcalign.estimation.ins_error import STATE_NAMES
from gcalign.io.stored import read_fields, write_fields
from gcalign.realtime.pulses import Pulses
from gcalign.schema import spec, stored


def table(cov: bool = True) -> ObservabilityTable:
    rng = np.random.default_rng(3)
    s = 4
    return ObservabilityTable(
        segments=("static", "climb", "turn", "cruise"), measure="velocity", scaling="p0",
        rtol=1e-12, piece_s=1.0, eta=rng.random((s, 21)), sigma_state=rng.random((s, 21)),
        rank=np.array([9, 15, 17, 12]), tom_rank=np.array([9, 14, 18, 13]),
        null_residual=rng.random(s) * 1e-10, condition=np.array([True, False, True, True]),
        eta_cum=rng.random((s, 21)), rank_cum=np.array([9, 16, 20, 20]),
        tom_rank_cum=np.array([9, 16, 20, 20]),
        cov_degree=rng.random((s, 21)) if cov else None,
        cov_degree_segment=rng.random((s, 21)) if cov else None)


@pytest.mark.parametrize("cov", [True, False])
def test_the_table_comes_back_field_for_field(tmp_path, cov):
    tab = table(cov)
    with h5py.File(tmp_path / "t.h5", "w") as f:
        write_fields(f.create_group("observability"), tab)
    with h5py.File(tmp_path / "t.h5") as f:
        g = f["observability"]
        assert g.attrs["states"] == ",".join(STATE_NAMES)
        assert g.attrs["rank_rtol"] == 1e-12 and g.attrs["measure"] == "velocity"
        assert g["eta"].attrs["units"] == "1" and g["eta"].attrs["shape"] == DEGREE
        assert g["condition"].dtype == np.int8
        assert ("cov_degree" in g) is cov and "margin" not in g  # not stored: derived
        back = read_fields(g, ObservabilityTable)
    for f_ in fields(ObservabilityTable):
        a, b = getattr(tab, f_.name), getattr(back, f_.name)
        if spec(f_) is None:
            continue
        if isinstance(a, np.ndarray):
            assert b.dtype == a.dtype and np.array_equal(a, b), f_.name
        else:
            assert a == b, f_.name


def test_a_new_field_is_one_line(tmp_path):
    """The one line below is all a new field needs to reach the results file, with its
    units and description, and to come back from it."""

    @dataclass(frozen=True)
    class Wider(ObservabilityTable):
        eta_max: np.ndarray | None = field(default=None, metadata=stored("1", description="max"))

    base = table()
    wider = Wider(**{f.name: getattr(base, f.name) for f in fields(base)},
                  eta_max=base.eta.max(axis=1))
    with h5py.File(tmp_path / "w.h5", "w") as f:
        write_fields(f.create_group("observability"), wider)
    with h5py.File(tmp_path / "w.h5") as f:
        ds = f["observability/eta_max"]
        assert ds.attrs["units"] == "1" and ds.attrs["description"] == "max"
        back = read_fields(f["observability"], Wider)
    assert np.array_equal(back.eta_max, base.eta.max(axis=1))


def test_a_north_finding_result_comes_back(tmp_path):
    """North-finding's arrays are (methods, azimuths, repeats) in the core and (repeats,
    azimuths) per method in the file (``coordinate/error``): stored and read back to the
    same arrays."""
    from gcalign.northfind import NorthfindResult, NorthfindSetup, run_northfind

    setup = NorthfindSetup(azimuths=np.radians([10.0, 200.0, 300.0]), lat=np.radians(40.0),
                           positions=8, repeats=2, tilt=np.radians(2.0), gyro_arw=1e-7)
    res = run_northfind(setup, np.random.default_rng(5))
    with h5py.File(tmp_path / "n.h5", "w") as f:
        write_fields(f.create_group("northfind"), res)
    with h5py.File(tmp_path / "n.h5") as f:
        g = f["northfind"]
        assert g["coordinate/error"].shape == (2, 3)  # (repeats, azimuths)
        assert np.array_equal(g["vector/estimate"][()], res.estimate("vector").T)
        back = read_fields(g, NorthfindResult, gyro_residual=None, accel_residual=None)
    for f_ in fields(NorthfindResult):
        if spec(f_) is not None and f_.name != "methods":
            a, b = getattr(res, f_.name), getattr(back, f_.name)
            assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), f_.name
    assert back.methods == res.methods


def test_nested_mapped_and_compressed_fields_come_back(tmp_path):
    """A nested result stored inline (the pulses in a realtime case's group), a mapping of
    series (one dataset per predictor) and compressed series, read back as they were."""

    @dataclass(frozen=True)
    class Case:
        pulses: Pulses = field(metadata=stored(None, inline=True))
        predicted: dict = field(metadata=stored("rad", frame="f", compress=True))
        note: str = "not stored"

    p = Pulses(t=np.arange(5.0), k=np.arange(5), dt_true=np.full(5, 1e-4), dt=np.zeros(5))
    case = Case(pulses=p, predicted={"kalman": np.ones((5, 3)), "ls": np.zeros((5, 3))})
    with h5py.File(tmp_path / "c.h5", "w") as f:
        write_fields(f.create_group("c"), case)
    with h5py.File(tmp_path / "c.h5") as f:
        g = f["c"]
        assert sorted(g) == ["dt", "dt_true", "k", "predicted", "t"]  # pulses inline
        assert g["t"].compression == "gzip" and g["predicted/ls"].attrs["frame"] == "f"
        back = read_fields(g, Case)
    assert all(np.array_equal(getattr(back.pulses, n), getattr(p, n)) for n in ("t", "k", "dt"))
    assert sorted(back.predicted) == ["kalman", "ls"]
    assert np.array_equal(back.predicted["kalman"], np.ones((5, 3)))


@dataclass(frozen=True)
class Term:
    value: np.ndarray = field(metadata=stored("{units}", what="NaN: not resolved",
                                              description="per {kind}"))
    units: str = ""  # (not read back: the dataset's units attribute says it)


@dataclass(frozen=True)
class Triad:
    kind: str = field(metadata=stored(None, attr=True))
    terms: dict[str, Term] = field(metadata=stored(""))


def test_units_and_texts_follow_the_result_and_a_mapping_of_results_comes_back(tmp_path):
    """``{units}`` is the result's own attribute, ``{kind}`` that of the result holding it;
    a mapping of results is a subgroup per key, read back as results."""
    tri = Triad("gyro", {"white": Term(np.array([1e-6, np.nan, 2e-6]), "rad/sqrt(s)"),
                         "instability": Term(np.array([3e-7, 4e-7, np.nan]), "rad/s")})
    with h5py.File(tmp_path / "a.h5", "w") as f:
        write_fields(f.create_group("gyro"), tri)
    with h5py.File(tmp_path / "a.h5") as f:
        ds = f["gyro/terms/white/value"]
        assert dict(ds.attrs) == {"units": "rad/sqrt(s)", "what": "NaN: not resolved",
                                  "description": "per gyro"}
        assert f["gyro/terms/instability/value"].attrs["units"] == "rad/s"
        back = read_fields(f["gyro"], Triad)
    assert back.kind == "gyro" and sorted(back.terms) == ["instability", "white"]
    assert np.array_equal(back.terms["white"].value, tri.terms["white"].value, equal_nan=True)


def test_a_new_north_finding_field_is_written_read_and_checked_from_its_one_line(tmp_path):
    """The one line of `spread` below is all it takes for the results file to hold it, for
    the reader to give it back and for the checks of a file read back to hold it to its
    shape (repeats × azimuths, like the estimates it sits beside)."""
    from gcalign.app.checked import Block, _check_block, from_fields
    from gcalign.errors import ScenarioError
    from gcalign.northfind import NorthfindResult, NorthfindSetup, run_northfind

    @dataclass(frozen=True, eq=False)
    class Wider(NorthfindResult):
        spread: np.ndarray | None = field(default=None, metadata=stored(
            "rad", shape="(repeats, azimuths)", axes=(1, 0), dims="R M"))

    setup = NorthfindSetup(azimuths=np.radians([10.0, 200.0, 300.0]), lat=np.radians(40.0),
                           positions=8, repeats=2)
    res = run_northfind(setup, np.random.default_rng(5))
    base = {f.name: getattr(res, f.name) for f in fields(res)}
    block = Block("northfind", from_fields(Wider))
    assert block.items["spread"].shapes == (("R", "M"),)
    for spread, ok in ((np.ones((3, 2)), True), (np.ones((3, 3)), False)):
        path = tmp_path / f"w{ok}.h5"
        with h5py.File(path, "w") as f:
            write_fields(f.create_group("northfind"), Wider(**base, spread=spread))
        with h5py.File(path) as f:
            g = f["northfind"]
            assert np.array_equal(read_fields(g, Wider, gyro_residual=None,
                                              accel_residual=None).spread, spread)
            if ok:
                _check_block(path, f, g, block)
            else:
                with pytest.raises(ScenarioError, match="dataset /northfind/spread must have "
                                   r"shape \(2, 3\), got \(3, 3\)"):
                    _check_block(path, f, g, block)


def test_a_new_invariant_is_written_checked_and_summarised_from_its_one_line(tmp_path):
    """The one line of `drift_peak` below puts a new invariant of a modulation scheme in the
    results file (units, frame), in the checks of a file read back (three values) and in
    the summary in arc-seconds (``drift_peak_arcsec``), beside the invariants there."""
    from gcalign.app.checked import from_fields
    from gcalign.modulate import ErrorTerms, builtin_scheme
    from gcalign.modulate.invariants import REF, InvariantReport, invariant_report
    from gcalign.schema import summary_of
    from gcalign.units import ARCSEC

    @dataclass(frozen=True)
    class Wider(InvariantReport):
        drift_peak: np.ndarray | None = field(default=None, metadata=stored(
            "rad", frame=REF, summary="arcsec", dims="3"))

    r = invariant_report(builtin_scheme("seed-12"), ErrorTerms.seed004())
    wider = Wider(**{f.name: getattr(r, f.name) for f in fields(r)},
                  drift_peak=np.array([2.0, 4.0, 8.0]) * ARCSEC)
    with h5py.File(tmp_path / "i.h5", "w") as f:
        write_fields(f.create_group("invariants"), wider)
    with h5py.File(tmp_path / "i.h5") as f:
        ds = f["invariants/drift_peak"]
        assert ds.attrs["units"] == "rad" and ds.attrs["frame"] == REF
        assert f["invariants"].attrs["period_s"] == r.period
    assert from_fields(Wider, "invariants/")["invariants/drift_peak"].shapes == ((3,),)
    got = summary_of(wider)
    assert np.allclose(got["drift_peak_arcsec"], [2.0, 4.0, 8.0], rtol=1e-14)
    assert list(got)[-1] == "drift_peak_arcsec"  # after the invariants, in field order
    assert got["misalignment_net_arcsec"] == (r.misalignment_net / ARCSEC).tolist()


@pytest.mark.parametrize("notch", [400.0, None])
def test_a_filter_chains_response_comes_back(tmp_path, notch):
    """A real-time filter chain's response as its fields say: the delays as attributes of
    the group, the notch's parts only with a notch; read back to the same arrays (what
    ``gcalign plot`` draws)."""
    from dataclasses import replace

    from gcalign.realtime.filters import ChainResponse, navigation_chain
    from gcalign.realtime.settings import FilterSettings

    r = navigation_chain(replace(FilterSettings(), notch_hz=notch)).on_grid()
    assert r.freq[0] == 0.125 and r.order == len(r.h) - 1
    with h5py.File(tmp_path / "r.h5", "w") as f:
        write_fields(f.create_group("filter"), r)
    with h5py.File(tmp_path / "r.h5") as f:
        g = f["filter"]
        assert g.attrs["delay"] == r.delay and g["group_delay"].attrs["units"] == "s"
        assert ("notch_b" in g) is (notch is not None)
        back = read_fields(g, ChainResponse)
    for f_ in fields(ChainResponse):
        a, b = getattr(r, f_.name), getattr(back, f_.name)
        assert (a is None and b is None) or np.array_equal(a, b), f_.name


def test_the_attitude_at_t1_t2_t3_is_summarised_and_checked_from_its_fields():
    """``gcalign align``'s attitude keys come from :class:`AlignmentAt`'s fields: their
    names and order in the JSON contract, degrees as ``numpy.degrees`` gives them, None
    without truth; the checks of ``/align/result`` from the same fields."""
    from gcalign.align.result import AlignmentAt
    from gcalign.app.checked import from_fields
    from gcalign.schema import summary_of

    att = np.radians([1.0, -2.0, 30.0]) + 1e-7
    at = AlignmentAt(att, att, None, None, att, None, None, None, None, 1.0, 2.0)
    got = summary_of(at)
    assert list(got) == ["coarse_attitude_deg", "attitude_t2_deg", "truth_t2_deg",
                         "error_t2_deg", "attitude_t3_deg", "truth_t3_deg", "error_t3_deg",
                         "misalignment_t2_deg", "misalignment_t3_deg"]
    assert got["attitude_t3_deg"] == np.degrees(att).tolist() and got["truth_t3_deg"] is None
    items = from_fields(AlignmentAt)
    assert sorted(k for k in items if not k.endswith("?")) == ["att_t2", "att_t3", "coarse_att"]
    assert all(d.shapes == ((3,),) for d in items.values())


@dataclass(frozen=True)
class Pass:  # (at module level: the annotations of a result are evaluated in its module)
    direction: str = field(metadata=stored(None, attr=True, summary=""))
    t: np.ndarray = field(metadata=stored("s", dims="N", summary="s"))
    end_rate: np.ndarray = field(metadata=stored("rad/s", dims="3", summary="dph"))  # the line


@dataclass(frozen=True)
class Run:
    name: str = field(metadata=stored(None, attr=True, summary=""))
    passes: list[Pass] = field(metadata=stored("", summary=""))


def test_a_new_per_pass_field_is_written_checked_and_summarised_from_its_one_line(tmp_path):
    """The one line of `end_rate` below, on the result of one pass, reaches every pass of a
    result holding a list of them: written under each numbered group (``passes/01``),
    checked there (``passes/*/end_rate``), read back, and in the summary of each pass in
    °/h, in field order, beside the pass's other summarised fields."""
    from gcalign.app.checked import from_fields
    from gcalign.schema import summary_of
    from gcalign.units import DPH

    rates = [np.array([1.0, 2.0, 3.0]) * DPH, np.array([-4.0, 0.5, 0.0]) * DPH]
    run = Run("fwd-rev", [Pass("forward", np.array([0.0, 1.0]), rates[0]),
                          Pass("reverse", np.array([1.0, 0.0]), rates[1])])
    with h5py.File(tmp_path / "p.h5", "w") as f:
        write_fields(f.create_group("run"), run)
    with h5py.File(tmp_path / "p.h5") as f:
        assert f["run/passes/01/end_rate"].attrs["units"] == "rad/s"
        back = [read_fields(g, Pass) for g in f["run/passes"].values()]
    assert [p.direction for p in back] == ["forward", "reverse"]
    assert np.array_equal(back[1].end_rate, rates[1])
    assert from_fields(Run)["passes/*/end_rate"].shapes == ((3,),)
    got = summary_of(run)
    assert list(got) == ["name", "passes"]
    assert [list(p) for p in got["passes"]] == [["direction", "t_s", "end_rate_dph"]] * 2
    assert got["passes"][1]["direction"] == "reverse"
    assert np.allclose(got["passes"][0]["end_rate_dph"], [1.0, 2.0, 3.0], rtol=1e-14)
    assert got["passes"][1]["t_s"] == [1.0, 0.0]


def test_a_summary_per_entry_is_grouped_flattened_and_has_no_nan():
    """Fields stored per entry of another field (per method) are summarised per entry under
    that field's name, where the first of them stands; an array of two axes flattened in
    its stored order; NaN (no value) as None, as JSON needs; degrees wrapped to [0, 360)
    where the field says so."""
    from gcalign.schema import summary_of

    @dataclass(frozen=True)
    class R:
        methods: tuple[str, ...] = field(metadata=stored(None, attr=True))
        spread: np.ndarray = field(metadata=stored("rad", summary="deg"))
        error: np.ndarray = field(metadata=stored("rad", per="methods", axes=(1, 0),
                                                  summary="deg"))
        pred: np.ndarray = field(metadata=stored("rad", per="methods", summary="deg"))
        heading: np.ndarray = field(metadata=stored("rad", summary="deg360"))

    err = np.radians(np.arange(12.0).reshape(2, 3, 2))  # (methods, M=3, R=2)
    r = R(("a", "b"), np.radians([1.0, np.nan]), err, np.radians([[1.0, np.nan, 2.0]] * 2),
          np.radians([-90.0, 370.0]))
    got = summary_of(r)
    assert list(got) == ["spread_deg", "methods", "heading_deg"]
    assert got["spread_deg"] == [np.degrees(np.radians(1.0)), None]
    assert list(got["methods"]) == ["a", "b"] and list(got["methods"]["b"]) == ["error_deg",
                                                                                 "pred_deg"]
    assert got["methods"]["b"]["error_deg"] == np.degrees(err[1].T).ravel().tolist()
    assert got["methods"]["a"]["pred_deg"][1] is None
    assert np.allclose(got["heading_deg"], [270.0, 10.0])


def test_a_new_per_method_field_reaches_the_northfind_json_from_its_one_line():
    """North-finding's summary per method is its fields' summary with the figures the
    command derives placed among them: a per-method field declared in one line (a spread
    per azimuth, in arc-seconds) is in every method's entry of the JSON, after the fields
    before it, and every key that was there keeps its value and place."""
    from dataclasses import replace

    from gcalign.api import example
    from gcalign.app.northfind.run import northfind_summary, run_northfind
    from gcalign.northfind.run import NorthfindResult
    from gcalign.units import ARCSEC

    @dataclass(frozen=True, eq=False)
    class Wider(NorthfindResult):
        spread: np.ndarray | None = field(default=None, metadata=stored(
            "rad", per="methods", dims="M", summary="arcsec"))

    sc = example("northfind")
    run = run_northfind(sc, 1)
    res = run.result
    p, m, _ = res.azimuth_est.shape
    spread = np.arange(p * m, dtype=float).reshape(p, m) * ARCSEC
    wider = Wider(**{f.name: getattr(res, f.name) for f in fields(res)}, spread=spread)
    before = northfind_summary(run, sc)["methods"]
    after = northfind_summary(replace(run, result=wider), sc)["methods"]
    assert list(after) == list(before) == list(res.methods)
    for i, name in enumerate(res.methods):
        assert list(after[name]) == [*list(before[name])[:-1], "spread_arcsec",
                                     "max_abs_error_pred_deg"]
        assert all(after[name][k] == v for k, v in before[name].items())
        assert np.allclose(after[name]["spread_arcsec"], np.arange(m) + i * m, rtol=1e-12)
