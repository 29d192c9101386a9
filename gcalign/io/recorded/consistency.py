"""Recorded data that contradict themselves: gyros against accelerometers and the earth rate.

A recording read with the wrong gyro units or axes looks like any other: the increments are
finite, regular and small enough, and the accelerometers pass the gravity check; every
command then runs and reports a wrong heading with exit 0 (deg/s declared rad/s: heading off
by 65-190°; gyro x and y swapped on lasergyro.imu: yaw 140.5° against -90.6°). Two physical
relations tie the gyros to what the accelerometers and the earth say, whatever the grade:

1. **The specific force turns as the gyros say.** Over a window the body turns by the
   rotation vector θ the gyros integrate, and a specific force that is fixed in the
   navigation frame (gravity, and a slowly varying acceleration) turns the other way in the
   body: ``f_b(t+T) ≈ f_b(t) + f_b(t) × θ``. The changes of the 1-s means of ``f_b`` over
   ``T`` = :data:`WINDOW_S` are regressed on ``f_b × θ`` (θ from the gyro rates less their
   :data:`HIGHPASS_S` moving mean: the earth rate and the bias): the slope ``k`` is 1 for
   gyros in the declared units and axes, about 1/57.3 for deg/s declared rad/s, 1/3600 for
   deg/h declared deg/s, 1/206265 for arc-seconds declared radians. The correlation ``ρ``
   says whether the recording turns enough to judge (the ±33° rolling MEMS vehicle of
   transfer_align_fog_mems.mat: ρ 0.91, k 0.87; the disturbed parked vehicle of
   lasergyro.imu: ρ 0.73, k 0.91); the same regression with the gyro axes permuted and
   their signs flipped (48 ways) finds the axes under which the specific force turns as the
   gyros say, when the declared ones do not (x and y swapped: ρ 0.12 as declared, 0.73
   swapped back).
2. **At rest the gyros measure the earth rate** (where the latitude is known): the mean
   rate is ``Ω = 15.04 °/h`` at ``90° − L`` from up, plus the bias. A mean rate that points
   there and is 57.3, 3600 or 206265 times too large (or too small) is the earth rate in
   other units (lasergyro.imu: 0.987 Ω at 55.4° from up, 55.8° expected).

3. **A reference turns as the gyros do.** The angle a reference's attitude turns by over
   windows between its epochs against the angle the gyros integrate (angles, so that a
   mounting between the two bodies does not matter): a reference in radians read as
   degrees turns 57.3 times too little (the FOG solution of transfer_align_fog_mems.mat
   written so: 0.0178; as written: 1.02). A psins-mat reference in degrees has angles of
   tens of radians, refused by the reader's ranges.
4. **A vehicle moves along its forward axis.** With a velocity (a reference's, an aiding
   file's), its accelerations along and across the track show on the body's forward and
   right axes (:func:`forward_axis`): x-forward axes (FLU) declared y-forward (RFU), which
   1 and the gravity check cannot see, show on +x.

Each check judges only on evidence: a correlation of at least :data:`MIN_RHO` and a factor
within 30 % of a unit's, or a permutation far better than the declared axes; anything else
leaves the recording as read. The refusal names the likely fix ("gyro looks like deg/s,
declared rad/s") and the key that turns the check off (``imu_file.check_consistency: false``,
``reference.check_attitude: false``). 1 and 2 (with a PSINS header's site) run as the file is
read; 2 (with the scenario's site), 3 and 4 where the scenario brings the other source
(:func:`gcalign.app.preflight.consistent`).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from gcalign import units as u
from gcalign.errors import ScenarioError
from gcalign.nav.earth import OMEGA_IE

__all__ = ["check_gyros", "earth_rate_at_rest", "forward_axis", "gyro_fit",
           "reference_against_gyros"]

BLOCK_S = 1.0  #: specific force and rates averaged over blocks (vibration out)
WINDOW_S = 10.0  #: the window over which the specific force turns
HIGHPASS_S = 60.0  #: the moving mean taken off the gyro rates (earth rate, bias)
MIN_RHO = 0.5  #: the correlation the fit needs before it judges
MIN_WINDOWS = 5  #: independent windows the fit needs
FACTOR_TOL = 0.3  #: a scale within 30 % of a unit's factor names that unit
REST_STD_MPS2 = 0.05  #: 1-s means of the specific force vary less than this at rest
REST_ANGLE_DEG = 10.0  #: the mean rate within this of the earth rate's direction

#: gyro units -> (SI factor, quantity): those a layout takes (:mod:`~.imu` reads them here)
GYRO_UNITS = {
    "rad": (1.0, "increments"), "deg": (u.DEG, "increments"),
    "arcsec": (u.ARCSEC, "increments"),
    "rad/s": (1.0, "rates"), "deg/s": (u.DEG, "rates"), "deg/h": (u.DPH, "rates"),
}
#: the units a check may name: those a layout takes, and arc-seconds per second (some FOGs)
_NAMED = {**GYRO_UNITS, "arcsec/s": (u.ARCSEC, "rates")}


def _blocks(dtheta: np.ndarray, dv: np.ndarray, ts: float, block_s: float = BLOCK_S):
    """Rotation vectors (n, 3) rad and mean specific forces (n, 3) m/s² of blocks of about
    `block_s`, and the block length, s."""
    m = max(1, int(round(block_s / ts)))
    n = len(dtheta) // m
    h = m * ts
    th = np.asarray(dtheta, float)[:n * m].reshape(n, m, 3).sum(1)
    f = np.asarray(dv, float)[:n * m].reshape(n, m, 3).sum(1)
    return th, f / h, h


def _moving_mean(x: np.ndarray, n: int) -> np.ndarray:
    """Centred moving mean of each column over `n` rows, the ends over what there is."""
    if n <= 1 or len(x) == 0:
        return x.copy()
    k = np.ones(n)
    count = np.convolve(np.ones(len(x)), k, mode="same")
    return np.column_stack([np.convolve(x[:, j], k, mode="same") / count
                            for j in range(x.shape[1])])


def _signed_permutations() -> list[np.ndarray]:
    out = []
    for p in itertools.permutations(range(3)):
        for s in itertools.product((1.0, -1.0), repeat=3):
            P = np.zeros((3, 3))
            for i in range(3):
                P[i, p[i]] = s[i]
            out.append(P)
    return out


_PERMUTATIONS = _signed_permutations()


def gyro_fit(dtheta: np.ndarray, dv: np.ndarray, ts: float) -> dict | None:
    """The regression of relation 1 (module docstring) under each of the 48 signed
    permutations P of the gyro axes: ``{"rho", "k", "windows", "fits": [(rho, k, P)]}``
    (fits sorted by rho, best first; P maps the read gyro axes to the accelerometers'),
    or None when the recording is too short to judge."""
    th, f, h = _blocks(dtheta, dv, ts)
    w = th / h
    L = int(round(WINDOW_S / h))
    if L < 1 or len(w) < L * (MIN_WINDOWS + 1):
        return None
    w_hp = w - _moving_mean(w, int(round(HIGHPASS_S / h)))
    cum = np.concatenate([np.zeros((1, 3)), np.cumsum(w_hp * h, axis=0)])
    theta = cum[L + 1:] - cum[1:-L]  # rotation over blocks i+1 .. i+L
    f1, f2 = f[:-L], f[L:]
    df = f2 - f1
    ss_df = float((df * df).sum())
    fits = []
    for P in _PERMUTATIONS:
        reg = np.cross(f1, theta @ P.T)
        a, b = float((reg * df).sum()), float((reg * reg).sum())
        if b <= 0 or ss_df <= 0:
            return None
        fits.append((a / math.sqrt(b * ss_df), a / b, P))
    fits.sort(key=lambda x: -x[0])
    ident = next(x for x in fits if np.array_equal(x[2], np.eye(3)))
    return {"rho": ident[0], "k": ident[1], "windows": len(df) // L, "fits": fits}


def _unit_for(declared: str, k: float) -> str | None:
    """The gyro unit whose factor is the declared one's times `k` (within
    :data:`FACTOR_TOL`), of the same quantity; None if none is."""
    if declared not in _NAMED:
        return None
    factor, quantity = _NAMED[declared]
    target = factor * k
    for name, (other, q) in _NAMED.items():
        if q == quantity and name != declared and \
                abs(math.log(target / other)) < math.log(1 + FACTOR_TOL):
            return name
    return None


def _fix(fmt: str, unit: str) -> str:
    """What to give: the unit key, or what to check where the format fixes the units."""
    if fmt == "psins":
        return "check the header's gyro scale factors (arcsec per count)"
    if fmt in ("psins-mat", "i2nav"):
        return f"convert the gyro columns to rad ({fmt} holds increments in rad)"
    if unit not in GYRO_UNITS:  # rates first, as a FOG's data sheet gives them
        accepted = sorted(GYRO_UNITS, key=lambda k: GYRO_UNITS[k][1] != "rates")
        return f"convert the gyro columns to one of {', '.join(accepted)}"
    return f"give units: {{gyro: {unit}}}"


def _axes_words(P: np.ndarray) -> str:
    """A signed permutation as the gyro axes it stands for: ``y, x, z`` (x and y swapped),
    ``x, -y, z`` (y's sign flipped)."""
    out = []
    for i in range(3):
        j = int(np.argmax(np.abs(P[i])))
        out.append(("-" if P[i, j] < 0 else "") + "xyz"[j])
    return ", ".join(out)


def _closest_to_identity(fits: list) -> tuple:
    """Among the fits as good as the best (within 0.02 in rho: an axis the data cannot
    see, the vertical of a level vehicle), the one that changes the fewest axes."""
    best = fits[0][0]
    ties = [x for x in fits if x[0] >= best - 0.02]
    return max(ties, key=lambda x: float(np.trace(x[2])))


def check_gyros(name: str, dtheta: np.ndarray, dv: np.ndarray, ts: float, *,
                gyro_units: str, C_rfu_file: np.ndarray, fmt: str) -> dict:
    """Relation 1 of the module docstring on increments already in RFU and SI; ScenarioError
    naming the likely fix when the gyros contradict the accelerometers. Returns what was
    found, for the recording's record."""
    fit = gyro_fit(dtheta, dv, ts)
    if fit is None:
        return {"judged": False, "why": f"shorter than {(MIN_WINDOWS + 1) * WINDOW_S:g} s"}
    rho, k = fit["rho"], fit["k"]
    best = _closest_to_identity(fit["fits"])
    record = {"judged": False, "rho": round(rho, 4), "k": round(k, 5),
              "windows": fit["windows"], "best_rho": round(best[0], 4)}
    if best[0] < MIN_RHO:
        record["why"] = f"the specific force turns too little to judge (rho {best[0]:.2f})"
        return record
    record["judged"] = True
    hatch = "or set imu_file check_consistency: false"
    if not np.array_equal(best[2], np.eye(3)) and rho < 0.5 * best[0]:
        Q = C_rfu_file.T @ best[2] @ C_rfu_file  # in the file's own axes
        words = _axes_words(np.round(Q))
        swapped = "x and y" if words.startswith("y, x") else "y and z" if words.startswith(
            "x, z, y") else "x and z" if words.startswith("z, y, x") else None
        what = f"gyro {swapped} look swapped" if swapped and "-" not in words else (
            f"the gyro axes look like ({words}) of the declared ones")
        raise ScenarioError(
            f"imu_file: {name}: {what}: the specific force turns as the gyros say only with "
            f"gyro x, y, z read as {words} (correlation {best[0]:.2f}, against {rho:.2f} as "
            f"declared); check the gyro columns against the accelerometer columns, {hatch}")
    if 0.5 <= k <= 2.0:
        return record
    unit = _unit_for(gyro_units, k)
    if unit is None:
        record["warning"] = (f"imu_file: {name}: the specific force turns {k:.3g} times as far "
                             "as the gyros say (1 expected): check the gyro units and scale")
        return record
    fix = _fix(fmt, unit)
    raise ScenarioError(
        f"imu_file: {name}: gyro looks like {unit}, declared {gyro_units}: the specific force "
        f"turns {k:.3g} times as far as the gyros say (correlation {rho:.2f} over "
        f"{fit['windows']} windows of {WINDOW_S:g} s); {fix}, {hatch}")


def earth_rate_at_rest(name: str, dtheta: np.ndarray, dv: np.ndarray, ts: float, lat: float,
                       *, gyro_units: str, fmt: str) -> dict:
    """Relation 2 of the module docstring (`lat` in rad): ScenarioError when the mean rate
    of a recording at rest is the earth rate in other units. Returns what was found."""
    th, f, h = _blocks(dtheta, dv, ts)
    w = th / h
    if len(w) < 10:
        return {"judged": False, "why": "shorter than 10 s"}
    if float(f.std(axis=0).max()) > REST_STD_MPS2:
        return {"judged": False, "why": "not at rest"}
    mean = w.mean(axis=0)
    norm = float(np.linalg.norm(mean))
    up = f.mean(axis=0) / np.linalg.norm(f.mean(axis=0))
    angle = math.degrees(math.acos(max(-1.0, min(1.0, float(mean @ up) / norm)))) if norm \
        else 90.0
    expected = 90.0 - math.degrees(lat)
    ratio = norm / OMEGA_IE
    record = {"judged": True, "ratio_to_earth_rate": round(ratio, 4),
              "angle_from_up_deg": round(angle, 2), "expected_deg": round(expected, 2)}
    if abs(angle - expected) > REST_ANGLE_DEG or 0.5 <= ratio <= 2.0:
        return record
    unit = _unit_for(gyro_units, 1.0 / ratio)
    if unit is None:
        return record
    fix = _fix(fmt, unit)
    raise ScenarioError(
        f"imu_file: {name}: gyro looks like {unit}, declared {gyro_units}: at rest it reads "
        f"{ratio:.4g} times the earth rate (15.04 °/h), in the earth rate's direction "
        f"({angle:.1f}° from up, {expected:.1f}° expected); {fix}, or set imu_file "
        "check_consistency: false")


# ----------------------------------------------------------------------- a reference


MIN_TURN_RAD = math.radians(1.0)  #: windows in which the gyros turn at least this much


def _windows(t: np.ndarray, t0: float, t1: float, length: float) -> list[tuple[int, int]]:
    """Consecutive, non-overlapping pairs of indices of `t` about `length` apart within
    [t0, t1]."""
    inside = np.flatnonzero((t >= t0) & (t <= t1))
    out: list[tuple[int, int]] = []
    if len(inside) < 2:
        return out
    i = int(inside[0])
    last = int(inside[-1])
    while i < last:
        j = int(np.searchsorted(t, t[i] + length))
        if j > last:
            break
        out.append((i, j))
        i = j
    return out


def _rotation_angle(C: np.ndarray) -> float:
    return math.acos(max(-1.0, min(1.0, (float(np.trace(C)) - 1.0) / 2.0)))


def reference_against_gyros(name: str, ref_t: np.ndarray, ref_att: np.ndarray,
                            ref_lat: float, imu_t: np.ndarray, dtheta: np.ndarray,
                            fmt: str) -> dict:
    """A reference's attitude against the gyros: over windows of :data:`WINDOW_S` between
    its epochs, the angle its attitude turns by against the angle the gyros integrate (the
    earth rate taken off), compared as angles, so that a mounting between the reference's
    body and the IMU's does not matter. A reference whose attitude turns 57.3 times too
    little (radians read as degrees) or too much (degrees read as radians) is refused
    naming the likely fix. Returns what was found."""
    from gcalign.nav.rotation import euler_to_dcm

    ts = float(np.median(np.diff(imu_t)))
    pairs = _windows(ref_t, float(imu_t[0]) + ts, float(imu_t[-1]), WINDOW_S)
    cum = np.concatenate([np.zeros((1, 3)), np.cumsum(dtheta, axis=0)])
    w_ie = OMEGA_IE * np.array([0.0, math.cos(ref_lat), math.sin(ref_lat)])
    a_ref, a_gyro = [], []
    for i, j in pairs:
        C1, C2 = euler_to_dcm(ref_att[i]), euler_to_dcm(ref_att[j])
        k1 = int(np.searchsorted(imu_t, ref_t[i], side="right"))
        k2 = int(np.searchsorted(imu_t, ref_t[j], side="right"))
        theta = cum[k2] - cum[k1] - C1.T @ w_ie * (ref_t[j] - ref_t[i])
        a_ref.append(_rotation_angle(C1.T @ C2))
        a_gyro.append(float(np.linalg.norm(theta)))
    ar, ag = np.asarray(a_ref), np.asarray(a_gyro)
    turning = ag > MIN_TURN_RAD
    record: dict = {"judged": False, "windows": int(turning.sum())}
    if turning.sum() < 3:
        record["why"] = "the gyros turn too little between its epochs to judge"
        return record
    k = float(np.median(ar[turning] / ag[turning]))
    record.update(judged=True, k=round(k, 5))
    if 0.5 <= k <= 2.0:
        return record
    for factor, what, fix in (
            (1.0 / u.DEG, "radians, read as degrees",
             "give them in degrees (csv and i2nav-nav take degrees)"),
            (u.DEG, "degrees, read as radians", "give them in radians (psins-mat takes radians)")):
        if abs(math.log(k * factor)) < math.log(1 + FACTOR_TOL):
            raise ScenarioError(
                f"reference: {name}: its attitude looks like {what}: it turns {k:.3g} times as "
                f"far as the gyros over {int(turning.sum())} windows of {WINDOW_S:g} s; "
                f"{fix}, or set reference check_attitude: false")
    record["warning"] = (f"reference: {name}: its attitude turns {k:.3g} times as far as the "
                         "gyros (1 expected): check its angles and their units")
    return record


# ----------------------------------------------------------------------- velocity

MOVING_MPS = 2.0  #: epochs faster than this show the direction the vehicle moves in
TRACK_BLOCK_S = 0.1  #: the vertical is carried through blocks this long
VERTICAL_TAU_S = 20.0  #: time constant pulling the carried vertical toward the specific force
SMOOTH_S = 1.0  #: accelerations compared as 1-s means
MIN_TRACK_RHO = 0.3  #: the correlation the forward axis needs before it is judged


def _vertical(th: np.ndarray, f: np.ndarray, h: float) -> np.ndarray:
    """The up direction in the body frame at each block (n, 3): carried through the block
    rotations of the gyros (a vector fixed in the navigation frame turns as ``u − θ × u`` in
    the body) and pulled toward the specific force with the time constant
    :data:`VERTICAL_TAU_S`, so that a tilt the vehicle holds is followed and its
    accelerations average out (a numba kernel: a Python loop took 0.6 s an hour of data)."""
    from gcalign.io.recorded._kernel import carried_vertical

    u0 = f[:max(1, int(round(5.0 / h)))].mean(axis=0)
    return carried_vertical(th, f, u0 / np.linalg.norm(u0), h / VERTICAL_TAU_S)


def forward_axis(name: str, imu_t: np.ndarray, dtheta: np.ndarray, dv: np.ndarray,
                 vel_t: np.ndarray, v_n: np.ndarray, C_rfu_file: np.ndarray,
                 source: str) -> dict:
    """Which body axis the vehicle moves along, from a velocity reference or aiding: the
    horizontal specific force (the specific force less its part along the up direction the
    gyros carry, :func:`_vertical`) along and across each candidate forward axis (±x, ±y of
    the declared body) against the vehicle's accelerations along and across its track
    (from the velocities, at their own epochs; blocks more than two blocks from an epoch
    are left out). A land vehicle moves along its forward axis (+y); a recording in
    x-forward axes (FLU) declared y-forward (RFU), which nothing else sees (z is up either
    way, the gyros agree with the accelerometers), correlates on +x (the MEMS vehicle of
    transfer_align_fog_mems.mat: 0.49 on +y, 0.05 on x; rewritten in FLU, 0.49 on +x).
    Refused naming the likely axes; returns what was found."""
    from gcalign.io.recorded.axes import describe

    record: dict = {"judged": False}
    vel_t, v_n = np.asarray(vel_t, float), np.asarray(v_n, float)
    ts = float(np.median(np.diff(imu_t)))
    th, f, h = _blocks(dtheta, dv, ts, TRACK_BLOCK_S)
    n = len(th)
    if n < int(30 / h) or len(vel_t) < 3:
        record["why"] = "too short to judge"
        return record
    t_b = imu_t[0] - ts + h * (np.arange(n) + 0.5)
    U = _vertical(th, f, h)
    f_h = f - (f * U).sum(1)[:, None] * U
    ve, vn = np.interp(t_b, vel_t, v_n[:, 0]), np.interp(t_b, vel_t, v_n[:, 1])
    speed = np.hypot(ve, vn)
    j = np.clip(np.searchsorted(vel_t, t_b), 1, len(vel_t) - 1)
    near = np.minimum(np.abs(vel_t[j] - t_b), np.abs(t_b - vel_t[j - 1])) <= 2 * max(
        h, float(np.median(np.diff(vel_t))))
    ok = near & (t_b > vel_t[0] + h) & (t_b < vel_t[-1] - h) & (speed > MOVING_MPS)
    if ok.sum() < int(30 / h):
        record["why"] = f"less than 30 s faster than {MOVING_MPS:g} m/s"
        return record
    ae, an = np.gradient(ve, h), np.gradient(vn, h)
    ux, uy = ve / np.maximum(speed, 1e-9), vn / np.maximum(speed, 1e-9)
    k = np.ones(max(1, int(round(SMOOTH_S / h))))
    k /= len(k)

    def smooth(x):
        return np.convolve(x, k, mode="same")

    a = np.concatenate([smooth(ae * ux + an * uy)[ok], smooth(ae * uy - an * ux)[ok]])
    a = a - a.mean()
    fs = np.column_stack([smooth(f_h[:, i]) for i in range(3)])
    fits = []
    for label, F in (("+y", (0.0, 1.0, 0.0)), ("+x", (1.0, 0.0, 0.0)),
                     ("-y", (0.0, -1.0, 0.0)), ("-x", (-1.0, 0.0, 0.0))):
        Fh = np.asarray(F) - (U @ np.asarray(F))[:, None] * U
        Fh /= np.linalg.norm(Fh, axis=1)[:, None]
        R = np.cross(Fh, U)
        b = np.concatenate([(fs * Fh).sum(1)[ok], (fs * R).sum(1)[ok]])
        b = b - b.mean()
        fits.append((float(a @ b / math.sqrt(float(a @ a) * float(b @ b))), label))
    fits.sort(reverse=True)
    declared = next(x for x in fits if x[1] == "+y")
    record.update(judged=fits[0][0] >= MIN_TRACK_RHO, rho=round(declared[0], 4),
                  best=fits[0][1], best_rho=round(fits[0][0], 4), blocks=int(ok.sum()))
    if fits[0][0] < MIN_TRACK_RHO or fits[0][1] == "+y" or declared[0] >= 0.5 * fits[0][0]:
        return record
    fwd, right = {"+x": ((1.0, 0.0), (0.0, -1.0)), "-y": ((0.0, -1.0), (-1.0, 0.0)),
                  "-x": ((-1.0, 0.0), (0.0, 1.0))}[fits[0][1]]
    R_fix = np.array([[right[0], right[1], 0.0], [fwd[0], fwd[1], 0.0], [0.0, 0.0, 1.0]])
    likely = describe(R_fix @ C_rfu_file)
    # The fix first: the CLI cuts a long message, and the file names can be long.
    raise ScenarioError(
        f"imu_file: the vehicle moves along the body's {fits[0][1]} axis, not +y (forward): "
        f"the axes look like {likely}, declared {describe(C_rfu_file)}: give axes: "
        f"{likely.lower()}, or set imu_file check_consistency: false (accelerations along "
        f"and across the track of {source}: correlation {fits[0][0]:.2f}, against "
        f"{declared[0]:.2f} on +y; {name})")
