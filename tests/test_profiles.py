"""MDR profiles against their exact transforms; the tabulated transform against the analytic shapes."""

import math

import numpy as np
import pytest
from scipy import integrate

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.profiles import (
    Cone,
    FlatPunch,
    PowerLaw,
    Sphere,
    Tabulated,
    make_profile,
    power_law_kappa,
)

ANALYTIC = {
    "sphere": Sphere(radius=2e-3),
    "cone": Cone(half_angle=math.radians(80.0)),
    "power_law_n3": PowerLaw(coefficient=4e5, exponent=3.0),
    "power_law_n1.5": PowerLaw(coefficient=2e-1, exponent=1.5),
    "power_law_n0.7": PowerLaw(coefficient=1e-3, exponent=0.7),
}


def abel_quadrature(profile, x: float) -> float:
    """MDR transform by adaptive quadrature with the r = x sin t substitution (independent of
    the closed forms under test): g(x) = x int_0^{pi/2} f'(x sin t) dt, f' by central difference."""
    step = 1e-7 * x

    def slope(r: float) -> float:
        return (float(profile.f(r + step)) - float(profile.f(max(r - step, 0.0)))) / (
            r + step - max(r - step, 0.0)
        )

    value, _ = integrate.quad(lambda t: slope(x * math.sin(t)), 0.0, math.pi / 2, epsabs=0, epsrel=1e-10)
    return x * value


@pytest.mark.parametrize("name", sorted(ANALYTIC))
def test_analytic_g_is_the_abel_transform_of_f(name):
    profile = ANALYTIC[name]
    for x in (1e-5, 3e-4, 1e-3):
        np.testing.assert_allclose(
            profile.g(x), abel_quadrature(profile, x), rtol=1e-6, err_msg=f"{name} at x={x}"
        )


@pytest.mark.parametrize("name", sorted(ANALYTIC))
def test_g_integral_and_inverse(name):
    profile = ANALYTIC[name]
    a = np.array([1e-5, 2e-4, 1.5e-3])
    expected = [
        integrate.quad(lambda x: float(profile.g(x)), 0, v, epsabs=0, epsrel=1e-12, limit=200)[0] for v in a
    ]
    np.testing.assert_allclose(profile.g_integral(a), expected, rtol=1e-9, err_msg=name)
    np.testing.assert_allclose(profile.radius_at_height(profile.g(a)), a, rtol=1e-12, err_msg=name)
    np.testing.assert_allclose(profile.g(-a), profile.g(a), rtol=0, err_msg=f"{name} symmetry")


def test_kappa_special_values():
    assert power_law_kappa(1.0) == pytest.approx(math.pi / 2, rel=1e-14)
    assert power_law_kappa(2.0) == pytest.approx(2.0, rel=1e-14)
    # power law n = 2 with c = 1/(2R) is the sphere
    np.testing.assert_allclose(
        PowerLaw(coefficient=1 / (2 * 2e-3), exponent=2.0).g([1e-4, 1e-3]),
        Sphere(radius=2e-3).g([1e-4, 1e-3]),
        rtol=1e-13,
    )


def test_flat_punch():
    punch = FlatPunch(radius=1e-3)
    np.testing.assert_array_equal(punch.g([0.0, 5e-4, 1e-3, 1.1e-3]), [0, 0, 0, np.inf])
    assert punch.punch_radius == 1e-3
    np.testing.assert_array_equal(punch.radius_at_height([0.0, 1e-6]), [1e-3, 1e-3])


def tabulate(profile, extent: float, samples: int) -> Tabulated:
    radius = np.linspace(0.0, extent, samples)
    return Tabulated(table_radius=radius, table_height=profile.f(radius))


