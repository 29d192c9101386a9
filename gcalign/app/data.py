"""The IMU data and truth of a scenario: simulated from `motion`, or read from `imu_file`.

Two views of the same data:

* :class:`Stream` -- blocks of measured increments with the truth at their end times,
  generated on the fly (simulation: truth → ideal increments → sensor errors), so that a
  72 h run never holds more than a block; what ``simulate`` and ``navigate`` use.
* :class:`RunData` -- the whole run as arrays (alignment passes need the stored block).
  :func:`scenario_data` builds it from the stream into preallocated arrays.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.io.paths import not_a_file
from gcalign.io.results import HDF5_SUFFIXES
from gcalign.io.scenario import Scenario
from gcalign.nav.earth import WGS84, EarthModel
from gcalign.nav.rotation import dcm_to_quat
from gcalign.sim.errors import ErrorStream
from gcalign.sim.imu import ImuData
from gcalign.sim.motions import Moving, Truth, sample_count


@dataclass(frozen=True)
class RunData:
    """What every pipeline starts from: IMU increments, truth if known, site, seed, earth."""

    imu: ImuData
    truth: Truth | None
    site: np.ndarray
    seed: int | None
    earth: EarthModel = WGS84


@dataclass(frozen=True)
class BlockTruth:
    """The truth at the end times of a block's increments: att (n, 3), q_nb (n, 4) or None
    (then whoever needs it computes ``euler_to_quat(att)``), v_n, pos (n, 3) and the motion
    segment of each increment (n,)."""

    att: np.ndarray
    q_nb: np.ndarray | None
    v_n: np.ndarray
    pos: np.ndarray
    segment: np.ndarray


@dataclass(frozen=True)
class DataBlock:
    """Measured increments k0 .. k0+n-1 (sensor frame) at end times t (n,), the truth there
    if known, and the mechanism angles q_bs (n, 4) if the IMU turns."""

    k0: int
    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    truth: BlockTruth | None = None
    q_bs: np.ndarray | None = None


@dataclass(frozen=True)
class Stream:
    """A run's data as blocks (see the module docstring). `truth0` is the truth at the time
    before the first increment (None for recorded data); `header` the recorded file's own
    ImuData (its att0, v0_n, site, meta) without the arrays."""

    ts: float
    samples: int
    site: np.ndarray
    earth: EarthModel
    seed: int | None
    source: str
    truth0: Truth | None
    make_blocks: Callable[[], Iterator[DataBlock]] = field(repr=False)
    header: ImuData | None = None
    has_mechanism: bool = False
    at: Callable[[int], tuple] | None = field(default=None, repr=False)

    def blocks(self) -> Iterator[DataBlock]:
        return self.make_blocks()

    def truth_at(self, k: int):
        """(att, v_n, pos) of the truth at sample k (the end of increment k − 1; k = 0 the
        start), or None without truth."""
        return None if self.at is None else self.at(k)[:3]

    def q_bs_at(self, k: int):
        """Mechanism angles q_bs at sample k, or None without a mechanism."""
        return None if self.at is None or not self.has_mechanism else self.at(k)[3]

    @property
    def t0(self) -> float:
        """Time before the first increment (s)."""
        return 0.0 if self.header is None else float(self.header.t[0] - self.ts)


def check_finite_block(t: np.ndarray, dtheta: np.ndarray, dv: np.ndarray) -> None:
    """ScenarioError naming the sensor and the time if simulated increments are not finite
    or beyond what recorded data may hold (:data:`gcalign.io.imu_files.MAX_DTHETA_RAD`,
    ``MAX_DV_MPS`` per sample): sensor errors far beyond any instrument, e.g.
    ``bias_dph: [1e308, 0, 0]``."""
    from gcalign.io.imu_files import MAX_DTHETA_RAD, MAX_DV_MPS

    for name, a, bound in (("gyro", dtheta, MAX_DTHETA_RAD), ("accel", dv, MAX_DV_MPS)):
        # NaN propagates into the extremes: False (and no temporary of the block's size)
        if a.max(initial=0.0) <= bound and -a.min(initial=0.0) <= bound:
            continue
        ok = (np.abs(a) <= bound).all(1)  # False for NaN too
        if not ok.all():
            k = int(np.argmin(ok))
            raise ScenarioError(f"imu.{name}: the sensor errors make the simulated increments "
                                f"{a[k].tolist()} at t = {float(t[k]):g} s, beyond {bound:g} "
                                "per sample; check the biases, scale factors and noise")


@dataclass(frozen=True)
class Recording:
    """A scenario's recorded file as read (:func:`read_recorded`): the increments in our
    conventions (``imu.meta["recording"]``: what the reader assumed) and the truth, if the
    file has it (a results file of ours)."""

    imu: ImuData
    truth: Truth | None = None


def read_recorded(scenario: Scenario) -> Recording:
    """The scenario's ``imu_file``, read and validated with its layout."""
    assert scenario.imu_file is not None
    return Recording(*read_data_file(Path(scenario.imu_file), scenario.recording_layout()))


