"""Transfer alignment: a slave IMU aligned and calibrated against a master INS on a moving
vehicle (``specs/006-transfer-alignment.md``; PSINS demo ``test_align_transfer_fog_mems``).

On arrays: :func:`transfer_align` takes the slave's increments, their times and the master's
solution (:class:`MasterSeries`) with :class:`TransferSettings`, and returns a
:class:`TransferResult` of per-epoch estimates and σ (φ, δv, ε, ∇, μ and optionally the
flexure θ, ω). :mod:`gcalign.transfer.simulate` builds a case with the truth known.
"""

from gcalign.transfer.filter import (
    MATCHINGS,
    MasterSeries,
    TransferResult,
    TransferSettings,
    attitude_error_vs,
    convergence_times,
    transfer_align,
)

__all__ = ["MATCHINGS", "MasterSeries", "TransferResult", "TransferSettings",
           "attitude_error_vs", "convergence_times", "transfer_align"]
