"""Input and output: scenario models (pydantic, :mod:`~gcalign.io.scenario`), recorded-data
readers (:mod:`~gcalign.io.recorded`, on :mod:`~gcalign.io.imu_files`) and the HDF5 results
file (:mod:`~gcalign.io.results`).

This is the only layer that knows YAML keys with units in their names; it converts them to
SI once and hands plain values to the core.
"""
