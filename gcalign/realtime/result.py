"""What a realtime case keeps (:class:`CaseResult`, its per-pulse records, each field saying
how it is stored: :mod:`gcalign.schema`) and its 1 kHz series (:class:`Series`); apart from
the chain that computes them (:mod:`gcalign.realtime.chain`), so that a results file read
back loads no kernel."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from gcalign.nav.rotation import wrap_pi
from gcalign.realtime.pulses import Pulses
from gcalign.schema import ATT_FRAME, stored

if TYPE_CHECKING:
    from gcalign.nav.earth import EarthModel
    from gcalign.realtime.cases import Case
    from gcalign.realtime.settings import Settings

METRICS = ("truth", "seed")  #: error references: θ(t_p), and the INS's output at t_p + T


@dataclass(frozen=True)
class Series:
    """The 1 kHz series of a run (only with ``keep_series``): t (K,) s; q_nb (K, 4) INS
    attitude; att (K, 3) INS [pitch, roll, yaw] unwrapped (rad); x (K, 3, 3) tracker states
    per axis [θ, ω, α]."""

    t: np.ndarray
    q_nb: np.ndarray
    att: np.ndarray
    x: np.ndarray


@dataclass(frozen=True)
class CaseResult:
    """Everything stored per pulse for one case (SI, rad; Euler ``[pitch, roll, yaw]``).

    Attributes
    ----------
    case, settings
    site : (3,) ``[lat, lon, h]`` (rad, rad, m); earth : the earth model.
    chain_delay : float, s
        Low-frequency group delay of the filter chain (the true T of the data).
    delay : float, s
        T the predictors use (``settings.delay_s``, or `chain_delay`).
    pulses : Pulses
        Edge times, latched solution index k, Δt (true and as measured).
    t_update : (P,) s
        ``kτ``, when the latched attitude was updated.
    t_valid : (P,) s
        Time of validity of the latched attitude, ``kτ − T``; that of a prediction is the
        pulse time itself (``pulses.t``).
    latched : (P, 3)
        The latched INS attitude (unwrapped).
    predicted : dict of (P, 3)
        Prediction to the pulse time per predictor (extrapolated outputs; unwrapped).
    truth : (P, 3)
        True attitude at the pulse time.
    ins_ref : (P, 3)
        The seed's reference: the INS's own output at ``t_p + T`` (cubic interpolation of
        the 1 kHz solutions; exact on the solution instants).
    series : Series or None
    """

    case: Case
    settings: Settings
    site: np.ndarray
    earth: EarthModel
    chain_delay: float
    delay: float
    pulses: Pulses = field(metadata=stored(None, inline=True))
    t_update: np.ndarray
    t_valid: np.ndarray = field(metadata=stored(
        "s", frame="time of validity of the latched attitude", compress=True, dims="P",
        optional=True))
    latched: np.ndarray = field(metadata=stored("rad", frame=ATT_FRAME + "; unwrapped",
                                                compress=True, dims="P 3"))
    predicted: dict[str, np.ndarray] = field(metadata=stored(
        "rad", frame=ATT_FRAME + "; at the pulse time (extrapolated)", compress=True,
        dims="P 3"))
    truth: np.ndarray = field(metadata=stored("rad", frame=ATT_FRAME + "; at the pulse time",
                                              compress=True, dims="P 3"))
    ins_ref: np.ndarray = field(metadata=stored(
        "rad", frame=ATT_FRAME + "; the INS's output T after the pulse (the seed's reference)",
        compress=True, dims="P 3"))
    series: Series | None = None

    def error(self, predictor: str, metric: str = "truth") -> np.ndarray:
        """Prediction error (P, 3) (rad, wrapped to ±π) of `predictor` against ``truth``
        (θ(t_p)) or ``seed`` (the INS's output T later, the seed's semi-physical metric)."""
        if metric not in METRICS:
            raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
        ref = self.truth if metric == "truth" else self.ins_ref
        # ``none`` is the latched attitude, there whichever predictors ran
        pred = self.latched if predictor == "none" else self.predicted[predictor]
        return wrap_pi(pred - ref)

    @property
    def component(self) -> int:
        """Euler component that the turn moves (see :attr:`Case.component`)."""
        return self.case.component