def read_data_file(path: Path, layout=None) -> tuple[ImuData, Truth | None]:
    """IMU (and truth, if the file has it) from our HDF5, or a recording of any layout
    (:func:`gcalign.io.recorded.read_recording`: PSINS .imu, PSINS MAT, KF-GINS text,
    CSV/text with declared columns, units and axes; ``.gz``/``.xz`` compressed too)."""
    from gcalign.io import results
    from gcalign.io.recorded import read_recording

    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"imu_file: {path}: {not_a_file(path)}")
    if path.suffix.lower() in HDF5_SUFFIXES:
        if layout is not None and layout.declared() | ({layout.format} - {"auto"}):
            raise ScenarioError(f"imu_file.format: {path} is a gcalign results file, which "
                                "says its own layout; remove format, axes and the rest")
        return results.read_imu(path), results.read_truth(path)
    try:
        return read_recording(path, layout), None
    except ValueError as err:
        text = str(err)
        raise ScenarioError(text if text.startswith("imu_file") else f"imu_file: {text}"
                            ) from None


def recording_record(sc: Scenario, recording: Recording | None) -> dict | None:
    """What the reader of the scenario's recorded file assumed (``meta["recording"]`` of
    the `recording` read for the run), or None for simulated data and our own HDF5 files."""
    if recording is None or sc.imu_file is None or sc.reads_own_recording:
        return None
    if Path(sc.imu_file).suffix.lower() in HDF5_SUFFIXES:
        return None
    return recording.imu.meta.get("recording")


def _recorded(scenario: Scenario, recording: Recording | None = None) -> RunData:
    """The recorded run: `recording` (the file as the preflight read it), else the file
    read here."""
    if recording is None:
        recording = read_recorded(scenario)
    imu, truth = recording.imu, recording.truth
    if scenario.site is not None:
        site = scenario.site.to_si()
    elif imu.site is not None:
        site = np.asarray(imu.site, float)
    elif scenario.initial is not None and (start := scenario.initial.position()) is not None:
        site = start  # where the run starts
    elif scenario.reference is not None:  # where the reference solution starts
        site = np.asarray(scenario.reference.read().pos[0], float)
    else:
        raise no_site(scenario)
    return RunData(imu=imu, truth=truth, site=site, seed=None, earth=scenario.earth_model)


def no_site(sc: Scenario) -> ScenarioError:
    """The refusal of a recording run when neither the file nor the scenario gives a site."""
    return ScenarioError(f"site: missing: {sc.imu_file} does not give the site (a CSV file has "
                         "no header); give --lat/--lon/--height, a site section in the "
                         "scenario, initial: {lat_deg, lon_deg, height_m}, or a reference)")


def _simulation(scenario: Scenario):
    if scenario.motion is None:
        raise ScenarioError("motion: missing; the scenario needs 'motion' or 'imu_file'")
    assert scenario.site is not None  # the model requires a site with a motion
    motion = scenario.motion.to_motion()
    mech = None
    if scenario.mechanism is not None:
        mech = scenario.mechanism.to_mechanism(scenario.motion.attitude_deg)
    return motion, mech, scenario.site.to_si()


