"""Loop gains by pole placement (seed 000 §2, eqs. 5-9): closed-loop roots vs designed poles.

Reference values are the designed poles themselves (physics of the loop), never earlier
output. Root matching uses the Hungarian assignment on |root − pole|, which is robust where
sorting is not (all three level poles share the real part −σ).

Double poles: a root of multiplicity 2 moves by ~sqrt(ε·|p|/|p''|) under a coefficient
perturbation ε, so ``numpy.roots`` of the quartic returns the double poles of both azimuth
designs with relative errors ~1e-8 in float64 — 1e-9 is not reachable that way. The double
poles are therefore checked by (1) the polynomial coefficients against the designed ones at
1e-12 relative, (2) p(r) ≈ 0 and p'(r) ≈ 0 at the designed double pole (multiplicity 2),
(3) deflation: dividing the closed-loop polynomial by one copy of the designed double factor
leaves a remainder ≈ 0 and a quotient with simple roots that equal the remaining designed
poles (including the second copy of the double pole) to < 1e-9 relative, and (4) the raw
``numpy.roots`` of the quartic at the sqrt(ε)-level tolerance 1e-6.
"""

import math

import numpy as np
import pytest
from lazy import lazy_attr

from gcalign.align import gains as G
from gcalign.nav import earth

linear_sum_assignment = lazy_attr("scipy.optimize", "linear_sum_assignment")

T_D = [10.0, 20.0, 50.0, 100.0, 200.0, 400.0]
XI = [0.3, 0.5, 0.707, 0.9]
GRID = [(t, x) for t in T_D for x in XI]
METHODS = ["double-oscillator", "oscillator-overdamped"]

LAT = math.radians(45.78)
GRAV = float(earth.gravity(LAT))
R_M = float(earth.radii(LAT)[0])


def freqs(t_d, xi):
    """ω_n, σ, ω_d from the definitions in DESIGN.md (independent of the module)."""
    wn = 2.0 * math.pi / (t_d * math.sqrt(1.0 - xi * xi))
    return wn, xi * wn, wn * math.sqrt(1.0 - xi * xi)


def designed_coeffs(t_d, xi, loop):
    """Designed characteristic polynomials, expanded by hand (highest power first)."""
    wn, s, wd = freqs(t_d, xi)
    if loop == "level":  # (s+σ)((s+σ)² + ω_d²), seed eq. 5
        return np.array([1.0, 3 * s, 3 * s * s + wd * wd, s**3 + s * wd * wd])
    if loop == "double-oscillator":  # (s² + 2σs + ω_n²)², seed eq. 8
        return np.array([1.0, 4 * s, 4 * s * s + 2 * wn * wn, 4 * s * wn * wn, wn**4])
    # (s + ω_n)²(s² + 2σs + ω_n²), seed eq. 9
    return np.array(
        [1.0, 2 * wn + 2 * s, 2 * wn * wn + 4 * s * wn, 2 * wn**3 + 2 * s * wn * wn, wn**4]
    )


def max_rel_root_error(roots, poles):
    """Largest |root − pole|/|pole| after the optimal one-to-one assignment."""
    cost = np.abs(roots[:, None] - poles[None, :])
    i, j = linear_sum_assignment(cost)
    assert len(i) == len(poles) == len(roots)
    return float(np.max(cost[i, j] / np.abs(poles[j])))


def rel_coeff_error(c, ref):
    return float(np.max(np.abs(c - ref) / np.abs(ref)))


def _azimuth(t_d, xi, method):
    gains = G.azimuth_gains(t_d, xi, GRAV, R_M, method)
    return gains, G.closed_loop_azimuth(gains, GRAV, R_M)


