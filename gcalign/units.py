"""Unit constants: multiply a value in the named unit to get SI (radians, seconds, m/s²).

Conversion happens once, in the config layer; the core only sees SI.
"""

import math

DEG = math.pi / 180.0  #: degree -> rad
ARCMIN = DEG / 60.0  #: arc-minute -> rad
ARCSEC = DEG / 3600.0  #: arc-second -> rad
HOUR = 3600.0  #: hour -> s
DPH = DEG / HOUR  #: °/h -> rad/s
DPSH = DEG / math.sqrt(HOUR)  #: °/√h -> rad/√s (angle random walk)
G0 = 9.7803267715  #: m/s², the PSINS reference gravity used for µg and g
UG = G0 * 1e-6  #: µg -> m/s²
UGPSHZ = UG  #: µg/√Hz -> m/s²/√Hz = m/s/√s (velocity random walk)
PPM = 1e-6  #: parts per million -> fraction
