"""A result written and read back from what its fields say (:mod:`gcalign.schema`): one writer
and one reader for every result dataclass, instead of one per command.

Each field declared with :func:`gcalign.schema.stored` becomes a dataset of the group (with
its ``units``, ``frame``, ``shape`` and ``description`` attributes) or an attribute of it; a
nested result dataclass becomes a subgroup (or, ``inline``, its fields join the group), a
list of them numbered subgroups (``00``, ``01``, ...), a mapping of arrays a subgroup of one
dataset per key; a field whose value is None is left out. Fields without that metadata are
not stored (what the run derives again, or what the command stores itself).
"""

from __future__ import annotations

import dataclasses
import functools
import re
import typing
from typing import Any, TypeVar

import h5py
import numpy as np

from gcalign.io.results import check_writes, put
from gcalign.schema import Stored, field_type, spec

T = TypeVar("T")


def write_fields(g: h5py.Group, result: Any, outer: Any = None) -> None:
    """Write the stored fields of the dataclass `result` into the group `g`; the ``{name}``
    of a field's texts are attributes of `result`, or of the result that holds it (`outer`)."""
    check_writes()  # its attributes and groups too: a full disk ends the run here
    outer = result if outer is None else outer
    for f in dataclasses.fields(result):
        how = spec(f)
        value = getattr(result, f.name)
        if how is None or value is None:
            continue
        name = how.name or f.name
        if how.attr:
            g.attrs[name] = ",".join(value) if isinstance(value, tuple) else value
        elif dataclasses.is_dataclass(value):
            write_fields(g if how.inline else g.create_group(name), value, outer)
        elif isinstance(value, list) and value and dataclasses.is_dataclass(value[0]):
            h = g.create_group(name)
            for i, item in enumerate(value):
                write_fields(h.create_group(f"{i:02d}"), item)
        elif isinstance(value, dict):
            h = g.create_group(name)
            for key, part in value.items():
                if dataclasses.is_dataclass(part):
                    write_fields(h.create_group(key), part, outer)
                else:
                    _put(h, key, part, how)
        elif how.units is None:  # text
            check_writes()
            g.create_dataset(name, data=np.array(value, dtype=h5py.string_dtype()))
        elif how.per is not None:  # one subgroup per entry of the first axis
            for entry, part in zip(getattr(result, how.per), value, strict=True):
                _put(g.require_group(entry), name, part, how)
        else:
            _put(g, name, value, _filled(how, result, outer))


def series_of(result: Any, outer: Any = None, under: str = "") -> dict[str, tuple[Any, Stored]]:
    """The stored arrays of the dataclass `result` by their path in its group (those of a
    result it holds under its name), each with how it is stored, its texts filled as
    :func:`write_fields` fills them: the columns of rows written block by block
    (:class:`gcalign.io.results.Series`)."""
    outer = result if outer is None else outer
    out: dict[str, tuple[Any, Stored]] = {}
    for f in dataclasses.fields(result):
        how, value = spec(f), getattr(result, f.name)
        if how is not None and value is not None:
            name = under + (how.name or f.name)
            out |= (series_of(value, outer, name + "/") if dataclasses.is_dataclass(value)
                    else {name: (value, _filled(how, result, outer))})
    return out


def _filled(how: Stored, result: Any, outer: Any) -> Stored:
    """`how` with each ``{name}`` of its texts replaced by that attribute of `result` (else
    of `outer`; a tuple joined by commas): what follows the result's settings."""
    def value(m: re.Match[str]) -> str:
        return _text(getattr(result, m.group(1), None) or getattr(outer, m.group(1)))

    texts = {k: getattr(how, k) for k in ("units", "frame", "shape", "names", "description")}
    texts = {k: re.sub(r"\{(\w+)\}", value, v) for k, v in texts.items()
             if v is not None and "{" in v}
    return dataclasses.replace(how, **texts) if texts else how


