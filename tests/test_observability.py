"""Observability (gcalign.estimation.observability, gcalign.calibrate.observability) against
the physics of spec 002 §6 (items 2–8): the static null space in closed form, the classic
10-state static rank 7, δλ unobservable with velocity matching, heading and scale-factor
excitation by manoeuvres, and the SOM/TOM rank theorem (seed eq. 12) on systems built so
that its condition holds or fails.
"""

from __future__ import annotations

import numpy as np
import pytest
from calibrate_cases import designed, site

from gcalign.calibrate import observability_table
from gcalign.calibrate.observability import pieces
from gcalign.errors import ScenarioError
from gcalign.estimation import ins_error as ie
from gcalign.estimation import observability as ob
from gcalign.nav import earth
from gcalign.nav.rotation import euler_to_dcm

I = ie.IDX


SITE = site()


@pytest.fixture(scope="module")
def flight():
    """The designed flight (configs/seed002_designed.yaml), navigation rate 25 Hz."""
    return designed()


@pytest.fixture(scope="module")
def table(flight):
    return observability_table(flight.truth, flight.segments, "velocity", "none")


def _seg(tab) -> dict[str, int]:
    """Segment name -> index of its first occurrence (the flight has five 'cruise')."""
    out: dict[str, int] = {}
    for i, n in enumerate(tab.segments):
        out.setdefault(n, i)
    return out


def _static(att, lat=SITE[0]):
    """F of a vehicle at rest with attitude `att`; also C_nb, ω_ie^n and f^n."""
    C = euler_to_dcm(att)
    w_n = earth.omega_ie_n(lat)
    f_n = np.array([0.0, 0.0, float(earth.gravity(lat))])
    F = ie.error_matrix(C, C.T @ f_n, C.T @ w_n, np.zeros(3), [lat, 0.3, 0.0])
    return F, C, w_n, f_n


@pytest.mark.parametrize("att_deg", [(0, 0, 0), (3, -2, 40), (-10, 25, -130)])
def test_static_null_space(att_deg):
    """Spec §6 item 3: x = (φ, 0, 0, ε^b = −C_n^b(ω_ie^n×φ), ∇^b = −C_n^b(f^n×φ), 0, 0) gives
    O x = 0 (1e-12 relative) for any φ, and its biases in ENU are DESIGN's static steady
    state: φE = −∇N/g, φN = ∇E/g, φU = −εE/(Ω cos L) + φN tan L."""
    F, C, w_n, f_n = _static(np.radians(att_deg))
    O = ob.piece_matrix(F, ie.measurement_matrix("velocity", SITE))
    rng = np.random.default_rng(5)
    lat, g, Om = SITE[0], f_n[2], earth.OMEGA_IE
    for _ in range(5):
        phi = rng.normal(size=3) * 1e-3
        x = np.zeros(21)
        x[ie.PHI] = phi
        x[ie.EB] = -C.T @ np.cross(w_n, phi)
        x[ie.DB] = -C.T @ np.cross(f_n, phi)
        assert np.linalg.norm(O @ x) <= 1e-12 * np.linalg.norm(O, 2) * np.linalg.norm(x)
        eps_n, nab_n = C @ x[ie.EB], C @ x[ie.DB]
        assert phi[0] == pytest.approx(-nab_n[1] / g, rel=1e-12)
        assert phi[1] == pytest.approx(nab_n[0] / g, rel=1e-12)
        assert phi[2] == pytest.approx(-eps_n[0] / (Om * np.cos(lat)) + phi[1] * np.tan(lat),
                                       rel=1e-9)
    # a one-term change (f^n×φ with the wrong sign) is not in the null space
    x[ie.DB] = +C.T @ np.cross(f_n, phi)
    assert np.linalg.norm(O @ x) > 1e-3 * np.linalg.norm(O, 2) * np.linalg.norm(x)


def test_static_level_yaw0_scale_factor_columns():
    """Spec §6 item 3: level at yaw 0, ω_ib^b = ω_ie^n has no x part and f^b = [0, 0, g]:
    the δKgx, δKax, δKay columns of O vanish, δKgy = ω_y εy, δKgz = ω_z εz, δKaz = g ∇z."""
    F, C, w_n, f_n = _static(np.zeros(3))
    O = ob.piece_matrix(F, ie.measurement_matrix("velocity", SITE))
    for k in ("dKgx", "dKax", "dKay"):
        assert np.all(O[:, I[k]] == 0.0)
    np.testing.assert_allclose(O[:, I["dKgy"]], w_n[1] * O[:, I["eby"]], rtol=1e-12, atol=0)
    np.testing.assert_allclose(O[:, I["dKgz"]], w_n[2] * O[:, I["ebz"]], rtol=1e-12, atol=0)
    np.testing.assert_allclose(O[:, I["dKaz"]], f_n[2] * O[:, I["dbz"]], rtol=1e-12, atol=0)


