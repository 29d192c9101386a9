"""Hostile inputs for the fuzz suite, and the contract every command keeps.

A :class:`Case` is a command line and the files it reads (written into an empty folder).
The generators below build them from a seeded :class:`random.Random` by mutating valid
inputs key by key (scenarios of every section and motion kind, a sweep, recorded data in
the three formats, results files, batch journals) and by the command-line options, so that
a failure reproduces from its seed and index. :func:`violations` states the contract:

* exit 2 (bad input) or 1 (other failure) -- or 0 where the mutation may still be valid;
* on failure exactly one line on stderr, ``error: ...``, and no traceback; a batch of which
  some runs failed is exit 1 with its complete results file (they are recorded in it,
  docs/batch.md) and an error line last;
* no new file in the folder on failure (no results file, journal, temp or lock file); on
  success no temp file and nothing but the named output;
* a successful run's summary holds only finite numbers;
* ``gcalign validate`` agrees with the run about bad input (exit 2 for both or neither);
* each case within ``TIME_LIMIT_S`` (``benchmarks/fuzz_report.py``, which times every case
  in its own process; the in-process suite only catches a hang, :data:`HANG_S`, as a
  loaded machine would make a time bound flaky, and bounds memory).

The class of each case (1 .. 11) is the numbered class of docs/robustness.md ("Before and
after") it attacks; 0 is a generic key-by-key mutation (contract only).
``benchmarks/fuzz_report.py`` runs the same cases in child processes (with a time and memory
limit) and counts violations per class.
"""

from __future__ import annotations

import io
import json
import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

TIME_LIMIT_S = 10.0  #: the time bound of one case (the fuzz report)
HANG_S = 120.0  #: the in-process suite's bound: a hang, not a slow case

#: Tight resource limits for the fuzz suite: every case that is accepted stays small.
FUZZ_ENV = {
    "GCALIGN_MAX_SAMPLES": "2000000",
    "GCALIGN_MAX_MEMORY_MB": "1024",
    "GCALIGN_MAX_OUTPUT_MB": "256",
    "GCALIGN_MAX_RUNS": "2000",
    "GCALIGN_MAX_VARIANTS": "200",
}


@dataclass(frozen=True)
class Case:
    cls: int  # robustness class attacked (0: generic mutation)
    name: str
    argv: tuple[str, ...]
    files: tuple[tuple[str, bytes], ...] = ()
    exits: frozenset[int] = frozenset({1, 2})  # allowed exit codes
    validate: str | None = None  # scenario whose `gcalign validate` must agree on exit 2
    outputs: tuple[str, ...] = ("out.h5",)  # files a successful run may leave
    dirs: tuple[str, ...] = ()  # folders to create (read-only when named "ro*")
    env: tuple[tuple[str, str], ...] = ()  # environment beside FUZZ_ENV (limits of the case)

    @property
    def id(self) -> str:
        return f"c{self.cls}:{self.name}"


# --------------------------------------------------------------------------- YAML text


class Raw(str):
    """YAML text inserted as is (hostile scalars, tags, anchors)."""


class Pairs(list):
    """A mapping as (key, value) pairs: it can hold a key twice."""


def emit(obj) -> str:
    """Flow-style YAML (a superset of JSON) of `obj`; Raw and Pairs as above."""
    if isinstance(obj, Raw):
        return str(obj)
    if isinstance(obj, Pairs):
        return "{" + ", ".join(f"{json.dumps(str(k))}: {emit(v)}" for k, v in obj) + "}"
    if isinstance(obj, dict):
        return emit(Pairs(obj.items()))
    if isinstance(obj, (list, tuple)):
        return "[" + ", ".join(emit(v) for v in obj) + "]"
    if obj is None:
        return "null"
    if isinstance(obj, bool):
        return "true" if obj else "false"
    if isinstance(obj, float):
        if math.isnan(obj):
            return ".nan"
        if math.isinf(obj):
            return ".inf" if obj > 0 else "-.inf"
        return repr(obj)
    if isinstance(obj, int):
        return str(obj)
    return json.dumps(str(obj))


def bomb(depth: int, width: int) -> Raw:
    """Billion laughs: `depth` levels, each `width` aliases of the one before."""
    levels = [f"&b0 [{', '.join(['lol'] * width)}]"]
    for d in range(1, depth):
        levels.append(f"&b{d} [{', '.join([f'*b{d - 1}'] * width)}]")
    return Raw("[" + ", ".join(levels) + "]")


# --------------------------------------------------------------------------- valid bases

