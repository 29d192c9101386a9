"""The IMU error model, applied to ideal increments block by block (in the sensor frame).

Per axis: constant bias, white noise (ARW/VRW), scale factor (optionally different for
positive and negative input: asymmetric), non-orthogonality/misalignment, quantisation,
and the time-varying sensor processes of KF-GINS and PSINS: a bias that is a first-order
Gauss–Markov process (stationary std σ, correlation time τ) and/or a random walk (density
q), a scale factor that is a Gauss–Markov process. The measured increment is
``(I + diag(k) + M) Δ_ideal + b T + n`` with ``k = scale (+ scale process)`` or, with an
asymmetric part, ``+ asym·sign(Δ_ideal)``, ``b = bias (+ bias processes)``; a quantiser
keeps its remainder.

The processes are discretised exactly at the sample interval T: ``x_k = a x_{k−1} + s w_k``
with ``a = e^{−T/τ}``, ``s = σ √(1 − a²)`` (Gauss–Markov; started from its stationary
distribution N(0, σ²)) or ``a = 1``, ``s = q √T`` (random walk, started at zero); x_k is
the value during increment k.

Bias instability (flicker noise, PSD B²/(2πf), whose Allan deviation is flat at 0.664·B)
has no finite-state form; it is approximated by a sum of first-order Gauss–Markov processes
of equal std whose correlation times are spread over the decades of τ it must cover
(:func:`flicker_components`: two a decade, from two decades below the range to a decade
above it). The sum's Allan variance is the sum of theirs (:func:`gm_allan_variance`, closed
form, sampled as the simulator runs it); the common std puts the middle of its extremes
over the range at 0.664·B, and it stays within ±:data:`FLICKER_TOLERANCE` (in σ) of it
over the whole range. The range is ``instability_tau`` or, by default, 1 s (10 samples, if
longer) to the run's duration. Each process starts at zero: the turn-on bias is
``bias``'s, and the flicker wanders from it.

Random numbers: one seeded ``numpy.random.Generator`` per run. The gyro noise of all N
samples comes first in its stream, then the accelerometer noise (the layout of the
whole-run draw ``g = rng.normal((N, 3)); a = rng.normal((N, 3))``), so a run gives the
same numbers whatever its block size, and the same as before streaming existed. Each
sensor process draws from a child generator of its own (``rng.spawn``, which leaves `rng`
where it was): adding a process changes no other number of the run.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class SensorErrors:
    """Errors of one sensor triad (SI).

    bias : (3,) rad/s (gyro) or m/s² (accel).
    noise : (3,) white-noise density: ARW in rad/√s or VRW in m/s/√s; per-sample std of an
        increment is ``noise * sqrt(ts)``.
    scale : (3,) scale-factor errors (fraction).
    asym : (3,) asymmetric scale-factor errors (fraction): added for positive input,
        subtracted for negative input.
    misalignment : (3, 3) small-angle non-orthogonality; zero diagonal.
    quantum : increment quantisation step (rad or m/s); 0 disables it.
    bias_gm_std, bias_gm_tau : (3,) first-order Gauss–Markov bias: stationary std (rad/s or
        m/s²) and correlation time (s); std 0: none.
    bias_rw : (3,) bias random walk density (rad/s/√s or m/s²/√s): rate (acceleration)
        random walk; the bias's std grows as ``bias_rw · √t``.
    scale_gm_std, scale_gm_tau : (3,) Gauss–Markov scale-factor error (fraction) and its
        correlation time (s); std 0: none.
    instability : (3,) bias instability B (rad/s or m/s²): a flicker bias whose Allan
        deviation is flat at 0.664·B (module docstring); 0: none.
    instability_tau : (lo, hi) s, the τ range over which it is flat (lo ≥ 10 samples); None:
        :func:`default_instability_tau`.
    """

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    noise: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: np.ndarray = field(default_factory=lambda: np.zeros(3))
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    quantum: float = 0.0
    asym: np.ndarray = field(default_factory=lambda: np.zeros(3))
    bias_gm_std: np.ndarray = field(default_factory=lambda: np.zeros(3))
    bias_gm_tau: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    bias_rw: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale_gm_std: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale_gm_tau: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    instability: np.ndarray = field(default_factory=lambda: np.zeros(3))
    instability_tau: tuple[float, float] | None = None

    def matrix(self) -> np.ndarray:
        """``I + diag(scale) + misalignment``, shape (3, 3)."""
        return np.eye(3) + np.diag(self.scale) + self.misalignment

    @property
    def noisy(self) -> bool:
        return bool(np.any(np.asarray(self.noise) != 0))

    @property
    def varying(self) -> bool:
        """Whether a bias or scale-factor process is set (the errors change with time)."""
        return bool(np.any(np.asarray(self.bias_gm_std) != 0)
                    or np.any(np.asarray(self.bias_rw) != 0)
                    or np.any(np.asarray(self.scale_gm_std) != 0)
                    or np.any(np.asarray(self.instability) != 0))


def _coefficients(std: np.ndarray, tau: np.ndarray, ts: float) -> tuple[np.ndarray, np.ndarray]:
    """``(a, s)`` (3,) of the exact discretisation ``x_k = a x_{k−1} + s w_k`` of a
    first-order Gauss–Markov process of stationary std `std` and correlation time `tau`."""
    a = np.exp(-ts / np.asarray(tau, dtype=float))
    return a, np.asarray(std, dtype=float) * np.sqrt(1.0 - a * a)


#: √(2 ln2/π): the flat Allan deviation of flicker noise of bias instability B is FLAT·B
FLAT = float(np.sqrt(2.0 * np.log(2.0) / np.pi))
#: Correlation times a decade in the Gauss–Markov sum that stands for flicker noise
FLICKER_PER_DECADE = 2
#: Largest relative departure of the sum's Allan deviation from 0.664·B over its range
#: (sampled form: 0.4 % from 100 samples on, 1.2–1.8 % from 10 to 30 samples; tested)
FLICKER_TOLERANCE = 0.02


def default_instability_tau(ts: float, duration: float) -> tuple[float, float]:
    """The τ range (s) of a bias instability without ``instability_tau``: from 1 s (or 10
    samples, if longer) to the run's duration (at least ten times the start)."""
    lo = max(1.0, 10.0 * ts)
    return lo, max(duration, 10.0 * lo)