def _text(v: Any) -> str:
    return ",".join(v) if isinstance(v, tuple) else str(v)


def _put(g: h5py.Group, name: str, value: Any, how: Stored) -> None:
    extra = {k: v for k, v in (("shape", how.shape), ("description", how.description),
                               ("names", how.names), ("what", how.what)) if v is not None}
    data = np.asarray(value)
    if how.axes is not None:
        data = np.transpose(data, how.axes)
    if how.flag:
        data = data.astype(np.int8)
    units = "1" if how.units is None else how.units  # ("": a pure number, as stored)
    create = {}
    if how.compress:  # (its empty attributes left out, as these files have always had them)
        create = {"compression": "gzip", "compression_opts": int(how.compress), "shuffle": True}
        extra = {k: v for k, v in extra.items() if v}
    put(g, name, data, units, how.frame, create=create, **extra)


def _get(ds: h5py.Dataset, how: Stored) -> np.ndarray:
    a: np.ndarray = np.asarray(ds[()])
    if how.axes is not None and a.ndim == len(how.axes):  # (else a form with fewer axes)
        a = np.transpose(a, np.argsort(how.axes))
    return a.astype(bool) if how.flag else a


def read_fields(g: h5py.Group, cls: type[T], **given: Any) -> T:
    """The dataclass `cls` from the group `g` as :func:`write_fields` wrote it; `given` fills
    fields the file does not hold; a field it cannot hold (not stored, no default) is None.
    A field stored as a flag comes back as bool, one stored as names as a tuple of str."""
    values: dict[str, Any] = {}
    for f, how, kind, inner in _stored_fields(cls):  # type: ignore[arg-type]
        if f.name in given or not f.init:
            continue
        name = how.name or f.name
        if how.attr:
            if name in g.attrs:
                v = g.attrs[name]
                v = v.decode() if isinstance(v, bytes) else v
                values[f.name] = (tuple(v.split(",")) if isinstance(v, str)
                                  and "tuple" in str(kind) else _plain(v))
        elif dataclasses.is_dataclass(inner) and (how.inline or name in g):
            values[f.name] = read_fields(g if how.inline else g[name], inner)  # type: ignore[arg-type]
        elif dict in (kind, typing.get_origin(kind)) and name in g:
            part = (typing.get_args(kind) or (None, None))[1]
            values[f.name] = {k: read_fields(x, part) if isinstance(x, h5py.Group) else
                              _get(x, how) for k, x in g[name].items()}
        elif how.per is not None:
            entries = values.get(how.per) or given.get(how.per) or ()
            parts = [g[e][name] for e in entries if e in g and name in g[e]]
            values[f.name] = (np.stack([_get(ds, how) for ds in parts])
                              if parts and len(parts) == len(entries) else None)
        elif name in g:
            if how.units is None:
                values[f.name] = tuple(x.decode() if isinstance(x, bytes) else str(x)
                                       for x in g[name][()])
            else:
                values[f.name] = _get(g[name], how)
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        if f.init and f.name not in values and f.default is dataclasses.MISSING and \
                f.default_factory is dataclasses.MISSING:
            values[f.name] = None  # not in the file (an optional series), or not stored
    return cls(**(values | given))


@functools.cache
def _stored_fields(cls: type) -> tuple[tuple[dataclasses.Field[Any], Stored, Any, Any], ...]:
    """``(field, how it is stored, its type, the dataclass it holds or its type)`` of each
    stored field of `cls`, its annotations evaluated once per class."""
    out = []
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        how = spec(f)
        if how is not None:
            kind = field_type(cls, f)
            held = () if typing.get_origin(kind) is dict else typing.get_args(kind)
            out.append((f, how, kind, next((a for a in held if dataclasses.is_dataclass(a)),
                                           kind)))
    return tuple(out)


def _plain(v: Any) -> Any:
    """A scalar attribute as a Python number or text."""
    return v.item() if isinstance(v, np.generic) else v