SITE = {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0}
S = {  # the base case: 60 s static, align section
    "name": "s", "site": SITE, "imu": {"rate_hz": 100, "seed": 1},
    "motion": {"kind": "static", "attitude_deg": [0, 0, 30], "duration_s": 60},
    "align": {"coarse": {"method": "given", "error_deg": [1, 1, 10]}, "mode": "conventional",
              "t1_s": 10, "t2_s": 50, "t3_s": 50, "level_s": 10,
              "stages": [{"t_xy_s": 10, "t_z_s": 20, "xi": 0.707}]},
}
FLIGHT = {
    "name": "fl", "site": {"lat_deg": 34, "lon_deg": 108, "height_m": 500},
    "imu": {"rate_hz": 100, "seed": 3,
            "gyro": {"bias_dph": [0.01, 0.01, 0.01], "arw_dprh": 0.001},
            "accel": {"bias_ug": [50, 50, 50], "vrw_ugrhz": 10}},
    "motion": {"kind": "flight", "attitude_deg": [0, 0, 45], "speed_mps": 50,
               "segments": [{"kind": "hold", "duration_s": 5},
                            {"kind": "accelerate", "accel_mps2": 1, "speed_mps": 55},
                            {"kind": "turn", "rate_dps": 3, "angle_deg": 30}]},
    "navigation": {"vertical": "damped", "vertical_tau_s": 20, "start_s": 1,
                   "duration_s": 15},
    "output": {"rate_hz": 10},
}
TURNTABLE = {
    "name": "tt", "site": {"lat_deg": 40, "lon_deg": 116}, "imu": {"rate_hz": 100},
    "motion": {"kind": "turntable", "duration_s": 12, "steps": [
        {"axis": "z", "profile": "rate", "rate_dps": 10, "duration_s": 5},
        {"profile": "rest", "duration_s": 2},
        {"axis": "x", "profile": "trapezoid", "angle_deg": 90, "rate_dps": 30,
         "accel_dps2": 20, "dwell_s": 1}]},
}
MECHANISM = {
    "name": "me", "site": {"lat_deg": 40, "lon_deg": 116}, "earth": "seed004",
    "imu": {"rate_hz": 100, "gyro": {"bias_dph": [0.01, 0.02, 0.03]}},
    "motion": {"kind": "static", "duration_s": 20},
    "mechanism": {"reference": "body", "repeat": True, "steps": [
        {"axis": "z", "profile": "trapezoid", "angle_deg": 180, "accel_s": 1, "const_s": 2,
         "decel_s": 1, "dwell_s": 2},
        {"axis": "-x", "profile": "swing", "amplitude_deg": 10, "frequency_hz": 0.5,
         "duration_s": 2}]},
}
SWING = {
    "name": "sw1", "site": SITE, "imu": {"rate_hz": 100, "seed": 4,
                                        "gyro": {"bias_dph": [0.01, 0.01, 0.01]}},
    "motion": {"kind": "swing", "attitude_deg": [0, 0, 30], "duration_s": 60,
               "swing": {"amplitude_deg": [2, 3, 4], "period_s": [10, 10, 20]}},
    "align": {"coarse": {"method": "inertial"}, "mode": "half-cycle", "level_s": 10,
              "t1_s": 10, "t2_s": 40, "t3_s": 45, "compensation": "one-off",
              "stages": [{"t_xy_s": 10, "t_z_s": 20, "passes": 1}, {"t_xy_s": 10,
                                                                    "t_z_s": 30, "passes": 2}]},
}
NORTHFIND = {
    "name": "nf", "site": {"lat_deg": 40, "lon_deg": 116},
    "imu": {"rate_hz": 50, "seed": 2, "gyro": {"bias_dph": [0.02, 0.02, 0.02],
                                               "arw_dprh": 0.002},
            "accel": {"bias_ug": [20, 20, 20], "vrw_ugrhz": 50}},
    "northfind": {"positions": 4, "dwell_s": 2, "azimuth_deg": 30, "tilt_deg": 2,
                  "tilt_direction_deg": 10, "repeats": 2},
}
REALTIME = {
    "name": "rt", "site": {"lat_deg": 34.25, "lon_deg": 108.9, "height_m": 400},
    "imu": {"seed": 2027},
    "realtime": {"solution_hz": 1000, "predictors": ["none", "kalman-ls"], "settle_s": 0.5,
                 "warmup_s": 0.1, "cases": [
                     {"name": "r5", "steps": [{"axis": "z", "profile": "rate", "rate_dps": 5,
                                               "duration_s": 2}]}]},
}
CALIBRATE = {  # a short flight: calibrate and observability (seed 002)
    "name": "cal", "site": {"lat_deg": 38.0, "lon_deg": 121.0, "height_m": 0},
    "imu": {"rate_hz": 50, "seed": 1, "gyro": {"bias_dph": [0.01, -0.01, 0.01],
                                               "arw_dprh": 0.001},
            "accel": {"bias_ug": [50, -50, 50], "vrw_ugrhz": 10}},
    "motion": {"kind": "flight", "speed_mps": 100, "segments": [
        {"kind": "hold", "duration_s": 10}, {"kind": "turn", "rate_dps": 9, "angle_deg": 90},
        {"kind": "hold", "duration_s": 10}]},
    "calibrate": {"measure": "velocity", "navigation_rate_hz": 25, "filter_rate_hz": 1},
    "observability": {"measure": "velocity", "piece_s": 5},
}
MODULATE = {  # seed 004: a static base on a single-axis mechanism, two schemes compared
    "name": "mo", "site": SITE, "earth": "seed004",
    "imu": {"rate_hz": 10, "seed": 5, "gyro": {"bias_dph": 0.01}, "accel": {"bias_ug": 100}},
    "motion": {"kind": "static", "duration_s": 600},
    "mechanism": {"scheme": "single-4", "dwell_s": 60, "accel_s": 2, "turn_s": 6},
    "modulate": {"compare": ["fixed", "single-4"], "hours": 0.2},
}
SWEEP = {"name": "sw", "base": "S.yaml", "grid": {"align.stages.0.t_z_s": [20, 30]},
         "seeds": 2}

#: (scenario, command) pairs mutated key by key
BASES: dict[str, tuple[dict, str]] = {
    "S": (S, "align"), "swing": (SWING, "align"), "flight": (FLIGHT, "navigate"),
    "turntable": (TURNTABLE, "simulate"), "mechanism": (MECHANISM, "navigate"),
    "northfind": (NORTHFIND, "northfind"), "realtime": (REALTIME, "realtime"),
    "calibrate": (CALIBRATE, "calibrate"), "observability": (CALIBRATE, "observability"),
}
#: bases of commands that came after the before/after count of docs/robustness.md; their
#: mutations come last, from a generator of their own, so that the cases above stay the same
LATE_BASES: dict[str, tuple[dict, str]] = {"modulate": (MODULATE, "modulate")}

#: The newer commands' bases, mutated with small limits in play (:func:`limited_cases`)
LIMITED_BASES: dict[str, tuple[dict, str]] = {
    "calibrate": (CALIBRATE, "calibrate"), "observability": (CALIBRATE, "observability"),
    "realtime": (REALTIME, "realtime"), "modulate": (MODULATE, "modulate")}
#: Limits small enough that a mutation multiplying the work (a rate, a duration, an order,
#: a piece length) meets them, well above what each base costs as given.
SMALL_LIMITS = (("GCALIGN_MAX_WORK", "2e10"), ("GCALIGN_MAX_MEMORY_MB", "256"),
                ("GCALIGN_MAX_OUTPUT_MB", "16"), ("GCALIGN_MAX_SAMPLES", "500000"),
                ("GCALIGN_MAX_REALTIME_SAMPLES", "2000000"))
#: Hostile values of a limit variable (each must be refused naming it, or honoured)
LIMIT_VALUES = ("abc", "", "0", "-1", "1e-300", "1e-9", "nan", "inf", "1e400", " 5 ")
#: Multipliers of numbers that cost: the limits, not the time bound, must stop them
COSTLY = ("1e3", "1e4", "1e6", "0.001", "1e-6")

# Hostile scalars and structures (YAML text).
HOSTILE = [
    "true", "false", "yes", "no", "on", "null", "~", "-1", "0", "1e-9", "1e308", "-1e308",
    "1e400", ".nan", ".inf", "-.inf", str(2**70), str(-(2**70)), "99999999999999999999999",
    "'abc'", "''", "' '", "[]", "{}", "[[[]]]", "[1, 2]", "[1, 2, 3, 4]", "2024-01-01",
    "0x10", "!!binary aGVsbG8=", "!!set {a, b}", "[.nan, 0, 0]", "[1e308, 0, 0]",
    "[true, 0, 0]", "{kind: nope}", "-0.0", "1e6", "1e5", "3.5", "'x\\u0000y'",
    "!!python/object/apply:os.system ['touch pwned']", "[" * 40 + "]" * 40,
    "'" + "x" * 5000 + "'",
]
BOOLS = {"true", "false", "yes", "no", "on"}


def _leaves(obj, path=()):
    """Paths of every value (mappings and lists included) in a nested structure."""
    yield path
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _leaves(v, (*path, i))


def _get(obj, path):
    for p in path:
        obj = obj[p]
    return obj


def _copy(obj):
    return json.loads(json.dumps(obj))