@pytest.mark.parametrize("name", sorted(set(ANALYTIC) - {"cone"}))
def test_table_converges_to_analytic_profile(name):
    """The tabulated transform converges to the analytic one. In the max norm the order is
    1.5: each kink of the piecewise-linear f gives g a sqrt-type kink."""
    profile = ANALYTIC[name]
    x = np.linspace(0.0, 1e-3, 57)
    scale = float(profile.g(1e-3))
    errors = []
    for samples in (201, 401):
        table = tabulate(profile, 1e-3, samples)
        errors.append(np.max(np.abs(table.g(x) - profile.g(x))) / scale)
        np.testing.assert_allclose(
            table.g_integral(x), profile.g_integral(x), atol=2e-3 * scale * 1e-3, err_msg=name
        )
    assert errors[1] < 2e-3, f"{name}: tabulated g off by {errors[1]:.2e} of g(x_max)"
    if name != "power_law_n0.7":  # the singular slope at r=0 limits that case to lower order
        assert errors[1] < errors[0] / 2.5, f"{name}: no order-1.5 convergence {errors}"


def test_table_is_exact_for_piecewise_linear_profile():
    """A cone sampled at two points is a cone: the transform is exact, also beyond the table."""
    cone = Cone(half_angle=math.radians(60.0))
    table = Tabulated(table_radius=[0.0, 1e-3], table_height=cone.f([0.0, 1e-3]))
    x = np.array([0.0, 1e-4, 1e-3, 5e-3])
    np.testing.assert_allclose(table.g(x), cone.g(x), rtol=1e-14, err_msg="sampled cone")
    np.testing.assert_allclose(table.g_integral(x), cone.g_integral(x), rtol=1e-13)
    np.testing.assert_allclose(table.radius_at_height(cone.g(x)), x, rtol=1e-12, atol=1e-18)
    assert table.closed_form_available is False
    assert table.characteristic_radius == 1e-3


def test_table_g_integral_matches_quadrature_of_g():
    """Against a fine trapezoid rule (adaptive quadrature trips over the kinks of g)."""
    table = tabulate(Sphere(radius=1e-3), 5e-4, 7)
    for a in (1e-4, 4.9e-4, 8e-4):
        x = np.linspace(0.0, a, 400_001)
        expected = integrate.trapezoid(table.g(x), x)
        assert float(table.g_integral(a)) == pytest.approx(expected, rel=1e-8), f"a={a}"


@pytest.mark.parametrize(
    ("radius", "height", "match"),
    [
        ([0.0, 1e-3, 0.5e-3], [0.0, 1e-6, 2e-6], r"table_radius must be strictly increasing"),
        ([0.0, 1e-3, 2e-3], [0.0, 2e-6, 1e-6], r"table_height must be non-decreasing"),
        ([1e-4, 1e-3], [0.0, 1e-6], r"table_radius\[0\] must be 0"),
        ([0.0, 1e-3], [1e-7, 1e-6], r"table_height\[0\] must be 0"),
        ([0.0, 1e-3], [0.0, 1e-6, 2e-6], r"same length"),
        ([0.0, np.nan], [0.0, 1e-6], r"table_radius\[1\] must be finite"),
        ([0.0], [0.0], r"at least 2 samples"),
        ([0.0, 1e-3], [0.0, 0.0], r"rise above 0"),
    ],
)
def test_bad_tables_name_the_key(radius, height, match):
    with pytest.raises(InputError, match=match):
        Tabulated(table_radius=radius, table_height=height)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: Sphere(radius=-1.0), r"indenter.radius must be > 0"),
        (lambda: Sphere(radius=np.inf), r"indenter.radius must be finite"),
        (lambda: Cone(half_angle=math.pi / 2), r"indenter.half_angle must be < pi/2"),
        (lambda: Cone(half_angle=0.0), r"indenter.half_angle must be > 0"),
        (lambda: PowerLaw(coefficient=1.0, exponent=-2.0), r"indenter.exponent must be > 0"),
        (lambda: FlatPunch(radius=float("nan")), r"indenter.radius must be finite"),
    ],
)
def test_bad_parameters_name_the_key(make, match):
    with pytest.raises(InputError, match=match):
        make()


def test_make_profile_dispatch():
    class Indenter:
        shape = "cone"
        radius = 0.0
        half_angle = 1.0
        coefficient = 0.0
        exponent = 0.0
        table_radius = ()
        table_height = ()

    assert make_profile(Indenter()).kind == "cone"
    Indenter.shape = "ellipsoid"
    with pytest.raises(InputError, match="indenter.shape"):
        make_profile(Indenter())
