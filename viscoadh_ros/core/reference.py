"""Closed-form contact solutions: the exact limits the simulator is tested against.

SI units throughout; depth ``d > 0`` presses in, force ``F > 0`` is compressive, ``< 0``
adhesive. ``E*`` (Pa) is the plane-strain contact modulus, ``w`` (J/m^2) the work of
adhesion. Array arguments (depth, contact radius, time) may have any shape; the result has
the same shape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import dawsn

from viscoadh_ros.core.criterion import (
    critical_glass_elongation,
    work_of_adhesion_detaching,
    work_of_adhesion_indenting,
)
from viscoadh_ros.core.errors import InputError, require_finite, require_positive
from viscoadh_ros.core.profiles import Profile
from viscoadh_ros.core.rheology import CreepElement

FloatArray = NDArray[np.float64]


def _array(name: str, values: ArrayLike, *, nonnegative: bool = False) -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be finite (got {array!r})")
    if nonnegative and np.any(array < 0.0):
        raise InputError(f"{name} must be >= 0 (got {array!r})")
    return array


def _work(w: float) -> float:
    value = require_finite("work_of_adhesion", w)
    if value < 0.0:
        raise InputError(f"work_of_adhesion must be >= 0 (got {value!r})")
    return value


# --- non-adhesive elastic contacts ---------------------------------------------------------


def hertz_radius(depth: ArrayLike, radius: float) -> FloatArray:
    """Hertz contact radius ``a = sqrt(R d)``, m (0 for ``d <= 0``)."""
    d = _array("depth", depth)
    return np.sqrt(require_positive("radius", radius) * np.maximum(d, 0.0))


def hertz_force(depth: ArrayLike, radius: float, modulus_star: float) -> FloatArray:
    """Hertz force ``F = (4/3) E* sqrt(R) d^(3/2)``, N (0 for ``d <= 0``)."""
    d = np.maximum(_array("depth", depth), 0.0)
    return (
        (4.0 / 3.0)
        * require_positive("modulus_star", modulus_star)
        * math.sqrt(require_positive("radius", radius))
        * d**1.5
    )


def _cone_slope(half_angle: float) -> float:
    angle = require_positive("half_angle", half_angle)
    if angle >= math.pi / 2:
        raise InputError(f"half_angle must be < pi/2 rad (got {angle!r})")
    return math.tan(angle)


def sneddon_cone_radius(depth: ArrayLike, half_angle: float) -> FloatArray:
    """Cone contact radius ``a = 2 d tan(half_angle) / pi``, m (0 for ``d <= 0``); half_angle
    between axis and flank, rad."""
    return 2.0 * np.maximum(_array("depth", depth), 0.0) * _cone_slope(half_angle) / math.pi


def sneddon_cone_force(depth: ArrayLike, half_angle: float, modulus_star: float) -> FloatArray:
    """Sneddon cone force ``F = (2/pi) E* d^2 tan(half_angle)``, N (0 for ``d <= 0``)."""
    d = np.maximum(_array("depth", depth), 0.0)
    return (2.0 / math.pi) * require_positive("modulus_star", modulus_star) * d**2 * _cone_slope(half_angle)


def flat_punch_stiffness(punch_radius: float, modulus_star: float) -> float:
    """Normal stiffness of a flat punch in full contact, ``k = 2 E* a0``, N/m."""
    return (
        2.0 * require_positive("modulus_star", modulus_star) * require_positive("punch_radius", punch_radius)
    )


def flat_punch_force(depth: ArrayLike, punch_radius: float, modulus_star: float) -> FloatArray:
    """Force ``F = 2 E* a0 d``, N, of a bonded punch (any sign of ``d``; valid until pull-off)."""
    return flat_punch_stiffness(punch_radius, modulus_star) * _array("depth", depth)


# --- elastic adhesion (JKR, Kendall, general MDR) ----------------------------------------


def jkr_depth(
    contact_radius: ArrayLike, radius: float, modulus_star: float, work_of_adhesion: float
) -> FloatArray:
    """JKR depth at contact radius ``a``: ``d = a^2/R - sqrt(2 pi a w / E*)``, m."""
    a = _array("contact_radius", contact_radius, nonnegative=True)
    r = require_positive("radius", radius)
    return a**2 / r - critical_glass_elongation(a, _work(work_of_adhesion), modulus_star)


def jkr_force(
    contact_radius: ArrayLike, radius: float, modulus_star: float, work_of_adhesion: float
) -> FloatArray:
    """JKR force at contact radius ``a``: ``F = 4 E* a^3/(3R) - sqrt(8 pi w E* a^3)``, N."""
    a = _array("contact_radius", contact_radius, nonnegative=True)
    e = require_positive("modulus_star", modulus_star)
    w = _work(work_of_adhesion)
    return 4.0 * e * a**3 / (3.0 * require_positive("radius", radius)) - np.sqrt(8.0 * math.pi * w * e * a**3)


@dataclass(frozen=True)
class ContactPoint:
    """A point of a force-depth curve: force (N), contact_radius (m), depth (m)."""

    force: float
    contact_radius: float
    depth: float


def _jkr_point(cube: float, radius: float, modulus_star: float, w: float) -> ContactPoint:
    a = cube ** (1.0 / 3.0)
    return ContactPoint(
        force=float(jkr_force(a, radius, modulus_star, w)),
        contact_radius=a,
        depth=float(jkr_depth(a, radius, modulus_star, w)),
    )


def jkr_pull_off_force_control(radius: float, modulus_star: float, work_of_adhesion: float) -> ContactPoint:
    """JKR pull-off under force control: ``F = -(3/2) pi R w`` at ``a^3 = 9 pi w R^2/(8 E*)``
    (the minimum of the parametric force ``F(a)``)."""
    w = _work(work_of_adhesion)
    r, e = require_positive("radius", radius), require_positive("modulus_star", modulus_star)
    return _jkr_point(9.0 * math.pi * w * r**2 / (8.0 * e), r, e, w)


def jkr_pull_off_displacement_control(
    radius: float, modulus_star: float, work_of_adhesion: float
) -> ContactPoint:
    """Last stable JKR point under displacement control: ``F = -(5/6) pi R w`` at
    ``a^3 = pi w R^2/(8 E*)`` (the minimum of the parametric depth ``d(a)``)."""
    w = _work(work_of_adhesion)
    r, e = require_positive("radius", radius), require_positive("modulus_star", modulus_star)
    return _jkr_point(math.pi * w * r**2 / (8.0 * e), r, e, w)


def kendall_pull_off(punch_radius: float, modulus_star: float, work_of_adhesion: float) -> float:
    """Kendall pull-off force of a flat punch, ``F = -sqrt(8 pi E* a0^3 w)``, N."""
    a0 = require_positive("punch_radius", punch_radius)
    return -math.sqrt(
        8.0 * math.pi * require_positive("modulus_star", modulus_star) * a0**3 * _work(work_of_adhesion)
    )


def mdr_adhesive_curve(
    profile: Profile, contact_radius: ArrayLike, modulus_star: float, work_of_adhesion: float
) -> tuple[FloatArray, FloatArray]:
    """Elastic adhesive contact of any profile by MDR, parametric in the contact radius ``a``:

        d = g(a) - sqrt(2 pi a w / E*),    F = 2 E* integral_0^a (d - g(x)) dx = 2 E* (d a - G(a))

    with ``G = profile.g_integral``. Returns ``(depth, force)`` (m, N), each shaped like ``a``.
    For a flat punch the contact radius is the punch radius (``a <= a0`` required); at
    ``a = a0`` this is Kendall's pull-off. All branches of the curve are returned; which are
    stable depends on the control (force or displacement).
    """
    a = _array("contact_radius", contact_radius, nonnegative=True)
    e = require_positive("modulus_star", modulus_star)
    w = _work(work_of_adhesion)
    if np.any(~np.isfinite(profile.g(a))):
        raise InputError("contact_radius exceeds the punch radius of the flat punch")
    depth = profile.g(a) - critical_glass_elongation(a, w, e)
    force = 2.0 * e * (depth * a - profile.g_integral(a))
    return depth, force


# --- viscoelastic references ---------------------------------------------------------------


def _ramp_kernel(y: FloatArray) -> FloatArray:
    """``y - D(y)`` (D: Dawson's integral) without cancellation: its series
    ``sum_n (-1)^n 2^(n+1) y^(2n+3) / (2n+3)!!`` (n >= 0) below y = 0.5."""
    series = np.zeros_like(y)
    term = 2.0 * y**3 / 3.0
    for n in range(16):
        series = series + term
        term = -term * 2.0 * y**2 / (2 * n + 5)
    return np.where(y < 0.5, series, y - dawsn(y))


def lee_radok_ramp_force(
    time: ArrayLike, velocity: float, radius: float, element: CreepElement
) -> FloatArray:
    """Lee-Radok force of a rigid sphere pressed at constant speed ``d = v t`` into a
    non-adhesive viscoelastic half-space, N, at times ``t >= 0`` (s).

    ``F(t) = (8 / (3 (1 - nu) R)) integral_0^t G(t - s) d(a^3)/ds ds`` with ``a^2 = R v s``
    (``16/(3R)`` when incompressible). With the element's exact Prony series the convolution
    is closed-form: each term ``g_i exp(-t/tau_i)`` contributes
    ``(3/2) g_i (R v tau_i)^(3/2) (sqrt(X) - D(sqrt(X)))`` with ``X = t/tau_i`` and Dawson's
    integral ``D`` (scipy ``dawsn``), and ``G_inf`` contributes ``G_inf (R v t)^(3/2)``. So this
    is exact to rounding (relative 1e-14), no quadrature error. Valid while the contact grows,
    which a monotone ramp guarantees.
    """
    t = _array("time", time, nonnegative=True)
    v = require_positive("velocity", velocity)
    r = require_positive("radius", radius)
    prony = element.prony
    total = prony.long_term_modulus * (r * v * t) ** 1.5
    for modulus, tau in zip(prony.moduli, prony.times, strict=True):
        total = total + 1.5 * modulus * (r * v * tau) ** 1.5 * _ramp_kernel(np.sqrt(t / tau))
    return 8.0 / (3.0 * (1.0 - element.poisson_ratio) * r) * total


@dataclass(frozen=True)
class FirstTouch:
    """First touch of a sphere on a viscoelastic adhesive half-space at zero depth.

    neck_radius: instantaneous neck radius ``a = (2 pi R^2 w / E0*)^(1/3)`` (m), JKR at d = 0
      with the glass modulus (``(pi R^2 w/(2 G0))^(1/3)`` when incompressible).
    force_drop: the instant force ``-(4/3) pi R w`` (N, tensile).
    relaxed_force: the force it relaxes to at fixed depth, ``-(4/3) pi R w_eff1`` (N).
    """

    neck_radius: float
    force_drop: float
    relaxed_force: float


def first_touch(radius: float, work_of_adhesion: float, element: CreepElement) -> FirstTouch:
    """Neck radius and force drop when a sphere of radius ``R`` (m) first touches (physics
    notes section 4)."""
    r = require_positive("radius", radius)
    w = _work(work_of_adhesion)
    return FirstTouch(
        neck_radius=(2.0 * math.pi * r**2 * w / element.glass_modulus_star) ** (1.0 / 3.0),
        force_drop=-(4.0 / 3.0) * math.pi * r * w,
        relaxed_force=-(4.0 / 3.0) * math.pi * r * work_of_adhesion_indenting(w, element),
    )


@dataclass(frozen=True)
class Figure4Scales:
    """The paper's Figure-4 normalisation with the relaxed modulus and ``w_eff2``:
    force ``F_c = (3/2) pi R w_eff2`` (N), contact radius ``a_c = (9 pi w_eff2 R^2/(8 E_r*))^(1/3)``
    (m), depth ``d_c = (3 pi^2 w_eff2^2 R/(64 E_r*^2))^(1/3)`` (m). ``(-F_c, a_c, -d_c)`` is the
    quasistatic pull-off point under force control."""

    force: float
    contact_radius: float
    depth: float


def figure4_scales(radius: float, work_of_adhesion: float, element: CreepElement) -> Figure4Scales:
    """Figure-4 normalisation (physics notes section 4) for a sphere of radius ``R`` (m)."""
    w2 = work_of_adhesion_detaching(_work(work_of_adhesion), element)
    return jkr_scales(radius, element.relaxed_modulus_star, w2)


def jkr_scales(radius: float, modulus_star: float, work_of_adhesion: float) -> Figure4Scales:
    """JKR units of a sphere of radius ``R`` (m) on modulus ``E*`` (Pa) with work ``w`` (J/m^2):
    ``F_c = 3/2 pi R w``, ``a_c``, ``d_c``; Figure 4 takes ``E_r*`` and ``w_eff2``."""
    r = require_positive("radius", radius)
    e = require_positive("modulus_star", modulus_star)
    w2 = _work(work_of_adhesion)
    return Figure4Scales(
        force=1.5 * math.pi * r * w2,
        contact_radius=(9.0 * math.pi * w2 * r**2 / (8.0 * e)) ** (1.0 / 3.0),
        depth=(3.0 * math.pi**2 * w2**2 * r / (64.0 * e**2)) ** (1.0 / 3.0),
    )
