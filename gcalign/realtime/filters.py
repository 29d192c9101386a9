"""The composite digital filter of seed 003 §2 (spec 003 §2): design, group delay, streaming.

Sensor increments at ``Fs`` = 5 kHz pass, during alignment, a linear-phase FIR low-pass of
*order* 180 (181 taps); in navigation an IIR notch at the gyro dither frequency, then a FIR
low-pass of order 40 (41 taps). Seed eq. (1): a linear-phase FIR of order N delays by
``T = N / (2 Fs)`` — 18 ms and 4 ms. The notch "introduces almost no phase delay" [P]; its
low-frequency group delay is ``1 − (a1 + 2 a2)/(1 + a1 + a2)`` samples (derivation in
:func:`notch_dc_delay`), ≈ ``1/(2π f0 Q)`` s: 40.6 µs for 400 Hz, Q = 10 [O], which at
20 °/s is 2.9″ — not negligible at the arc-second level, so the default delay T used by
the predictors is the chain's real low-frequency group delay (:attr:`FilterChain.delay`).

The cut-off frequencies, window, notch frequency and Q are not in the seed: they are
settings (:class:`gcalign.realtime.settings.FilterSettings`) with the spec's [O] defaults.

Streaming: :meth:`FilterChain.apply` filters one chunk and returns the carried state
(the notch's ``lfilter`` ``zi``, the FIR's last N inputs), so a long run is filtered in
pieces with the same numbers as in one piece (tested).

>>> from gcalign.realtime.settings import FilterSettings
>>> nav = navigation_chain(FilterSettings())
>>> round(nav.fir_delay * 1e3, 9), round(nav.notch_delay * 1e6, 2), round(nav.delay * 1e3, 4)
(4.0, 40.65, 4.0406)
>>> round(alignment_chain(FilterSettings()).delay * 1e3, 9)
18.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from gcalign.realtime.settings import FilterSettings
from gcalign.schema import stored

__all__ = [
    "ChainResponse",
    "ChainState",
    "FilterChain",
    "alignment_chain",
    "design_fir",
    "design_notch",
    "fir_ops_per_sample",
    "first_moment",
    "navigation_chain",
    "notch_dc_delay",
]

#: FIRs of more taps than this are applied through FFTs (the seed's 41 and 181 directly)
DIRECT_TAPS = 1024


def fir_ops_per_sample(taps: float, chunk: float) -> float:
    """Operations per sample and channel of an FIR as :meth:`FilterChain.apply` runs it on
    chunks of `chunk` samples: the taps of a direct convolution, or, above ``DIRECT_TAPS``,
    three FFTs of the chunk with its carried inputs (about 5 N log2 N each, N = chunk + 2
    taps) spread over the chunk's samples."""
    if taps <= DIRECT_TAPS:
        return taps
    N = chunk + 2.0 * taps
    return 15.0 * N * math.log2(N) / max(chunk, 1.0)


def _signal() -> ModuleType:
    """scipy.signal, imported when a filter is designed or run (not at start-up)."""
    from scipy import signal

    return signal


def design_fir(order: int, cutoff_hz: float, fs: float, window: str = "hamming") -> np.ndarray:
    """Linear-phase FIR low-pass of `order` N (N + 1 taps), unit DC gain (``Σh = 1``).

    ``scipy.signal.firwin(N + 1, cutoff, window, fs)`` (windowed sinc; scaled so the DC
    gain is 1, which a rate or an increment stream needs to keep its mean). Shape (N + 1,).
    """
    h = _signal().firwin(order + 1, cutoff_hz, window=window, fs=fs)
    return h / h.sum()


