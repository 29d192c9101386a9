"""What a result's fields are, said once, on the field: the unit (SI, as stored), the frame,
the shape, the name and form in the results file. The core's result dataclasses declare
their fields with this metadata (``field(metadata=stored("rad", ...))``); the results
file's generic writer and reader (:func:`gcalign.io.results.write_fields`,
:func:`~gcalign.io.results.read_fields`) follow it, so that a new field of a result is one
line in one file. No h5py, no pydantic: the core may import this module.

>>> from dataclasses import dataclass, field, fields
>>> @dataclass
... class Fix:
...     t: float = field(metadata=stored("s", attr=True))
...     pos: object = field(metadata=stored("rad, rad, m", frame="[latitude, longitude, height]"))
>>> [(f.name, spec(f).units) for f in fields(Fix)]
[('t', 's'), ('pos', 'rad, rad, m')]
"""

from __future__ import annotations

import dataclasses
import math
import sys
import typing
from dataclasses import dataclass
from typing import Any

import numpy as np

from gcalign import units as u

KEY = "gcalign"  #: the key of the metadata mapping that holds a :class:`Stored`


@dataclass(frozen=True)
class Stored:
    """How one field of a result is stored.

    units : the ``units`` attribute of its dataset (SI); None: text, stored without units.
    frame : its ``frame`` attribute (axes and conventions), if any.
    shape : its ``shape`` attribute (the axes in words), if any.
    description : its ``description`` attribute, if any.
    name : its name in the file (default: the field's).
    attr : stored as an attribute of the group, not a dataset (a tuple of names as one text
        joined by commas).
    flag : a boolean array, stored as 0/1 (int8) and read back as bool.
    axes : the order its axes are stored in (``numpy.transpose``), if not its own: a core
        array (M, R) stored as the file's (R, M) says ``axes=(1, 0)``.
    per : the field that names the entries of its first axis: each entry is stored in a
        subgroup of that name (``per="methods"``: ``coordinate/error``, ``vector/error``).
    inline : a nested result whose fields join its parent's group (no subgroup of its own).
    compress : stored compressed (gzip, shuffled): long series; True: level 1, a number:
        that level.
    names : its ``names`` attribute (what its entries are, comma-separated), if any.
    what : its ``what`` attribute (how its values come about), if any.
    summary : the unit the summary gives it in (:func:`summary_of`: the key
        ``<name>_<summary>``, e.g. ``"arcsec"``), or None (not in the summary, or summarised
        by its command).
    label : its name in the summary, if not its own (``"attitude_t2"``: ``attitude_t2_deg``).

    A ``{name}`` in its units, frame, shape, names or description is that attribute of the
    result, or of the result that holds it (a tuple joined by commas):
    ``stored("{measure_units}")``, units that follow the measurement.

    What its values must be when a results file is read back (the checks of
    :mod:`gcalign.app.checked`):

    dims : its stored shape in sizes named within the result (``"R M"``: repeats ×
        azimuths; a number is a fixed size; ``"R M | M"``: either form), or None (no check
        of its own).
    optional : the readers do without it.
    finite : every value finite (False: NaN stands for "none").
    whole : whole numbers (indices, counts).
    rule : ``increasing`` (a time), ``unit`` (unit quaternions) or empty.
    """

    units: str | None
    frame: str | None = None
    shape: str | None = None
    description: str | None = None
    name: str | None = None
    attr: bool = False
    flag: bool = False
    axes: tuple[int, ...] | None = None
    per: str | None = None
    inline: bool = False
    compress: bool | int = False
    names: str | None = None
    what: str | None = None
    summary: str | None = None
    label: str | None = None
    dims: str | None = None
    optional: bool = False
    finite: bool = True
    whole: bool = False
    rule: str = ""


#: The frame text of an attitude triple (DESIGN.md conventions), as results files carry it.
ATT_FRAME = "[pitch, roll, yaw], C_nb = Rz(yaw) Rx(pitch) Ry(roll), ENU, yaw CCW positive"
#: The frame text of a misalignment vector φ.
PHI_FRAME = "misalignment, ENU: C_nb,est C_nb,true^T = exp(-[phi x])"


def stored(units: str | None, **how: Any) -> dict[str, Stored]:
    """The metadata of a dataclass field stored in the results file as :class:`Stored` says
    (`how`: its keywords): ``x: np.ndarray = field(metadata=stored("rad", frame=...))``."""
    return {KEY: Stored(units, **how)}


def spec(f: dataclasses.Field[Any]) -> Stored | None:
    """How the field `f` is stored, or None (not stored)."""
    return f.metadata.get(KEY)