@pytest.mark.parametrize("t_d, xi", GRID)
def test_level_roots_equal_designed_poles(t_d, xi):
    gains = G.level_gains(t_d, xi, GRAV, R_M)
    coeffs = G.closed_loop_level(gains, GRAV, R_M)
    assert rel_coeff_error(coeffs, designed_coeffs(t_d, xi, "level")) < 1e-12
    wn, s, wd = freqs(t_d, xi)
    poles = np.array([-s, complex(-s, wd), complex(-s, -wd)])
    np.testing.assert_allclose(G.designed_poles_level(t_d, xi), poles, rtol=1e-15)
    assert max_rel_root_error(np.roots(coeffs), poles) < 1e-9
    assert gains.k1 > 0 and gains.k2 > -1 and gains.k3 > 0


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("t_d, xi", GRID)
def test_azimuth_coefficients_match_design(t_d, xi, method):
    gains, coeffs = _azimuth(t_d, xi, method)
    assert rel_coeff_error(coeffs, designed_coeffs(t_d, xi, method)) < 1e-12
    assert gains.k1 > 0 and gains.k2 > -1 and gains.k3 > 0 and gains.k4 > 0
    # The same polynomial from the designed poles (np.poly) agrees to round-off too.
    from_poles = np.poly(G.designed_poles_azimuth(t_d, xi, method))
    assert np.isrealobj(from_poles)  # conjugate pairs
    assert rel_coeff_error(coeffs, from_poles) < 1e-12


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("t_d, xi", GRID)
def test_azimuth_double_pole_has_multiplicity_two(t_d, xi, method):
    _, coeffs = _azimuth(t_d, xi, method)
    wn, s, wd = freqs(t_d, xi)
    double = complex(-s, wd) if method == "double-oscillator" else complex(-wn, 0.0)
    dcoeffs = np.polyder(coeffs)
    k = np.arange(len(coeffs) - 1, -1, -1)
    # Scales: sum of |terms| of p(r) and p'(r), the size of the round-off in evaluating them.
    scale_p = np.sum(np.abs(coeffs) * abs(double) ** k)
    scale_dp = np.sum(np.abs(dcoeffs) * abs(double) ** k[1:])
    assert abs(np.polyval(coeffs, double)) / scale_p < 1e-13
    assert abs(np.polyval(dcoeffs, double)) / scale_dp < 1e-12


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("t_d, xi", GRID)
def test_azimuth_roots_by_deflation(t_d, xi, method):
    _, coeffs = _azimuth(t_d, xi, method)
    wn, s, wd = freqs(t_d, xi)
    pair = [complex(-s, wd), complex(-s, -wd)]
    if method == "double-oscillator":
        factor = np.array([1.0, 2 * s, wn * wn])  # one copy of (s² + 2σs + ω_n²)
        rest = np.array(pair)
    else:
        factor = np.array([1.0, wn])  # one copy of (s + ω_n)
        rest = np.array([complex(-wn, 0.0)] + pair)
    quotient, remainder = np.polydiv(coeffs, factor)
    assert np.max(np.abs(remainder)) / coeffs[-1] < 1e-12
    assert max_rel_root_error(np.roots(quotient), rest) < 1e-9


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("t_d, xi", GRID)
def test_azimuth_raw_roots_at_double_root_tolerance(t_d, xi, method):
    _, coeffs = _azimuth(t_d, xi, method)
    poles = G.designed_poles_azimuth(t_d, xi, method)
    assert max_rel_root_error(np.roots(coeffs), poles) < 1e-6  # ~sqrt(ε): double roots


@pytest.mark.parametrize("t_d, xi", GRID)
def test_double_oscillator_is_the_seed_closed_form(t_d, xi):
    wn, s, _ = freqs(t_d, xi)
    gains = G.azimuth_gains(t_d, xi, GRAV, R_M, "double-oscillator")
    ws2 = GRAV / R_M
    # seed: K_U1 = K_U4 = 2σ, K_U2 = 2σ²/(ξω_s)² − 1, K_U3 = σ⁴/(ξ⁴ g)
    ref = [2 * s, 2 * s * s / (xi * xi * ws2) - 1, s**4 / (xi**4 * GRAV), 2 * s]
    np.testing.assert_allclose([gains.k1, gains.k2, gains.k3, gains.k4], ref, rtol=1e-13)


