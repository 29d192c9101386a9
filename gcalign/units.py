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


#: Angle units chosen by size (:func:`angle_unit`): name, factor to rad, printed symbol.
ANGLE_UNITS = {"deg": (DEG, "°"), "arcmin": (ARCMIN, "′"), "arcsec": (ARCSEC, "″")}


def angle_unit(peak_rad: float) -> str:
    """The unit an angle of size `peak_rad` (rad) reads best in: ``deg`` from 1°,
    ``arcmin`` from 1′, else ``arcsec`` (a NaN or an infinity: ``deg``).

    >>> angle_unit(2 * DEG), angle_unit(5 * ARCMIN), angle_unit(3 * ARCSEC)
    ('deg', 'arcmin', 'arcsec')
    """
    peak = abs(peak_rad)
    if not peak < math.inf or peak >= DEG:
        return "deg"
    return "arcmin" if peak >= ARCMIN else "arcsec"


def angle_text(rad: float, digits: int = 3) -> str:
    """An angle (rad) in the unit that reads best for its size, with its symbol.

    >>> angle_text(0.5 * DEG), angle_text(12 * ARCSEC)
    ('30′', '12″')
    """
    factor, symbol = ANGLE_UNITS[angle_unit(rad)]
    return f"{rad / factor:.{digits}g}{symbol}"