def field_type(cls: type, f: dataclasses.Field[Any]) -> Any:
    """The type of field `f` of `cls` (its annotation evaluated in the module of `cls`), or
    Any where it cannot be evaluated here."""
    if not isinstance(f.type, str):
        return f.type
    try:
        return eval(f.type, vars(sys.modules[cls.__module__]))  # noqa: S307 - an annotation
    except (NameError, AttributeError, SyntaxError, TypeError):
        return Any


def nested(cls: type, f: dataclasses.Field[Any]) -> tuple[type | None, bool]:
    """The result dataclass field `f` of `cls` holds (itself, optional, or a list or a
    mapping of them; None if none) and whether it is a list or a mapping of them."""
    kind = field_type(cls, f)
    inner = next((a for a in typing.get_args(kind) if dataclasses.is_dataclass(a)), kind)
    listed = typing.get_origin(kind) in (list, tuple, dict)
    return (inner if isinstance(inner, type) and dataclasses.is_dataclass(inner) else None,
            listed)


#: How the summary gives a value in each summary unit (:attr:`Stored.summary`) from the SI
#: one, and the unit the key ends in: degrees as ``numpy.degrees`` gives them (``deg360``
#: wrapped to [0, 360)), the other units by dividing by their SI value, so that the JSON
#: keeps its bits; ``""``: as it is (text, counts, flags), the key without a unit.
SUMMARY_UNITS: dict[str, tuple[str, Any]] = {
    "": ("", None), "deg": ("deg", np.degrees),
    "deg360": ("deg", lambda a: np.mod(np.degrees(a), 360.0)),
    **{k: (k, lambda a, s=si: a / s) for k, si in (
        ("s", 1.0), ("m", 1.0), ("mps", 1.0), ("arcsec", u.ARCSEC), ("dph", u.DPH), ("ug", u.UG))},
}


def summary_of(result: Any) -> Any:
    """The summary of the dataclass `result` (a list of them: a list of their summaries):
    its fields that name a summary unit, in field order, as plain numbers in that unit,
    ``{"<label>_<unit>": value}``. A field holding a result or a list of results gives its
    summary under ``<label>``; a field stored per entry (:attr:`Stored.per`) goes into
    ``<per>: {entry: {...}}``, placed where the first such field stands. Arrays of more than
    one axis are flattened in their stored order (:attr:`Stored.axes`); None and numbers
    that are not finite give None (JSON has no NaN)."""
    if isinstance(result, (list, tuple)):
        return [summary_of(r) for r in result]
    out: dict[str, Any] = {}
    for f in dataclasses.fields(result):
        how = spec(f)
        if how is None or how.summary is None:
            continue
        v = getattr(result, f.name)
        name = how.label or f.name
        if dataclasses.is_dataclass(v) or (isinstance(v, (list, tuple)) and v
                                           and dataclasses.is_dataclass(v[0])):
            out[name] = summary_of(v)
            continue
        suffix, to = SUMMARY_UNITS[how.summary]
        key = f"{name}_{suffix}" if suffix else name
        if how.per is None:
            out[key] = _plain(v, to, how.axes)
            continue
        entries = out.setdefault(how.per, {})
        for entry, part in zip(getattr(result, how.per), v, strict=True):
            entries.setdefault(entry, {})[key] = _plain(part, to, how.axes)
    return out


def placed(summary: dict[str, Any], before: dict[str, dict[str, Any]],
           end: dict[str, Any] | None = None) -> dict[str, Any]:
    """`summary` (:func:`summary_of`) with a command's derived figures among its keys:
    ``before[key]`` just before `key`, `end` after the last; a field summarised later still
    joins (after the keys that were there before it, in field order)."""
    out: dict[str, Any] = {}
    for key, value in summary.items():
        out |= before.get(key, {})
        out[key] = value
    return out | (end or {})


def plain(v: Any, unit: str = "", axes: tuple[int, ...] | None = None) -> Any:
    """`v` as the summary gives a value in the summary unit `unit` (:data:`SUMMARY_UNITS`):
    plain numbers, an array in its `axes` order flattened, numbers not finite as None."""
    return _plain(v, SUMMARY_UNITS[unit][1], axes)


def _plain(v: Any, to: Any, axes: tuple[int, ...] | None) -> Any:
    """A value of the summary: plain numbers (`to`: from SI), flattened, non-finite as None."""
    if v is None or isinstance(v, str):
        return v
    a = np.asarray(v, dtype=float) if to is not None else np.asarray(v)
    if axes is not None and a.ndim == len(axes):
        a = np.transpose(a, axes)
    if to is not None:
        a = to(a)
    if a.ndim > 1:
        a = a.ravel()
    plain = a.tolist()
    if a.dtype.kind != "f" or np.isfinite(a).all():
        return plain
    return None if a.ndim == 0 else [x if math.isfinite(x) else None for x in plain]
