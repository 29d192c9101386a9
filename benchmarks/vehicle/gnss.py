"""GNSS fixes of the vehicle's antenna: 1 Hz, a σ per epoch that wanders between 0.05 and
0.5 m, noise drawn from that σ, and outages with no fix at all.

σ: blocks of 20-90 s, each at a level drawn log-uniformly in [σ_min, σ_max] (so every
decade of σ gets its share of epochs), joined by 5 s cosine ramps in log σ; north and east
share it, down is 1.5 times it (a receiver's vertical is its weakest). The file states σ
to 0.1 mm and the noise is drawn from the σ it states.

The antenna sits at the lever arm l^b (FRD, m) from the IMU: its true position is
r^e + C_n^e C_b^n l^b, converted back to geodetic exactly; the noise (NED metres) moves
latitude and longitude through the radii there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmarks.vehicle import earth
from benchmarks.vehicle.trajectory import Trajectory

#: σ down / σ horizontal
DOWN_FACTOR = 1.5


@dataclass(frozen=True)
class Fixes:
    """t (M,) s from the route's start; lat, lon (rad), h (m) with noise; sigma_ned (M, 3)
    m; truth_lat, truth_lon, truth_h: the antenna without noise; outages: [(start, end)]
    s, the times of the last fix before and the first after each."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    h: np.ndarray
    sigma_ned: np.ndarray
    truth_lat: np.ndarray
    truth_lon: np.ndarray
    truth_h: np.ndarray
    outages: list


def sigma_profile(rng: np.random.Generator, t: np.ndarray, lo: float = 0.05,
                  hi: float = 0.5) -> np.ndarray:
    """Horizontal σ (m) at times `t` (M,) s (module docstring)."""
    edges = [float(t[0]) - 1.0]
    while edges[-1] <= t[-1]:
        edges.append(edges[-1] + rng.uniform(20.0, 90.0))
    edges_a = np.asarray(edges)
    levels = rng.uniform(np.log(lo), np.log(hi), len(edges_a))
    k = np.clip(np.searchsorted(edges_a, t, side="right") - 1, 0, len(levels) - 1)
    log_s = levels[k].copy()
    # a 5 s cosine ramp from the previous level into each block
    ramp = np.clip((t - edges_a[k]) / 5.0, 0.0, 1.0)
    prev = levels[np.maximum(k - 1, 0)]
    w = 0.5 - 0.5 * np.cos(np.pi * ramp)
    log_s = np.where(k > 0, prev + (levels[k] - prev) * w, log_s)
    return np.round(np.exp(log_s), 4)


def antenna(traj: Trajectory, t: np.ndarray, lever_frd: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The antenna's true lat, lon (rad), h (m) at times `t` (M,)."""
    st = traj.state(t)
    C_en = earth.C_en(st.lat, st.lon)
    r = earth.to_ecef(st.lat, st.lon, st.h) + np.einsum(
        "kij,kj->ki", C_en, st.C_nb @ np.asarray(lever_frd, float))
    return earth.to_geodetic(r)


def outage_windows(centres, length: float = 60.0) -> list[tuple[float, float]]:
    """Whole-second windows of `length` s centred on `centres` (s)."""
    return [(float(np.round(c - length / 2)), float(np.round(c - length / 2)) + length)
            for c in centres]


def fixes(traj: Trajectory, lever_frd, outages: list[tuple[float, float]],
          rng_sigma: np.random.Generator, rng_noise: np.random.Generator,
          rate_hz: float = 1.0, end: float | None = None) -> Fixes:
    """Fixes at every whole 1/rate_hz s of the drive (from 1 s to `end`, default the
    drive's end), none strictly inside an outage window (its ends keep theirs)."""
    end = traj.duration if end is None else end
    t_all = np.arange(1.0, np.floor(end) + 1e-9, 1.0 / rate_hz)
    s_h = sigma_profile(rng_sigma, t_all)
    sigma = np.column_stack([s_h, s_h, np.round(DOWN_FACTOR * s_h, 4)])
    noise = rng_noise.standard_normal((len(t_all), 3)) * sigma  # drawn for every epoch
    keep = np.ones(len(t_all), bool)
    for a, b in outages:
        keep &= ~((t_all > a + 1e-9) & (t_all < b - 1e-9))
    t, sigma, noise = t_all[keep], sigma[keep], noise[keep]
    lat, lon, h = antenna(traj, t, lever_frd)
    r_m, r_n = earth.radii(lat)
    return Fixes(t, lat + noise[:, 0] / (r_m + h), lon + noise[:, 1] / ((r_n + h) * np.cos(lat)),
                 h - noise[:, 2], sigma, lat, lon, h, list(outages))