def _set(obj, path, value):
    if not path:
        return value
    parent = _get(obj, path[:-1])
    parent[path[-1]] = value
    return obj


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def mutate(rng: random.Random, data: dict) -> tuple[str, str, int, frozenset[int]]:
    """One key-by-key mutation of `data`: (YAML text, label, class, allowed exit codes)."""
    data = _copy(data)
    paths = list(_leaves(data))[1:]
    path = rng.choice(paths)
    where = ".".join(map(str, path))
    old = _get(data, path)
    op = rng.choices(["set", "del", "extra", "dup", "bomb", "deep"],
                     [70, 8, 6, 8, 5, 3])[0]
    parent = _get(data, path[:-1])
    if op == "del" and isinstance(parent, dict):
        del parent[path[-1]]
        return emit(data), f"del {where}", 0, frozenset({0, 1, 2})
    if op == "extra" and isinstance(parent, dict):
        parent["zz_unknown"] = 1
        return emit(data), f"extra key beside {where}", 0, frozenset({2})
    if op == "dup" and isinstance(parent, dict):
        pairs = Pairs(parent.items())
        pairs.append((path[-1], old))  # the same key again, even with the same value
        data = _set(data, path[:-1], pairs) if path[:-1] else pairs
        return emit(data), f"duplicate key {where}", 8, frozenset({2})
    if op == "bomb":
        depth, width = rng.choice([(6, 9), (8, 9), (9, 9), (12, 4), (30, 2)])
        _set(data, path, bomb(depth, width))
        return emit(data), f"alias bomb {depth}x{width} at {where}", 1, frozenset({2})
    if op == "deep":
        n = rng.choice([200, 2000, 20000])
        _set(data, path, Raw("[" * n + "]" * n))
        return emit(data), f"nesting {n} at {where}", 0, frozenset({2})
    value = rng.choice(HOSTILE)
    _set(data, path, Raw(value))
    label = f"{where} = {value[:30]}"
    if value in BOOLS and _is_number(old):
        return emit(data), label, 8, frozenset({2})
    if path[-1] == "seed" and value in (str(2**70), str(-(2**70)), "99999999999999999999999",
                                        "-1"):
        return emit(data), label, 5, frozenset({2})
    cls = 6 if value in ("1e308", "-1e308", "1e-9", "[1e308, 0, 0]", "1e400") else 0
    if value in ("1e6", "1e5") and path[-1] in ("duration_s", "rate_hz", "fs_hz", "dwell_s",
                                                "positions", "repeats", "solution_hz"):
        cls = 1
    return emit(data), label, cls, frozenset({0, 1, 2})


def scenario_cases(rng: random.Random, n: int, bases=None) -> list[Case]:
    """`n` key-by-key mutations of the valid bases (default :data:`BASES`), each run by its
    command and checked against `gcalign validate`."""
    bases = BASES if bases is None else bases
    out = []
    names = list(bases)
    for i in range(n):
        base = names[i % len(names)]
        data, command = bases[base]
        text, label, cls, exits = mutate(rng, data)
        out.append(Case(cls, f"{base}/{command}: {label}",
                        (command, "case.yaml", "-o", "out.h5"),
                        (("case.yaml", text.encode()),), exits, validate="case.yaml"))
    return out


def limited_cases(rng: random.Random, n: int) -> list[Case]:
    """`n` mutations of the newer commands' bases (:data:`LIMITED_BASES`) under
    :data:`SMALL_LIMITS`: a key-by-key mutation (class 0), a number that costs scaled up or
    down (class 1: a limit or a bound must refuse it, within the time bound), or a limit
    variable set to a hostile value (class 1: refused naming the variable, or honoured)."""
    out = []
    names = list(LIMITED_BASES)
    for i in range(n):
        base = names[i % len(names)]
        data, command = LIMITED_BASES[base]
        env = SMALL_LIMITS
        kind = rng.choice(["mutate", "costly", "limit"])
        if kind == "mutate":
            text, label, cls, exits = mutate(rng, data)
        elif kind == "costly":
            d = _copy(data)
            paths = [p for p in list(_leaves(d))[1:] if _is_number(_get(d, p))]
            path = rng.choice(paths)
            factor = rng.choice(COSTLY)
            _set(d, path, float(_get(d, path)) * float(factor))
            text, label = emit(d), f"{'.'.join(map(str, path))} × {factor}"
            cls, exits = 1, frozenset({0, 1, 2})
        else:
            var = rng.choice([k for k, _ in SMALL_LIMITS])
            value = rng.choice(LIMIT_VALUES)
            env = tuple((k, v) for k, v in SMALL_LIMITS if k != var) + ((var, value),)
            text, label = emit(data), f"{var}={value!r}"
            cls, exits = 1, frozenset({0, 2})
        out.append(Case(cls, f"limited {base}/{command}: {label}",
                        (command, "case.yaml", "-o", "out.h5"),
                        (("case.yaml", text.encode()),), exits, validate="case.yaml", env=env))
    return out


def sweep_cases(rng: random.Random, n: int) -> list[Case]:
    """Mutations of the sweep SW (two variants on S) and of its base."""
    out = []
    s_text = emit(S).encode()
    for i in range(n):
        if i % 3 == 2:  # the base scenario, mutated
            text, label, cls, exits = mutate(rng, S)
            files = (("S.yaml", text.encode()), ("SW.yaml", emit(SWEEP).encode()))
            name = f"SW base: {label}"
        else:
            text, label, cls, exits = mutate(rng, SWEEP)
            files = (("S.yaml", s_text), ("SW.yaml", text.encode()))
            name = f"SW: {label}"
        out.append(Case(cls, name, ("batch", "SW.yaml", "-o", "out.h5", "-w", "1"), files,
                        exits))
    return out


def _output_exits(out: str) -> frozenset[int]:
    """-o naming a folder or nothing, or a path under a file, is bad input (must show 5);
    a folder that cannot be created (read-only) may be either."""
    return frozenset({1, 2}) if out.startswith("ro/") else frozenset({2})


