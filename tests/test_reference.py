"""Closed forms checked against each other, against the MDR integral and against quadrature;
energy criterion against the physics notes."""

import math

import numpy as np
import pytest
from scipy import integrate

from viscoadh_ros.core import reference as ref
from viscoadh_ros.core.criterion import (
    critical_edge_speeds,
    critical_glass_elongation,
    scale_separation_holds,
    work_of_adhesion_detaching,
    work_of_adhesion_indenting,
)
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.profiles import Cone, FlatPunch, PowerLaw, Sphere
from viscoadh_ros.core.rheology import CreepElement

# (R m, E* Pa, w J/m^2) over the scales the product is meant for
SPHERES = [(2e-3, 4e6, 0.05), (1e-6, 1e9, 1e-3), (0.5, 1e5, 10.0)]


def standard_solid(g0=1e6, g1=1e4, eta1=1e3, nu=0.5) -> CreepElement:
    return CreepElement(
        glass_shear_modulus=g0,
        kelvin_shear_moduli=np.array([g1]),
        kelvin_viscosities=np.array([eta1]),
        poisson_ratio=nu,
    )


@pytest.mark.parametrize(("radius", "modulus", "work"), SPHERES)
def test_jkr_without_adhesion_is_hertz(radius, modulus, work):
    a = np.linspace(0.0, 1e-2 * radius, 11)
    depth = ref.jkr_depth(a, radius, modulus, 0.0)
    np.testing.assert_allclose(ref.hertz_radius(depth, radius), a, rtol=1e-12, err_msg=f"R={radius}")
    np.testing.assert_allclose(
        ref.jkr_force(a, radius, modulus, 0.0),
        ref.hertz_force(depth, radius, modulus),
        rtol=1e-12,
        err_msg=f"R={radius}",
    )


@pytest.mark.parametrize(("radius", "modulus", "work"), SPHERES)
def test_general_mdr_curve_is_jkr_for_a_sphere(radius, modulus, work):
    a = np.linspace(0.0, 1e-2 * radius, 21)
    depth, force = ref.mdr_adhesive_curve(Sphere(radius=radius), a, modulus, work)
    np.testing.assert_allclose(
        depth, ref.jkr_depth(a, radius, modulus, work), rtol=1e-12, atol=1e-25, err_msg="depth"
    )
    np.testing.assert_allclose(
        force, ref.jkr_force(a, radius, modulus, work), rtol=1e-12, atol=1e-25, err_msg="force"
    )


def test_general_mdr_curve_without_adhesion_is_sneddon_and_power_law():
    cone = Cone(half_angle=math.radians(70.0))
    d = np.array([1e-6, 1e-5, 3e-4])
    depth, force = ref.mdr_adhesive_curve(cone, ref.sneddon_cone_radius(d, cone.half_angle), 2e6, 0.0)
    np.testing.assert_allclose(depth, d, rtol=1e-12, err_msg="cone depth")
    np.testing.assert_allclose(
        force, ref.sneddon_cone_force(d, cone.half_angle, 2e6), rtol=1e-12, err_msg="Sneddon"
    )
    # power law n = 2 is the sphere: Hertz
    law = PowerLaw(coefficient=1 / (2 * 3e-3), exponent=2.0)
    depth, force = ref.mdr_adhesive_curve(law, ref.hertz_radius(d, 3e-3), 2e6, 0.0)
    np.testing.assert_allclose(force, ref.hertz_force(d, 3e-3, 2e6), rtol=1e-12, err_msg="power law n=2")


def test_flat_punch_curve_ends_at_kendall():
    punch = FlatPunch(radius=1e-3)
    depth, force = ref.mdr_adhesive_curve(punch, 1e-3, 4e6, 0.05)
    assert float(force) == pytest.approx(ref.kendall_pull_off(1e-3, 4e6, 0.05), rel=1e-12)
    assert float(force) == pytest.approx(float(ref.flat_punch_force(depth, 1e-3, 4e6)), rel=1e-12)
    assert ref.flat_punch_stiffness(1e-3, 4e6) == pytest.approx(8e3)
    with pytest.raises(InputError, match="punch radius"):
        ref.mdr_adhesive_curve(punch, 2e-3, 4e6, 0.05)


