"""Damaged input files of every recorded-data reader, and what reading them must do.

:func:`make_files` writes one small valid file of each layout the readers take (IMU:
PSINS ``.imu`` plain, ``.gz`` and ``.xz``, CSV plain and ``.xz``, KF-GINS text, PSINS MAT
compressed and not; aiding: KF-GINS GNSS, RTKLIB ``.pos``, ENU velocity, odometer;
reference: PSINS ``avp`` MAT, KF-GINS navigation text, CSV), cut from the real recordings
of ``tests/data`` where there is one. :data:`DAMAGES` damages each file in the ways a disk,
a transfer or a user does:

* ``truncated``: the second half cut off; ``stub``: the first 10 bytes only; ``empty``;
* ``zeroed block``: 4 kB of zeros in the middle (a sparse hole); ``flipped``: 16 bytes
  inverted at a third; ``random``: random bytes of the same size; ``nul``: all zeros;
* ``as gzip``, ``as xz``, ``as plain``: the content recompressed the other way, or not at
  all, under the same name (gzip data named ``.xz``, text named ``.gz``);
* ``text``: a few lines of text in its place (text named ``.mat``); ``mat``: a MAT file in
  its place (a MAT file named ``.csv``);
* ``line dropped``, ``line doubled``: the middle line of a text file removed, repeated.

Each damaged file is read by each of its readers (:data:`READERS`: ``read_recording``,
``read_gnss``, ``read_velocity``, ``read_odometer``, ``read_reference``) and
:func:`outcome` classes what happened against the undamaged file:

* ``same``: the same arrays (the damage fell where nothing is read, or was undone);
* ``refused``: ScenarioError, one line naming the file;
* ``data``: other arrays, accepted: possible only where the damage can be data (a changed
  digit of a text file, a zeroed stretch of an uncompressed MAT array; a dropped or
  doubled line of an aiding or reference file, whose epochs need not be regular; a text
  file cut at a line, or in its last number) -- never for a compressed file, whose
  checksums see every damage;
* ``vague``: ScenarioError that does not name the file or is not one line;
* ``internal``: any other exception.

The contract (:func:`broken`): ``same``, ``refused`` or, where the damage can be data,
``data``. ``python tests/reader_damage.py`` prints the counts (docs/robustness.md).
"""

from __future__ import annotations

import gzip
import io
import lzma
import random
import sys
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"


@dataclass(frozen=True)
class Source:
    """A valid file: its name (suffix and all), kind and content."""

    name: str
    text: bool  # a text table (uncompressed content)
    content: bytes


def _psins_rows(rows: int) -> bytes:
    """The header and the first `rows` samples of lasergyro.imu."""
    lines = lzma.decompress((DATA / "lasergyro.imu.xz").read_bytes()).split(b"\n")
    head = [i for i, ln in enumerate(lines) if ln.strip() and not ln.startswith(b"%")]
    return b"\n".join(lines[:head[3] + rows]) + b"\n"


def _mat(variables: dict, compress: bool) -> bytes:
    import scipy.io

    buf = io.BytesIO()
    scipy.io.savemat(buf, variables, do_compression=compress)
    return buf.getvalue()


def _table(rows: np.ndarray, header: str = "", fmt: str = "%.12g", sep: str = ",") -> bytes:
    buf = io.StringIO()
    if header:
        buf.write(header + "\n")
    np.savetxt(buf, rows, fmt=fmt, delimiter=sep)
    return buf.getvalue().encode()


