"""Recorded data of any source, read into gcalign's conventions with a record of what was
assumed (spec 005): IMU recordings of several layouts (:mod:`.imu`), declared body axes
(:mod:`.axes`), aiding files -- GNSS positions, velocities, odometer speed
(:mod:`.aiding`) -- and reference solutions with the initial state (:mod:`.reference`).

Capabilities never see a file format: these readers return arrays in SI, body x right,
y forward, z up, ENU, time in seconds, and say what they assumed.
"""

from gcalign.io.recorded.aiding import (
    PositionFixes,
    Velocities,
    overlap,
    read_gnss,
    read_odometer,
    read_velocity,
)
from gcalign.io.recorded.axes import AXES_HELP, rotation_to_rfu
from gcalign.io.recorded.imu import FORMATS, Layout, read_recording
from gcalign.io.recorded.reference import (
    Reference,
    initial_state,
    read_reference,
    reference_at,
)

__all__ = [
    "AXES_HELP", "FORMATS", "Layout", "PositionFixes", "Reference", "Velocities",
    "initial_state", "overlap", "read_gnss", "read_odometer", "read_recording",
    "read_reference", "read_velocity", "reference_at", "rotation_to_rfu",
]
