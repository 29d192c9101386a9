"""Exact ideal IMU increments from a motion, in blocks, in the sensor frame.

Gyro: ``Δθ_k = rotvec(q_is(k-1)* ⊗ q_is(k))`` with ``q_is = q_ie(t) ⊗ q_en(L, λ) ⊗ q_ns``
(inertial frame = ECEF at the start of the block; the frame cancels in the difference), so
an ideal strapdown update reproduces truth to round-off, through any turn.
Accelerometer: ``Δv_k = ∫ f_s dt`` by Simpson's rule on `substeps` (even) sub-intervals,
``f_s = C_sn (v̇_n + (2ω_ie^n + ω_en^n) × v_n − g_n)`` (the specific force at rest points up).
Segment boundaries of a moving base fall on sample times (the scenario layer enforces it),
and every sub-point of a sample is evaluated with that sample's segment, so f is smooth
inside every sample and Simpson's error is below 1e-12 m/s per sample.

Blocks of :data:`BLOCK` samples keep memory independent of a run's duration; the numbers
do not depend on the block size beyond round-off of the inertial frame's origin.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gcalign.nav.earth import WGS84, C_en, EarthModel
from gcalign.nav.rotation import (
    dcm_to_quat,
    euler_to_quat,
    quat_conj,
    quat_mult,
    quat_to_euler,
    quat_to_rotvec,
)
from gcalign.sim.mechanism import Mechanism
from gcalign.sim.motions import MotionType, Moving, Static, Truth, Turntable, sample_count
from gcalign.sim.schedule import AngleProfile, Schedule, Step

Array = NDArray[np.float64]  #: a float64 array (shapes in the docstrings)

BLOCK = 1 << 16  #: samples per block of the numba route (fixed site)
GENERIC_BLOCK = 1 << 14  #: of the NumPy route: ~1.4 KB of temporaries per sample


@dataclass(frozen=True)
class SimBlock:
    """Increments k0 .. k0+n-1 and the truth at their end times (SI).

    t (n,) end times; dtheta, dv (n, 3) sensor frame; att (n, 3), q_nb (n, 4), v_n (n, 3),
    pos (n, 3) body truth at t; segment (n,) motion segment of each increment; q_bs (n, 4)
    mechanism angles at t (None without a mechanism).
    """

    k0: int
    t: np.ndarray
    dtheta: np.ndarray
    dv: np.ndarray
    att: np.ndarray
    q_nb: np.ndarray
    v_n: np.ndarray
    pos: np.ndarray
    segment: np.ndarray
    q_bs: np.ndarray | None


def _rotate(q: Array, v: Array) -> Array:
    """C(q) v for quaternions (..., 4) and vectors (..., 3)."""
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def initial_truth(motion: MotionType, site: ArrayLike, earth: EarthModel = WGS84) -> Truth:
    """The truth at t = 0 as a one-row :class:`Truth`."""
    k = motion.kinematics(np.array([0.0]), site, earth)
    return Truth(t=np.zeros(1), att=np.array(k.att), v_n=np.array(k.v_n), pos=np.array(k.pos),
                 segment=np.zeros(1, dtype=np.int64))


def ideal_blocks(motion: MotionType, site: ArrayLike, ts: float, earth: EarthModel = WGS84,
                 mechanism: Mechanism | None = None, block: int | None = None,
                 substeps: int = 2) -> Iterator[SimBlock]:
    """The ideal increments of `motion` at `site` ``[lat, lon, h]`` in blocks."""
    if substeps % 2:
        raise ValueError(f"substeps must be even for Simpson's rule, got {substeps}")
    n_total = sample_count(motion.duration, ts)
    m = substeps
    site = np.asarray(site, dtype=float)
    if isinstance(motion, Static | Turntable):
        yield from _fixed_site_blocks(motion, site, ts, earth, mechanism, block or BLOCK, m,
                                      n_total)
    else:
        yield from _numpy_blocks(motion, site, ts, earth, mechanism, block or GENERIC_BLOCK,
                                 m, n_total)


def _numpy_blocks(motion: MotionType, site: Array, ts: float, earth: EarthModel,
                  mechanism: Mechanism | None, block: int, m: int,
                  n_total: int) -> Iterator[SimBlock]:
    """The vectorised route: any motion, the kinematics on a grid of sub-points."""
    h = ts / m
    weights = np.ones(m + 1)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    weights *= h / 3.0
    for k0 in range(0, n_total, block):
        n = min(block, n_total - k0)
        # Sub-point times from integers, so a boundary is the same number in both rows.
        idx = (k0 + np.arange(n))[:, None] * m + np.arange(m + 1)
        grid = idx * h
        seg = None
        if isinstance(motion, Moving):
            # A sample's end belongs to the segment that ends there (left limit), every
            # other sub-point to the segment it lies in: a boundary on a sample time is
            # then integrated with the limits of each side.
            seg = motion.segment_index(grid, side="right")
            seg[:, -1] = motion.segment_index(grid[:, -1], side="left")
            seg = seg.ravel()
            kin = motion.grid_kinematics(grid, seg, site, earth)
        else:
            kin = motion.kinematics(grid.ravel(), site, earth)
        lat, height = kin.pos[:, 0], kin.pos[:, 2]
        w = 2.0 * earth.omega_ie_n(lat) + earth.omega_en_n(lat, height, kin.v_n)
        f_n = kin.a_n + np.cross(w, kin.v_n)
        f_n[:, 2] += earth.gravity(lat, height)
        # Sample points: each row's start, then the last row's end.
        sp = np.r_[np.arange(n) * (m + 1), n * (m + 1) - 1]
        if mechanism is None:  # f_b = C_bn f_n at every sub-point, quaternions at samples
            f_s = np.einsum("kji,kj->ki", kin.C_nb, f_n).reshape(n, m + 1, 3)
            q_ns = q_nb = dcm_to_quat(kin.C_nb[sp])
        else:
            q_all = dcm_to_quat(kin.C_nb)
            q_ns_all = mechanism.q_ns(grid.ravel(), q_all)
            f_s = _rotate(quat_conj(q_ns_all), f_n).reshape(n, m + 1, 3)
            q_nb, q_ns = q_all[sp], q_ns_all[sp]
        dv = np.einsum("j,kjc->kc", weights, f_s)
        if isinstance(motion, Moving):
            _split_at_boundaries(dv, motion, mechanism, site, earth, k0, n, ts, m)
        if mechanism is not None and mechanism.lever is not None:
            dv += mechanism.lever_dv(k0, n, ts)

        t_s = grid.ravel()[sp]
        half = 0.5 * earth.omega_ie * (t_s - t_s[0])
        q_ie = np.stack([np.cos(half), 0 * half, 0 * half, np.sin(half)], -1)
        pos_s = kin.pos[sp]
        q_en = dcm_to_quat(C_en(pos_s[:, 0], pos_s[:, 1]))
        q_is = quat_mult(quat_mult(q_ie, q_en), q_ns)
        dtheta = quat_to_rotvec(quat_mult(quat_conj(q_is[:-1]), q_is[1:]))

        # Truth at the end of each increment (the row's end: the increment's own segment).
        ends = np.arange(n) * (m + 1) + m
        q_bs = None
        if mechanism is not None:
            q_bs = mechanism.q_bs(grid.ravel()[ends], q_nb[1:])
        yield SimBlock(k0=k0, t=grid.ravel()[ends], dtheta=dtheta, dv=dv,
                       att=np.array(kin.att[ends]), q_nb=np.array(q_nb[1:]),
                       v_n=np.array(kin.v_n[ends]),
                       pos=np.array(kin.pos[ends]),
                       segment=(np.zeros(n, np.int64) if seg is None else seg[ends]),
                       q_bs=q_bs)


def _specific_force_s(motion: Moving, mechanism: Mechanism | None, site: Array,
                      earth: EarthModel, t: Array, seg: int) -> Array:
    """f_s at times t of one segment (the integrand of Δv)."""
    kin = motion.kinematics(t, site, earth, segment=np.full(t.shape, seg))
    q_nb = dcm_to_quat(kin.C_nb)
    q_ns = q_nb if mechanism is None else mechanism.q_ns(t, q_nb)
    lat, height = kin.pos[:, 0], kin.pos[:, 2]
    w = 2.0 * earth.omega_ie_n(lat) + earth.omega_en_n(lat, height, kin.v_n)
    f_n = kin.a_n + np.cross(w, kin.v_n)
    f_n[:, 2] += earth.gravity(lat, height)
    return _rotate(quat_conj(q_ns), f_n)


def _split_at_boundaries(dv: Array, motion: Moving, mechanism: Mechanism | None, site: Array,
                         earth: EarthModel, k0: int, n: int, ts: float, m: int) -> None:
    """Δv of the samples whose interior holds a segment boundary (the acceleration or a
    rate jumps there): Simpson on each side of the boundary, each with its own segment."""
    starts = np.cumsum([0.0] + [s.duration for s in motion.segments[:-1]])
    for j, b in enumerate(starts[1:], start=1):
        k = int(np.floor(b / ts + 1e-9))
        if not k0 <= k < k0 + n or abs(b - k * ts) < 1e-9 * ts or abs(b - (k + 1) * ts) < 1e-9 * ts:
            continue
        total = np.zeros(3)
        for a, c, seg in ((k * ts, b, j - 1), (b, (k + 1) * ts, j)):
            tt = a + (c - a) * np.arange(m + 1) / m
            w = np.ones(m + 1)
            w[1:-1:2], w[2:-1:2] = 4.0, 2.0
            total += (w * (c - a) / (3.0 * m)) @ _specific_force_s(motion, mechanism, site,
                                                                    earth, tt, seg)
        dv[k - k0] = total


_IDENTITY = Schedule((Step((0.0, 0.0, 1.0), AngleProfile.rest(1.0)),))


def _fixed_site_blocks(motion: Static | Turntable, site: Array, ts: float, earth: EarthModel,
                       mechanism: Mechanism | None, block: int, m: int,
                       n_total: int) -> Iterator[SimBlock]:
    """The numba route for a base at a fixed site (:func:`fixed_site_block`)."""
    from gcalign.sim._kernels import fixed_site_block

    q_nb0 = euler_to_quat(np.asarray(motion.att0, float))
    body = motion.schedule if isinstance(motion, Turntable) else None
    # at rest: v_n = 0 and a_n = 0, so f_n is the normal gravity, up
    f_n = np.array([0.0, 0.0, float(earth.gravity(site[0], site[2]))])
    q_en = dcm_to_quat(C_en(site[0], site[1]))
    body_tab = (body or _IDENTITY).kernel_tables()
    mech_tab = (mechanism.schedule if mechanism is not None else _IDENTITY).kernel_tables()
    mech_nav = mechanism is not None and mechanism.reference == "navigation"
    for k0 in range(0, n_total, block):
        n = min(block, n_total - k0)
        dtheta, dv = np.empty((n, 3)), np.empty((n, 3))
        q_nb, q_bs = np.empty((n, 4)), np.empty((n, 4))
        fixed_site_block(k0, n, ts, m, earth.omega_ie, q_en, f_n, q_nb0, body_tab,
                         body is not None, mech_tab, mechanism is not None, mech_nav,
                         dtheta, dv, q_nb, q_bs)
        if mechanism is not None and mechanism.lever is not None:
            dv += mechanism.lever_dv(k0, n, ts)
        t = (k0 + 1 + np.arange(n)) * ts
        att = np.broadcast_to(np.asarray(motion.att0, float), (n, 3)) if body is None else \
            quat_to_euler(q_nb)
        yield SimBlock(k0=k0, t=t, dtheta=dtheta, dv=dv, att=np.array(att), q_nb=q_nb,
                       v_n=np.zeros((n, 3)), pos=np.tile(site, (n, 1)),
                       segment=np.zeros(n, np.int64), q_bs=q_bs if mechanism is not None else None)