def scenario_stream(scenario: Scenario, seed: int | None = None,
                    block: int | None = None, recording: Recording | None = None) -> Stream:
    """The scenario's data as blocks (simulated with its sensor errors, or recorded:
    `recording` as the preflight read it, else the file read here)."""
    from gcalign.sim.ideal import ideal_blocks, initial_truth

    earth = scenario.earth_model
    if scenario.imu_file is not None:
        return stream_of(_recorded(scenario, recording), earth, block)

    motion, mech, site = _simulation(scenario)
    seed = scenario.imu.seed if seed is None else seed
    ts = scenario.imu.ts
    n = sample_count(motion.duration, ts)
    errors = scenario.imu.errors()

    def simulated_blocks() -> Iterator[DataBlock]:
        stream = ErrorStream(errors, ts, np.random.default_rng(seed), n, private=True)
        for b in ideal_blocks(motion, site, ts, earth, mech, block=block):
            dtheta, dv = stream.apply(b.dtheta, b.dv)
            check_finite_block(b.t, dtheta, dv)
            yield DataBlock(b.k0, b.t, dtheta, dv,
                            BlockTruth(b.att, b.q_nb, b.v_n, b.pos, b.segment), b.q_bs)

    def simulated_at(k: int):
        """Truth at sample k from the motion itself (truth at any time)."""
        t = np.array([k * ts])
        seg = None
        if isinstance(motion, Moving):  # the end of increment k − 1: its own segment
            seg = motion.segment_index(t, side="left")
        kin = (motion.kinematics(t, site, earth, segment=seg) if seg is not None
               else motion.kinematics(t, site, earth))
        q_bs = None
        if mech is not None:
            q_bs = mech.q_bs(t, dcm_to_quat(kin.C_nb))[0]
        return kin.att[0].copy(), kin.v_n[0].copy(), kin.pos[0].copy(), q_bs

    return Stream(ts, n, site, earth, seed, "simulated", initial_truth(motion, site, earth),
                  simulated_blocks, has_mechanism=mech is not None, at=simulated_at)


def stream_of(data: RunData, earth: EarthModel | None = None,
              block: int | None = None) -> Stream:
    """A whole run held in memory (recorded data, a batch's cached simulation) as a Stream."""
    from gcalign.sim.ideal import BLOCK

    imu, truth = data.imu, data.truth
    size = block or BLOCK

    def blocks() -> Iterator[DataBlock]:
        for k0 in range(0, len(imu), size):
            sl = slice(k0, k0 + size)
            tr = None
            if truth is not None:
                seg = (np.zeros(len(imu.t[sl]), np.int64) if truth.segment is None
                       else truth.segment[1:][sl])
                tr = BlockTruth(truth.att[1:][sl], None, truth.v_n[1:][sl], truth.pos[1:][sl],
                                seg)
            yield DataBlock(k0, imu.t[sl], imu.dtheta[sl], imu.dv[sl], tr,
                            None if imu.q_bs is None else imu.q_bs[sl])

    t0 = None if truth is None else Truth(truth.t[:1], truth.att[:1], truth.v_n[:1],
                                          truth.pos[:1], None if truth.segment is None
                                          else truth.segment[:1])
    header = replace(imu, t=imu.t[:1], dtheta=imu.dtheta[:0], dv=imu.dv[:0],
                     q_bs=None if imu.q_bs is None else imu.q_bs[:0])
    q_bs0 = imu.meta.get("q_bs0")

    def at(k: int):
        q = None if imu.q_bs is None else (q_bs0 if k == 0 else imu.q_bs[k - 1])
        if truth is None:
            return None, None, None, q
        return truth.att[k], truth.v_n[k], truth.pos[k], q

    return Stream(imu.ts, len(imu), data.site, earth or data.earth, data.seed, imu.source, t0,
                  blocks, header, imu.q_bs is not None,
                  at if truth is not None or imu.q_bs is not None else None)


