"""Recorded data of any source, read into gcalign's conventions with a record of what was
assumed (spec 005): IMU recordings (:mod:`.imu`), declared body axes (:mod:`.axes`).

Capabilities never see a file format: these readers return arrays in SI, body x right,
y forward, z up, ENU, time in seconds, and say what they assumed.
"""

from gcalign.io.recorded.axes import AXES_HELP, rotation_to_rfu
from gcalign.io.recorded.imu import FORMATS, Layout, read_recording

__all__ = ["AXES_HELP", "FORMATS", "Layout", "read_recording", "rotation_to_rfu"]