@pytest.mark.parametrize("yaw_deg", [0.0, 37.0, -120.0])
def test_classic_ten_state_static_model_has_rank_7(yaw_deg):
    """Spec §6 item 4 (Bar-Itzhack & Berman): φ, δvE, δvN, ∇E, ∇N, εE, εN, εU observed
    through δvE, δvN at rest has rank 7 (null space: the three φ–bias pairs)."""
    F21, C, _, _ = _static(np.radians([0.0, 0.0, yaw_deg]))
    keep = [0, 1, 2, 3, 4]
    F = np.zeros((10, 10))
    F[:5, :5] = F21[np.ix_(keep, keep)]
    F[3:5, 5:7] = np.eye(2)  # ∇E, ∇N in the navigation frame
    F[0:3, 7:10] = -np.eye(3)  # ε in the navigation frame
    H = np.zeros((2, 10))
    H[0, 3] = H[1, 4] = 1.0
    assert ob.degree(ob.piece_matrix(F, H), measured=[3, 4]).rank == 7
    # the same from the 21-state F with the biases rotated to ENU (level, so C is a yaw)
    F_b = np.zeros((10, 10))
    F_b[:5, :5] = F[:5, :5]
    F_b[:5, 5:7] = F21[np.ix_(keep, [12, 13])] @ np.linalg.inv(C[:2, :2])
    F_b[:5, 7:10] = F21[np.ix_(keep, [9, 10, 11])] @ C.T
    np.testing.assert_allclose(F_b, F, atol=1e-15)


def test_delta_lambda_unobservable_with_velocity(flight, table):
    """Spec §6 item 2: the δλ column of F is zero, so with velocity matching δλ is in the
    null space of every piece: η_δλ = 0 in every segment and cumulatively, rank ≤ 20
    (reached); position matching observes it."""
    pc = pieces(flight.truth, flight.segments)
    O = ob.piece_matrix(pc.F, ie.measurement_matrix("velocity", SITE))
    assert np.all(O[:, :, I["dlam"]] == 0.0)
    assert np.all(table.eta[:, I["dlam"]] == 0.0) and np.all(table.eta_cum[:, I["dlam"]] == 0)
    assert table.rank.max() <= 20 and table.rank_cum[-1] == 20
    pos = observability_table(flight.truth, flight.segments, "position", covariance=False)
    assert np.all(pos.eta[:, I["dlam"]] > 0)


def test_rank_rises_with_manoeuvres_and_a_turn_lifts_heading(table):
    """Spec §6 item 5: at rest φU is tied to εE (η_φU = 0); the ground roll and the turns
    make it observable (η_φU up by orders of magnitude over level cruise and the climb); the
    cumulative rank rises static → ground roll → pitch-up and reaches 20 there."""
    seg = _seg(table)
    rc = table.rank_cum
    assert rc[seg["static"]] < rc[seg["ground roll"]] < rc[seg["pitch-up"]] == 20
    eta_u = table.eta[:, I["phiU"]]
    level = max(eta_u[seg["cruise 100 m/s"]], eta_u[seg["climb 60 deg"]])
    assert eta_u[seg["static"]] == 0.0
    for lifted in ("ground roll", "left turn 180", "right turn 90", "left turn 90"):
        assert eta_u[seg[lifted]] >= 100 * level
    assert eta_u[seg["right turn 90"]] > 1e3 * eta_u[seg["cruise 100 m/s"]]


def _cumulative_separation(flight, k: str, j: str) -> np.ndarray:
    pc = pieces(flight.truth, flight.segments)
    O = ob.piece_matrix(pc.F, ie.measurement_matrix("velocity", SITE))
    return np.array([ob.separation(ob.som(O[pc.segment <= i]), I[k], I[j])
                     for i in range(len(flight.segments))])


