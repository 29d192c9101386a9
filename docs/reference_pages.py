"""The reference pages of the documentation, generated from the code at every build so that
they cannot drift from it (``docs/gen_pages.py`` writes them into the site;
``tests/test_docs.py`` holds them to ``gcalign COMMAND --help``):

* :func:`cli_page`: every command, argument and option of the Typer app, with the help text
  ``--help`` prints (the same click help records);
* :func:`scenario_page`: every scenario key of the pydantic models, with its type, default,
  unit (from the key's suffix, the project's rule), bounds and description;
* :func:`results_page`: the groups and datasets of each kind of results file, from
  :func:`result_layout` (the one place that knows where the layout is described).

Plain functions returning Markdown; nothing here imports mkdocs.
"""

from __future__ import annotations

import html
import json
import types
from typing import Annotated, Any, Literal, Union, get_args, get_origin

# --------------------------------------------------------------------------- command line


def _esc(text: str) -> str:
    """Help text as Markdown: no HTML from `<path>`-like metavars, backticks kept."""
    text = html.escape(" ".join(str(text).split()), quote=False)
    return text.replace("[", "\\[").replace("]", "\\]")  # never a link reference


def cli_commands():
    """``(click group, {name: click command})`` of the gcalign command line, in the order
    ``gcalign --help`` lists them."""
    import typer.main

    from gcalign.cli import app

    group = typer.main.get_command(app)
    ctx = group.make_context("gcalign", [], resilient_parsing=True)
    return group, {name: group.get_command(ctx, name) for name in group.list_commands(ctx)}


def help_records(command, name: str) -> list[tuple[str, str]]:
    """``(option or argument, help)`` of every parameter `--help` shows, in its order."""
    ctx = command.make_context(name, [], resilient_parsing=True)
    out = []
    for p in command.get_params(ctx):
        if getattr(p, "hidden", False):
            continue
        record = p.get_help_record(ctx)
        if record is not None:
            out.append((record[0], record[1] or ""))
    return out


def cli_page() -> str:
    group, commands = cli_commands()
    lines = ["# Command line", "",
             "Every command, argument and option of `gcalign`, generated from the command "
             "line itself at each build of this site (the text `gcalign COMMAND --help` "
             "prints). Exit codes: 0 success, 2 bad input (one line naming the field, the "
             "value and what is allowed; no results file), 1 other failures, 130 "
             "interrupted, 143 terminated.", "",
             "```text", "gcalign [--version] COMMAND [ARGS]...", "```", "",
             _esc(group.help or ""), ""]
    lines += _params(group, "gcalign")
    lines += ["", "| command | what it does |", "| --- | --- |"]
    for name, cmd in commands.items():
        short = cmd.get_short_help_str(limit=300)
        lines.append(f"| [`{name}`](#gcalign-{name}) | {_esc(short).replace('|', '&#124;')} |")
    for name, cmd in commands.items():
        ctx = cmd.make_context(name, [], resilient_parsing=True)
        usage = " ".join(cmd.collect_usage_pieces(ctx))
        lines += ["", f"## gcalign {name}", "", "```text", f"gcalign {name} {usage}", "```",
                  "", _esc(cmd.help or ""), ""]
        lines += _params(cmd, name)
    return "\n".join(lines) + "\n"


def _params(command, name: str) -> list[str]:
    out = []
    for opts, text in help_records(command, name):
        out += [f"`{opts}`", f":   {_esc(text) or '&nbsp;'}", ""]
    return out


# --------------------------------------------------------------------------- scenario keys

#: Unit of a key by its suffix (the project's rule: the unit is part of the key's name).
UNITS = (("_dphrh", "°/h/√h"), ("_ughrh", "µg/√h"), ("_dps3", "°/s³"), ("_dps2", "°/s²"),
         ("_dps", "°/s"), ("_dph", "°/h"),
         ("_dprh", "°/√h"), ("_ugrhz", "µg/√Hz"), ("_ugs", "µg·s"), ("_ug", "µg"),
         ("_ppm", "ppm"), ("_deg", "°"), ("_arcsec", "″"), ("_arcmin", "′"),
         ("_mps2", "m/s²"), ("_mps", "m/s"), ("_hz", "Hz"), ("_ms", "ms"), ("_us", "µs"),
         ("_cm", "cm"), ("_km", "km"), ("_m", "m"), ("_s", "s"), ("_rad", "rad"))


def unit_of(key: str) -> str:
    return next((u for suffix, u in UNITS if key.endswith(suffix)), "")


def _strip(tp):
    """Annotated[...] removed; its metadata returned beside."""
    meta: list = []
    while get_origin(tp) is Annotated:
        args = get_args(tp)
        tp, meta = args[0], [*meta, *args[1:]]
    return tp, meta


