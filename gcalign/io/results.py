"""The HDF5 results file: one schema, written atomically, readable without gcalign.

Layout (README "Results file"): root attributes ``gcalign_version``, ``kind`` (the command),
``command_line``, ``scenario_yaml`` (the scenario text), ``seed``, ``created_utc`` and
``summary_json`` (what ``gcalign show`` prints); groups ``/truth``, ``/imu``, ``/navigate``,
``/align``, ``/northfind``, ``/batch``. Every dataset carries a ``units`` attribute and,
where it applies, a ``frame`` attribute. Arrays are SI, time along axis 0.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import h5py
import numpy as np
import yaml

from gcalign import __version__
from gcalign.errors import ScenarioError
from gcalign.sim.imu import ImuData
from gcalign.sim.motions import Truth

HDF5_SUFFIXES = {".h5", ".hdf5", ".hdf"}  #: file names read as our results files
PHI_FRAME = "misalignment, ENU: C_nb,est C_nb,true^T = exp(-[phi x])"
ATT_FRAME = "[pitch, roll, yaw], C_nb = Rz(yaw) Rx(pitch) Ry(roll), ENU, yaw CCW positive"


@contextmanager
def atomic_h5(path: Path) -> Iterator[h5py.File]:
    """Open `path` for writing under a temporary name; rename on success, delete on failure.

    An interrupted or failed run therefore never leaves a truncated file under the final name.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with h5py.File(tmp, "w") as f:
            yield f
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def put(group: h5py.Group, name: str, data, units: str, frame: str | None = None, **attrs):
    """Write one dataset with its units (and frame) attributes."""
    ds = group.create_dataset(name, data=np.asarray(data))
    ds.attrs["units"] = units
    if frame:
        ds.attrs["frame"] = frame
    for k, v in attrs.items():
        ds.attrs[k] = v
    return ds


class Series:
    """Datasets that grow block by block: chunked, compressed (gzip + shuffle), resizable
    along axis 0, each with its units (and frame) attribute. ``append(name=array, …)``
    adds rows to every named dataset; ``flush()`` (required once, after the last append)
    writes what is still held.

    Rows are held until a whole chunk is ready, so each chunk is compressed and written
    once: appending a few hundred rows at a time straight to the file recompresses the
    open chunk on every resize (4.3 s instead of 0.4 s for 259 200 rows of three columns).
    Memory is bounded by one chunk per dataset; the file never holds a run's series in
    memory."""

    def __init__(self, group: h5py.Group, spec: dict[str, tuple[int | None, str, str | None]],
                 chunk_rows: int = 4096, **attrs):
        self.group = group
        self.chunk_rows = chunk_rows
        self._held: dict[str, list[np.ndarray]] = {}
        self._held_rows: dict[str, int] = {}
        self._datasets: dict[str, h5py.Dataset] = {}
        for name, (width, units, frame) in spec.items():
            shape = (0,) if width is None else (0, width)
            ds = group.create_dataset(
                name, shape=shape, maxshape=(None,) + shape[1:], dtype="f8",
                chunks=(chunk_rows,) + shape[1:], compression="gzip", compression_opts=4,
                shuffle=True)
            ds.attrs["units"] = units
            if frame:
                ds.attrs["frame"] = frame
            self._datasets[name] = ds
            self._held[name] = []
            self._held_rows[name] = 0
        for k, v in attrs.items():
            group.attrs[k] = v

    def append(self, **arrays) -> None:
        for name, a in arrays.items():
            a = np.array(a, dtype=float)
            self._held[name].append(a)
            self._held_rows[name] += len(a)
            if self._held_rows[name] >= self.chunk_rows:
                self._write(name, whole_chunks=True)

    def flush(self) -> None:
        for name in self._held:
            self._write(name, whole_chunks=False)

    def _write(self, name: str, whole_chunks: bool) -> None:
        held = self._held[name]
        if not held:
            return
        rows = np.concatenate(held) if len(held) > 1 else held[0]
        n = len(rows) - len(rows) % self.chunk_rows if whole_chunks else len(rows)
        ds = self._datasets[name]
        m = ds.shape[0]
        ds.resize(m + n, axis=0)
        ds[m:] = rows[:n]
        self._held[name] = [rows[n:]] if n < len(rows) else []
        self._held_rows[name] = len(rows) - n