@pytest.mark.parametrize(("radius", "modulus", "work"), SPHERES)
def test_pull_off_points_are_extrema_of_the_parametric_curves(radius, modulus, work):
    force_point = ref.jkr_pull_off_force_control(radius, modulus, work)
    assert force_point.force == pytest.approx(-1.5 * math.pi * radius * work, rel=1e-12)
    displacement_point = ref.jkr_pull_off_displacement_control(radius, modulus, work)
    assert displacement_point.force == pytest.approx(-5.0 / 6.0 * math.pi * radius * work, rel=1e-12)
    for point, curve in ((force_point, ref.jkr_force), (displacement_point, ref.jkr_depth)):
        a = point.contact_radius * np.array([0.999, 1.0, 1.001])
        values = curve(a, radius, modulus, work)
        assert values[1] < values[0] and values[1] < values[2], f"{curve.__name__} has no minimum at a={a[1]}"
    assert force_point.depth == pytest.approx(
        float(ref.jkr_depth(force_point.contact_radius, radius, modulus, work))
    )


def test_figure4_scales_are_the_relaxed_pull_off_point():
    element = standard_solid()
    radius, work = 2e-3, 0.05
    scales = ref.figure4_scales(radius, work, element)
    w2 = work * (1e6 + 1e4) / 1e4
    point = ref.jkr_pull_off_force_control(radius, element.relaxed_modulus_star, w2)
    assert scales.force == pytest.approx(-point.force, rel=1e-12)
    assert scales.contact_radius == pytest.approx(point.contact_radius, rel=1e-12)
    assert scales.depth == pytest.approx(-point.depth, rel=1e-12)


def test_first_touch_is_glassy_jkr_at_zero_depth():
    element = standard_solid(nu=0.4)
    radius, work = 3e-3, 0.04
    touch = ref.first_touch(radius, work, element)
    e0 = element.glass_modulus_star
    assert float(ref.jkr_depth(touch.neck_radius, radius, e0, work)) == pytest.approx(
        0.0, abs=1e-12 * touch.neck_radius
    )
    assert float(ref.jkr_force(touch.neck_radius, radius, e0, work)) == pytest.approx(
        touch.force_drop, rel=1e-12
    )
    w1 = work_of_adhesion_indenting(work, element)
    assert touch.relaxed_force == pytest.approx(-4.0 / 3.0 * math.pi * radius * w1, rel=1e-12)
    incompressible = ref.first_touch(radius, work, standard_solid())
    assert incompressible.neck_radius == pytest.approx(
        (math.pi * radius**2 * work / (2 * 1e6)) ** (1 / 3), rel=1e-12
    )


@pytest.mark.parametrize("nu", [0.5, 0.3])
def test_lee_radok_ramp_against_quadrature(nu):
    element = CreepElement(
        glass_shear_modulus=1e6,
        kelvin_shear_moduli=np.array([2e4, 3e5]),
        kelvin_viscosities=np.array([2e3, 3e2]),
        poisson_ratio=nu,
    )
    radius, velocity = 2e-3, 1e-4

    def quadrature(t: float) -> float:
        def rate(s: float) -> float:  # d(a^3)/ds
            return 1.5 * (radius * velocity) ** 1.5 * math.sqrt(s)

        points = [max(t - k * tau, 0.0) for tau in element.relaxation_times for k in (1, 5)]
        value = integrate.quad(
            lambda s: float(element.relaxation_modulus(t - s)) * rate(s),
            0,
            t,
            points=points,
            epsabs=0,
            epsrel=1e-12,
            limit=400,
        )[0]
        return 8.0 / (3.0 * (1.0 - nu) * radius) * value

    for t in (1e-5, 1e-3, 0.05, 1.0, 30.0):
        assert float(ref.lee_radok_ramp_force(t, velocity, radius, element)) == pytest.approx(
            quadrature(t), rel=1e-9
        ), f"t={t}, nu={nu}"


