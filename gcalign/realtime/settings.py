"""Settings of a real-time attitude run (seed 003; spec 003), SI units and radians, validated.

The seed leaves most numbers open (spec 003 §2–§4): cut-off frequencies, notch frequency
and Q, Qc, R, P0, the noise model. Each is a setting here with the spec's [O] default, and
each bad value raises ``ValueError("setting: what is allowed, got value")`` (the scenario
layer turns it into one line and exit code 2).

>>> s = Settings()
>>> s.samples_per_solution, s.tau, s.filter.nav_order, round(s.tracker.r ** 0.5 / ARCSEC, 3)
(5, 0.001, 40, 0.03)
>>> Settings(pulses=PulseSettings(rate_hz=2000.0))  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: pulses.rate_hz: must be ≤ solution_hz = 1000 Hz (a pulse latches ...), got 2000
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from gcalign.choices import PREDICTORS
from gcalign.units import ARCSEC, DEG

__all__ = [
    "CHAINS",
    "PREDICTORS",
    "PULSE_MODES",
    "FilterSettings",
    "PulseSettings",
    "SensorSettings",
    "Settings",
    "TrackerSettings",
    "seed_semi_physical",
]

CHAINS = ("navigation", "alignment")  #: filter chains (seed §2)
PULSE_MODES = ("solution", "async")  #: pulses on the solution instants, or asynchronous


def _positive(name: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name}: must be a finite number > 0, got {value!r}")


def _non_negative(name: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name}: must be a finite number ≥ 0, got {value!r}")


@dataclass(frozen=True, kw_only=True)
class FilterSettings:
    """The composite filter (seed §2; spec 003 §2 [O] defaults).

    Parameters
    ----------
    fs_hz : float, Hz
        Sensor sampling and filter rate f1 (seed: 5 kHz).
    align_order, nav_order : int
        FIR orders N (taps N + 1): alignment 180, navigation 40 (seed §2), ≥ 1.
    align_cutoff_hz, nav_cutoff_hz : float, Hz
        FIR cut-offs (not in the seed; [O] 100 Hz and 200 Hz), in (0, fs_hz/2).
    notch_hz : float or None, Hz
        IIR notch frequency, the gyro dither frequency ([O] 400 Hz); None: no notch.
    notch_q : float
        Notch quality factor ([O] 10), > 0.
    window : str
        ``scipy.signal.firwin`` window.
    chain : {"navigation", "alignment"}
        Which chain filters the increments of a run (navigation: notch + FIR of order 40).
    """

    fs_hz: float = 5000.0
    align_order: int = 180
    align_cutoff_hz: float = 100.0
    nav_order: int = 40
    nav_cutoff_hz: float = 200.0
    notch_hz: float | None = 400.0
    notch_q: float = 10.0
    window: str = "hamming"
    chain: str = "navigation"

    def __post_init__(self) -> None:
        _positive("filter.fs_hz", self.fs_hz)
        nyq = 0.5 * self.fs_hz
        for name in ("align_order", "nav_order"):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= 1):
                raise ValueError(f"filter.{name}: must be an integer ≥ 1 (FIR order = taps − 1), "
                                 f"got {v!r}")
        for name in ("align_cutoff_hz", "nav_cutoff_hz"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0 < v < nyq):
                raise ValueError(f"filter.{name}: must be in (0, {nyq:g}) Hz (below the Nyquist "
                                 f"frequency fs_hz/2), got {v!r}")
        if self.notch_hz is not None and not (math.isfinite(self.notch_hz)
                                              and 0 < self.notch_hz < nyq):
            raise ValueError(f"filter.notch_hz: must be in (0, {nyq:g}) Hz (below the Nyquist "
                             f"frequency fs_hz/2) or null for no notch, got {self.notch_hz!r}")
        _positive("filter.notch_q", self.notch_q)
        if self.chain not in CHAINS:
            raise ValueError(f"filter.chain: must be one of {CHAINS}, got {self.chain!r}")


@dataclass(frozen=True, kw_only=True)
class SensorSettings:
    """The gyro channel along the turntable axis (spec 003 §4 [O] noise model; the seed
    gives no noise figures, so every default here is an assumption, stated in the results).

    Parameters
    ----------
    quantum : float, rad
        Angle per count ([O] 0.1″); counts carry their remainder, so the quantised angle
        stays within one quantum of the sensed angle. 0: no quantisation.
    arw : float, rad/√s
        Angle random walk (white rate noise), ≥ 0; default 0.0005 °/√h (a 1″-class ring
        laser gyro), a random walk of 0.1″ over a 12 s case.
    dither_amplitude : float, rad
        Peak of the mechanical dither seen in the sensed angle, ≥ 0 (0: none); default
        100″. A mechanically dithered RLG is what the notch is for, and the dither makes
        the quantisation error white (without it, 5 °/s is exactly 36 counts per sample and
        the quantisation error stands still).
    dither_hz : float, Hz
        Dither frequency (the notch is meant for it), > 0.
    """

    quantum: float = 0.1 * ARCSEC
    arw: float = 0.0005 * DEG / 60.0
    dither_amplitude: float = 100.0 * ARCSEC
    dither_hz: float = 400.0

    def __post_init__(self) -> None:
        _non_negative("sensor.quantum", self.quantum)
        _non_negative("sensor.arw", self.arw)
        _non_negative("sensor.dither_amplitude", self.dither_amplitude)
        _positive("sensor.dither_hz", self.dither_hz)


@dataclass(frozen=True, kw_only=True)
class PulseSettings:
    """External sync pulses (seed §2.2, Fig. 1).

    Parameters
    ----------
    mode : {"solution", "async"}
        ``solution``: a pulse at every ``solution_hz/rate_hz``-th solution instant, plus
        `offset_s` (the seed's semi-physical setting has offset 0, so Δt = 0);
        ``async``: a free-running pulse clock, first edge at `offset_s` (None: uniform
        random in [0, 1/rate_hz)), period ``(1 + drift_ppm·1e-6)/rate_hz``, Gaussian jitter.
    rate_hz : float, Hz
        Pulse rate f3 ≤ solution_hz.
    offset_s : float or None, s
        See `mode`; in ``solution`` mode it must be in [0, 1/solution_hz).
    jitter_s : float, s
        1σ of the edge-time jitter (async), ≥ 0.
    drift_ppm : float
        Rate error of the pulse clock against the INS clock (async).
    resolution_s : float, s
        Resolution of the FPGA counter that measures Δt (rounded to the nearest count); 0:
        exact.
    """

    mode: str = "solution"
    rate_hz: float = 1000.0
    offset_s: float | None = 0.0
    jitter_s: float = 0.0
    drift_ppm: float = 0.0
    resolution_s: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in PULSE_MODES:
            raise ValueError(f"pulses.mode: must be one of {PULSE_MODES}, got {self.mode!r}")
        _positive("pulses.rate_hz", self.rate_hz)
        if self.offset_s is not None:
            _non_negative("pulses.offset_s", self.offset_s)
        _non_negative("pulses.jitter_s", self.jitter_s)
        _non_negative("pulses.resolution_s", self.resolution_s)
        if not math.isfinite(self.drift_ppm) or abs(self.drift_ppm) >= 1e6:
            raise ValueError(f"pulses.drift_ppm: must be finite and in (−1e6, 1e6), "
                             f"got {self.drift_ppm!r}")


@dataclass(frozen=True, kw_only=True)
class TrackerSettings:
    """The per-axis Kalman tracker on [θ, ω, α] (seed §2.3.1; spec 003 §3).

    Parameters
    ----------
    qc : float, rad²/s⁵
        Intensity of the white jerk W driving α ([O] 1), > 0.
    r : float, rad²
        Variance of the attitude observation ([O] (0.03″)², the quantisation noise
        q²/12 of a 0.1″ quantum), > 0.
    sigma0 : (3,) float, (rad, rad/s, rad/s²)
        Initial standard deviations of θ, ω, α about ``[z_0, 0, 0]``, each > 0.
    """

    qc: float = 1.0
    r: float = (0.03 * ARCSEC) ** 2
    sigma0: tuple[float, float, float] = (0.03 * ARCSEC, 20.0 * DEG, 20.0 * DEG)

    def __post_init__(self) -> None:
        _positive("tracker.qc", self.qc)
        _positive("tracker.r", self.r)
        if len(self.sigma0) != 3:
            raise ValueError(f"tracker.sigma0: must have 3 entries (θ, ω, α), got {self.sigma0!r}")
        for v in self.sigma0:
            _positive("tracker.sigma0", v)


@dataclass(frozen=True, kw_only=True)
class Settings:
    """Everything a case needs besides its motion (spec 003 §1–§4).

    Parameters
    ----------
    solution_hz : float, Hz
        Attitude solution rate f2 (seed: 1 kHz); ``filter.fs_hz`` must be a whole multiple.
    delay_s : float or None, s
        T used by the predictors: None = the chain's low-frequency group delay; the seed
        uses 4 ms (its FIR alone).
    settle_s : float, s
        The start of a case excluded from the metrics (the table is at rest before t = 0;
        filter and tracker start there); a case lasts longer (its own duration).
    warmup_s : float, s
        The gyro channel and the filters run this long at rest before t = 0, so that they
        start in steady state with the dither and the noise (an INS aligned and running).
    corner_s : float, s
        Half-width of the windows around steps in α reported separately (spec 003 §4).
    chunk_s : float, s
        Length of the streamed blocks (memory does not grow with the run).
    predictors : tuple of str
        Predictors to run, from :data:`PREDICTORS`.
    """

    solution_hz: float = 1000.0
    filter: FilterSettings = field(default_factory=FilterSettings)
    sensor: SensorSettings = field(default_factory=SensorSettings)
    pulses: PulseSettings = field(default_factory=PulseSettings)
    tracker: TrackerSettings = field(default_factory=TrackerSettings)
    delay_s: float | None = None
    settle_s: float = 1.0
    warmup_s: float = 0.2
    corner_s: float = 0.05
    chunk_s: float = 1.0
    predictors: tuple[str, ...] = PREDICTORS

    def __post_init__(self) -> None:
        _positive("solution_hz", self.solution_hz)
        ratio = self.filter.fs_hz / self.solution_hz
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ValueError(f"filter.fs_hz: must be a whole multiple of solution_hz = "
                             f"{self.solution_hz:g} Hz, got {self.filter.fs_hz:g} Hz "
                             f"(ratio {ratio:g})")
        check_pulses(self.pulses, self.solution_hz)
        if self.delay_s is not None:
            _non_negative("delay_s", self.delay_s)
        _non_negative("settle_s", self.settle_s)
        _non_negative("warmup_s", self.warmup_s)
        _non_negative("corner_s", self.corner_s)
        _positive("chunk_s", self.chunk_s)
        bad = [p for p in self.predictors if p not in PREDICTORS]
        if bad or not self.predictors:
            raise ValueError(f"predictors: must be a non-empty selection of {PREDICTORS}, "
                             f"got {self.predictors!r}")

    @property
    def samples_per_solution(self) -> int:
        """Sensor samples per attitude solution, ``fs_hz / solution_hz`` (seed: 5)."""
        return round(self.filter.fs_hz / self.solution_hz)

    @property
    def tau(self) -> float:
        """Solution interval τ = 1/f2 (s)."""
        return 1.0 / self.solution_hz


def check_pulses(p: PulseSettings, solution_hz: float) -> None:
    """Checks of a pulse train against the solution rate (also for per-case overrides)."""
    if p.rate_hz > solution_hz * (1 + 1e-12):
        raise ValueError(f"pulses.rate_hz: must be ≤ solution_hz = {solution_hz:g} Hz (a pulse "
                         f"latches the latest solution), got {p.rate_hz:g}")
    if p.mode == "solution":
        m = solution_hz / p.rate_hz
        if abs(m - round(m)) > 1e-9:
            raise ValueError(f"pulses.rate_hz: must divide solution_hz = {solution_hz:g} Hz in "
                             f"mode 'solution' (pulses on solution instants), got "
                             f"{p.rate_hz:g}")
        if p.offset_s is None or not p.offset_s < 1.0 / solution_hz:
            raise ValueError(f"pulses.offset_s: must be in [0, {1.0 / solution_hz:g}) s in mode "
                             f"'solution', got {p.offset_s!r}")


def seed_semi_physical(settings: Settings | None = None) -> Settings:
    """The seed's semi-physical setting (§3.2): T fixed at 4 ms (n = 4), pulses on every
    solution instant (Δt = 0); everything else from `settings`."""
    s = settings or Settings()
    return replace(s, delay_s=4e-3, pulses=PulseSettings(mode="solution",
                                                         rate_hz=s.solution_hz, offset_s=0.0))