def fixed_cases() -> list[Case]:
    """The named reproductions of the robustness classes that are not Dask, kill or disk-full
    tests."""
    s = emit(S).encode()
    sw = emit(SWEEP).encode()

    def sc(**over) -> bytes:
        d = _copy(S)
        for dotted, v in over.items():
            _set(d, tuple(int(p) if p.isdigit() else p for p in dotted.split("__")), v)
        return emit(d).encode()

    def sweep(**over) -> bytes:
        d = _copy(SWEEP)
        d.update(over)
        return emit(d).encode()

    C = Case
    cases = [
        # 1 resources
        # (streamed since the core rebuild: align reads only its window, 50 s of the 1e5 s)
        C(1, "duration 1e5 s at 100 Hz", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(motion__duration_s=1e5)),), frozenset({0})),
        C(1, "simulate 1e6 s at 1e5 Hz", ("simulate", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(motion__duration_s=1e6, imu__rate_hz=1e5)),), frozenset({2})),
        C(1, "navigate 1e6 s at 1e4 Hz", ("navigate", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(motion__duration_s=1e6, imu__rate_hz=1e4)),), frozenset({2})),
        C(1, "simulate full-rate output of 1e6 s", ("simulate", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(motion__duration_s=1e6, output={"rate_hz": "full"})),),
          frozenset({2})),
        C(1, "seeds 1e10", ("batch", "SW.yaml", "-o", "out.h5"),
          (("S.yaml", s), ("SW.yaml", sweep(seeds=10_000_000_000))), frozenset({2})),
        C(1, "grid 39x39x39x40", ("batch", "SW.yaml", "-o", "out.h5"),
          (("S.yaml", s), ("SW.yaml", sweep(grid={
              "align.stages.0.t_z_s": list(range(20, 59)),
              "align.stages.0.t_xy_s": list(range(5, 44)),
              "align.stages.0.xi": [round(0.3 + 0.01 * k, 2) for k in range(39)],
              "imu.seed": list(range(40))}))), frozenset({2})),
        C(1, "-w 24 on a small machine", ("batch", "SW.yaml", "-o", "out.h5", "-w", "100000"),
          (("S.yaml", s), ("SW.yaml", sw)), frozenset({2})),
        C(1, "alias bomb 528 bytes", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(name=bomb(9, 9))),), frozenset({2}), validate="a.yaml"),
        C(1, "alias bomb in an unknown key", ("validate", "a.yaml"),
          (("a.yaml", emit({**_copy(S), "x": bomb(9, 9)}).encode()),), frozenset({2}),
          outputs=()),
        C(1, "alias bomb in a sweep grid", ("batch", "SW.yaml", "-o", "out.h5"),
          (("S.yaml", s), ("SW.yaml", sweep(grid={"align.mode": bomb(9, 9)}))),
          frozenset({2})),
        C(1, "northfind 1e5 positions of 1e6 s", ("northfind", "a.yaml", "-o", "out.h5"),
          (("a.yaml", emit({**NORTHFIND, "northfind": {**NORTHFIND["northfind"],
                                                       "positions": 100000,
                                                       "dwell_s": 1e6}}).encode()),),
          frozenset({0}), validate="a.yaml"),  # dwell means in closed form: cheap
        # 4 a bad metric leaves nothing
        C(4, "metrics: [no_such_metric]", ("batch", "SW.yaml"),
          (("S.yaml", s), ("SW.yaml", sweep(metrics=["no_such_metric"]))), frozenset({2}),
          outputs=()),
        # 5 seeds
        C(5, "--seed -5", ("align", "a.yaml", "--seed", "-5", "-o", "out.h5"),
          (("a.yaml", s),), frozenset({2})),
        C(5, "--seed 1e23", ("simulate", "a.yaml", "--seed", "99999999999999999999999",
                             "-o", "out.h5"), (("a.yaml", s),), frozenset({2})),
        C(5, "--seed 2**63", ("align", "a.yaml", "--seed", str(2**63), "-o", "out.h5"),
          (("a.yaml", s),), frozenset({2})),
        C(5, "imu.seed 2**70", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(imu__seed=2**70)),), frozenset({2}), validate="a.yaml"),
        C(5, "seed_start 2**63 - 1 with 2 seeds", ("batch", "SW.yaml", "-o", "out.h5"),
          (("S.yaml", s), ("SW.yaml", sweep(seed_start=2**63 - 1))), frozenset({2})),
        # 6 silent garbage
        C(6, "stages t_xy 1e-9", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(align__stages=[{"t_xy_s": 1e-9, "t_z_s": 1e-9}])),),
          frozenset({1, 2})),
        C(6, "gyro bias 1e308", ("simulate", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(imu={"gyro": {"bias_dph": [1e308, 0, 0]}})),), frozenset({1, 2})),
        C(6, "accel bias 1e308", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(imu={"accel": {"bias_ug": [1e308, 0, 0]}})),), frozenset({1, 2})),
        # 8 validate agrees with the run
        C(8, "empty scenario", ("validate", "a.yaml"), (("a.yaml", b""),), frozenset({2}),
          outputs=()),
        C(8, "empty scenario, align", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", b""),), frozenset({2})),
        C(8, "neither motion nor imu_file", ("validate", "a.yaml"),
          (("a.yaml", emit({"name": "x", "site": SITE}).encode()),), frozenset({2}),
          outputs=()),
        C(8, "missing imu_file", ("validate", "a.yaml"),
          (("a.yaml", emit({"name": "x", "imu_file": "nope.imu"}).encode()),),
          frozenset({2}), outputs=()),
        C(8, "t2_s past the data", ("validate", "a.yaml"),
          (("a.yaml", sc(align__t2_s=500, align__t3_s=500)),), frozenset({2}), outputs=()),
        C(8, "rate_hz: yes", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(imu__rate_hz=Raw("yes"))),), frozenset({2}), validate="a.yaml"),
        C(8, "passes: true", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(align__passes=True)),), frozenset({2}), validate="a.yaml"),
        C(8, "key given twice", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", s[:-1] + b', "name": "again"}'),), frozenset({2}), validate="a.yaml"),
        C(8, "key given twice, block style", ("validate", "a.yaml"),
          (("a.yaml", b"name: a\nsite: {lat_deg: 45, lon_deg: 126}\nname: b\n"
                      b"motion: {kind: static, duration_s: 60}\n"),), frozenset({2}),
          outputs=()),
        # 11 messages
        C(11, "--passes abc", ("align", "a.yaml", "--passes", "abc"), (("a.yaml", s),),
          frozenset({2})),
        C(11, "--seed abc", ("simulate", "a.yaml", "--seed", "abc"), (("a.yaml", s),),
          frozenset({2})),
        C(11, "unknown option", ("simulate", "a.yaml", "--nope"), (("a.yaml", s),),
          frozenset({2})),
        C(11, "missing argument", ("simulate",), (), frozenset({2})),
        C(11, "unknown command", ("nosuchcommand",), (), frozenset({2})),
        C(11, "long bad value", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(align__mode="m" * 100_000)),), frozenset({2})),
    ]
    # found by the generated cases (seed 14), kept by name
    fl = _copy(FLIGHT)
    fl["imu"]["accel"]["bias_ug"] = [50, -1e308, 50]
    fl_turn = _copy(FLIGHT)
    fl_turn["motion"]["segments"][2]["angle_deg"] = -1e308
    cases += [
        C(6, "accel bias -1e308 in a flight: validate refuses it too",
          ("navigate", "a.yaml", "-o", "out.h5"), (("a.yaml", emit(fl).encode()),),
          frozenset({2}), validate="a.yaml"),
        C(6, "a turn of -1e308 deg: not a number of samples",
          ("navigate", "a.yaml", "-o", "out.h5"), (("a.yaml", emit(fl_turn).encode()),),
          frozenset({2}), validate="a.yaml"),
        C(8, "a boolean nested in a list of numbers", ("align", "a.yaml", "-o", "out.h5"),
          (("a.yaml", sc(motion__attitude_deg=[0, 0, [True, 0, 0]])),), frozenset({2}),
          validate="a.yaml"),
        C(6, "a sweep variant that diverges: exit 1, the batch file records it",
          ("batch", "SW.yaml", "-o", "out.h5", "-w", "1"),
          (("S.yaml", s), ("SW.yaml", sweep(grid={"align.stages.0.t_z_s": [20, 1e-9]}))),
          frozenset({1})),
    ]
    # 3 filesystem
    for cmd in ("simulate", "align"):
        for out, what in (("", "empty -o"), (".", "-o ."), ("adir", "-o existing dir"),
                          ("ro/x.h5", "-o in a read-only dir"),
                          ("afile/x.h5", "-o under a file")):
            cases.append(C(3, f"{cmd} {what}", (cmd, "a.yaml", "-o", out),
                           (("a.yaml", s), ("afile", b"x")), _output_exits(out),
                           dirs=("adir", "ro")))
    for out, what in (("", "empty -o"), (".", "-o ."), ("adir", "-o existing dir"),
                      ("ro/x.h5", "-o in a read-only dir")):
        cases.append(C(3, f"batch {what}", ("batch", "SW.yaml", "-o", out, "-w", "1"),
                       (("S.yaml", s), ("SW.yaml", sw)), _output_exits(out),
                       dirs=("adir", "ro")))
    align_file = results_file("")  # any results file with figures: plot's -o is checked first
    for out, what in (("afile", "-o existing file"), ("afile/figs", "-o under a file"),
                      ("", "empty -o")):
        cases.append(C(3, f"plot {what}", ("plot", "d.h5", "-o", out),
                       (("d.h5", align_file), ("afile", b"x")), frozenset({2}), outputs=()))
    return cases