def test_lee_radok_limits_are_hertz():
    element = standard_solid()
    radius, velocity = 2e-3, 1e-5
    fast = 1e-9  # much shorter than the relaxation time: glassy Hertz
    assert float(ref.lee_radok_ramp_force(fast, velocity, radius, element)) == pytest.approx(
        float(ref.hertz_force(velocity * fast, radius, element.glass_modulus_star)), rel=1e-5
    )
    elastic = CreepElement(glass_shear_modulus=1e6)
    t = np.array([0.0, 1.0, 10.0])
    np.testing.assert_allclose(
        ref.lee_radok_ramp_force(t, velocity, radius, elastic),
        ref.hertz_force(velocity * t, radius, elastic.glass_modulus_star),
        rtol=1e-13,
        err_msg="elastic ramp",
    )


def test_effective_works_for_the_standard_solid():
    g0, g1 = 1e6, 1e4
    element = standard_solid(g0, g1)
    assert work_of_adhesion_indenting(0.05, element) == pytest.approx(0.05 * g1 / (g0 + g1), rel=1e-13)
    assert work_of_adhesion_detaching(0.05, element) == pytest.approx(0.05 * (g0 + g1) / g1, rel=1e-13)
    np.testing.assert_allclose(
        critical_glass_elongation([1e-4, 2e-4], 0.05, element.glass_modulus_star),
        np.sqrt(math.pi * np.array([1e-4, 2e-4]) * 0.05 / (2 * g0)),
        rtol=1e-13,
    )


def test_critical_speeds_reproduce_the_papers_estimate():
    g0, g1 = 1e9, 1e7
    element = standard_solid(g0, g1, eta1=1e-3 * (g0 + g1))  # tau = eta1/(G0+G1) = 1 ms
    v_c1, v_c2 = critical_edge_speeds(element, 1e-2, 1e-9)
    assert v_c1 == pytest.approx(math.pi * 1e-4, rel=1e-10)
    assert v_c2 == pytest.approx(v_c1 * (g1 / (g0 + g1)) ** 2, rel=1e-10)
    assert 2.5e-8 < v_c2 < 3.5e-8
    holds = scale_separation_holds([1e-3, 1e-4, 0.0, -1e-7, -1e-8], (v_c1, v_c2))
    np.testing.assert_array_equal(holds, [True, False, True, True, False])
    assert critical_edge_speeds(CreepElement(glass_shear_modulus=1e6), 0.05, 1e-9) == (0.0, 0.0)
    assert critical_edge_speeds(element, 0.0, 1e-9) == (0.0, 0.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: ref.hertz_force([1e-6, np.nan], 1e-3, 1e6), "depth must be finite"),
        (lambda: ref.jkr_force(1e-4, -1e-3, 1e6, 0.1), "radius must be > 0"),
        (lambda: ref.jkr_depth(1e-4, 1e-3, 1e6, -0.1), "work_of_adhesion must be >= 0"),
        (lambda: ref.jkr_depth(-1e-4, 1e-3, 1e6, 0.1), "contact_radius must be >= 0"),
        (lambda: ref.sneddon_cone_force(1e-6, 2.0, 1e6), "half_angle must be < pi/2"),
        (lambda: ref.lee_radok_ramp_force(1.0, 0.0, 1e-3, standard_solid()), "velocity must be > 0"),
        (lambda: critical_edge_speeds(standard_solid(), 0.1, 0.0), "adhesion.interaction_range must be > 0"),
        (lambda: scale_separation_holds(np.inf, (1.0, 1.0)), "edge_speed must be finite"),
    ],
)
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(InputError, match=match):
        call()
