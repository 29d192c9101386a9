"""Estimation: Kalman filter predict/update, discretisation, INS error models, observability.

Plain NumPy functions on arrays (filterpy style); used by in-flight calibration (seed 002)
and real-time attitude prediction (seed 003).
"""