# --------------------------------------------------------------------------- recorded data


def psins_text(rows: int = 3000, header=None, rng=None) -> str:
    """A small PSINS .imu file: static, level, 100 Hz, counts with noise."""
    rng = rng or np.random.default_rng(0)
    h = header or [[0.5, 0.2, -90.6, 0, 0, 0], [34.246, 108.91, 380, 0, 10, 9.780327],
                   [0.1, 0.1, 0.1, 125, 125, 125]]
    counts = np.zeros((rows, 6), dtype=np.int64)
    counts[:, :3] = rng.poisson(1.5, (rows, 3)) * np.array([0, 1, 1]) - 0
    counts[:, 5] = 80 + rng.integers(-1, 2, rows)
    lines = ["% PSINS-format SIMU log file (made by the gcalign fuzz suite)"]
    lines += [" ".join(str(x) for x in row) for row in h]
    lines += [" ".join(map(str, r)) for r in counts]
    return "\n".join(lines) + "\n"


def csv_text(rows: int = 2000, t=None, values=None) -> str:
    ts = 0.01
    t = np.arange(1, rows + 1) * ts if t is None else t
    d = np.zeros((len(t), 6)) if values is None else values
    d[:, 5] = 9.8 * ts if values is None else d[:, 5]
    d[:, 1] = 7.29e-5 * 0.7 * ts if values is None else d[:, 1]
    lines = ["t,dtheta_x,dtheta_y,dtheta_z,dv_x,dv_y,dv_z"]
    lines += [",".join(repr(float(x)) for x in (ti, *row)) for ti, row in zip(t, d,
                                                                              strict=True)]
    return "\n".join(lines) + "\n"


def h5_bytes(build: Callable) -> bytes:
    """An HDF5 file made in memory by `build(f)`."""
    import h5py

    buf = io.BytesIO()
    with h5py.File(buf, "w") as f:
        build(f)
    return buf.getvalue()


def simulate_summary(rows: int) -> dict:
    """The summary `gcalign simulate` writes (its keys), for a static run of `rows`."""
    return {"scenario": "crafted", "seed": 1, "earth": "wgs84", "samples": rows,
            "rate_hz": 100.0, "duration_s": rows / 100, "output_rate_hz": 100.0,
            "mechanism": False, "compute_s": 0.01, "initial_attitude_deg": [0.0, 0.0, 0.0],
            "final_attitude_deg": [0.0, 0.0, 0.0], "final_velocity_mps": [0.0, 0.0, 0.0],
            "distance_m": 0.0, "height_range_m": [0.0, 0.0],
            "final_displacement_m": [0.0, 0.0, 0.0], "output": "d.h5"}


_DELETE = object()
#: mutations of one attribute: (root "/" or "/imu", attribute, new value or _DELETE)
ATTR_MUTATIONS = {
    "summary missing": ("/", "summary_json", _DELETE),
    "summary invalid": ("/", "summary_json", "{not json"),
    "summary a list": ("/", "summary_json", "[1, 2]"),
    "summary empty": ("/", "summary_json", "{}"),
    "summary NaN": ("/", "summary_json", '{"x": NaN}'),
    "kind missing": ("/", "kind", _DELETE),
    "kind unknown": ("/", "kind", "nosuch"),
    "kind batch": ("/", "kind", "batch"),
    "kind align": ("/", "kind", "align"),
    "kind navigate": ("/", "kind", "navigate"),
    "kind a number": ("/", "kind", 7),
    "scenario missing": ("/", "scenario_yaml", _DELETE),
    "scenario invalid": ("/", "scenario_yaml", "a: [1, 2"),
    "scenario bomb": ("/", "scenario_yaml", "name: " + bomb(9, 9)),
    "scenario a list": ("/", "scenario_yaml", "[1, 2]"),
    "version missing": ("/", "gcalign_version", _DELETE),
    "ts missing": ("/imu", "ts", _DELETE),
    "ts 0": ("/imu", "ts", 0.0),
    "ts negative": ("/imu", "ts", -0.01),
    "ts NaN": ("/imu", "ts", float("nan")),
    "ts a string": ("/imu", "ts", "fast"),
    "ts 1e300": ("/imu", "ts", 1e300),
    "site wrong shape": ("/imu", "site", np.zeros(2)),
    "site latitude 2 rad": ("/imu", "site", np.array([2.0, 0.0, 0.0])),
    "att0 NaN": ("/imu", "att0", np.array([np.nan, 0, 0])),
}


def results_file(mutation: str = "", rows: int = 2000) -> bytes:
    """A gcalign results file with /imu (as `gcalign simulate` writes it), crafted."""

    def build(f):
        import yaml

        ts = 0.01
        sc = {"name": "crafted", "site": {"lat_deg": 40, "lon_deg": 116}}
        attrs = {"gcalign_version": "0.1.0", "kind": "simulate",
                 "scenario_yaml": yaml.safe_dump(sc), "seed": 1,
                 "summary_json": json.dumps(simulate_summary(rows)),
                 "command_line": "gcalign simulate", "created_utc": "2026-01-01T00:00:00"}
        t = np.arange(1, rows + 1) * ts
        dth = np.tile([0.0, 7.29e-5 * 0.7 * ts, 7.29e-5 * 0.7 * ts], (rows, 1))
        dv = np.tile([0.0, 0.0, 9.8 * ts], (rows, 1))
        g_attrs = {"ts": ts, "source": "crafted", "site": np.radians([40, 116, 0]) * [1, 1, 0],
                   "att0": np.zeros(3), "v0_n": np.zeros(3)}
        m = mutation
        where, key, value = ATTR_MUTATIONS.get(m, (None, None, None))
        if where is not None:
            target = attrs if where == "/" else g_attrs
            if value is _DELETE:
                del target[key]
            else:
                target[key] = value
        elif m == "dtheta (5, 2)":
            dth = np.zeros((5, 2))
        elif m == "dtheta 1-d":
            dth = np.zeros(rows)
        elif m == "dv shorter":
            dv = dv[:-7]
        elif m == "t shorter":
            t = t[:10]
        elif m == "NaN rows":
            dth = dth.copy()
            dth[100:110] = np.nan
        elif m == "inf dv":
            dv = dv.copy()
            dv[5, 2] = np.inf
        elif m == "t decreasing":
            t = t[::-1].copy()
        elif m == "t gap":
            t = t.copy()
            t[1000:] += 90.0
        elif m == "dtheta strings":
            dth = np.array([["a", "b", "c"]] * rows, dtype=object)
        elif m == "empty":
            t, dth, dv = t[:0], dth[:0], dv[:0]
        for k, v in attrs.items():
            f.attrs[k] = v
        if m == "no imu":
            return
        g = f.create_group("imu")
        for k, v in g_attrs.items():
            g.attrs[k] = v
        if m != "t missing":
            g.create_dataset("t", data=t)
        if m == "dtheta strings":
            import h5py

            g.create_dataset("dtheta", data=dth.astype(str).astype(object),
                             dtype=h5py.string_dtype())
        elif m == "dtheta a group":
            g.create_group("dtheta")
        else:
            g.create_dataset("dtheta", data=dth)
        g.create_dataset("dv", data=dv)

    return h5_bytes(build)