def _is_model(tp) -> bool:
    from pydantic import BaseModel

    return isinstance(tp, type) and issubclass(tp, BaseModel)


def _flat(meta) -> list:
    """Annotated metadata with pydantic's FieldInfo opened into its constraints."""
    from pydantic.fields import FieldInfo

    out = []
    for m in meta:
        out += _flat(m.metadata) if isinstance(m, FieldInfo) else [m]
    return out


def type_text(tp, extra=()) -> str:
    """A field's type as a user writes it in YAML (`extra`: the metadata pydantic took
    off the field's annotation)."""
    tp, meta = _strip(tp)
    meta = _flat([*extra, *meta])
    origin = get_origin(tp)
    lengths = {getattr(m, "min_length", None) for m in meta} | {
        getattr(m, "max_length", None) for m in meta}
    if origin is list and lengths - {None} == {3}:
        broadcast = any("broadcast" in getattr(getattr(m, "func", None), "__name__", "")
                        for m in meta)
        return ("number or " if broadcast else "") + "[x, y, z]"
    if origin in (Union, types.UnionType):
        args = [a for a in get_args(tp) if a is not type(None)]
        text = " or ".join(dict.fromkeys(type_text(a) for a in args))
        return text + (" or null" if len(args) < len(get_args(tp)) else "")
    if origin is Literal:
        return " \\| ".join(f"`{a}`" for a in get_args(tp))
    if origin in (list, tuple):
        args = [a for a in get_args(tp) if a is not Ellipsis]
        inner = type_text(args[0]) if args else "value"
        return f"list of {inner}"
    if origin is dict:
        args = get_args(tp)
        return f"mapping of {type_text(args[1])}" if len(args) == 2 else "mapping"
    if _is_model(tp):
        return "mapping"
    return {float: "number", int: "integer", str: "text", bool: "true \\| false"}.get(
        tp, getattr(tp, "__name__", str(tp)).lower().replace("path", "path"))


def bounds_text(field) -> str:
    """The bounds of a field: pydantic's ge/gt/le/lt and gcalign's physical Bounds."""
    from gcalign.io.scenario.bounds import Bound

    found: list = _flat(field.metadata)
    stack = [field.annotation]
    while stack:
        tp = stack.pop()
        tp, meta = _strip(tp)
        found += _flat(meta)
        stack += [a for a in get_args(tp) if a is not type(None)]
    parts: list[str] = []
    for m in found:
        if isinstance(m, Bound):
            parts.append(f"{m.range()}")
        for attr, sign in (("ge", "≥"), ("gt", ">"), ("le", "≤"), ("lt", "<")):
            v = getattr(m, attr, None)
            if v is not None and not isinstance(m, Bound):
                parts.append(f"{sign} {v:g}" if isinstance(v, (int, float)) else f"{sign} {v}")
    return ", ".join(dict.fromkeys(parts))


def default_text(field) -> str:
    from pydantic_core import PydanticUndefined

    if field.default_factory is not None:
        try:
            value = field.default_factory()
        except TypeError:
            return ""
    elif field.default is PydanticUndefined:
        return "required"
    else:
        value = field.default
    if _is_model(type(value)):
        return ""
    try:
        text = json.dumps(value, ensure_ascii=False, default=str)
    except (TypeError, ValueError):
        text = str(value)
    return f"`{text}`" if len(text) <= 40 else "(see the section)"


def _sub_models(tp) -> list[tuple[str, Any]]:
    """``(suffix, model)`` of the mappings a field holds: the model itself (``""``), the
    items of a list (``"[]"``), the values of a mapping (``".NAME"``), each arm of a union
    of models (``" (kind: moving)"``)."""
    tp, _ = _strip(tp)
    origin = get_origin(tp)
    if _is_model(tp):
        return [("", tp)]
    if origin in (Union, types.UnionType):
        arms = [a for a in get_args(tp) if a is not type(None)]
        out = []
        for arm in arms:
            for suffix, model in _sub_models(arm):
                kind = getattr(model, "model_fields", {}).get("kind")
                tag = ""
                if kind is not None and get_origin(_strip(kind.annotation)[0]) is Literal:
                    tag = f" (kind: {', '.join(get_args(_strip(kind.annotation)[0]))})"
                out.append((suffix + (tag if len(arms) > 1 else ""), model))
        return out
    if origin in (list, tuple):
        args = [a for a in get_args(tp) if a is not Ellipsis]
        return [("[]" + s, m) for s, m in _sub_models(args[0])] if args else []
    if origin is dict and len(get_args(tp)) == 2:
        return [(".NAME" + s, m) for s, m in _sub_models(get_args(tp)[1])]
    return []


