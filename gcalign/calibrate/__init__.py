"""In-flight self-calibration of an airborne SINS (seed 002; ``specs/002-inflight-calibration.md``).

A 21-state φ-angle Kalman filter (attitude, velocity and position errors, gyro and
accelerometer biases and diagonal scale factors) aided by differential GNSS velocity,
position or both, on a navigation run at 25 Hz with 1 Hz filter steps; closed-loop
feedback; NEES/NIS against the truth; an optional RTS smoother; and the PWCS + SVD
observability table of the seed's §3–4.

Modules
-------
- :mod:`gcalign.calibrate.data` -- inputs as plain arrays (:class:`FlightData`,
  :class:`Trajectory`, :class:`Span`) from a motion's truth and ideal increments with the
  injected errors (navigation increments combined from IMU ones), recorded data of a
  parked vehicle (:func:`parked_data`, zero-velocity aiding).
- :mod:`gcalign.calibrate.filter` -- :func:`calibrate`, :func:`covariance_run` (the RTS
  smoother is :func:`gcalign.estimation.kalman.rts`).
- :mod:`gcalign.calibrate.observability` -- :func:`observability` (settings
  :class:`ObservabilitySettings`), :func:`observability_table`.

The error model is :mod:`gcalign.estimation.ins_error`, the Kalman steps
:mod:`gcalign.estimation.kalman`, the PWCS/SVD algebra :mod:`gcalign.estimation.observability`.
"""

from gcalign.calibrate.data import (
    FlightData,
    Span,
    Trajectory,
    combine_increments,
    draw_truth,
    flight_from_ideal,
    imu_errors,
    motion_spans,
    parked_data,
    perturb,
    proposed_truth,
    sampled_truth,
    trajectory,
    white_noise,
    zero_velocity_aiding,
    zero_velocity_data,
)
from gcalign.calibrate.filter import (
    CalibrationResult,
    CovarianceRun,
    Settings,
    calibrate,
    covariance_run,
)
from gcalign.calibrate.observability import (
    ObservabilitySettings,
    ObservabilityTable,
    observability,
    observability_table,
)

__all__ = [
    "CalibrationResult", "CovarianceRun", "FlightData", "ObservabilitySettings",
    "ObservabilityTable", "Settings", "Span", "Trajectory", "calibrate", "combine_increments",
    "covariance_run", "draw_truth", "flight_from_ideal", "imu_errors", "motion_spans",
    "observability", "observability_table", "parked_data", "perturb", "proposed_truth",
    "sampled_truth", "trajectory", "white_noise", "zero_velocity_aiding", "zero_velocity_data",
]