@pytest.mark.parametrize(
    ("k", "j", "first", "threshold"),
    [
        ("dKgx", "ebx", "pitch-up", 1e-3),  # rotation about body x
        ("dKgy", "eby", "roll left", 1e-3),  # about body y (forward)
        ("dKgz", "ebz", "left turn 180", 1e-3),  # about body z
        ("dKax", "dbx", "left turn 180", 0.1),  # f_x changes: the turn's 26 m/s², the bank
        ("dKay", "dby", "ground roll", 0.1),  # f_y changes: the take-off acceleration
        ("dKaz", "dbz", "pitch-up", 0.1),  # f_z changes: pull-up
    ],
)
def test_scale_factor_separates_only_under_its_excitation(flight, k, j, first, threshold):
    """Spec §6 item 6. In a piece with constant ω the δKg_i column is ω_i times the ε_i
    column, so the two separate only where ω_i changes; the separation (the part of one
    column not explained by the other, in rad/s for δKg|ε, m/s² for δKa|∇) of the
    cumulative SOM first exceeds 1e-3 rad/s (earth and transport rates stay below 1e-4
    rad/s) or 0.1 m/s² at the first manoeuvre that changes ω_i or f_i, and jumps there."""
    sep = _cumulative_separation(flight, k, j)
    names = [s.name for s in flight.segments]
    i = names.index(first)
    assert np.flatnonzero(sep > threshold)[0] == i, dict(zip(names, sep.round(6), strict=True))
    assert sep[i] > 100 * sep[i - 1]


def test_gyro_scale_factor_degree_per_segment_p0(flight):
    """Spec §6 item 6 in the seed's terms, with states scaled by P0 (unscaled, the argmax
    association mixes δKg with ε and ∇): η_δKg_i in the manoeuvre that rotates about i is
    ≥ 10² × its value in level cruise."""
    tab = observability_table(flight.truth, flight.segments, "velocity", "p0",
                              covariance=False)
    seg = _seg(tab)
    for k, manoeuvre in (("dKgx", "pitch-up"), ("dKgy", "roll left"),
                         ("dKgz", "left turn 180")):
        level = max(tab.eta[seg["cruise 100 m/s"], I[k]], tab.eta[seg["cruise"], I[k]])
        assert tab.eta[seg[manoeuvre], I[k]] > 0
        assert tab.eta[seg[manoeuvre], I[k]] >= 100 * level


def test_accelerometer_biases_rise_in_pitch_up_and_roll(table):
    """Spec §5, §6 item 7: ∇x, ∇y are unobservable at rest (tied to the level tilts) and
    rise in the pitch-up and roll; ∇z is tiny in level flight and larger in pitch-up, roll."""
    seg = _seg(table)
    eta = table.eta
    for k in ("dbx", "dby"):
        assert eta[seg["static"], I[k]] == 0.0
        assert eta[seg["pitch-up"], I[k]] > 0 and eta[seg["roll left"], I[k]] > 0
    level = max(eta[seg["cruise 100 m/s"], I["dbz"]], eta[seg["cruise"], I["dbz"]])
    assert eta[seg["pitch-up"], I["dbz"]] > 100 * max(level, 1e-300)
    assert eta[seg["roll left"], I["dbz"]] > 100 * max(level, 1e-300)


def _rank(A: np.ndarray) -> int:
    return ob.degree(A, measured=[0]).rank


def test_som_equals_tom_where_the_null_space_condition_holds():
    """Seed eq. (12) on systems built for it. (a) Random pieces whose unobservable states
    have zero columns of F, so null(O_j) ⊂ null(F_j): SOM rank = TOM rank. (b) ḃ = 0, ċ = b
    alternating with ȧ = c, a measured: null(O_1) = {b, c} is not in null(F_1); the SOM
    never sees b (rank 2) while the TOM does (rank 3)."""
    rng = np.random.default_rng(8)
    H = np.zeros((1, 6))
    H[0, 0] = 1.0
    for _ in range(20):
        Fs, Os = [], []
        for _ in range(4):
            F = rng.normal(size=(6, 6))
            F[:, rng.choice(np.arange(1, 6), size=2, replace=False)] = 0.0
            O = ob.piece_matrix(F, H)
            assert ob.null_space_residual(O, F) < 1e-12
            Fs.append(F)
            Os.append(O)
        assert _rank(ob.som(Os)) == _rank(ob.tom(Os, Fs, [0.5] * 4))
    F1 = np.zeros((3, 3))
    F1[2, 1] = 1.0
    F2 = np.zeros((3, 3))
    F2[0, 2] = 1.0
    H = np.array([[1.0, 0.0, 0.0]])
    Fs = [F1, F2, F1, F2]
    Os = [ob.piece_matrix(F, H) for F in Fs]
    assert ob.null_space_residual(Os[0], F1) > 0.5
    assert _rank(ob.som(Os)) == 2 and _rank(ob.tom(Os, Fs, [1.0] * 4)) == 3