H5_MUTATIONS = [
    "", "summary missing", "summary invalid", "summary a list", "summary empty",
    "summary NaN", "kind missing",
    "kind unknown", "kind batch", "kind align", "kind navigate", "kind a number",
    "scenario missing", "scenario invalid", "scenario bomb", "scenario a list",
    "version missing", "ts missing", "ts 0", "ts negative", "ts NaN", "ts a string",
    "ts 1e300", "dtheta (5, 2)", "dtheta 1-d", "dv shorter", "t shorter", "t missing",
    "NaN rows", "inf dv", "t decreasing", "t gap", "dtheta strings", "dtheta a group",
    "empty", "site wrong shape", "site latitude 2 rad", "att0 NaN", "no imu",
]


def recorded_cases(rng: random.Random) -> list[Case]:
    """Recorded data (PSINS, CSV, HDF5) and results files, crafted; every command that
    reads them."""
    out = []
    nav = ("navigate", "d", "--init", "header", "-o", "out.h5")
    # HDF5: navigate, show, plot (and align through a scenario's imu_file)
    for m in H5_MUTATIONS:
        data = results_file(m)
        valid = m == ""
        for argv in (("navigate", "d.h5", "-o", "out.h5"), ("show", "d.h5"),
                     ("plot", "d.h5", "-o", "figs")):
            outputs = ("out.h5",) if argv[0] == "navigate" else ("figs",)
            exits = frozenset({0}) if valid else frozenset({0, 1, 2})
            if argv[0] == "plot":  # a simulate file: its truth and IMU figures
                exits = frozenset({0}) if valid else frozenset({0, 1, 2})
            if m in ("summary missing", "summary invalid", "summary a list", "kind missing",
                     "kind a number", "version missing") and argv[0] == "plot":
                exits = frozenset({2})
            if m.startswith(("summary", "kind", "version")) and argv[0] == "show":
                exits = frozenset({2})
            if m.startswith(("ts", "dtheta", "dv ", "t ", "NaN", "inf", "empty", "site",
                             "att0", "no imu")) and argv[0] == "navigate":
                exits = frozenset({2})
            out.append(Case(7 if not m.startswith(("NaN", "inf", "t gap")) else 6,
                            f"{argv[0]} on results file: {m or 'valid'}", argv,
                            (("d.h5", data),), exits, outputs=outputs))
        scen = emit({"name": "rec", "imu_file": "d.h5",
                     "align": {"coarse": {"method": "analytic"},
                               "mode": "conventional", "t1_s": 5, "t2_s": 15, "t3_s": 15,
                               "level_s": 2, "stages": [{"t_xy_s": 5, "t_z_s": 10}]}}).encode()
        if m in ("", "ts 0", "ts missing", "dtheta (5, 2)", "NaN rows", "t gap", "empty"):
            out.append(Case(7, f"align with imu_file results file: {m or 'valid'}",
                            ("align", "a.yaml", "-o", "out.h5"),
                            (("a.yaml", scen), ("d.h5", data)),
                            frozenset({0, 1, 2}) if m == "" else frozenset({2}),
                            validate="a.yaml"))
    # PSINS headers and rows
    good = [[0.5, 0.2, -90.6, 0, 0, 0], [34.246, 108.91, 380, 0, 10, 9.780327],
            [0.1, 0.1, 0.1, 125, 125, 125]]
    bad_headers = {
        "latitude 90": (1, 0, 90), "latitude -91": (1, 0, -91), "pitch 95": (0, 0, 95),
        "roll 400": (0, 1, 400), "interval 0": (1, 4, 0), "interval -10": (1, 4, -10),
        "interval 1e300": (1, 4, 1e300), "interval nan": (1, 4, "nan"), "g 0": (1, 5, 0),
        "g 1e10": (1, 5, 1e10), "gyro scale 0": (2, 0, 0), "accel scale nan": (2, 3, "nan"),
        "height 1e9": (1, 2, 1e9), "longitude 1e6": (1, 1, 1e6), "VE inf": (0, 3, "inf"),
        "t0 nan": (1, 3, "nan"), "header word": (1, 2, "high"),
    }
    for label, (r, c, v) in bad_headers.items():
        h = [list(row) for row in good]
        h[r][c] = v
        out.append(Case(6, f"PSINS header {label}", nav[:1] + ("d.imu",) + nav[2:],
                        (("d.imu", psins_text(500, h).encode()),), frozenset({2})))
    text = psins_text(500)
    lines = text.splitlines()
    for label, edit in {
        "row of letters": lambda ls: ls[:100] + ["a b c d e f"] + ls[101:],
        "row with 5 fields": lambda ls: ls[:100] + ["1 2 3 4 5"] + ls[101:],
        "header only": lambda ls: ls[:4],
        "two header rows": lambda ls: ls[:3],
        "empty": lambda ls: [],
        "binary": None,
        "one sample": lambda ls: ls[:5],
        "huge counts": lambda ls: ls[:100] + ["1e300 0 0 0 0 1e300"] + ls[101:],
        "valid": lambda ls: ls,
    }.items():
        body = (bytes(rng.randrange(256) for _ in range(2000)) if edit is None
                else ("\n".join(edit(lines)) + "\n").encode())
        exits = {"one sample": frozenset({0, 1, 2}), "valid": frozenset({0})}.get(
            label, frozenset({1, 2}))
        out.append(Case(6, f"PSINS {label}", nav[:1] + ("d.imu",) + nav[2:],
                        (("d.imu", body),), exits))
    # CSV time stamps and values, aligned through a scenario (CSV has no initial state)
    t = np.arange(1, 2001) * 0.01
    csv_scen = emit({"name": "rec", "site": {"lat_deg": 34, "lon_deg": 108},
                     "imu_file": "d.csv",
                     "align": {"coarse": {"method": "analytic"},
                               "mode": "conventional", "t1_s": 5, "t2_s": 15, "t3_s": 15,
                               "level_s": 2, "stages": [{"t_xy_s": 5, "t_z_s": 10}]}}).encode()
    csv_bodies = {f"CSV {k}": csv_text(len(tt), tt) for k, tt in {
        "90 s gap": np.concatenate([t[:1000], t[1000:] + 90]),
        "repeated time": np.concatenate([t[:10], t[9:]]),
        "reversed": t[::-1].copy(),
        "jitter 30 %": t + 0.003 * np.sin(np.arange(2000) * 1.7),
        "ts 1e-12": t * 1e-10}.items()}
    for label, val in {"NaN": "nan", "inf": "inf", "1e308": "1e308"}.items():
        rows = csv_text(2000).splitlines()
        rows[500] = ",".join([rows[500].split(",")[0]] + [val] * 6)
        csv_bodies[f"CSV value {label}"] = "\n".join(rows) + "\n"
    csv_bodies["CSV valid"] = csv_text(2000)
    for label, body in csv_bodies.items():
        exits = frozenset({0}) if label == "CSV valid" else (
            frozenset({1, 2}) if label.endswith("1e308") else frozenset({2}))
        out.append(Case(6, label, ("align", "a.yaml", "-o", "out.h5"),
                        (("a.yaml", csv_scen), ("d.csv", body.encode())), exits,
                        validate="a.yaml"))
    # A scenario with recorded data: the same checks in validate
    for label, body in {"csv gap": csv_text(2000, np.concatenate([t[:1000], t[1000:] + 90])),
                        "psins latitude 90": psins_text(500, [good[0], [90, 108, 380, 0, 10,
                                                                        9.78], good[2]])}.items():
        name = "d.csv" if label.startswith("csv") else "d.imu"
        scen = emit({"name": "rec", "site": {"lat_deg": 34, "lon_deg": 108},
                     "imu_file": name}).encode() if label.startswith("csv") else emit(
            {"name": "rec", "imu_file": name}).encode()
        out.append(Case(8, f"validate recorded data: {label}", ("validate", "a.yaml"),
                        (("a.yaml", scen), (name, body.encode())), frozenset({2}),
                        outputs=()))
    return out


