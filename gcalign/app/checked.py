"""Results files read back (plot, show, export, ``navigate --init``): the summary, the
groups of the command that wrote it (:func:`layout`), and one check per kind of what those
groups hold.

Each dataset is checked alone first (:func:`gcalign.io.results.check_layout`: numbers
with their units, finite, times monotonic), then against the kind's :data:`SCHEMAS`: the
datasets the readers need are there, and every dataset has the shape its writer gives it,
with sizes that agree across the group (the time ``t`` of length N and every series
(N, k); an attitude (N, 3); the estimates (K, n) of the n states named by the ``states``
attribute; innovations one row per update), whole numbers where indices are stored,
unit quaternions, segment indices within the segment names. A size is what most of the
datasets that share it say (the odd one is named, not the time it disagrees with).

A dataset of a schema's group that no entry names is checked alone only; the damage suite
(``tests/test_damage.py``) holds each writer's files to their schemas.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import typing
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from gcalign.align.result import AlignmentAt, PassRows
from gcalign.allan import TriadRecord
from gcalign.errors import ScenarioError
from gcalign.estimation.calibration import CalibrationResult, Errors, Spans
from gcalign.estimation.degrees import ObservabilityTable
from gcalign.io import results
from gcalign.modulate.analysis import SchemeAnalysis
from gcalign.modulate.linear import LinearSeries
from gcalign.nav.rows import NavRows
from gcalign.northfind.run import NorthfindResult
from gcalign.realtime.filters import ChainResponse
from gcalign.realtime.result import CaseResult
from gcalign.schema import field_type, nested
from gcalign.schema import spec as stored_spec
from gcalign.sim.motions import Truth
from gcalign.transfer.filter import TransferResult

#: kinds whose every dataset has units and finite values when written (north-finding stores
#: NaN for a prediction it cannot make, a batch for a failed run's metrics, navigation for
#: errors without truth; /imu and /truth have readers of their own)
STRICT = frozenset({"align", "calibrate", "observability", "realtime", "modulate"})

Dim = int | str  #: a fixed size, a size named within the kind ("N"), or "_" (any)


@dataclass(frozen=True)
class Data:
    """What one dataset holds: one of `shapes`, numbers (or `text`), finite unless told,
    whole numbers (`whole`), and a `rule`: ``increasing`` (strictly), ``unit`` (rows of
    unit norm: quaternions), ``index<G`` (whole numbers in [0, G)), ``range`` (0, 1, ...,
    n - 1: the index scales of HDF5's dimensions)."""

    shapes: tuple[tuple[Dim, ...], ...]
    text: bool = False
    finite: bool = True
    whole: bool = False
    rule: str = ""


def num(*shapes: tuple[Dim, ...], **kw) -> Data:
    return Data(tuple(shapes), **kw)


def text(*shapes: tuple[Dim, ...]) -> Data:
    return Data(tuple(shapes), text=True)


def times(n: str) -> Data:
    return Data(((n,),), rule="increasing")


@dataclass(frozen=True)
class Block:
    """The datasets of each group matching `where` (``*`` for one level of any name) by
    path within it (``error/phi``; ``*`` matches any name; a trailing ``?``: optional), and
    the sizes given by text attributes of comma-separated names, ``("S", "calibrate",
    "states")`` (``.``: the group itself; ``"a|b"``: a where the group has it, else b), by
    numeric attributes of one value per name (`numbers`, same form), or by a count attribute
    of the group (`counts`: ``("H", "order", 1)``, H = order + 1; absent from a file: no
    say). Each level the entries name may hold the index scales of HDF5's netCDF view
    (``component``, ``component4``, ...: :func:`gcalign.io.results.add_dimension_scales`),
    which the block adds as its last entries."""

    where: str
    items: dict[str, Data]
    names: tuple[tuple[str, str, str], ...] = ()  #: (size, group or ".", attribute)
    numbers: tuple[tuple[str, str, str], ...] = ()
    counts: tuple[tuple[str, str, int], ...] = ()  #: (size, attribute of the group, + k)

    def __post_init__(self) -> None:
        levels = dict.fromkeys(rel.rpartition("/")[0] + "/" for rel in self.items)
        object.__setattr__(self, "items", self.items | {
            f"{level}component*?".lstrip("/"): INDEX for level in levels})


def from_fields(cls: type, under: str = "", **sizes: str) -> dict[str, Data]:
    """A block's entries from the stored fields of a result dataclass that say their dims
    (:class:`gcalign.schema.Stored`), in its subgroup `under` (``"linear/"``), if any, and
    those of the results it holds (in their subgroup, ``*/`` for a list or a mapping; a
    mapping of arrays: ``name/*``), a size named otherwise in that block by `sizes`
    (``D="Q"``): a new field is checked as it is declared."""
    items: dict[str, Data] = {}
    for f in dataclasses.fields(cls):
        how = stored_spec(f)
        inner, listed = nested(cls, f)
        if how is not None and inner is not None:
            items |= from_fields(inner, under if how.inline else
                                 under + (how.name or f.name) + "/" + ("*/" if listed else ""))
        if how is None or how.dims is None:
            continue
        mapping = typing.get_origin(field_type(cls, f)) is dict
        key = (under + ("*/" if how.per else "") + (how.name or f.name)
               + ("/*" if mapping else "") + ("?" if how.optional else ""))
        shapes = tuple(tuple(int(d) if d.isdigit() else sizes.get(d, d) for d in alt.split())
                       for alt in how.dims.split("|"))
        items[key] = Data(shapes, text=how.units is None, finite=how.finite, whole=how.whole,
                          rule=how.rule)
    return items


V3 = num(("N", 3))
INDEX = num(("_",), rule="range")  # the index scales of HDF5's netCDF view (Block)
#: a filter's states S, named by the group's attributes with a display unit and scale each
STATES = (("S", ".", "states"), ("S", ".", "display_units"))
SCALES = (("S", ".", "display_scale"),)

TRUTH = Block("truth", {**from_fields(Truth), "segment_names?": text(("G",))})
REFERENCE = Block("reference", {"t": times("N"), "att": V3})
IMU = Block("imu", {"t": times("N"), "dtheta": V3, "dv": V3,
                    "q_bs?": num(("N", 4), rule="unit")})

SCHEMAS: dict[str, tuple[Block, ...]] = {
    "simulate": (TRUTH, IMU),
    "navigate": (Block("navigate", {**from_fields(NavRows), "att": V3, "v_n": V3, "pos": V3}),
                 TRUTH, REFERENCE),
    "align": (
        Block("align/pass_*", from_fields(PassRows)),
        Block("align/result", from_fields(AlignmentAt)),
        Block("align/transfer", {**from_fields(TransferResult), "nis?": num(("K",))},
              STATES, SCALES),
        TRUTH, REFERENCE),
    "northfind": (Block("northfind", from_fields(NorthfindResult),
                        counts=(("P", "positions", 0), ("R", "repeats", 0))),),
    "calibrate": (
        Block("calibrate", {}, STATES, SCALES),
        Block("calibrate/segments", from_fields(Spans)),
        Block("calibrate/outages", {"start": times("O"), "end": times("O"),
                                    "length": num(("O",))}),
        Block("calibrate/runs/*", {
            **from_fields(CalibrationResult), "update_t?": times("U"),
            **from_fields(Errors, "smoothed/error/"),
            "navigation/t?": times("R"), "navigation/t_run?": times("R"),
            "navigation/att?": num(("R", 3)), "navigation/v_n?": num(("R", 3)),
            "navigation/pos?": num(("R", 3)), **from_fields(Errors, "navigation/error/", D="Q"),
            **from_fields(Errors, "reference_error/", D="E")},
            names=(("S", "calibrate", "states"), ("m", ".", "measure_names"))),
        TRUTH, REFERENCE),
    "observability": (
        Block("observability", from_fields(ObservabilityTable),
            # a transfer run's σ tables span its filter's states, the others the PWCS ones
            names=(("S", ".", "states"), ("C", ".", "covariance_states|states"))),
        TRUTH),
    "realtime": (
        Block("realtime/cases/*", from_fields(CaseResult)),
        Block("realtime/filter", from_fields(ChainResponse), counts=(("H", "order", 1),))),
    "modulate": (Block("modulate/*", {
        **from_fields(NavRows), "error/pos": V3, "error/phi": V3,
        **from_fields(SchemeAnalysis), "invariants/*?": num((3,)),
        **from_fields(LinearSeries, "linear/")}),),
    "allan": (Block("allan/*", from_fields(TriadRecord)),),
    "batch": (
        Block("batch/runs", {
            "variant": num(("R",), whole=True), "seed": num(("R",), whole=True),
            "status": text(("R",)), "error?": text(("R",)), "vkey?": text(("R",)),
            "wall_s?": num(("R",), finite=False),
            "metrics/*": num(("R",), ("R", "_"), finite=False)}),
        Block("batch/aggregate/*/*", {"*": num((), ("k",), finite=False)})),
}


def layout(kind: str) -> tuple[str, ...]:
    """The groups a command of that kind writes beside ``/truth``: its own (``/align``),
    or ``simulate``'s ``/truth`` and ``/imu``."""
    return ("truth", "imu") if kind == "simulate" else (kind,)


def read_checked(path: Path) -> tuple[str, dict, dict]:
    """``(kind, summary, root attributes)`` of a results file whose command's groups
    (:func:`layout`) are present and undamaged
    (:func:`gcalign.io.results.check_layout`) and whose datasets fit together as the
    kind's writer makes them (:data:`SCHEMAS`); ScenarioError (one line) otherwise."""
    kind, summary, attrs = results.read_summary(path)
    if kind in SCHEMAS:
        results.check_layout(Path(path), kind, layout(kind), kind in STRICT)
        with results.open_results(path) as f:
            tree = _Tree(f)
            for block in SCHEMAS[kind]:
                for g in tree.matches(block.where, h5py.Group):
                    _check_block(Path(path), f, g, block)
            extra = EXTRA.get(kind)
            if extra is not None:
                extra(Path(path), f, summary)
    return kind, summary, attrs


# --------------------------------------------------------------------------- the check


class _Tree:
    """The objects under one group by relative path, opened once (a schema's entries are
    patterns matched against these paths)."""

    def __init__(self, g: h5py.Group):
        self.group = g
        self.objects: dict[str, h5py.Dataset | h5py.Group] = {}
        g.visititems(lambda name, obj: self.objects.__setitem__(name, obj))

    def matches(self, rel: str, leaf=h5py.Dataset) -> list:
        """The datasets (or groups, ``leaf=h5py.Group``; ``""``: the group itself) at the
        relative path `rel`, each part a name or a pattern, in file order."""
        if not rel:
            return [self.group]
        parts = rel.split("/")
        return [obj for name, obj in self.objects.items()
                if isinstance(obj, leaf) and name.count("/") == len(parts) - 1
                and all(fnmatch.fnmatchcase(a, b) for a, b in
                        zip(name.split("/"), parts, strict=True))]


@dataclass
class _Votes:
    """The sizes each named dimension of a group is given, and by what (in order)."""

    by: dict[str, list[tuple[int, str]]] = field(default_factory=dict)

    def add(self, dim: str, size: int, what: str) -> None:
        self.by.setdefault(dim, []).append((size, what))

    def sizes(self) -> dict[str, tuple[int, str]]:
        """Each dimension's size (the most given; of a tie, the first) and who gave it."""
        out = {}
        for dim, votes in self.by.items():
            count = Counter(n for n, _ in votes)
            best = max(count.values())
            out[dim] = next((n, w) for n, w in votes if count[n] == best)
        return out


def _size(dim: Dim, sizes: dict[str, tuple[int, str]]) -> int | None:
    if isinstance(dim, int):
        return dim
    return sizes[dim][0] if dim in sizes else None  # (not: "_", or a size nothing gave)


def _attribute_votes(path: Path, f: h5py.File, g: h5py.Group, block: Block,
                     votes: _Votes) -> None:
    for dim, where, attrs in (*block.names, *block.numbers):
        owner = g if where == "." else f.get(where)
        attr = next((a for a in attrs.split("|") if owner is not None and a in owner.attrs),
                    attrs.split("|")[-1])  # "a|b": a where the file has it, else b
        label = f"{owner.name if owner is not None else '/' + where} attribute {attr!r}"
        v = owner.attrs.get(attr) if owner is not None else None
        if (dim, where, attrs) in block.names:
            v = v.decode("utf-8", "replace") if isinstance(v, bytes) else v
            if not isinstance(v, str):
                raise ScenarioError(f"{path}: {label} must list names separated by commas, "
                                    f"got {results._short(v)}")
            votes.add(dim, len(v.split(",")), label)
            continue
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            a = np.array([np.nan])
        if v is None or a.ndim != 1 or not np.isfinite(a).all():
            raise ScenarioError(f"{path}: {label} must hold finite numbers, one per name, "
                                f"got {results._short(v)}")
        votes.add(dim, len(a), label)
    for dim, attr, k in block.counts:
        if attr in g.attrs:
            v = g.attrs[attr]
            try:
                n = int(v)
            except (TypeError, ValueError):
                n = -1
            if n < 0 or n != v:
                raise ScenarioError(f"{path}: {g.name} attribute {attr!r} must be a count, "
                                    f"got {results._short(v)}")
            votes.add(dim, n + k, f"{g.name} attribute {attr!r}" + (f" + {k}" if k else ""))


def _required(path: Path, tree: _Tree, rel: str) -> None:
    """ScenarioError when the dataset `rel` (no pattern in its last part) is missing from
    the group, or from any group its parent path matches (``*/error``: every method's)."""
    g = tree.group
    parent, _, leaf = rel.rpartition("/")
    owners = tree.matches(parent, h5py.Group)
    if not owners and "*" not in parent:
        raise ScenarioError(f"{path}: dataset {g.name}/{rel} missing (a results file of "
                            "this kind has it)")
    for h in owners:
        if not isinstance(h.get(leaf), h5py.Dataset):
            raise ScenarioError(f"{path}: dataset {h.name}/{leaf} missing (a results file "
                                "of this kind has it)")


def _check_block(path: Path, f: h5py.File, g: h5py.Group, block: Block) -> None:
    """One group of a schema: its datasets alone, then their sizes against each other and
    against the attributes that name them."""
    votes = _Votes()
    _attribute_votes(path, f, g, block, votes)
    tree = _Tree(g)
    found: list[tuple[h5py.Dataset, Data, tuple[Dim, ...]]] = []
    seen: set[str] = set()
    for rel, spec in block.items.items():
        optional, rel = rel.endswith("?"), rel.rstrip("?")
        if not optional and "*" not in rel.rpartition("/")[2]:
            _required(path, tree, rel)
        for ds in tree.matches(rel):
            if ds.name in seen:  # named by an earlier entry
                continue
            seen.add(ds.name)
            _check_values(path, ds, spec)
            shape = next((s for s in spec.shapes if len(s) == ds.ndim), None)
            found.append((ds, spec, shape or spec.shapes[0]))
            for dim, n in zip(shape or (), ds.shape if shape else (), strict=True):
                if isinstance(dim, str) and dim != "_":  # (no say when the axes differ)
                    votes.add(dim, n, ds.name)
    sizes = votes.sizes()
    for dim, given in votes.by.items():  # an attribute the datasets outvote
        for n, what in given:
            if " attribute " in what and n != sizes[dim][0]:
                raise ScenarioError(f"{path}: {what} gives {n} names or values, the datasets "
                                    f"{sizes[dim][0]} (as {sizes[dim][1]})")
    for ds, spec, shape in found:
        expected = tuple(_size(d, sizes) for d in shape)
        if len(expected) != ds.ndim or any(e is not None and e != n for e, n in
                                           zip(expected, ds.shape, strict=True)):
            shown = " or ".join(_shown(tuple(_size(d, sizes) for d in s)) for s in spec.shapes)
            why = [f"{sizes[d][0]} as {sizes[d][1]}" for s in spec.shapes for d in s
                   if isinstance(d, str) and d in sizes]
            raise ScenarioError(f"{path}: dataset {ds.name} must have shape {shown}, got "
                                f"{ds.shape}" + (f" ({'; '.join(dict.fromkeys(why))})"
                                                 if why else ""))
        if spec.rule.startswith("index<"):
            _check_index(path, ds, spec.rule[len("index<"):], sizes)


def _shown(shape: tuple[int | None, ...]) -> str:
    text = ", ".join("any" if n is None else str(n) for n in shape)
    return f"({text},)" if len(shape) == 1 else f"({text})"


def _check_values(path: Path, ds: h5py.Dataset, spec: Data) -> None:
    """Type, finiteness, whole numbers and the rule of one dataset on its own."""
    is_text = h5py.check_string_dtype(ds.dtype) is not None or ds.dtype.kind in "OSU"
    if spec.text:
        if not is_text:
            raise ScenarioError(f"{path}: dataset {ds.name} must hold text, got {ds.dtype}")
        return
    if is_text or ds.dtype.kind not in "fiub":
        raise ScenarioError(f"{path}: dataset {ds.name} must hold numbers, got "
                            f"{'text' if is_text else ds.dtype}")
    a = np.asarray(ds[()], dtype=float)
    bad = ~np.isfinite(a)
    if spec.finite and bad.any():
        at = np.argwhere(np.atleast_1d(bad))[0].tolist()
        raise ScenarioError(f"{path}: dataset {ds.name} holds a value that is not finite at "
                            f"{at}; finite numbers expected")
    if spec.whole and np.any(a[~bad] != np.round(a[~bad])):
        raise ScenarioError(f"{path}: dataset {ds.name} must hold whole numbers (indices, "
                            "counts)")
    if spec.rule == "increasing" and a.ndim == 1 and a.size > 1:  # else its shape is refused
        step = np.diff(a)
        if not (step > 0).all():
            i = int(np.argmax(~(step > 0)))
            raise ScenarioError(f"{path}: dataset {ds.name} (time) must increase strictly: "
                                f"row {i} {float(a[i])!r}, row {i + 1} {float(a[i + 1])!r}")
    if spec.rule == "range" and not np.array_equal(a, np.arange(a.size)):
        raise ScenarioError(f"{path}: dataset {ds.name} (an index scale) must hold 0, 1, ..., "
                            f"{a.size - 1}")
    if spec.rule == "unit" and a.ndim == 2 and len(a):
        norm = np.linalg.norm(a, axis=1)
        off = np.abs(norm - 1.0) > 1e-6
        if off.any():
            i = int(np.argmax(off))
            raise ScenarioError(f"{path}: dataset {ds.name} must hold unit quaternions; row "
                                f"{i} has norm {norm[i]:.6g}")


def _check_index(path: Path, ds: h5py.Dataset, dim: str, sizes) -> None:
    n = sizes.get(dim, (None,))[0]
    if n is None:
        return
    a = np.asarray(ds[()], dtype=float)
    out = (a < 0) | (a >= n)
    if out.any():
        i = int(np.argmax(out))
        raise ScenarioError(f"{path}: dataset {ds.name} must index the {n} names of "
                            f"{sizes[dim][1]}: row {i} holds {a[i]:g}")


# --------------------------------------------------------------------------- by kind


def _batch(path: Path, f: h5py.File, summary: dict) -> None:
    """A batch's runs against its summary: each metric stored, variants that exist,
    statuses ``ok``/``failed``, and a finite value of every metric for each run that
    succeeded (a failed run's metrics are NaN; vector metrics are padded with NaN)."""
    runs = f["batch/runs"]
    variants = summary.get("variants")
    metrics = summary.get("metrics")
    if not isinstance(variants, list) or not isinstance(metrics, list):
        raise ScenarioError(f"{path}: root attribute 'summary_json' of a batch must list its "
                            "'variants' and 'metrics'")
    v = runs["variant"][()]
    if len(v) and (v.min() < 0 or v.max() >= len(variants)):
        i = int(np.argmax((v < 0) | (v >= len(variants))))
        raise ScenarioError(f"{path}: dataset {runs.name}/variant must index the "
                            f"{len(variants)} variants of the summary: row {i} holds {v[i]}")
    status = [s.decode() if isinstance(s, bytes) else str(s) for s in runs["status"][()]]
    odd = [s for s in status if s not in ("ok", "failed")]
    if odd:
        raise ScenarioError(f"{path}: dataset {runs.name}/status must hold 'ok' or 'failed', "
                            f"got {odd[0][:40]!r}")
    ok = np.array([s == "ok" for s in status], dtype=bool)
    for m in metrics:
        ds = runs.get(f"metrics/{m}") if isinstance(m, str) else None
        if not isinstance(ds, h5py.Dataset):
            raise ScenarioError(f"{path}: dataset {runs.name}/metrics/{m} missing (the "
                                "summary lists it)")
        a = np.asarray(ds[()], dtype=float).reshape(len(ok), -1)
        empty = ok & ~np.isfinite(a).any(axis=1)
        if empty.any():
            i = int(np.argmax(empty))
            raise ScenarioError(f"{path}: dataset {ds.name} holds no finite value at row {i}, "
                                "a run that succeeded")
        for stats in _Tree(f).matches(f"batch/aggregate/*/{m}", h5py.Group):  # per component
            for stat in stats.values():
                if isinstance(stat, h5py.Dataset) and stat.shape != ds.shape[1:]:
                    raise ScenarioError(f"{path}: dataset {stat.name} must have shape "
                                        f"{ds.shape[1:]}, got {stat.shape} (as the runs' "
                                        f"{ds.name})")


def _align(path: Path, f: h5py.File, summary: dict) -> None:
    g = f["align"]
    if not any(k.startswith("pass_") for k in g) and "transfer" not in g:
        raise ScenarioError(f"{path}: /align holds no pass_NN group and no /align/transfer")


#: checks of a kind beyond its schema's shapes
EXTRA: dict[str, Callable[[Path, h5py.File, dict], None]] = {"batch": _batch, "align": _align}
