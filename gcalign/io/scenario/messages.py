"""The one-line messages of a scenario that pydantic refuses: one line per field, the bad
value shown cut to a readable length."""

from __future__ import annotations

import re
import reprlib

from pydantic import ValidationError

from gcalign.errors import clip
from gcalign.io.scenario.walk import keys_at

# Model-level checks name their field at the start of the message ("segments: ..."),
# since pydantic gives them the model's location only.
_FIELD_PREFIX = re.compile(r"^([a-z_0-9]+(?:\.[a-z_0-9]+)*): ")


#: The tags of the discriminated motion union (``kind`` of gcalign.io.scenario.motion's
#: models), here since the models' own refusals use this module (motion imports the base).
MOTION_KINDS = ("static", "swing", "moving", "turntable", "flight")

# Location parts that name a member of a union type, not a key the user wrote (also the
# tags of the discriminated motion union).
_UNION_TAG = re.compile(r"^(float|int|str|bool|constrained-\w+|\w+\[.*\]|"
                        + "|".join(MOTION_KINDS) + r")$")


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxdict = 3, 6, 4
_REPR.maxstring = _REPR.maxother = 60
_REPR.maxlong = 40
CUT = 80  #: characters of a bad value echoed in a message


def cut(value) -> str:
    """A value as a message shows it: repr, at most about CUT characters (a bad value
    can be megabytes long, or an alias bomb)."""
    text = repr(clip(value, CUT)) if isinstance(value, str) else _REPR.repr(value)
    return text if len(text) <= CUT + 2 else clip(text, CUT)


def scenario_errors(err: ValidationError, source: str = "", root: type | None = None,
                    whole: str = "scenario", at: str = "") -> str:
    """One line per invalid field: ``source: field: what is wrong, got VALUE``; an unknown
    key lists the keys of its mapping in `root` (the model that was validated: the
    `whole` scenario, or a sweep; or its section at the dotted key `at`).

    Pydantic reports every failed member of a union (``float | 'measured'``) separately;
    those become one line whose alternatives are joined by "or".
    """
    by_field: dict[str, list[str]] = {}
    got_of: dict[str, str] = {}
    for e in err.errors():
        loc = [*filter(None, at.split(".")),
               *(str(x) for x in e["loc"] if not _UNION_TAG.match(str(x)))]
        msg = e["msg"].removeprefix("Value error, ")
        m = _FIELD_PREFIX.match(msg)
        if m:
            if not loc or loc[-1] != m.group(1):  # a field validator names its own field
                loc.append(m.group(1))
            msg = msg[m.end() :]
        where = ".".join(loc) or whole
        if e["type"] == "extra_forbidden":
            keys = keys_at(e["loc"][:-1], root) if root is not None else None
            here = ".".join(loc[:-1]) or f"the {whole}"
            msg = ("unknown key" + (f"; {here} has: {', '.join(keys)}" if keys else
                                    " (check the spelling)"))
        elif e["type"] in ("union_tag_invalid", "union_tag_not_found"):
            ctx = e.get("ctx", {})
            key = str(ctx.get("discriminator", "kind")).strip("'")
            where = ".".join([*loc, key])
            allowed = str(ctx.get("expected_tags", "")).replace("'", "") or ", ".join(
                MOTION_KINDS)
            msg = (f"allowed: {allowed}, got {cut(ctx['tag'])}" if "tag" in ctx
                   else f"missing; allowed: {allowed}")
        elif e["type"] not in {"missing", "model_type", "value_error"}:
            got_of[where] = f", got {cut(e.get('input'))}"
        msgs = by_field.setdefault(where, [])
        if msg not in msgs:
            msgs.append(msg)
    lines = [f"{where}: {' or '.join(msgs)}{got_of.get(where, '')}"
             for where, msgs in by_field.items()]
    return "\n".join(f"{source}: {line}" if source else line for line in lines)