@pytest.mark.parametrize("t_d, xi", GRID)
def test_seed_closed_form_for_method_b_misses_the_design(t_d, xi):
    """Seed eq. 9 prints K_U1 = 2ω_n, K_U2 = 2σ²/(ξω_s)² − 1, K_U3 = σ⁴/(ξ⁴g), K_U4 = 2σ.

    (The extracted text reads 2σ²/(ξω_n)² − 1, which is identically 1; read as for method
    a.) Built into eq. 7 it reproduces the s³, s² and s⁰ coefficients of
    (s+ω_n)²(s²+2σs+ω_n²) but its s¹ coefficient is 4σω_n² instead of 2ω_n²(ω_n+σ),
    short by 2ω_n³(1−ξ), a relative error (1−ξ)/(1+ξ) (5 % to 54 % on this grid).
    """
    wn, s, _ = freqs(t_d, xi)
    ws2 = GRAV / R_M
    seed = G.AzimuthGains(
        k1=2 * wn, k2=2 * s * s / (xi * xi * ws2) - 1, k3=s**4 / (xi**4 * GRAV), k4=2 * s
    )
    coeffs = G.closed_loop_azimuth(seed, GRAV, R_M)
    ref = designed_coeffs(t_d, xi, "oscillator-overdamped")
    np.testing.assert_allclose(coeffs[[0, 1, 2, 4]], ref[[0, 1, 2, 4]], rtol=1e-12)
    np.testing.assert_allclose(coeffs[3] - ref[3], -2 * wn**3 * (1 - xi), rtol=1e-9)
    assert abs(coeffs[3] - ref[3]) / ref[3] > 0.05
    poles = G.designed_poles_azimuth(t_d, xi, "oscillator-overdamped")
    assert max_rel_root_error(np.roots(coeffs), poles) > 0.05
    # The literal reading K_U2 = 2σ²/(ξω_n)² − 1 = 1 is further off still.
    literal = G.AzimuthGains(k1=seed.k1, k2=1.0, k3=seed.k3, k4=seed.k4)
    lit = G.closed_loop_azimuth(literal, GRAV, R_M)
    assert rel_coeff_error(lit, ref) > 0.5


@pytest.mark.parametrize("xi", XI)
def test_method_b_gains_scale_with_omega_n(xi):
    """The cubic in x = K_U4/ω_n depends on ξ only: K_U1/ω_n, K_U4/ω_n do not change with T_d."""
    ratios = []
    for t_d in T_D:
        wn, _, _ = freqs(t_d, xi)
        g = G.azimuth_gains(t_d, xi, GRAV, R_M, "oscillator-overdamped")
        ratios.append([g.k1 / wn, g.k4 / wn, (1 + g.k2) * GRAV / R_M / wn**2])
    ratios = np.array(ratios)
    np.testing.assert_allclose(ratios, np.broadcast_to(ratios[0], ratios.shape), rtol=1e-13)
    x = ratios[0, 1]
    assert abs(x**3 - 2 * (1 + xi) * x**2 + (2 + 4 * xi) * x - 2 * (1 + xi)) < 1e-14


def test_method_aliases():
    for alias, name in [("a", "double-oscillator"), ("b", "oscillator-overdamped")]:
        assert G.azimuth_gains(100, 0.707, GRAV, R_M, alias) == G.azimuth_gains(
            100, 0.707, GRAV, R_M, name
        )


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(t_d=0.0), r"t_d \(damped period, s\) must be a finite number > 0, got 0.0"),
        (dict(t_d=-5), r"t_d .* got -5"),
        (dict(t_d=float("nan")), r"t_d .* got nan"),
        (dict(t_d="ten"), r"t_d .* got 'ten'"),
        (dict(xi=0.0), r"xi \(damping ratio\) must be a number with 0 < xi < 1, got 0.0"),
        (dict(xi=1.0), r"xi .* got 1.0"),
        (dict(g=0.0), r"g \(gravity, m/s²\) must be a finite number > 0, got 0.0"),
        (dict(r=-1.0), r"r \(earth radius, m\) .* got -1.0"),
    ],
)
def test_validation_names_field_value_and_range(kwargs, match):
    args = dict(t_d=100.0, xi=0.707, g=GRAV, r=R_M) | kwargs
    with pytest.raises(ValueError, match=match):
        G.level_gains(**args)
    with pytest.raises(ValueError, match=match):
        G.azimuth_gains(**args, method="oscillator-overdamped")


def test_validation_of_method():
    msg = r"method must be one of 'double-oscillator', 'oscillator-overdamped', .*got 'c'"
    with pytest.raises(ValueError, match=msg):
        G.azimuth_gains(100.0, 0.707, GRAV, R_M, "c")
    with pytest.raises(ValueError, match="method"):
        G.designed_poles_azimuth(100.0, 0.707, None)
