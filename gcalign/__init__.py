"""gcalign: a laboratory for strapdown inertial navigation alignment and north-finding.

Conventions, fixed once for the whole package (PSINS-compatible; DESIGN.md):

* Navigation frame n: East-North-Up. Body frame b: x right, y forward, z up.
* Attitude ``att = [pitch, roll, yaw]`` (rad), ``C_nb = Rz(yaw) @ Rx(pitch) @ Ry(roll)``;
  yaw counter-clockwise positive. North-finding reports azimuth clockwise from north.
* Names carry frames, destination first: ``C_nb`` maps body to navigation
  (``v_n = C_nb @ v_b``), ``q_nb``, ``omega_ie_n``, ``f_b``.
* Inside the package: SI units and radians only; user units appear in YAML keys and
  printed tables with the unit in the name (``bias_dph``), converted once in the config.
* Time along axis 0: arrays are ``(N,)``, ``(N, 3)``, ``(N, 3, 3)``; time is a separate
  ``(N,)`` array in seconds. IMU sample k holds the increments over ``(t_k - T, t_k]``.

The Python API (:mod:`gcalign.api`; docs/how-to/python.md): :func:`load` a scenario (a file, a
mapping or recorded data; overrides by dotted key) or take a built-in one
(:func:`example`), :func:`run` any command on it (``run("align", sc)``, the same run and
results file as ``gcalign align``), and :func:`read` a results file back into the same
:class:`Result`. Importing gcalign loads none of it until it is used.
"""

from gcalign._version import __version__ as __version__

_API = ("load", "example", "run", "read", "commands", "Result")


def __getattr__(name: str):
    if name in _API:
        from gcalign import api

        return getattr(api, name)
    raise AttributeError(f"module 'gcalign' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*(n for n in globals() if n.startswith("__")), *_API})