def scenario_sections(root=None, prefix: str = "") -> list[tuple[str, Any]]:
    """``(dotted path, model)`` of every mapping of a scenario (or of the model `root`,
    its paths starting with `prefix`), depth first from the top."""
    from gcalign.io.scenario import Scenario

    out: list[tuple[str, Any]] = []
    seen: set[tuple[str, Any]] = set()

    def walk(path: str, model) -> None:
        if (path, model) in seen or path.count(".") > 8:
            return
        seen.add((path, model))
        out.append((path, model))
        for key, field in model.model_fields.items():
            if field.exclude:
                continue
            for suffix, sub in _sub_models(field.annotation):
                walk(f"{path}.{key}{suffix}" if path else f"{key}{suffix}", sub)

    walk(prefix, Scenario if root is None else root)
    return out


def _doc(model) -> str:
    from pydantic import BaseModel

    doc = model.__doc__ or ""
    if not doc or doc == BaseModel.__doc__ or model.__module__.startswith("pydantic"):
        return ""
    return _esc(doc.strip().split("\n\n")[0])


def scenario_page() -> str:
    from gcalign.io.scenario.recording import ImuLayout

    lines = ["# Scenario keys", "",
             "Every key a scenario file may hold, generated from the pydantic models that "
             "read it (`gcalign.io.scenario`) at each build of this site: its type, its "
             "default, its unit (the key's suffix says it: `_deg` °, `_dph` °/h, `_ug` µg, "
             "`_s` s, …; values are converted to SI once, on reading), its bounds (a value "
             "outside is refused with the reason) and what it means. Unknown keys are "
             "errors; a key a mode or an option makes void is a warning. A dotted key "
             "(`align.stages.0.t_z_s`) addresses the same keys from `--set` and from a "
             "sweep's `grid`.", "",
             "`imu_file:` takes a path, or a mapping of `path` and the layout keys of "
             "[imu_file (mapping)](#imu_file-mapping).", ""]
    sections = scenario_sections() + scenario_sections(ImuLayout, "imu_file (mapping)")
    for path, model in sections:
        title = path or "top level"
        lines += [f"## {title}", ""]
        doc = _doc(model)
        if doc:
            lines += [doc, ""]
        lines += ["| key | type | default | unit | bounds | description |",
                  "| --- | --- | --- | --- | --- | --- |"]
        for key, field in model.model_fields.items():
            if field.exclude:
                continue
            subs = _sub_models(field.annotation)
            name = f"`{key}`"
            if subs:
                target = f"{path}.{key}{subs[0][0]}" if path else f"{key}{subs[0][0]}"
                name = f"[`{key}`](#{_anchor(target)})"
            bounds = bounds_text(field)
            desc = "" if (field.description or "") in bounds else _esc(field.description or "")
            kind = type_text(field.annotation, field.metadata)
            lines.append(f"| {name} | {kind} | {default_text(field)} | {unit_of(key)} "
                         f"| {bounds} | {desc.replace('|', chr(92) + '|')} |")
        lines.append("")
    return "\n".join(lines)


def _anchor(title: str) -> str:
    """The id Python-Markdown's toc gives a heading (its default slugify)."""
    from markdown.extensions.toc import slugify

    return slugify(title, "-")


# --------------------------------------------------------------------------- results file


def result_layout() -> dict[str, list[dict]]:
    """Per kind of results file, its datasets: ``group`` (a pattern, ``*`` any name),
    ``name``, ``shapes`` (sizes named within the kind), ``optional``, ``text``, ``rule``,
    and the sizes that group's attributes give. Read from the checks of files read back
    (:data:`gcalign.app.checked.SCHEMAS`); the one function to change when the results are
    described on their dataclasses."""
    from gcalign.app.checked import SCHEMAS

    out: dict[str, list[dict]] = {}
    for kind, blocks in SCHEMAS.items():
        rows = []
        for block in blocks:
            sizes = [f"{s} from `{attr}`" + ("" if g == "." else f" of /{g}")
                     for s, g, attr in (*block.names, *block.numbers)]
            sizes += [f"{s} = `{attr}` + {k}" if k else f"{s} = `{attr}`"
                      for s, attr, k in block.counts]
            for name, data in block.items.items():
                if name.startswith("component") or (name.endswith("?")
                                                     and name[:-1] in block.items):
                    continue  # the netCDF index scales (in the intro); a key made required
                rows.append({"group": block.where, "name": name.rstrip("?"),
                             "optional": name.endswith("?"), "shapes": data.shapes,
                             "text": data.text, "rule": data.rule, "whole": data.whole,
                             "sizes": sizes})
        out[kind] = rows
    return out


def _shape(shape) -> str:
    return "(" + ", ".join(str(d) for d in shape) + ("," if len(shape) == 1 else "") + ")"