# --------------------------------------------------------------------------- journals


def journal_cases(rng: random.Random) -> list[Case]:
    """`batch --resume` on crafted journals of the sweep SW: garbage lines are skipped or
    rejected with one line; NaN and short metrics never enter the aggregate."""
    s, sw = emit(S).encode(), emit(SWEEP).encode()
    header = json.dumps({"type": "header", "sweep": "sw", "runs": 4})

    def rec(**over) -> str:
        r = {"type": "run", "variant": 0, "vkey": "@VKEY0", "seed": 1, "status": "ok",
             "metrics": {"error_t3_deg": [0.1, 0.2, 0.3]}, "error": "", "wall_s": 0.1}
        r.update(over)
        return json.dumps(r)

    bodies = {
        "binary garbage": bytes(rng.randrange(256) for _ in range(4000)),
        "random text": "\n".join("".join(rng.choice("{}[]\":,ab01 ") for _ in range(60))
                                 for _ in range(50)).encode(),
        "record without metrics": (header + "\n" + rec().replace(
            ', "metrics": {"error_t3_deg": [0.1, 0.2, 0.3]}', "") + "\n").encode(),
        "metrics NaN": (header + "\n" + rec(metrics={"error_t3_deg": [float("nan"), 0, 0]})
                        + "\n").encode(),
        "metrics short list": (header + "\n" + rec(metrics={"error_t3_deg": [0.1]})
                               + "\n").encode(),
        "metrics a string": (header + "\n" + rec(metrics={"error_t3_deg": "x"}) + "\n").encode(),
        "metrics null": (header + "\n" + rec(metrics=None) + "\n").encode(),
        "seed a string": (header + "\n" + rec(seed="1") + "\n").encode(),
        "seed huge": (header + "\n" + rec(seed=2**70) + "\n").encode(),
        "variant wrong": (header + "\n" + rec(variant=99) + "\n").encode(),
        "a list line": (header + "\n[1, 2, 3]\n").encode(),
        "torn last line": (header + "\n" + rec() + "\n" + rec(seed=2)[:40]).encode(),
        "huge line": (header + "\n" + "x" * 2_000_000 + "\n").encode(),
        "invalid utf-8": (header + "\n").encode() + b"\xff\xfe\xfa\n",
        "a directory": None,
    }
    out = []
    for label, body in bodies.items():
        files = [("S.yaml", s), ("SW.yaml", sw)]
        dirs: tuple[str, ...] = ()
        if body is None:
            dirs = ("out.h5.journal.jsonl",)
        else:
            files.append(("out.h5.journal.jsonl", body))
        exits = frozenset({0, 2}) if body is not None else frozenset({1, 2})
        out.append(Case(7, f"resume from journal: {label}",
                        ("batch", "SW.yaml", "-o", "out.h5", "--resume", "-w", "1"),
                        tuple(files), exits, outputs=("out.h5", "out.h5.journal.jsonl"),
                        dirs=dirs))
    for m in ("", "summary missing", "kind missing", "version missing"):
        out.append(Case(7, f"resume from a results file: {m or 'not a batch'}",
                        ("batch", "SW.yaml", "-o", "out.h5", "--resume", "-w", "1"),
                        (("S.yaml", s), ("SW.yaml", sw), ("out.h5", results_file(m))),
                        frozenset({2}), outputs=("out.h5",)))
    return out


# --------------------------------------------------------------------------- options