def sources() -> list[Source]:
    """The valid files (module docstring), small: a few thousand rows at most."""
    import scipy.io

    psins = _psins_rows(600)
    fog = scipy.io.loadmat(DATA / "transfer_align_fog_mems.mat")
    mimu, avp = fog["mimu"][:400], fog["fogavp"][:40]
    t = mimu[:, 6]
    csv = _table(np.column_stack([t, mimu[:, :6]]), "t,gx,gy,gz,ax,ay,az", "%.17g")
    i2nav_rows = np.column_stack([456300.0 + t, mimu[:, [1, 0]], -mimu[:, 2],
                                  mimu[:, [4, 3]], -mimu[:, 5]])  # RFU -> FRD
    i2nav = _table(i2nav_rows, fmt="%.17g", sep=" ")
    gnss = (DATA / "gnss_rtk_kfgins.txt").read_bytes()
    pos = (DATA / "rtklib_sample.pos").read_bytes()
    tv = avp[:, 9]
    vel = _table(np.column_stack([tv, avp[:, 3:6]]), "t,ve,vn,vu")
    odo = _table(np.column_stack([tv, np.linalg.norm(avp[:, 3:6], axis=1)]), "t,speed")
    deg = 180 / np.pi
    nav = _table(np.column_stack([np.zeros_like(tv), 456300.0 + tv, avp[:, 6] * deg,
                                  avp[:, 7] * deg, avp[:, 8], avp[:, 4], avp[:, 3], -avp[:, 5],
                                  avp[:, 1] * deg, avp[:, 0] * deg, -avp[:, 2] * deg]),
                 fmt="%.12g", sep=" ")
    ref_csv = _table(np.column_stack([tv, avp[:, 0:3] * deg, avp[:, 3:6], avp[:, 6:8] * deg,
                                      avp[:, 8]]),
                     "t,pitch,roll,yaw,ve,vn,vu,lat,lon,h")
    return [
        Source("rec.imu", True, psins), Source("rec.imu.gz", False, gzip.compress(psins)),
        Source("rec.imu.xz", False, lzma.compress(psins)),
        Source("rec.csv", True, csv), Source("rec.csv.xz", False, lzma.compress(csv)),
        Source("rec.i2nav.txt", True, i2nav),
        Source("mimu.mat", False, _mat({"mimu": mimu}, compress=True)),
        Source("mimu_plain.mat", False, _mat({"mimu": mimu}, compress=False)),
        Source("gnss.txt", True, gnss), Source("sol.pos", True, pos),
        Source("vel.csv", True, vel), Source("odo.csv", True, odo),
        Source("avp.mat", False, _mat({"avp": avp}, compress=True)),
        Source("ref.nav", True, nav), Source("ref.csv", True, ref_csv),
    ]


def _reader(name: str) -> list[tuple[str, Callable[[Path], object]]]:
    """The readers of a file, by the layout its name stands for."""
    from gcalign.io.recorded import aiding, read_gnss, read_recording, read_reference
    from gcalign.io.recorded.imu import Layout

    if name.startswith("rec.i2nav"):
        return [("read_recording i2nav",
                 lambda p: read_recording(p, Layout(format="i2nav", check_gravity=False)))]
    if name.startswith(("rec.", "mimu")):
        return [("read_recording", lambda p: read_recording(p, Layout(check_gravity=False)))]
    if name == "gnss.txt":
        return [("read_gnss i2nav-gnss", lambda p: read_gnss(p, "i2nav-gnss"))]
    if name == "sol.pos":
        return [("read_gnss rtklib-pos", lambda p: read_gnss(p, "rtklib-pos"))]
    if name == "vel.csv":
        return [("read_velocity", lambda p: aiding.read_velocity(p, "ENU"))]
    if name == "odo.csv":
        return [("read_odometer", lambda p: aiding.read_odometer(p, "F"))]
    fmt = {"avp.mat": "psins-mat", "ref.nav": "i2nav-nav", "ref.csv": "csv"}[name]
    readers = [(f"read_reference {fmt}", lambda p: read_reference(p, fmt))]
    if fmt == "psins-mat":  # velocity aiding from a reference's avp
        readers.append(("read_velocity_aiding psins-mat",
                        lambda p: aiding.read_velocity_aiding(p, "psins-mat")))
    return readers


def _recompress(src: Source, how: str) -> bytes:
    plain = _plain(src)
    return {"as gzip": gzip.compress, "as xz": lzma.compress, "as plain": lambda b: b}[how](
        plain)


def _plain(src: Source) -> bytes:
    if src.name.endswith(".gz"):
        return gzip.decompress(src.content)
    if src.name.endswith(".xz"):
        return lzma.decompress(src.content)
    return src.content


def _line(src: Source, how: str) -> bytes:
    lines = src.content.split(b"\n")
    k = len(lines) // 2
    return b"\n".join(lines[:k] + ([lines[k]] * 2 if how == "line doubled" else [])
                      + lines[k + 1:])


def _zeroed(b: bytes) -> bytes:
    a = bytearray(b)
    k = len(a) // 2
    a[k:k + 4096] = bytes(len(a[k:k + 4096]))
    return bytes(a)


def _flipped(b: bytes) -> bytes:
    a = bytearray(b)
    k = len(a) // 3
    a[k:k + 16] = bytes(x ^ 0xFF for x in a[k:k + 16])
    return bytes(a)


