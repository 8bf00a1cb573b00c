"""Rigid axisymmetric indenters and their MDR profiles.

An indenter is described by its gap profile ``f(r)`` (m): the height of its surface above
the tip at radius ``r``. The Method of Dimensionality Reduction maps the 3D contact onto a
1D row of springs pressed by the *MDR profile*

    g(x) = |x| * integral_0^|x| f'(r) / sqrt(x^2 - r^2) dr                       (m)

so that the element at ``x`` in contact is displaced by ``d - g(x)``. All methods are
vectorised: ``x`` (m) may be a scalar or an array of any shape, the result has the same
shape (float64). Profiles are symmetric, ``g(-x) = g(x)``.

Besides ``g`` every profile offers ``g_integral(a) = integral_0^a g(x) dx`` (m^2), which gives
the elastic MDR force ``F = 2 E* (d a - g_integral(a))`` without quadrature, and
``radius_at_height(h)``, the smallest ``x >= 0`` with ``g(x) >= h`` (the non-adhesive contact
radius at depth ``h``), used to size simulation domains.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from viscoadh_ros.core.errors import InputError, require_positive

FloatArray = NDArray[np.float64]


def power_law_kappa(exponent: float) -> float:
    """MDR stretch factor ``kappa(n) = sqrt(pi) Gamma(n/2 + 1) / Gamma(n/2 + 1/2)`` of a power
    law ``f = c r^n`` (dimensionless): ``g = kappa(n) c |x|^n``. ``kappa(1) = pi/2``, ``kappa(2) = 2``."""
    n = require_positive("indenter.exponent", exponent)
    # lgamma keeps large exponents from overflowing Gamma.
    return math.sqrt(math.pi) * math.exp(math.lgamma(n / 2 + 1) - math.lgamma(n / 2 + 0.5))


def _abs_float(x: ArrayLike) -> FloatArray:
    return np.abs(np.asarray(x, dtype=np.float64))


def _nonnegative_height(h: ArrayLike) -> FloatArray:
    heights = np.asarray(h, dtype=np.float64)
    if not np.all(np.isfinite(heights)) or np.any(heights < 0.0):
        raise InputError(f"height must be finite and >= 0 (got {heights!r})")
    return heights


class Profile(ABC):
    """A rigid axisymmetric indenter (abstract base)."""

    #: shape name, as in the scene key ``indenter.shape``
    kind: str = ""
    #: True if an exact closed form exists for the elastic contact (Hertz, Sneddon, punch, power law)
    closed_form_available: bool = True

    @property
    @abstractmethod
    def characteristic_radius(self) -> float:
        """Length scale of the geometry, m: the radius where the flank slope ``f'(r)`` reaches 1
        (beyond it the half-space assumption fails; sphere: ``R``), the punch radius, or the
        extent of a table. ``math.inf`` for scale-free shapes (a cone has the same slope
        everywhere): size domains by depth with :meth:`radius_at_height` instead."""

    @abstractmethod
    def f(self, r: ArrayLike) -> FloatArray:
        """Gap profile ``f(r)``, m, at radius ``r`` (m), same shape as ``r``."""

    @abstractmethod
    def g(self, x: ArrayLike) -> FloatArray:
        """MDR profile ``g(x)``, m, at 1D coordinate ``x`` (m), same shape as ``x``."""

    @abstractmethod
    def g_integral(self, a: ArrayLike) -> FloatArray:
        """``integral_0^|a| g(x) dx``, m^2, same shape as ``a``."""

    @abstractmethod
    def radius_at_height(self, h: ArrayLike) -> FloatArray:
        """Smallest ``x >= 0`` with ``g(x) >= h`` (m) for heights ``h >= 0`` (m): the contact
        radius of the non-adhesive contact at depth ``h``."""

    def __repr__(self) -> str:
        fields = ", ".join(f"{k}={v!r}" for k, v in vars(self).items() if not k.startswith("_"))
        return f"{type(self).__name__}({fields})"


class Sphere(Profile):
    """Sphere in the paraboloid approximation: ``f = r^2/(2R)``, ``g = x^2/R``.

    radius: sphere radius ``R``, m (> 0).
    """

    kind = "sphere"

    def __init__(self, *, radius: float) -> None:
        self.radius = require_positive("indenter.radius", radius)

    @property
    def characteristic_radius(self) -> float:
        return self.radius

    def f(self, r: ArrayLike) -> FloatArray:
        return _abs_float(r) ** 2 / (2.0 * self.radius)

    def g(self, x: ArrayLike) -> FloatArray:
        return _abs_float(x) ** 2 / self.radius

    def g_integral(self, a: ArrayLike) -> FloatArray:
        return _abs_float(a) ** 3 / (3.0 * self.radius)

    def radius_at_height(self, h: ArrayLike) -> FloatArray:
        return np.sqrt(self.radius * _nonnegative_height(h))


class Cone(Profile):
    """Cone: ``f = r cot(half_angle)``, ``g = (pi/2) |x| cot(half_angle)``.

    half_angle: angle between the axis and the flank, rad, in (0, pi/2). A flat-ish cone
    (small slope ``cot(half_angle)``) has ``half_angle`` close to pi/2.
    """

    kind = "cone"

    def __init__(self, *, half_angle: float) -> None:
        angle = require_positive("indenter.half_angle", half_angle)
        if angle >= math.pi / 2:
            raise InputError(f"indenter.half_angle must be < pi/2 rad (got {angle!r})")
        self.half_angle = angle
        self._slope = 1.0 / math.tan(angle)

    @property
    def characteristic_radius(self) -> float:
        return math.inf

    def f(self, r: ArrayLike) -> FloatArray:
        return _abs_float(r) * self._slope

    def g(self, x: ArrayLike) -> FloatArray:
        return (math.pi / 2) * self._slope * _abs_float(x)

    def g_integral(self, a: ArrayLike) -> FloatArray:
        return (math.pi / 4) * self._slope * _abs_float(a) ** 2

    def radius_at_height(self, h: ArrayLike) -> FloatArray:
        return _nonnegative_height(h) / ((math.pi / 2) * self._slope)


class FlatPunch(Profile):
    """Flat cylindrical punch of radius ``a0``: ``g = 0`` for ``|x| <= a0``, ``+inf`` outside.

    radius: punch radius ``a0``, m (> 0). The contact radius of a punch in contact is ``a0``.
    """

    kind = "flat_punch"

    def __init__(self, *, radius: float) -> None:
        self.radius = require_positive("indenter.radius", radius)

    @property
    def punch_radius(self) -> float:
        """Punch radius ``a0``, m."""
        return self.radius

    @property
    def characteristic_radius(self) -> float:
        return self.radius

    def f(self, r: ArrayLike) -> FloatArray:
        return np.where(_abs_float(r) <= self.radius, 0.0, np.inf)

    def g(self, x: ArrayLike) -> FloatArray:
        return np.where(_abs_float(x) <= self.radius, 0.0, np.inf)

    def g_integral(self, a: ArrayLike) -> FloatArray:
        return np.where(_abs_float(a) <= self.radius, 0.0, np.inf)

    def radius_at_height(self, h: ArrayLike) -> FloatArray:
        return np.full_like(_nonnegative_height(h), self.radius)


class PowerLaw(Profile):
    """Power-law indenter ``f = c r^n``, ``g = kappa(n) c |x|^n`` (see :func:`power_law_kappa`).

    coefficient: ``c``, m^(1-n) (> 0); exponent: ``n`` (> 0, dimensionless).
    """

    kind = "power_law"

    def __init__(self, *, coefficient: float, exponent: float) -> None:
        self.coefficient = require_positive("indenter.coefficient", coefficient)
        self.exponent = require_positive("indenter.exponent", exponent)
        self._kappa = power_law_kappa(self.exponent)

    @property
    def characteristic_radius(self) -> float:
        n, c = self.exponent, self.coefficient
        if n == 1.0:
            return math.inf
        # f'(r) = n c r^(n-1) = 1
        return (n * c) ** (-1.0 / (n - 1.0))

    def f(self, r: ArrayLike) -> FloatArray:
        return self.coefficient * _abs_float(r) ** self.exponent

    def g(self, x: ArrayLike) -> FloatArray:
        return self._kappa * self.coefficient * _abs_float(x) ** self.exponent

    def g_integral(self, a: ArrayLike) -> FloatArray:
        n = self.exponent
        return self._kappa * self.coefficient * _abs_float(a) ** (n + 1.0) / (n + 1.0)

    def radius_at_height(self, h: ArrayLike) -> FloatArray:
        return (_nonnegative_height(h) / (self._kappa * self.coefficient)) ** (1.0 / self.exponent)


class Tabulated(Profile):
    """Indenter given as samples of its gap profile ``f(r)``.

    table_radius: radii ``r_i``, m, strictly increasing, starting at 0 (at least 2 samples).
    table_height: heights ``f(r_i)``, m, starting at 0 and non-decreasing.

    ``f`` is the piecewise-linear interpolant of the samples, continued beyond the last
    sample with the last slope (a conical flank), so a contact that outgrows the table stays
    defined; :attr:`characteristic_radius` is the table extent so domains are sized to it.

    MDR transform, exact for that interpolant: with ``r = x sin t`` the transform becomes
    ``g(x) = x * integral_0^(pi/2) f'(x sin t) dt``, free of the ``1/sqrt(x^2 - r^2)``
    singularity. For a piecewise-constant ``f'`` it integrates in closed form: each slope
    change ``ds_j`` at node ``r_j`` adds a shifted cone

        g(x) = sum_j ds_j * x * arccos(r_j / x)          (terms with x > r_j)
        integral_0^a g = sum_j ds_j * ((a^2/2) arccos(r_j/a) - (r_j/2) sqrt(a^2 - r_j^2))

    so no quadrature error remains; the only error against a smooth shape is the
    interpolation of ``f`` (second order in the sample spacing, see tests).
    """

    kind = "table"
    closed_form_available = False

    def __init__(self, *, table_radius: ArrayLike, table_height: ArrayLike) -> None:
        radius = _finite_table("indenter.table_radius", table_radius)
        height = _finite_table("indenter.table_height", table_height)
        if radius.size != height.size:
            raise InputError(
                f"indenter.table_radius and indenter.table_height must have the same length "
                f"(got {radius.size} and {height.size})"
            )
        if radius.size < 2:
            raise InputError(f"indenter.table_radius needs at least 2 samples (got {radius.size})")
        if radius[0] != 0.0:
            raise InputError(f"indenter.table_radius[0] must be 0 (got {radius[0]!r})")
        if height[0] != 0.0:
            raise InputError(f"indenter.table_height[0] must be 0 (got {height[0]!r})")
        steps = np.diff(radius)
        bad = np.flatnonzero(steps <= 0.0)
        if bad.size:
            i = int(bad[0]) + 1
            raise InputError(
                f"indenter.table_radius must be strictly increasing "
                f"(table_radius[{i}] = {radius[i]!r} <= table_radius[{i - 1}] = {radius[i - 1]!r})"
            )
        bad = np.flatnonzero(np.diff(height) < 0.0)
        if bad.size:
            i = int(bad[0]) + 1
            raise InputError(
                f"indenter.table_height must be non-decreasing (monotone profile) "
                f"(table_height[{i}] = {height[i]!r} < table_height[{i - 1}] = {height[i - 1]!r})"
            )
        if height[-1] <= 0.0:
            raise InputError("indenter.table_height must rise above 0 somewhere (got all zeros)")
        self.table_radius = tuple(float(v) for v in radius)
        self.table_height = tuple(float(v) for v in height)
        self._r = radius
        self._h = height
        slopes = np.diff(height) / steps
        self._slope_last = float(slopes[-1])
        # Slope changes at the nodes r_0..r_{M-2}; the last slope continues to infinity.
        self._kink_radius = radius[:-1]
        self._kink_slope = np.diff(slopes, prepend=0.0)

    @property
    def characteristic_radius(self) -> float:
        return float(self._r[-1])

    def f(self, r: ArrayLike) -> FloatArray:
        radii = _abs_float(r)
        inside = np.interp(radii, self._r, self._h)
        beyond = self._h[-1] + self._slope_last * (radii - self._r[-1])
        return np.where(radii <= self._r[-1], inside, beyond)

    def _kink_terms(self, x: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Broadcast ``|x|`` (shape S) against the kinks: returns ``x[..., None]``,
        ``r_j / x`` clipped to [0, 1] and the mask ``x > r_j`` (shape S + (M,))."""
        xs = _abs_float(x)[..., None]
        active = xs > self._kink_radius
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(active, self._kink_radius / np.where(xs > 0.0, xs, 1.0), 1.0)
        return xs, np.clip(ratio, 0.0, 1.0), active

    def g(self, x: ArrayLike) -> FloatArray:
        xs, ratio, active = self._kink_terms(x)
        cones = np.where(active, xs * np.arccos(ratio), 0.0)
        return cones @ self._kink_slope

    def g_integral(self, a: ArrayLike) -> FloatArray:
        xs, ratio, active = self._kink_terms(a)
        terms = 0.5 * xs**2 * (np.arccos(ratio) - ratio * np.sqrt(1.0 - ratio**2))
        return np.where(active, terms, 0.0) @ self._kink_slope

    def radius_at_height(self, h: ArrayLike) -> FloatArray:
        """Smallest ``x`` with ``g(x) >= h``: the running
        maximum of ``g`` on a grid (``g`` of a non-convex table need not be monotone), then
        bisection inside the first grid cell that reaches ``h``, to machine precision."""
        heights = _nonnegative_height(h)
        upper = float(self._r[-1])
        while float(self.g(upper)) < float(np.max(heights, initial=0.0)):
            if upper > 1e6 * self._r[-1]:
                raise InputError(
                    f"height {float(np.max(heights))!r} m is beyond the reach of the tabulated "
                    "profile (its last slope is too flat)"
                )
            upper *= 2.0
        grid = np.linspace(0.0, upper, 4097)
        envelope = np.maximum.accumulate(self.g(grid))
        index = np.searchsorted(envelope, heights, side="left").clip(1, grid.size - 1)
        low, high = grid[index - 1], grid[index]
        for _ in range(60):
            mid = 0.5 * (low + high)
            reached = self.g(mid) >= heights
            high = np.where(reached, mid, high)
            low = np.where(reached, low, mid)
        return np.where(heights <= 0.0, 0.0, high)


def _finite_table(name: str, values: ArrayLike) -> FloatArray:
    try:
        array = np.asarray(values, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a list of numbers (got {values!r})") from None
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        i = int(bad[0])
        raise InputError(f"{name}[{i}] must be finite (got {array[i]!r})")
    return array


def make_profile(indenter: Any) -> Profile:
    """Build the profile described by an ``IndenterConfig`` (or any object with its fields:
    ``shape``, ``radius``, ``half_angle``, ``coefficient``, ``exponent``, ``table_radius``,
    ``table_height``). Raises :class:`InputError` naming the bad key."""
    shape = indenter.shape
    if shape == "sphere":
        return Sphere(radius=indenter.radius)
    if shape == "cone":
        return Cone(half_angle=indenter.half_angle)
    if shape == "flat_punch":
        return FlatPunch(radius=indenter.radius)
    if shape == "power_law":
        return PowerLaw(coefficient=indenter.coefficient, exponent=indenter.exponent)
    if shape == "table":
        return Tabulated(table_radius=indenter.table_radius, table_height=indenter.table_height)
    raise InputError(
        f"indenter.shape must be one of sphere, cone, flat_punch, power_law, table (got {shape!r})"
    )