def _is_number_text(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def option_cases(rng: random.Random, n: int) -> list[Case]:
    """Bad option values on every command (one line, exit 2, nothing written)."""
    s = emit(S).encode()
    files = (("a.yaml", s), ("S.yaml", s), ("SW.yaml", emit(SWEEP).encode()))
    bad = ["abc", "-5", "1e3", "", "9" * 40, "nan", "--", "-", "0x1f", "１"]
    table = [
        (("simulate", "a.yaml"), ["--seed"]),
        (("align", "a.yaml"), ["--seed", "--passes", "--mode", "--compensation", "--t1",
                               "--t2", "--t3"]),
        (("navigate", "a.yaml"), ["--seed", "--start", "--duration", "--vertical", "--init"]),
        (("northfind", "a.yaml"), ["--seed"]),
        (("realtime", "a.yaml"), ["--seed"]),
        (("batch", "SW.yaml"), ["--workers", "--scheduler"]),
    ]
    out = []
    for i in range(n):
        head, opts = table[i % len(table)]
        opt = rng.choice(opts)
        value = rng.choice(bad)
        numeric = _is_number_text(value)
        exits = frozenset({1, 2}) if opt == "--scheduler" else (
            frozenset({0, 1, 2}) if numeric else frozenset({2}))
        out.append(Case(11, f"{head[0]} {opt} {value[:20]!r}",
                        (*head, opt, value, "-o", "out.h5"), files, exits))
    return out


def input_file_cases() -> list[Case]:
    """Scenario files that are not scenarios."""
    bodies = {
        "empty": b"", "null": b"null\n", "a list": b"[1, 2]\n", "a number": b"42\n",
        "binary": bytes(range(256)) * 8, "invalid utf-8": b"name: \xff\xfe\n",
        "two documents": b"name: a\n---\nname: b\n", "tabs": b"name: a\n\tsite: 1\n",
        "unclosed": b"name: [a, b\n", "python tag": b"!!python/object/apply:os.system "
                                                     b"['touch pwned']\n",
        "huge line": b"name: " + b"x" * 5_000_000 + b"\n",
        "deep nesting": b"a: " + b"[" * 20000 + b"]" * 20000 + b"\n",
    }
    out = []
    for cmd in ("validate", "simulate", "align", "navigate", "northfind", "realtime", "batch"):
        for label, body in bodies.items():
            if cmd not in ("validate", "batch") and label not in ("empty", "binary",
                                                                  "python tag"):
                continue
            argv = (cmd, "a.yaml") if cmd == "validate" else (cmd, "a.yaml", "-o", "out.h5")
            out.append(Case(8 if label == "empty" else 7, f"{cmd} on {label} file", argv,
                            (("a.yaml", body),), frozenset({2})))
        for label, argv in {"a directory": (cmd, "adir"), "missing": (cmd, "nope.yaml")}.items():
            out.append(Case(7, f"{cmd} on {label}", argv, (), frozenset({2}), dirs=("adir",)))
    return out


def all_cases(seed: int, n_scenarios: int = 240, n_sweeps: int = 24,
              n_options: int = 30, n_late: int = 30, n_limited: int = 60) -> list[Case]:
    """Every case of one fuzz run, in a fixed order (the same seed gives the same cases);
    generators added later come last, each with its own random stream, so that the cases
    before them stay the same."""
    rng = random.Random(seed)
    return [*fixed_cases(), *scenario_cases(rng, n_scenarios), *sweep_cases(rng, n_sweeps),
            *recorded_cases(rng), *journal_cases(rng), *option_cases(rng, n_options),
            *input_file_cases(),
            *scenario_cases(random.Random(f"{seed}-late"), n_late, LATE_BASES),
            *limited_cases(random.Random(f"{seed}-limited"), n_limited)]


# --------------------------------------------------------------------------- contract


@dataclass
class Outcome:
    exit_code: int | None  # None: did not finish (hang, killed)
    stderr: str
    new_files: list[str] = field(default_factory=list)  # relative paths created by the run
    elapsed_s: float = 0.0
    summary: object = None  # a successful run's summary (from its results file), if any
    validate_exit: int | None = None
    validate_stderr: str = ""
    note: str = ""  # killed by the time or memory limit, exception type, ...


def violations(case: Case, out: Outcome, time_limit_s: float = TIME_LIMIT_S) -> list[str]:
    """What the outcome breaks of the contract (empty: kept), a case slower than
    `time_limit_s` included."""
    v = []
    err = out.stderr.strip()
    if out.exit_code is None:
        return [f"did not finish ({out.note})"]
    if "Traceback" in out.stderr or out.note.startswith("exception"):
        v.append("traceback")
    if "internal error" in out.stderr:
        v.append("an unexpected exception (internal error)")
    if out.exit_code not in case.exits:
        v.append(f"exit {out.exit_code}, expected {sorted(case.exits)}")
    partial = (out.exit_code == 1 and case.argv[:1] == ("batch",)
               and isinstance(out.summary, dict) and out.summary.get("failed", 0) > 0
               and out.summary.get("complete") is True)
    if out.exit_code != 0 and not partial:
        lines = err.splitlines()
        if len(lines) != 1 or not lines[0].startswith("error: "):
            v.append(f"{len(lines)} stderr lines")
        elif len(lines[0]) > 400:
            v.append(f"stderr line of {len(lines[0])} characters")
        if out.new_files:
            v.append(f"left files {sorted(out.new_files)[:4]}")
    elif partial:  # a batch of which some runs failed: a result (docs/batch.md), exit 1
        last = err.splitlines()[-1] if err else ""
        if not last.startswith("error: ") or "run(s) failed" not in last:
            v.append("a batch with failed runs and no error line")
        extra = [p for p in out.new_files if p not in case.outputs]
        if extra:
            v.append(f"left files {sorted(extra)[:4]}")
    else:
        extra = [p for p in out.new_files
                 if not any(p == o or p.startswith(o.rstrip("/") + "/") for o in case.outputs)]
        if extra:
            v.append(f"left files {sorted(extra)[:4]}")
        if _non_finite(out.summary):
            v.append("non-finite number in the summary")
    if "pwned" in out.new_files:
        v.append("a YAML tag executed code")
    if case.validate is not None and out.validate_exit is not None:
        if (out.exit_code == 2) != (out.validate_exit == 2) and not _another_command(
                out.validate_stderr, case.argv[0]):
            v.append(f"validate exit {out.validate_exit}, the run {out.exit_code}")
    if out.elapsed_s > time_limit_s:
        v.append(f"took {out.elapsed_s:.1f} s")
    return v


def _another_command(stderr: str, command: str) -> bool:
    """Did validate refuse what another command of the scenario would cost (``error:
    observability: needs ...`` beside a calibrate run)? validate checks every section."""
    from gcalign.app.registry import COMMANDS

    head = stderr.removeprefix("error: ").split(":", 1)[0]
    return head in COMMANDS and head != command and " needs " in stderr


def _non_finite(x) -> bool:
    if isinstance(x, float):
        return not math.isfinite(x)
    if isinstance(x, dict):
        return any(_non_finite(v) for v in x.values())
    if isinstance(x, list):
        return any(_non_finite(v) for v in x)
    return False


# --------------------------------------------------------------------------- running


READ_ONLY = "/proc/gcalign-fuzz"  # not writable even by root (a chmod'ed folder would be)


def materialize(case: Case, folder) -> list[str]:
    """Write the case's files into `folder`; return its command line (paths resolved)."""
    from pathlib import Path

    folder = Path(folder)
    for d in case.dirs:
        if d != "ro":
            (folder / d).mkdir(parents=True, exist_ok=True)
    for name, body in case.files:
        (folder / name).write_bytes(body)
    for name, body in case.files:
        if b"@VKEY" in body:  # a journal of the sweep: the real variant keys
            from gcalign.app.batch.sweep import load_sweep

            sw = load_sweep(folder / "SW.yaml")
            for vi, key in enumerate(sw.keys):
                body = body.replace(f"@VKEY{vi}".encode(), key.encode())
            (folder / name).write_bytes(body)
    return [a.replace("ro/", READ_ONLY + "/", 1) if a.startswith("ro/") else a
            for a in case.argv]


def snapshot(folder) -> set[str]:
    """Every file under `folder` (hidden ones too), relative."""
    from pathlib import Path

    folder = Path(folder)
    return {str(p.relative_to(folder)) for p in folder.rglob("*")
            if p.is_file() or p.is_symlink()}


def read_summary(folder, case: Case):
    """The summary of a successful run's results file (NaN kept), or None."""
    from pathlib import Path

    for o in case.outputs:
        p = Path(folder) / o
        if p.is_file() and p.suffix == ".h5":
            import h5py

            try:
                with h5py.File(p, "r") as f:
                    return json.loads(f.attrs["summary_json"])
            except Exception:  # noqa: BLE001 - a crafted input file left as it was
                return None
    return None
