"""Truth trajectories: static, swing and moving (by segments) bases.

A motion is a function of time giving the Euler angles, their rates, and the forward
speed along the body y axis (DESIGN.md "Truth and IMU simulation"; seed 000 §5.2, §5.3).
:func:`generate` samples it at the IMU rate and integrates the position; the exact
ideal increments are built from it in :mod:`gcalign.sim.imu`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gcalign.nav import earth
from gcalign.nav.rotation import euler_to_dcm


@dataclass(frozen=True)
class Segment:
    """One piece of a moving-base motion (SI): duration (s), forward acceleration along
    body y (m/s²), Euler-angle rates ``[pitch, roll, yaw]`` (rad/s)."""

    duration: float
    accel: float = 0.0
    rate: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Motion:
    """Motion of the base (SI, radians).

    kind : "static" | "swing" | "moving".
    att0 : (3,) initial (static, moving) or mean (swing) attitude ``[pitch, roll, yaw]``.
    amplitude, period, phase : (3,) swing per Euler angle: ``att0 + A sin(2π t/T + phase)``.
    segments : moving only; the last segment is held until `duration`.
    """

    kind: str
    att0: tuple[float, float, float]
    duration: float
    amplitude: tuple[float, float, float] = (0.0, 0.0, 0.0)
    period: tuple[float, float, float] = (1.0, 1.0, 1.0)
    phase: tuple[float, float, float] = (0.0, 0.0, 0.0)
    segments: tuple[Segment, ...] = ()

    def evaluate(self, t, t_segment=None):
        """Attitude, attitude rate, forward speed and its rate at times `t` (s), shape (N,).

        `t_segment` (N,), optional, picks the segment of a moving base by another time: the
        IMU simulation evaluates every sub-point of a sample with the segment of the
        sample's midpoint, so a boundary on a sample time takes the left or right limit
        as the integral over that sample needs.

        Returns ``att (N, 3) rad, att_dot (N, 3) rad/s, speed (N,) m/s, speed_dot (N,) m/s²``.
        """
        t = np.asarray(t, dtype=float)
        att0 = np.asarray(self.att0, dtype=float)
        zeros = np.zeros_like(t)
        if self.kind == "static":
            att = np.broadcast_to(att0, t.shape + (3,)).copy()
            return att, np.zeros_like(att), zeros, zeros
        if self.kind == "swing":
            w = 2.0 * np.pi / np.asarray(self.period, dtype=float)
            arg = t[:, None] * w + np.asarray(self.phase, dtype=float)
            amp = np.asarray(self.amplitude, dtype=float)
            return att0 + amp * np.sin(arg), amp * w * np.cos(arg), zeros, zeros
        if self.kind == "moving":
            return self._evaluate_segments(t, t if t_segment is None else t_segment)
        raise ValueError(f"motion.kind: got {self.kind!r}, allowed: static, swing, moving")

    def _evaluate_segments(self, t, t_segment):
        durations = np.array([s.duration for s in self.segments], dtype=float)
        accel = np.array([s.accel for s in self.segments], dtype=float)
        rate = np.array([s.rate for s in self.segments], dtype=float).reshape(-1, 3)
        starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
        # State at the start of each segment (attitude and speed are continuous).
        att_start = np.asarray(self.att0, dtype=float) + np.concatenate(
            [np.zeros((1, 3)), np.cumsum(rate[:-1] * durations[:-1, None], axis=0)]
        )
        speed_start = np.concatenate([[0.0], np.cumsum(accel[:-1] * durations[:-1])])
        # A time exactly on a boundary belongs to the later segment; the last one is held.
        j = np.clip(np.searchsorted(starts, t_segment, side="right") - 1, 0, len(starts) - 1)
        dt = t - starts[j]
        att = att_start[j] + rate[j] * dt[:, None]
        speed = speed_start[j] + accel[j] * dt
        return att, rate[j], speed, accel[j]


@dataclass(frozen=True)
class Truth:
    """Sampled truth (SI): times (N+1,), attitude (N+1, 3), ENU velocity (N+1, 3),
    position ``[lat, lon, h]`` (N+1, 3) in rad, rad, m."""

    t: np.ndarray
    att: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray


def kinematics(motion: Motion, t, t_segment=None):
    """Attitude, DCM, ENU velocity and its time derivative at times `t` (vectorised).

    ``v_n = C_nb [0, s, 0]`` is the body-forward speed s resolved in ENU; its derivative
    is ``ṡ c + s ċ`` with c the second column of C_nb (d/dt by the chain rule on the
    Euler angles).
    """
    att, att_dot, s, s_dot = motion.evaluate(t, t_segment)
    C = euler_to_dcm(att)
    p, y = att[:, 0], att[:, 2]
    pd, yd = att_dot[:, 0], att_dot[:, 2]
    c = C[:, :, 1]  # [-sin y cos p, cos y cos p, sin p]
    c_dot = np.stack(
        [
            -np.cos(y) * np.cos(p) * yd + np.sin(y) * np.sin(p) * pd,
            -np.sin(y) * np.cos(p) * yd - np.cos(y) * np.sin(p) * pd,
            np.cos(p) * pd,
        ],
        -1,
    )
    v_n = s[:, None] * c
    a_n = s_dot[:, None] * c + s[:, None] * c_dot
    return att, C, v_n, a_n


def integrate_position(t, v_n, pos0, iterations: int = 3):
    """Latitude, longitude, height along a finely sampled ENU velocity (trapezoid rule).

    The radii depend on the latitude being integrated; a few fixed-point passes settle it
    (each pass changes R_M by the latitude change times dR_M/dL, ~1e-5 relative).
    """
    pos0 = np.asarray(pos0, dtype=float)
    dt = np.diff(t)
    h = pos0[2] + np.concatenate([[0.0], np.cumsum(0.5 * (v_n[1:, 2] + v_n[:-1, 2]) * dt)])
    lat = np.full_like(t, pos0[0])
    for _ in range(iterations):
        r_m, r_n = earth.radii(lat)
        lat_rate = v_n[:, 1] / (r_m + h)
        lat = pos0[0] + np.concatenate(
            [[0.0], np.cumsum(0.5 * (lat_rate[1:] + lat_rate[:-1]) * dt)]
        )
    r_m, r_n = earth.radii(lat)
    lon_rate = v_n[:, 0] / ((r_n + h) * np.cos(lat))
    lon = pos0[1] + np.concatenate([[0.0], np.cumsum(0.5 * (lon_rate[1:] + lon_rate[:-1]) * dt)])
    return np.stack([lat, lon, h], -1)


def sample_grid(n: int, ts: float, substeps: int):
    """Sub-point times of each of n samples, (n, substeps + 1), and the samples' midpoints (n,).

    Neighbouring rows share their end points; times are built from integers so that a
    boundary is the same number in both rows.
    """
    k = np.arange(n)[:, None] * substeps + np.arange(substeps + 1)
    h = ts / substeps
    return k * h, (np.arange(n) + 0.5) * ts


def sample_count(duration: float, ts: float) -> int:
    """Number of IMU samples in `duration` (rounded, so 400 s at 0.01 s gives 40000)."""
    return int(round(duration / ts))