def results_page() -> str:
    from gcalign.app.checked import layout as groups_of
    from gcalign.app.readback import kinds

    commands = kinds()

    lines = ["# Results file", "",
             "One HDF5 file per run, written under a temporary name and renamed when complete "
             "(an interrupted run leaves no truncated file). Root attributes: "
             "`gcalign_version`, `kind` (the command), `command_line`, `scenario_yaml` (the "
             "scenario's text), `seed`, `created_utc`, `summary_json` (what `gcalign show` "
             "prints). Every dataset has a `units` attribute (SI) and, where it applies, a "
             "`frame`; arrays have time along axis 0, so MATLAB's `h5read` shows them "
             "transposed. A group's `t` is an HDF5 dimension scale of its series (their "
             "other axes `component`, 0, 1, 2): xarray and other netCDF readers see named "
             "dimensions and a time coordinate. A results file made from a recording keeps "
             "what its reader assumed under `/recording` (`format`, `axes`, `C_rfu_file`, "
             "`units`, `time_origin`, `rate_hz`, `gaps`, `gravity_check`, `warnings`).", "",
             "The tables below are generated at each build from the checks every results "
             "file passes when it is read back (`gcalign show`, `plot`, `export`, "
             "`navigate --init`): the datasets a reader needs, their shapes with sizes named "
             "within the kind (N samples, K filter epochs, S states, …), optional ones "
             "marked. `gcalign export FILE --format csv` writes any group's series as a "
             "table; `gcalign.io.results.series(FILE, GROUP)` reads them with their units.",
             ""]
    layout = result_layout()
    for kind, rows in layout.items():
        cmd = commands.get(kind)
        groups = ", ".join(f"`/{g}`" for g in groups_of(kind)) if cmd is not None else ""
        lines += [f"## {kind}", ""]
        if cmd is not None:
            lines += [f"Written by `gcalign {kind}`" + (f"; its groups: {groups}." if groups
                                                      else "."), ""]
        lines += ["| group | dataset | shape | notes |", "| --- | --- | --- | --- |"]
        for r in rows:
            notes = [n for n in ("optional" if r["optional"] else "",
                                 "text" if r["text"] else "",
                                 "whole numbers" if r["whole"] else "",
                                 {"increasing": "strictly increasing",
                                  "unit": "unit quaternions",
                                  "range": "0 … n−1"}.get(r["rule"], r["rule"].replace(
                                      "index<", "index into ")))
                     if n]
            shape = " or ".join(_shape(s) for s in r["shapes"])
            lines.append(f"| `/{r['group']}` | `{r['name']}` | {shape} | "
                         f"{', '.join(notes)} |")
        sizes = sorted({s for r in rows for s in r["sizes"]})
        if sizes:
            lines += ["", "Sizes given by attributes: " + "; ".join(sizes) + "."]
        lines.append("")
    return "\n".join(lines)


# --------------------------------------------------------------------------- limits, decisions


def limits_page() -> str:
    from gcalign import limits

    lines = ["# Limits", "",
             "Every command estimates what a run will cost before it starts and refuses one "
             "past a limit, with one line naming the estimate, the limit and the environment "
             "variable that raises it (exit 2), e.g. `GCALIGN_MAX_SAMPLES=5e9 gcalign "
             "simulate long.yaml`. Generated from `gcalign.limits` at each build.", "",
             "| variable | default | what it bounds |", "| --- | --- | --- |"]
    for value in vars(limits).values():
        if isinstance(value, limits.Limit):
            default = ("half the memory available when the command starts"
                       if value.env == "GCALIGN_MAX_MEMORY_MB" else
                       "2 × the cores" if value.env == "GCALIGN_MAX_WORKERS" else
                       f"{value.default:g}{value.unit}")
            lines.append(f"| `{value.env}` | {default} | {_esc(value.what)} |")
    lines += ["", "Seeds lie in [0, 2^63). A Dask `--scheduler` that does not answer (or has "
              "no workers) fails within 15 s. How the limits are held to account: "
              "[Hostile input and faults](../robustness.md).", ""]
    return "\n".join(lines)


def decisions_page() -> str:
    from pathlib import Path

    folder = Path(__file__).parent / "decisions"
    lines = ["# Decisions", "",
             "Design decisions others would wonder about, each in a few lines: context, "
             "decision, consequence (newest last).", ""]
    for path in sorted(folder.glob("*.md")):
        title = next((ln.lstrip("# ").strip() for ln in path.read_text().splitlines()
                      if ln.startswith("#")), path.stem)
        lines.append(f"- [{path.stem[:3]}: {title}](../decisions/{path.name})")
    return "\n".join(lines) + "\n"