def design_notch(f0_hz: float, q: float, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Second-order IIR notch at `f0_hz` with quality factor `q` (``scipy.signal.iirnotch``).

    Returns ``(b, a)``, each shape (3,); ``b = g [1, −2 cos w0, 1]``, ``a = [1, a1, a2]``,
    unit gain at DC.
    """
    b, a = _signal().iirnotch(f0_hz, q, fs=fs)
    return np.asarray(b, dtype=float), np.asarray(a, dtype=float)


def first_moment(h: np.ndarray) -> float:
    """Centre of mass ``Σ k h_k / Σ h_k`` of a FIR (samples): its exact DC group delay, and
    its group delay at every frequency when ``h`` is symmetric (= N/2)."""
    h = np.asarray(h, dtype=float)
    return float(np.arange(len(h)) @ h / h.sum())


def notch_dc_delay(b: np.ndarray, a: np.ndarray) -> float:
    """Low-frequency group delay of ``H = B(z⁻¹)/A(z⁻¹)`` (samples), in closed form.

    The group delay of a polynomial ``P(z⁻¹) = Σ p_k z⁻ᵏ`` at ω → 0 is its first moment
    ``Σ k p_k / Σ p_k``, and that of a ratio is the difference. ``b`` of a notch is
    symmetric (moment 1) and ``a = [1, a1, a2]`` has moment ``(a1 + 2 a2)/(1 + a1 + a2)``,
    so ``τ(0) = 1 − (a1 + 2 a2)/(1 + a1 + a2)`` (spec 003 §2, test 2).
    """
    return first_moment(b) - first_moment(a)


@dataclass(frozen=True)
class ChainState:
    """Carried filter state between chunks: notch ``zi`` (2, m) or None; the FIR's last N
    inputs (N, m), oldest first."""

    notch: np.ndarray | None
    fir: np.ndarray


#: frequency step of :meth:`FilterChain.on_grid` (Hz); the grid is a quarter step off the
#: notch's zero, where the group delay is singular
GRID_STEP_HZ = 0.5


@dataclass(frozen=True)
class ChainResponse:
    """A chain's taps and its response on a frequency grid (:meth:`FilterChain.on_grid`), as
    the results file keeps them; the notch's parts are None without a notch."""

    fs: float = field(metadata=stored("Hz", attr=True))
    fir_delay: float = field(metadata=stored("s", attr=True))
    notch_delay: float = field(metadata=stored("s", attr=True))
    delay: float = field(metadata=stored("s", attr=True))
    order: int = field(metadata=stored("1", attr=True))
    h: np.ndarray = field(metadata=stored("1", description="FIR taps, sum 1", dims="H",
                                          optional=True))
    freq: np.ndarray = field(metadata=stored("Hz", dims="F", rule="increasing"))
    magnitude: np.ndarray = field(metadata=stored("1", description="|H| of the chain",
                                                  dims="F"))
    magnitude_fir: np.ndarray = field(metadata=stored("1", dims="F"))
    notch_b: np.ndarray | None = field(metadata=stored("1", dims="3", optional=True))
    notch_a: np.ndarray | None = field(metadata=stored("1", dims="3", optional=True))
    magnitude_notch: np.ndarray | None = field(metadata=stored("1", dims="F", optional=True))
    group_delay: np.ndarray = field(metadata=stored("s", dims="F"))


@dataclass(frozen=True)
class FilterChain:
    """A notch (optional) followed by a linear-phase FIR, at the sample rate `fs` (Hz).

    Attributes
    ----------
    fs : float, Hz
    h : (N + 1,) float
        FIR taps, ``Σh = 1``.
    notch_ba : tuple of (3,) arrays, or None
        ``(b, a)`` of the notch.
    """

    fs: float
    h: np.ndarray
    notch_ba: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def order(self) -> int:
        """FIR order N (taps − 1)."""
        return len(self.h) - 1

    @property
    def fir_delay(self) -> float:
        """FIR group delay ``N / (2 Fs)`` (s), seed eq. (1), from the taps' first moment."""
        return first_moment(self.h) / self.fs

    @property
    def notch_delay(self) -> float:
        """Notch low-frequency group delay (s); 0 without a notch."""
        if self.notch_ba is None:
            return 0.0
        return notch_dc_delay(*self.notch_ba) / self.fs

    @property
    def delay(self) -> float:
        """Low-frequency group delay of the whole chain (s): the T of spec 003 §1."""
        return self.fir_delay + self.notch_delay

    def group_delay(self, freqs_hz: np.ndarray) -> np.ndarray:
        """Group delay of the chain (s) at `freqs_hz` (``scipy.signal.group_delay``), (F,)."""
        f = np.asarray(freqs_hz, dtype=float)
        _, gd = _signal().group_delay((self.h, [1.0]), w=f, fs=self.fs)
        if self.notch_ba is not None:
            gd = gd + _signal().group_delay(self.notch_ba, w=f, fs=self.fs)[1]
        return gd / self.fs

    def on_grid(self, step: float = GRID_STEP_HZ) -> ChainResponse:
        """The taps and the magnitude (chain, FIR, notch) and group delay of the chain at
        ``(k + 1/4) step`` Hz up to the Nyquist frequency."""
        freq = (np.arange(int(self.fs / 2 / step)) + 0.25) * step
        b, a = (None, None) if self.notch_ba is None else self.notch_ba
        return ChainResponse(
            self.fs, self.fir_delay, self.notch_delay, self.delay, self.order, self.h, freq,
            np.abs(self.response(freq)), np.abs(FilterChain(self.fs, self.h).response(freq)),
            b, a, None if self.notch_ba is None else  # the notch alone
            np.abs(FilterChain(self.fs, np.ones(1), self.notch_ba).response(freq)),
            self.group_delay(freq))

    def response(self, freqs_hz: np.ndarray) -> np.ndarray:
        """Complex frequency response of the chain at `freqs_hz`, (F,)."""
        f = np.asarray(freqs_hz, dtype=float)
        H = _signal().freqz(self.h, [1.0], worN=f, fs=self.fs)[1]
        if self.notch_ba is not None:
            H = H * _signal().freqz(*self.notch_ba, worN=f, fs=self.fs)[1]
        return H

    def initial_state(self, channels: int = 1, x0: float | np.ndarray = 0.0) -> ChainState:
        """State of a chain that has seen the constant input `x0` forever (zero: at rest).

        ``lfilter_zi`` is the steady state for a unit step; each stage's input is the
        previous stage's output, which for a constant equals it (unit DC gains).
        """
        x0 = np.broadcast_to(np.asarray(x0, dtype=float), (channels,))
        notch = None
        if self.notch_ba is not None:
            notch = _signal().lfilter_zi(*self.notch_ba)[:, None] * x0[None, :]
        return ChainState(notch=notch, fir=np.tile(x0, (self.order, 1)))

    def apply(self, x: np.ndarray, state: ChainState) -> tuple[np.ndarray, ChainState]:
        """Filter one chunk `x` (n, m) along axis 0 from `state`; returns ``(y, new_state)``."""
        x = np.asarray(x, dtype=float)
        zn = state.notch
        if self.notch_ba is not None:
            x, zn = _signal().lfilter(*self.notch_ba, x, axis=0, zi=zn)
        # FIR y_i = Σ_k h_k x_{i−k} over the carried inputs and this chunk (direct
        # convolution per channel: lfilter's FIR path loops over channels in Python); a long
        # FIR through FFTs, the same sums to round-off (60000 taps took minutes directly)
        buf = np.concatenate([state.fir, x])
        if len(self.h) > DIRECT_TAPS:
            y = _signal().fftconvolve(buf, self.h[:, None], mode="valid", axes=0)
            return y, ChainState(notch=zn, fir=buf[len(buf) - self.order:])
        y = np.empty_like(x)
        for j in range(x.shape[1]):
            y[:, j] = np.convolve(buf[:, j], self.h, mode="valid")
        return y, ChainState(notch=zn, fir=buf[len(buf) - self.order:])


def navigation_chain(fs: FilterSettings) -> FilterChain:
    """Navigation chain: notch at ``notch_hz`` (Q ``notch_q``; none if ``notch_hz`` is None),
    then the FIR of order ``nav_order`` at ``nav_cutoff_hz`` (seed §2: 40, spec [O] 200 Hz)."""
    notch = None if fs.notch_hz is None else design_notch(fs.notch_hz, fs.notch_q, fs.fs_hz)
    return FilterChain(fs.fs_hz, design_fir(fs.nav_order, fs.nav_cutoff_hz, fs.fs_hz,
                                            fs.window), notch)


def alignment_chain(fs: FilterSettings) -> FilterChain:
    """Alignment chain: the FIR of order ``align_order`` at ``align_cutoff_hz`` (seed §2: 180,
    spec [O] 100 Hz), no notch."""
    return FilterChain(fs.fs_hz, design_fir(fs.align_order, fs.align_cutoff_hz, fs.fs_hz,
                                            fs.window))