def gm_allan_variance(tau: np.ndarray, std: float, T: float,
                      ts: float | None = None) -> np.ndarray:
    """Allan variance at `tau` of a stationary first-order Gauss–Markov process of std `std`
    and correlation time `T`.

    Continuous (`ts` None; IEEE Std 952 C.1.6 with q_c² = 2σ²/T)::

        σ²(τ) = (2σ²T/τ) [1 − (T/2τ)(3 − 4e^{−τ/T} + e^{−2τ/T})]

    Sampled (`ts` given): the simulator's process, held during each increment,
    ``x_k = a x_{k−1} + s w_k`` with a = e^{−ts/T}; for clusters of m = τ/ts samples
    (S a cluster's sum, autocovariance σ² a^|n|)::

        σ²(τ) = (Var S − Cov(S_1, S_2)) / m²,
        Var S = σ² [m(1+a)/(1−a) − 2a(1−a^m)/(1−a)²],  Cov = σ² a(1−a^m)²/(1−a)²

    which the continuous form reaches only at τ ≫ ts (at τ = ts it is 1.5 times it for
    T ≫ ts). Beyond T = 1000·ts the two agree within 0.5 % from τ = 10 ts on, and the
    continuous one is used (the sampled one cancels there).
    """
    tau = np.asarray(tau, dtype=float)
    if ts is not None and T <= 1e3 * ts:
        m = np.maximum(np.round(tau / ts), 1.0)
        d = -np.expm1(-ts / T)  # 1 − a
        e = -np.expm1(-m * ts / T)  # 1 − a^m
        a = 1.0 - d
        v = (m * (1.0 + a) / d - 2.0 * a * e / d**2 - a * e**2 / d**2) / m**2
        return np.asarray(std**2 * v)
    x = tau / T
    with np.errstate(divide="ignore", invalid="ignore"):
        full = 2.0 / x * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x))
    # τ ≪ T: the bracket cancels; its series 2(x/3 − x²/4 + 7x³/60) (error ~x⁴)
    series = 2.0 * (x / 3.0 - x**2 / 4.0 + 7.0 * x**3 / 60.0)
    return np.asarray(std**2 * np.where(x < 1e-2, series, full))


