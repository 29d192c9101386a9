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
"""

__version__ = "0.1.0"
