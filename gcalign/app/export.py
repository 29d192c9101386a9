"""``gcalign export``: the time series of a results file in other tools' formats (spec 005).

==============  ==========================================================================
format          what is written
==============  ==========================================================================
``csv``         ``t`` and every series of the group by component, as stored (SI), the
                unit of each column in its header name (``att_pitch (rad)``)
``mat``         MATLAB file (``scipy.io.savemat``): one variable per series as stored,
                ``units`` a struct of their units, ``source`` and ``group`` as text
``i2nav-nav``   KF-GINS navigation result text: week, seconds of week, lat, lon (deg),
                h (m), vN, vE, vD (m/s), roll, pitch, yaw (deg; NED, yaw = heading)
``psins-avp``   MATLAB file with PSINS's ``avp = [att(3) v(3) lat lon h t]`` (rad, m/s
                ENU, rad, m, s)
==============  ==========================================================================

gcalign's RFU/ENU attitude ``[pitch, roll, yaw]`` (``C_nb = Rz(yaw) Rx(pitch) Ry(roll)``)
and KF-GINS's FRD/NED ``[roll, pitch, yaw]`` (z-y-x) are the same rotations about the same
physical axes, down being minus up: roll and pitch are equal and the NED yaw is the
heading, ``−yaw`` (tested against the matrices). The week of the i2nav-nav file is 0
unless given: gcalign's time is the recording's own (GNSS seconds of week for i2nav input).
Files are written under a temporary name and renamed (:func:`gcalign.io.results.atomic_file`):
nothing half-written is left, and a full disk is one line. The export's size is held against
``GCALIGN_MAX_OUTPUT_MB`` before anything is written. A MAT file's header names gcalign and
the source file where scipy would write the date, so one results file always exports to the
same bytes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gcalign import limits
from gcalign._version import __version__
from gcalign.errors import ScenarioError
from gcalign.io import results

FORMATS = {"csv": ".csv", "mat": ".mat", "i2nav-nav": ".nav", "psins-avp": ".avp.mat"}


def default_output(path: Path, fmt: str) -> Path:
    """``runs/x-navigate.h5`` -> ``runs/x-navigate.csv`` (``.mat``, ``.nav``, ``.avp.mat``)."""
    return path.with_name(path.name.split(".")[0] + FORMATS[fmt])


#: formats that hold a navigation solution (attitude, velocity, position): a calibration
#: exports its solution at every navigation sample to them, its estimates to the others
NAVIGATION_FORMATS = ("i2nav-nav", "psins-avp")


def default_group(path: Path, fmt: str = "csv") -> str:
    """The group of the command that wrote the file (``navigate``, ``simulate``'s
    ``truth``, ...); where that group keeps its series in subgroups, the one holding the
    result: an alignment's last pass (``align/pass_05``: it ends at T2, whence T3), a
    calibration's first run (``calibrate/runs/00``: its estimates and σ), or to a
    navigation format (:data:`NAVIGATION_FORMATS`) its solution at every navigation sample
    (``calibrate/runs/00/navigation``). :func:`gcalign.io.results.series` says which groups
    hold series when there is none."""
    from gcalign.app.checked import read_checked

    kind = read_checked(path)[0]
    group = {"simulate": "truth"}.get(kind, kind)
    timed = results.timed_groups(path, group)
    if not timed or group in timed:
        return group
    if kind == "calibrate" and fmt in NAVIGATION_FORMATS \
            and "calibrate/runs/00/navigation" in timed:
        return "calibrate/runs/00/navigation"
    return timed[-1] if kind == "align" else timed[0]


def export(path, fmt: str, out=None, group: str | None = None, week: int = 0,
           note=None) -> Path:
    """Write the series of `group` of the results file `path` in format `fmt` to `out`
    (default :func:`default_output`); ScenarioError (one line) on a bad format, file or
    group. `note(text)`, when given, is told which group a default chose if it is not the
    command's own (an alignment's last pass). Returns the path written."""
    path = Path(path)
    if fmt not in FORMATS:
        raise ScenarioError(f"--format: {fmt!r} is not an export format; allowed: "
                            f"{', '.join(FORMATS)}")
    own = default_group(path, fmt)  # reads the file through its kind's checks (app.checked)
    if group is None and note is not None and "/" in own:
        others = [g for g in results.timed_groups(path, own.split("/")[0]) if g != own]
        note(f"exported /{own}" + (f"; --group for another: {', '.join(others)}"
                                    if others else ""))
    group = group or own
    data = results.series(path, group)
    out = results.check_output(default_output(path, fmt) if out is None else out)
    if out.resolve() == path.resolve():
        raise ScenarioError(f"--output: {out} is the results file itself; give another name")
    cols = results.columns(path, group) if fmt == "csv" else None
    _check_size(fmt, data, path, group)
    writer = {"csv": _csv, "mat": _mat, "i2nav-nav": _i2nav_nav, "psins-avp": _psins_avp}[fmt]
    with results.atomic_file(out, "w" if fmt in ("csv", "i2nav-nav") else "wb") as fh:
        writer(fh, path, group, data if cols is None else cols, week)
    return out


#: Bytes per value as written: 17 significant digits and a separator in text, float64 in MAT
_VALUE_BYTES = {"csv": 25, "i2nav-nav": 25, "mat": 8, "psins-avp": 8}


def _check_size(fmt: str, data, path: Path, group: str) -> None:
    """The export's size against ``GCALIGN_MAX_OUTPUT_MB`` before anything is written
    (uncompressed: a MAT file's compression is not known before it is done)."""
    values = (11 * len(data["t"][0]) if fmt == "i2nav-nav" else
              sum(int(np.asarray(a).size) for a, _ in data.values()))
    limits.MAX_OUTPUT_MB.check(values * _VALUE_BYTES[fmt] / 2**20,
                               f"export of {path} /{group} as {fmt}")


def _csv(fh, path: Path, group: str, cols, week: int) -> None:
    header = ",".join(f"{name} ({units})" for name, _, units in cols)
    fh.write(f"# gcalign export of {path}, group /{group}; SI as stored, unit of each "
             "column in its name\n")
    fh.write(header + "\n")
    np.savetxt(fh, np.column_stack([a for _, a, _ in cols]), fmt="%.17g", delimiter=",")


def _savemat(fh, variables: dict, source: Path) -> None:
    """``scipy.io.savemat`` with a header that says what wrote the file, in place of the
    date scipy writes there: the same results file exports to the same bytes."""
    import scipy.io

    scipy.io.savemat(fh, variables, do_compression=True)
    text = f"MATLAB 5.0 MAT-file, written by gcalign {__version__} from {source.name}"
    header = text.encode("ascii", "replace")[:116].ljust(116, b" ")
    fh.seek(0)
    fh.write(header)  # the first 116 bytes are free text (MAT-file format, level 5)


def _mat(fh, path: Path, group: str, data, week: int) -> None:
    arrays = {name: a for name, (a, _) in data.items()}
    units = {name: u for name, (_, u) in data.items()}
    _savemat(fh, {**arrays, "units": units, "source": str(path), "group": group}, path)


def _nav(data, group: str, path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    missing = [k for k in ("att", "v_n", "pos") if k not in data]
    if missing:
        raise ScenarioError(f"--format: {path}: /{group} has no {', '.join(missing)} series "
                            "(a navigation solution needs att, v_n and pos); it has "
                            f"{', '.join(data)}")
    return data["t"][0], data["att"][0], data["v_n"][0], data["pos"][0]


def _i2nav_nav(fh, path: Path, group: str, data, week: int) -> None:
    t, att, v, pos = _nav(data, group, path)
    heading = np.degrees(-att[:, 2])
    heading = (heading + 180.0) % 360.0 - 180.0
    rows = np.column_stack([np.full(len(t), week), t, np.degrees(pos[:, 0]),
                            np.degrees(pos[:, 1]), pos[:, 2], v[:, 1], v[:, 0], 0.0 - v[:, 2],
                            np.degrees(att[:, 1]), np.degrees(att[:, 0]), heading])
    np.savetxt(fh, rows, fmt=["%d"] + ["%.17g"] * 10)


def _psins_avp(fh, path: Path, group: str, data, week: int) -> None:
    t, att, v, pos = _nav(data, group, path)
    _savemat(fh, {"avp": np.column_stack([att, v, pos, t])}, path)