def write_header(f: h5py.File, kind: str, scenario_yaml: str, seed: int | None, summary: dict):
    f.attrs["gcalign_version"] = __version__
    f.attrs["kind"] = kind
    f.attrs["command_line"] = " ".join(["gcalign", *sys.argv[1:]])
    f.attrs["scenario_yaml"] = scenario_yaml
    f.attrs["seed"] = -1 if seed is None else int(seed)
    f.attrs["created_utc"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
    f.attrs["summary_json"] = json.dumps(summary)


def write_truth(f: h5py.File, truth: Truth):
    g = f.create_group("truth")
    put(g, "t", truth.t, "s")
    put(g, "att", truth.att, "rad", ATT_FRAME)
    put(g, "v_n", truth.v_n, "m/s", "ENU")
    put(g, "pos", truth.pos, "rad, rad, m", "[latitude, longitude, height], WGS-84")


def write_imu(f: h5py.File, imu: ImuData):
    g = f.create_group("imu")
    g.attrs["ts"] = imu.ts
    g.attrs["source"] = imu.source
    put(g, "t", imu.t, "s", description="end time of each increment")
    put(g, "dtheta", imu.dtheta, "rad", "body: x right, y forward, z up")
    put(g, "dv", imu.dv, "m/s", "body: x right, y forward, z up")
    for name in ("site", "att0", "v0_n"):
        value = getattr(imu, name)
        if value is not None:
            g.attrs[name] = value


def open_results(path: Path) -> h5py.File:
    """Open a gcalign results file for reading; ScenarioError if it is missing or not ours."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: file not found")
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise ScenarioError(f"{path}: not an HDF5 file (expected a gcalign results file)") from None
    if "gcalign_version" not in f.attrs:
        f.close()
        raise ScenarioError(
            f"{path}: an HDF5 file, but not a gcalign results file (no 'gcalign_version' attribute)"
        )
    return f


def read_summary(path: Path) -> tuple[str, dict, dict]:
    """``(kind, summary, root attributes)`` of a results file."""
    with open_results(path) as f:
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
    return str(attrs["kind"]), json.loads(attrs["summary_json"]), attrs


def read_truth(path: Path) -> Truth | None:
    with open_results(path) as f:
        if "truth" not in f:
            return None
        g = f["truth"]
        seg = g["segment"][()].astype(np.int64) if "segment" in g else None
        return Truth(t=g["t"][()], att=g["att"][()], v_n=g["v_n"][()], pos=g["pos"][()],
                     segment=seg)


def read_imu(path: Path) -> ImuData:
    """The IMU block stored by ``gcalign simulate`` (so the same data feeds several runs)."""
    with open_results(path) as f:
        if "imu" not in f:
            raise ScenarioError(f"{path}: holds no /imu group (write one with 'gcalign simulate')")
        g = f["imu"]
        if "summed_from_ts" in g.attrs:
            raise ScenarioError(
                f"{path}: /imu holds increments summed to {1 / float(g.attrs['ts']):g} Hz "
                f"(output.rate_hz); navigation needs every sample (coning and sculling are "
                f"lost in sums): simulate again with output: {{rate_hz: full}}")
        extra: dict = {k: np.asarray(g.attrs[k]) for k in ("site", "att0", "v0_n") if k in g.attrs}
        scenario = yaml.safe_load(str(f.attrs.get("scenario_yaml", ""))) or {}
        motion = scenario.get("motion") if isinstance(scenario, dict) else None
        kind = motion.get("kind") if isinstance(motion, dict) else None
        return ImuData(
            t=g["t"][()],
            dtheta=g["dtheta"][()],
            dv=g["dv"][()],
            ts=float(g.attrs["ts"]),
            source=str(path),
            meta=({"motion_kind": kind} if kind else {})
            | ({"q_bs0": np.asarray(g.attrs["q_bs0"])} if "q_bs0" in g.attrs else {}),
            q_bs=g["q_bs"][()] if "q_bs" in g else None,
            **extra,
        )


def read_scenario_yaml(path: Path) -> str:
    with open_results(path) as f:
        return str(f.attrs["scenario_yaml"])