DAMAGES: dict[str, Callable[[Source], bytes | None]] = {
    "truncated": lambda s: s.content[:len(s.content) // 2],
    "stub": lambda s: s.content[:10],
    "empty": lambda s: b"",
    "zeroed block": lambda s: _zeroed(s.content),
    "flipped": lambda s: _flipped(s.content),
    "random": lambda s: random.Random(len(s.content)).randbytes(len(s.content)),
    "nul": lambda s: bytes(len(s.content)),
    "as gzip": lambda s: _recompress(s, "as gzip") if s.name.endswith((".xz", ".gz")) else None,
    "as xz": lambda s: _recompress(s, "as xz") if s.name.endswith((".xz", ".gz")) else None,
    "as plain": lambda s: _recompress(s, "as plain") if s.name.endswith((".xz", ".gz"))
    else None,
    "text": lambda s: b"t,a,b\n1,2,3\n2,3,4\n" if not s.text else None,
    "mat": lambda s: _mat({"x": np.arange(12.0).reshape(4, 3)}, False) if s.text else None,
    "line dropped": lambda s: _line(s, "line dropped") if s.text else None,
    "line doubled": lambda s: _line(s, "line doubled") if s.text else None,
}


@dataclass(frozen=True)
class Case:
    source: Source
    damage: str
    reader: str
    read: Callable[[Path], object]

    @property
    def id(self) -> str:
        return f"{self.source.name}-{self.damage}-{self.reader}".replace(" ", "_")


def cases() -> list[Case]:
    """Every valid file × every damage that applies to it × every reader of it."""
    out = []
    for src in sources():
        for damage, make in DAMAGES.items():
            if make(src) is None:
                continue
            for reader, read in _reader(src.name):
                out.append(Case(src, damage, reader, read))
    return out


def _arrays(obj) -> list[np.ndarray]:
    if hasattr(obj, "dtheta"):
        return [obj.t, obj.dtheta, obj.dv]
    return [np.asarray(v) for v in vars(obj).values() if isinstance(v, np.ndarray)]


def _same(a, b) -> bool:
    x, y = _arrays(a), _arrays(b)
    return len(x) == len(y) and all(p.shape == q.shape and np.array_equal(p, q)
                                    for p, q in zip(x, y, strict=True))


def outcome(case: Case, folder: Path) -> tuple[str, str]:
    """``(class, message)`` of reading the damaged file (module docstring)."""
    from gcalign.errors import ScenarioError
    good = folder / "good" / case.source.name
    bad = folder / "bad" / case.source.name
    for p, content in ((good, case.source.content), (bad, DAMAGES[case.damage](case.source))):
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content)  # type: ignore[arg-type]
    expected = case.read(good)
    try:
        got = case.read(bad)
    except ScenarioError as err:
        text = str(err)
        named = str(bad) in text and "\n" not in text
        return ("refused" if named else "vague"), text
    except Exception as err:  # noqa: BLE001 - what the contract forbids, counted
        return "internal", f"{type(err).__name__}: {err}"
    return ("same" if _same(got, expected) else "data"), ""


#: damages that can be data: a changed or lost number of an uncompressed file
CAN_BE_DATA = ("zeroed block", "flipped", "line dropped", "line doubled")


def broken(case: Case, cls: str) -> bool:
    if cls in ("same", "refused"):
        return False
    compressed = case.source.name.endswith((".gz", ".xz")) or (
        case.source.name.endswith(".mat") and "plain" not in case.source.name)
    can_be_data = case.damage in CAN_BE_DATA or (case.damage == "truncated" and case.source.text)
    return not (cls == "data" and can_be_data and not compressed)


def count(folder: Path) -> tuple[Counter, list[tuple[str, str, str]]]:
    """Outcomes by class, and the broken cases ``(id, class, message)``."""
    tally: Counter = Counter()
    bad = []
    for case in cases():
        cls, msg = outcome(case, folder / case.id)
        tally[cls] += 1
        tally[(case.reader, cls)] += 1
        if broken(case, cls):
            bad.append((case.id, cls, msg[:160]))
    return tally, bad


def print_counts(tally: Counter, broken: list, row: str, what: str, rows, classes) -> None:
    """The counts as a Markdown table (docs/robustness.md), one row per `rows`, then the
    broken cases."""
    print(f"| {row} | {what} | " + " | ".join(classes) + " |")
    print("| --- | ---: | " + " | ".join("---:" for _ in classes) + " |")
    for r in [*rows, None]:
        counts = [tally[c] if r is None else tally[(r, c)] for c in classes]
        print(f"| {'all' if r is None else r} | {sum(counts)} | "
              + " | ".join(map(str, counts)) + " |")
    print(f"broken: {len(broken)}")
    for b in broken:
        print("  ", *b)


if __name__ == "__main__":
    import tempfile

    all_cases = cases()
    files = len(sources())
    print(f"{files} files, {len(DAMAGES)} damages, {len({c.reader for c in all_cases})} "
          f"readers: {len(all_cases)} reads")
    with tempfile.TemporaryDirectory() as d:
        tally, bad = count(Path(d))
    print_counts(tally, bad, "reader", "reads", sorted({c.reader for c in all_cases}),
                 ("same", "refused", "data", "vague", "internal"))