def gather(stream: Stream) -> RunData:
    """The whole run as arrays (preallocated; one block of temporaries at a time)."""
    n = stream.samples
    t = np.empty(n)
    dtheta, dv = np.empty((n, 3)), np.empty((n, 3))
    q_bs = np.empty((n, 4)) if stream.has_mechanism else None
    truth, first = None, stream.truth0
    if first is not None:  # the truth at sample 0, then at the end of each increment
        seg, rows = np.empty(n + 1, np.int64), (n + 1, 3)
        truth = Truth(np.empty(n + 1), np.empty(rows), np.empty(rows), np.empty(rows), seg)
        truth.t[0], truth.att[0], truth.v_n[0], truth.pos[0] = (stream.t0, first.att[0],
                                                                first.v_n[0], first.pos[0])
        seg[0] = 0 if first.segment is None else first.segment[0]
    for b in stream.blocks():
        sl = slice(b.k0, b.k0 + len(b.t))
        t[sl], dtheta[sl], dv[sl] = b.t, b.dtheta, b.dv
        if truth is not None and b.truth is not None:
            s1 = slice(b.k0 + 1, b.k0 + 1 + len(b.t))
            truth.t[s1], truth.att[s1], truth.v_n[s1] = b.t, b.truth.att, b.truth.v_n
            truth.pos[s1], seg[s1] = b.truth.pos, b.truth.segment
        if q_bs is not None and b.q_bs is not None:
            q_bs[sl] = b.q_bs
    if stream.header is not None:
        imu = replace(stream.header, t=t, dtheta=dtheta, dv=dv, q_bs=q_bs)
    else:
        imu = ImuData(t=t, dtheta=dtheta, dv=dv, ts=stream.ts, site=stream.site, q_bs=q_bs)
    return RunData(imu=imu, truth=truth, site=stream.site, seed=stream.seed, earth=stream.earth)


def scenario_data(scenario: Scenario, seed: int | None = None,
                  cache_key: str | None = None, recording: Recording | None = None) -> RunData:
    """Simulate the scenario's motion with its IMU errors, or read its recorded IMU file
    (`recording`: the file as the preflight read it).

    `seed` overrides ``imu.seed``; the same scenario and seed give the same numbers.
    `cache_key` (a batch variant) lets successive seeds share the noise-free simulation:
    it is computed once per key in this process (see :func:`cached_noise_free`).
    """
    if scenario.imu_file is not None:
        return _recorded(scenario, recording)
    if cache_key is not None:
        return with_errors(scenario, cached_noise_free(scenario, cache_key), seed)
    return gather(scenario_stream(scenario, seed))


def noise_free(scenario: Scenario) -> RunData:
    """Truth and ideal increments of a simulated scenario: the part that no seed changes
    (a batch computes it once per variant)."""
    from gcalign.sim.imu import ideal_imu

    motion, mech, site = _simulation(scenario)
    truth, ideal = ideal_imu(motion, site, scenario.imu.ts, earth=scenario.earth_model,
                             mechanism=mech)
    return RunData(imu=ideal, truth=truth, site=site, seed=None, earth=scenario.earth_model)


def with_errors(scenario: Scenario, ideal: RunData, seed: int | None = None) -> RunData:
    """The scenario's sensor errors applied to noise-free data; `seed` overrides imu.seed."""
    seed = scenario.imu.seed if seed is None else seed
    stream = ErrorStream(scenario.imu.errors(), ideal.imu.ts, np.random.default_rng(seed),
                         len(ideal.imu), private=True)
    dtheta, dv = stream.apply(ideal.imu.dtheta, ideal.imu.dv)
    check_finite_block(ideal.imu.t, dtheta, dv)
    return RunData(imu=replace(ideal.imu, dtheta=dtheta, dv=dv), truth=ideal.truth,
                   site=ideal.site.copy(), seed=seed, earth=ideal.earth)


_NOISE_FREE: dict[str, RunData] = {}  # cache key -> noise-free data, in this process


def cached_noise_free(scenario: Scenario, key: str) -> RunData:
    """:func:`noise_free` computed once per key (a batch variant: truth and ideal increments
    are about 2/3 of a seed 000 run; only the sensor errors depend on the seed). Same
    numbers, bit for bit (tested). The cached arrays are read-only, so code that would
    modify them fails loudly. At most four variants are kept.
    """
    hit = _NOISE_FREE.get(key)
    if hit is None:
        if len(_NOISE_FREE) >= 4:
            _NOISE_FREE.pop(next(iter(_NOISE_FREE)))
        hit = _NOISE_FREE[key] = noise_free(scenario)
        for obj in (hit.truth, hit.imu):
            for value in vars(obj).values():
                if isinstance(value, np.ndarray):
                    value.flags.writeable = False
    return hit
