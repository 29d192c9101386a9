"""Physical bounds of scenario values, each stated once with its reason.

Outside them a value is not something an instrument, a vehicle or an aiding source can
present, and the numbers computed from it look like results while meaning nothing: a rate
of 1e9 °/s turns 556 times between two 5 kHz samples and aliases (the realtime table
showed 144000″ beside a closed form of 1.44e10″); a DGNSS σ of 1e-300 m/s squares to zero
in R = σ² and the filter divides by round-off (a NEES mean of 2.9e9). Each bound is a
validator in a field's type (``Annotated[float, RATE_DPS]``) whose refusal names the
allowed range and why: ``calibrate.sigma_v_mps: must be within [0.001, 1000] m/s (...),
got 1e-300``.

Rates are bounded by what a strapdown gyro measures, sensor errors by what the worst
sensor shows (with margin), standard deviations from below by the best instrument (a
DGNSS velocity σ of 1 mm/s) and from above by "no information". The filter itself stays
consistent far below the floors (calibrate's NEES mean 15 at σ_v = 1e-9 m/s) and fails
only where σ² underflows (σ < 1e-154): the floors are physics, with float64 to spare.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pydantic import GetCoreSchemaHandler
from pydantic_core import CoreSchema, core_schema


def _g(x: float) -> str:
    return f"{x:g}"


@dataclass(frozen=True)
class Bound:
    """``lo ≤ x ≤ hi`` (``−hi ≤ x ≤ hi`` with `magnitude`) in `unit`; `why` is the reason the
    refusal gives. Called on a number, a list of numbers or None (left alone)."""

    lo: float
    hi: float
    unit: str
    why: str
    magnitude: bool = False

    def range(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        if self.magnitude:
            return f"[{_g(-self.hi)}, {_g(self.hi)}]{unit}"
        return f"[{_g(self.lo)}, {_g(self.hi)}]{unit}"

    def holds(self, x: float) -> bool:
        return abs(x) <= self.hi if self.magnitude else self.lo <= x <= self.hi

    def __get_pydantic_core_schema__(self, source: Any,
                                     handler: GetCoreSchemaHandler) -> CoreSchema:
        """Validate the type first, then the bound (pydantic's after-validator)."""
        return core_schema.no_info_after_validator_function(self, handler(source))

    def __call__(self, value: Any) -> Any:
        values = value if isinstance(value, list) else [value]
        for x in values:
            if isinstance(x, (int, float)) and math.isfinite(x) and not self.holds(x):
                raise ValueError(f"must be within {self.range()} ({self.why}), got {_g(x)}")
        return value


# ----------------------------------------------------------------------- motion

RATE_DPS = Bound(0.0, 3600.0, "°/s", "10 turns/s, beyond the input range of any strapdown "
                 "gyro: navigation grade ±400 … ±1000 °/s, MEMS to ±2000 °/s", magnitude=True)
ANGULAR_ACCEL_DPS2 = Bound(0.0, 1e5, "°/s²", "the largest rate within 36 ms; no turntable, "
                           "mechanism or vehicle turns faster", magnitude=True)
ANGULAR_JERK_DPS3 = Bound(0.0, 1e8, "°/s³", "the largest angular acceleration within 1 ms",
                          magnitude=True)
ACCEL_MPS2 = Bound(0.0, 1000.0, "m/s²", "about 100 g, beyond any navigating vehicle",
                   magnitude=True)

# ----------------------------------------------------------------------- sensor errors

GYRO_BIAS_DPH = Bound(0.0, 3.6e4, "°/h", "10 °/s, more than the bias of any gyro (MEMS "
                      "≤ ±5 °/s)", magnitude=True)
ACCEL_BIAS_UG = Bound(0.0, 1e5, "µg", "0.1 g, more than the bias of any accelerometer "
                      "(MEMS ≤ ±60 mg)", magnitude=True)
SCALE_PPM = Bound(0.0, 1e5, "ppm", "10 %, more than the scale-factor error of any sensor",
                  magnitude=True)
ARW_DPRH = Bound(0.0, 10.0, "°/√h", "more than the angle random walk of any gyro "
                 "(consumer MEMS 0.1 … 1 °/√h)")
VRW_UGRHZ = Bound(0.0, 1e4, "µg/√Hz", "more than the noise of any accelerometer "
                  "(consumer MEMS 100 … 300 µg/√Hz)")
GYRO_BIAS_RW_DPHRH = Bound(0.0, 3.6e4, "°/h/√h", "a bias wandering by 10 °/s in an hour, "
                           "beyond any gyro's rate random walk")
ACCEL_BIAS_RW_UGRH = Bound(0.0, 1e5, "µg/√h", "a bias wandering by 0.1 g in an hour, beyond "
                           "any accelerometer's random walk")
CORRELATION_TIME_S = Bound(1e-3, 1e9, "s", "from a millisecond (white noise at any IMU rate) to "
                           "30 years (a constant)")
SENSOR_RATE_HZ = Bound(0.0, 1e6, "Hz", "1 MHz, beyond the output rate of any IMU")

# ----------------------------------------------------------------------- filters

_FLOOR = "no instrument or prior knows it better; σ → 0 makes the covariance singular"
SIGMA_V_MPS = Bound(1e-3, 1e3, "m/s", "from the 1 mm/s of carrier-phase velocity, the best a "
                    "receiver gives, to no information")
SIGMA_P_M = Bound(1e-3, 1e6, "m", "from the 1 mm of a survey fix to no information")
P0_SCALE = Bound(1e-3, 1e3, "", "P0 from a thousandth to a thousand times the listed σ")
P0_ATTITUDE_ARCSEC = Bound(1e-3, 6.48e5, "″", f"up to 180°; {_FLOOR}")
P0_VELOCITY_MPS = Bound(1e-4, 1e3, "m/s", _FLOOR)
P0_POSITION_M = Bound(1e-3, 1e6, "m", _FLOOR)
P0_GYRO_BIAS_DPH = Bound(1e-6, 3.6e4, "°/h", f"a hundredth of a strategic gyro's bias "
                         f"stability at the least; {_FLOOR}")
P0_ACCEL_BIAS_UG = Bound(1e-3, 1e5, "µg", _FLOOR)
P0_SCALE_PPM = Bound(1e-3, 1e5, "ppm", _FLOOR)
ATTITUDE_SIGMA_ARCSEC = Bound(1e-4, 3600.0, "″", "from a thousandth of the sensor's 0.1″ "
                              f"count to 1°; {_FLOOR}")
P0_ANGLE_ARCSEC = Bound(1e-4, 6.48e5, "″", f"up to 180°; {_FLOOR}")
P0_RATE_DPS = Bound(1e-6, 3600.0, "°/s", f"up to the largest rate; {_FLOOR}")
P0_ANGULAR_ACCEL_DPS2 = Bound(1e-6, 1e5, "°/s²", f"up to the largest acceleration; {_FLOOR}")
LEVER_ARM_M = Bound(0.0, 100.0, "m", "an aiding antenna on the vehicle carrying the IMU "
                    "(the largest aircraft span 80 m)", magnitude=True)
TRANSFER_LEVER_ARM_M = Bound(0.0, 500.0, "m", "a slave IMU and its master INS on one vehicle "
                             "(the longest ship is 458 m)", magnitude=True)
VELOCITY_MPS = Bound(0.0, 1e4, "m/s", "about Mach 30, beyond any navigating vehicle (the "
                     "range of a PSINS header)", magnitude=True)
NOISE_MPS = Bound(0.0, 1e3, "m/s", "no information beyond it")
CLOCK_DRIFT_PPM = Bound(0.0, 1e5, "ppm", "10 %, more than any clock drifts", magnitude=True)