def test_flight_segments_where_the_condition_holds(flight):
    """On the flight: wherever the condition holds (the static segment, in P0 units), the
    SOM and TOM ranks agree; elsewhere they may not (reported, not asserted)."""
    tab = observability_table(flight.truth, flight.segments, "velocity", "p0",
                              covariance=False)
    assert tab.condition[0] and tab.segments[0] == "static"
    assert np.all(tab.rank[tab.condition] == tab.tom_rank[tab.condition])


def test_covariance_degree_of_constant_states_never_falls(table):
    """Spec §6 item 11: σ of a constant state never increases, so σ_k(0)/σ_k(t) ≥ 1 and is
    non-decreasing along the run for the twelve sensor errors."""
    cd = table.cov_degree[:, ie.IMU]
    assert np.all(cd >= 1.0 - 1e-12)
    assert np.all(np.diff(cd, axis=0) >= -1e-9)


def test_degree_definition_on_a_closed_form():
    """η = σ_(k)/σ_0 with the association argmax |v_i|: a diagonal O has σ_i = |d_i|
    owned by state i; a zero column has η = 0; σ below the rank tolerance counts as 0."""
    Q = np.diag([2.0, 0.5, 1e-14, 0.0])
    d = ob.degree(Q, measured=[0])
    np.testing.assert_allclose(d.eta, [1.0, 0.25, 0.0, 0.0])
    assert d.rank == 2 and list(d.owner[:2]) == [0, 1]
    d = ob.degree(Q, measured=[0], scale=[1.0, 1.0, 1e13, 1.0])
    assert d.rank == 3 and d.eta[2] == pytest.approx(0.05)


def test_rank_margin_on_a_closed_form():
    """The margin is the smaller of σ_rank/cut and cut/σ_rank+1 (cut = rtol·σ_max): on
    diag(2, 0.5, 1e-14, 0) with rtol 1e-12 the cut is 2e-12, the last kept value 0.5 (×2.5e11
    above) and the first dropped 1e-14 (×200 below); a full-rank matrix has only the first."""
    d = ob.degree(np.diag([2.0, 0.5, 1e-14, 0.0]), measured=[0], rtol=1e-12)
    assert d.margin == pytest.approx(200.0)
    d = ob.degree(np.diag([2.0, 0.5, 1e-11]), measured=[0], rtol=1e-12)
    assert d.rank == 3 and d.margin == pytest.approx(1e-11 / 2e-12)
    d = ob.degree(np.diag([2.0, 0.0]), measured=[0], rtol=1e-12)
    assert d.margin == pytest.approx(1.0 / 1e-12)


def test_table_carries_the_rank_margins(table):
    """Each segment's and each cumulative rank has its margin (> 1: the rank is above the
    cut-off and the next value below it)."""
    assert table.margin.shape == table.rank.shape == table.margin_cum.shape
    assert np.all(table.margin > 1.0) and np.all(table.margin_cum > 1.0)


def test_bad_table_input(flight):
    data = flight
    for kwargs, field in (({"scaling": "sigma"}, "scaling"), ({"rtol": 0.0}, "rtol"),
                          ({"piece_s": -1.0}, "piece_s"), ({"measure": "heading"}, "measure")):
        with pytest.raises(ScenarioError) as exc:
            observability_table(data.truth, data.segments, **kwargs)
        assert str(exc.value).startswith(field) and "\n" not in str(exc.value)


def test_expm_stack_and_r_factor_equal_the_lapack_routes(flight):
    """The observability table avoids LAPACK's tall and threaded paths (they collapse on a
    shared machine); its matrix exponential and triangular factor agree with scipy's expm
    and numpy's SVD to 1e-12 on the flight's own F (entries from 1e-13 to 26)."""
    from scipy.linalg import expm

    pc = pieces(flight.truth, flight.segments)
    E = ob.expm_stack(pc.F[::20] * pc.duration[::20, None, None])
    for Fj, dj, Ej in zip(pc.F[::20], pc.duration[::20], E, strict=True):
        ref = expm(Fj * dj)
        np.testing.assert_allclose(Ej, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    A = ob.som(ob.piece_matrix(pc.F[:200], ie.measurement_matrix("velocity", SITE)))
    R = ob.r_factor(A)
    assert R.shape == (21, 21)
    s_ref = np.linalg.svd(A, compute_uv=False)
    np.testing.assert_allclose(np.linalg.svd(R, compute_uv=False), s_ref, rtol=1e-10,
                               atol=1e-13 * s_ref[0])
