"""The names a user chooses among, each list written once: the code that acts on a choice
takes its tuple from here, and the command line's help lists it from here (no NumPy, no
pydantic: ``gcalign --help`` imports this module).

>>> " | ".join(COMPENSATIONS)
'none | one-off | continued'
"""

from __future__ import annotations

#: gyrocompass alignment modes (:mod:`gcalign.align.cycles`)
ALIGN_MODES = ("conventional", "full-cycle", "half-cycle")
#: ``align.mode``: the gyrocompass modes and transfer alignment (spec 006)
ALIGN_MODES_ALL = (*ALIGN_MODES, "transfer")
#: attitude compensation from T2 to T3 (:mod:`gcalign.align.compensate`)
COMPENSATIONS = ("none", "one-off", "continued")
#: layouts of a recording (:data:`gcalign.io.recorded.imu.FORMATS`), and "auto" (from the
#: file's suffix)
RECORDING_FORMATS = ("psins", "psins-mat", "i2nav", "csv")
#: formats ``gcalign export`` writes (:data:`gcalign.app.export.FORMATS`)
EXPORT_FORMATS = ("csv", "mat", "i2nav-nav", "psins-avp")
#: vertical channel of strapdown navigation (:mod:`gcalign.nav.strapdown`)
VERTICAL_MODES = ("free", "hold", "damped")
#: ``navigation.vertical``: those, or "auto" (chosen from the base's motion)
VERTICAL_CHOICES = ("auto", *VERTICAL_MODES)
#: DGNSS measurements of in-flight calibration (:mod:`gcalign.estimation.ins_error`)
MEASUREMENTS = ("velocity", "position", "both")
#: a calibration run's injected errors: the scenario's, or drawn from P0 with the seed
TRUTH_SOURCES = ("scenario", "draw")
#: north-finding's azimuth methods, in the order of the result arrays
#: (:mod:`gcalign.northfind.estimate`)
AZIMUTH_METHODS = ("coordinate", "vector", "naive", "none")
#: ``northfind.methods``: those and the seed's vector form as printed
AZIMUTH_METHODS_ALL = (*AZIMUTH_METHODS, "vector_literal")
#: attitude predictors to the pulse time (:mod:`gcalign.realtime.settings`, spec 003 §3)
PREDICTORS = ("none", "taylor", "kalman-ls")
#: what transfer alignment matches (:mod:`gcalign.transfer.filter`)
MATCHINGS = ("attitude+velocity", "velocity", "attitude")


def listed(names: tuple[str, ...]) -> str:
    """A choice list as the help shows it: ``a | b | c``."""
    return " | ".join(names)
