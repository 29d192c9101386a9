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
    summary : the unit the summary gives it in (:func:`summary_of`: the key
        ``<name>_<summary>``, e.g. ``"arcsec"``), or None (not in the summary, or summarised
        by its command).
    label : its name in the summary, if not its own (``"attitude_t2"``: ``attitude_t2_deg``).

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


#: SI per summary unit (:attr:`Stored.summary`): the summary divides the stored value by it
#: (degrees: ``numpy.degrees``)
SUMMARY_UNITS = {"s": 1.0, "m": 1.0, "arcsec": u.ARCSEC, "dph": u.DPH, "ug": u.UG}


def summary_of(result: Any) -> dict[str, Any]:
    """The fields of the dataclass `result` that name a summary unit, in field order, as
    plain numbers in that unit (None stays None): ``{"<label>_<unit>": value in unit}``."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(result):
        how = spec(f)
        if how is None or how.summary is None:
            continue
        v = getattr(result, f.name)
        if v is not None:
            a = np.asarray(v, dtype=float)
            v = (np.degrees(a) if how.summary == "deg" else a / SUMMARY_UNITS[how.summary]
                 ).tolist()
        out[f"{how.label or f.name}_{how.summary}"] = v
    return out
