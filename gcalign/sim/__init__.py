"""Simulation: motions of the base with truth at any time, ideal IMU increments and the
sensor error model. Takes and returns SI arrays; nothing here reads files or YAML."""
