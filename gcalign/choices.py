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


def listed(names: tuple[str, ...]) -> str:
    """A choice list as the help shows it: ``a | b | c``."""
    return " | ".join(names)