def flicker_components(instability: np.ndarray, lo: float, hi: float, ts: float
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Correlation times (n,) s and stds (3, n) of the Gauss–Markov processes, sampled every
    `ts`, whose sum has an Allan deviation flat at FLAT·`instability` (3,) within
    ±FLICKER_TOLERANCE over τ in [`lo`, `hi`] (`lo` ≥ 10 `ts`; module docstring): two a
    decade from two decades below `lo` (the sum sags at its short end without them: 2 % at
    one decade), but none shorter than `ts` (white noise at the sample rate, not flicker), to
    a decade above `hi`; the common std sets the middle of the sum's extremes over the range
    (sampled form of :func:`gm_allan_variance`) at FLAT·B."""
    decades = np.log10(hi) - np.log10(lo) + 3.0
    n = int(np.ceil(decades * FLICKER_PER_DECADE - 1e-9)) + 1
    times = lo / 100.0 * 10.0 ** (np.arange(n) / FLICKER_PER_DECADE)
    times = times[times >= ts * (1 - 1e-9)]
    tau = np.geomspace(lo, hi, 256)
    unit = np.sqrt(sum(gm_allan_variance(tau, 1.0, T, ts) for T in times))  # std 1 each
    middle = float(np.sqrt(unit.min() * unit.max()))
    std = FLAT * np.asarray(instability, float)[:, None] / middle
    return times, np.broadcast_to(std, (3, len(times))).copy()


class _Recursion:
    """One process ``x_k = a x_{k−1} + s w_k`` per axis across blocks, from its own
    generator; `x` is the value before the next sample."""

    def __init__(self, a: np.ndarray, s: np.ndarray, x0: np.ndarray,
                 rng: np.random.Generator):
        self.a, self.s, self.x, self.rng = a, s, x0, rng

    def next(self, n: int) -> np.ndarray:
        """The values during the next `n` samples (n, 3)."""
        from scipy.signal import lfilter  # only where a process runs (start-up)

        drive = self.rng.standard_normal((n, 3)) * self.s
        out = np.empty((n, 3))
        for i in range(3):
            out[:, i], zf = lfilter([1.0], [1.0, -self.a[i]], drive[:, i],
                                    zi=[self.a[i] * self.x[i]])
        self.x = out[-1].copy() if n else self.x
        return out


class _Processes:
    """The time-varying bias and scale factor of one triad (module docstring)."""

    def __init__(self, err: SensorErrors, ts: float, rng: np.random.Generator,
                 duration: float = np.inf):
        g_bias, g_rw, g_scale, g_flicker = rng.spawn(4)  # the first three as spawn(3)
        self.parts: list[tuple[str, _Recursion]] = []
        if np.any(np.asarray(err.bias_gm_std) != 0):
            a, s = _coefficients(err.bias_gm_std, err.bias_gm_tau, ts)
            x0 = np.asarray(err.bias_gm_std, float) * g_bias.standard_normal(3)
            self.parts.append(("bias", _Recursion(a, s, x0, g_bias)))
        if np.any(np.asarray(err.bias_rw) != 0):
            self.parts.append(("bias", _Recursion(np.ones(3), np.asarray(err.bias_rw, float)
                                                  * np.sqrt(ts), np.zeros(3), g_rw)))
        if np.any(np.asarray(err.scale_gm_std) != 0):
            a, s = _coefficients(err.scale_gm_std, err.scale_gm_tau, ts)
            x0 = np.asarray(err.scale_gm_std, float) * g_scale.standard_normal(3)
            self.parts.append(("scale", _Recursion(a, s, x0, g_scale)))
        if np.any(np.asarray(err.instability) != 0):
            lo, hi = err.instability_tau or default_instability_tau(ts, duration)
            times, stds = flicker_components(err.instability, lo, hi, ts)
            for T, s_T, g in zip(times, stds.T, g_flicker.spawn(len(times)), strict=True):
                a, s = _coefficients(s_T, np.full(3, T), ts)
                self.parts.append(("bias", _Recursion(a, s, np.zeros(3), g)))

    def next(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Bias (n, 3) and scale-factor error (n, 3) of the processes during the next n
        samples (without the constant parts)."""
        bias, scale = np.zeros((n, 3)), np.zeros((n, 3))
        for kind, rec in self.parts:
            (bias if kind == "bias" else scale)[:] += rec.next(n)
        return bias, scale


@dataclass(frozen=True)
class ImuErrors:
    gyro: SensorErrors = field(default_factory=SensorErrors)
    accel: SensorErrors = field(default_factory=SensorErrors)


class _Channel:
    """One triad's error state across blocks: its noise stream and quantiser remainder."""

    def __init__(self, err: SensorErrors, ts: float, rng: np.random.Generator | None,
                 process_rng: np.random.Generator | None = None, duration: float = np.inf):
        self.err, self.ts, self.rng = err, ts, rng
        self.M = err.matrix().T
        self.unit = bool(np.all(self.M == np.eye(3)))  # no scale factor or misalignment
        self.bias_ts = np.asarray(err.bias, dtype=float) * ts
        self.asym = np.asarray(err.asym, dtype=float) if np.any(np.asarray(err.asym) != 0) \
            else None
        self.sigma = np.asarray(err.noise, dtype=float) * np.sqrt(ts)
        self.running = np.zeros(3)  # unquantised running sum
        self.total = np.zeros(3)  # quantised running sum already output
        self.processes = None if process_rng is None else _Processes(err, ts, process_rng,
                                                                      duration)
        #: the processes' values of the last block, (bias (n, 3), scale (n, 3)), or None
        self.last: tuple[np.ndarray, np.ndarray] | None = None

    def apply(self, ideal: np.ndarray) -> np.ndarray:
        from gcalign.sim import _noise

        err = self.err
        triad = ideal.ndim == 2 and ideal.shape[1] == 3 and ideal.dtype == np.float64
        if (self.rng is not None and triad and self.unit and self.asym is None
                and self.processes is None):  # the common case in one loop, same numbers
            out = _noise.noisy_sum(ideal, self.bias_ts, self.rng, self.sigma)
        else:
            out = ideal + self.bias_ts if self.unit else ideal @ self.M + self.bias_ts
            if self.asym is not None:
                out += self.asym * np.abs(ideal)
            if self.processes is not None:
                bias, scale = self.last = self.processes.next(len(ideal))
                out += bias * self.ts + scale * ideal
            if self.rng is not None:
                if triad:  # rng.standard_normal(shape) · sigma added, without the array
                    _noise.add_noise(out, self.rng, self.sigma)
                else:
                    noise = self.rng.standard_normal(ideal.shape)
                    noise *= self.sigma  # in place: one block-sized temporary fewer
                    out += noise
        if err.quantum > 0:
            # Quantise the running sum, then difference it (the remainder is kept).
            run = np.cumsum(np.concatenate([self.running[None], out]), axis=0)[1:]
            q = np.round(run / err.quantum) * err.quantum
            out = np.diff(np.concatenate([self.total[None], q]), axis=0)
            self.running, self.total = run[-1].copy(), q[-1].copy()
        return out


class ErrorStream:
    """Applies :class:`ImuErrors` to consecutive blocks of ideal increments.

    `samples` is the run's total length N: the accelerometer noise stream starts after
    the 3N gyro normals of `rng` (see the module docstring). It is positioned at the first
    block. `private`: nothing else draws from `rng` afterwards, so if the gyro has drawn all
    3N by then (the whole run in one block), the accelerometer continues the gyro's
    generator instead of skipping 3N normals on a copy of it (same numbers; a caller's
    generator otherwise ends where the gyro left it).
    """

    def __init__(self, errors: ImuErrors, ts: float, rng: np.random.Generator, samples: int,
                 private: bool = False):
        g_rng = rng if errors.gyro.noisy else None
        self._samples, self._private = samples, private
        # the generator at the start of the run, for the accelerometer to skip from
        self._a_start = None if not errors.accel.noisy else (
            copy.deepcopy(rng) if g_rng is not None else rng)
        self._g_drawn = 0  # gyro normals drawn so far
        varying = errors.gyro.varying or errors.accel.varying
        g_proc, a_proc = rng.spawn(2) if varying else (None, None)
        run = samples * ts  # the default τ range of a bias instability ends here
        self.gyro = _Channel(errors.gyro, ts, g_rng, g_proc if errors.gyro.varying else None,
                             run)
        self.accel = _Channel(errors.accel, ts, None, a_proc if errors.accel.varying else None,
                              run)

    def _accel_rng(self) -> np.random.Generator:
        """The accelerometer's generator, 3N normals after the start of the run."""
        assert self._a_start is not None
        if self._private and self.gyro.rng is not None and self._g_drawn == 3 * self._samples:
            return self.gyro.rng  # the gyro's draws were the skip; it draws no more
        a_rng, left = self._a_start, 3 * self._samples
        from gcalign.sim import _noise

        _noise.skip_normals(a_rng, left)  # skip the gyro part of the stream
        return a_rng

    def apply(self, dtheta: np.ndarray, dv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured (dtheta, dv) of the next block."""
        gyro = self.gyro.apply(dtheta)
        if self.gyro.rng is not None:
            self._g_drawn += dtheta.size
        if self._a_start is not None:
            self.accel.rng, self._a_start = self._accel_rng(), None
        return gyro, self.accel.apply(dv)
