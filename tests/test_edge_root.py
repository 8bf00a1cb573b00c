"""The edge root finder (`_kernels._bisect`, safeguarded secant since 0.3.0) finds the root
plain bisection found (the 0.2.0 finder, kept below as the reference) to within the edge
tolerance, on many random brackets of rows with random memory, with the sign of h right on
each side of the bracket it returns."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from scenes import one_contact

from viscoadh_ros.core import _kernels
from viscoadh_ros.core.simulator import ContactSimulator


@numba.njit(cache=False)
def _reference_bisect(x_lo, x_hi, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit):
    """The 0.2.0 `_bisect`, verbatim: returns (root, evaluations of h)."""
    tol = _kernels.EDGE_TOLERANCE * dx
    calls = 0
    for _ in range(80):
        mid = 0.5 * (x_lo + x_hi)
        if mid <= x_lo or mid >= x_hi or x_hi - x_lo <= tol:
            break
        calls += 1
        if _kernels._h(mid, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit) >= 0.0:
            x_lo = mid
        else:
            x_hi = mid
    return 0.5 * (x_lo + x_hi), calls


def _row(kelvin: tuple, viscosities: tuple, seed: int, smooth: bool, elements: int) -> _kernels.Row:
    contact = one_contact(
        {"shape": "sphere", "radius": 1e-3},
        kelvin=kelvin,
        viscosities=viscosities,
        work=0.05,
        numerics={"model": "time_stepped", "elements": elements},
    )
    sim = ContactSimulator(contact)
    rng = np.random.default_rng(seed)
    n, k = elements, len(kelvin)
    if smooth:
        x = np.linspace(0.0, 1.0, n)[:, None]
        memory = 2e-6 * (
            rng.normal(size=(1, k)) + rng.normal(size=(1, k)) * x + rng.normal(size=(1, k)) * x**2
        )
    else:
        memory = rng.normal(scale=2e-6, size=(n, k))
    unit = rng.uniform(size=(n, k)) * sim._model.steady
    return sim._model._build_row(2e-4, memory, unit)


def _rounding_band(row, x, d, lo, hi, x_lo, x_hi) -> float:
    """Half-width of the band around a root x where rounding decides the sign of h: a bound
    of the rounding of h's terms over the slope of h across the bracket, m."""
    g = _kernels._g_at(x, row.gf, row.df)
    w = _kernels._w_side(x, row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df)
    scale = abs(d) + abs(g) + abs(w) + row.c_crit * math.sqrt(x)
    args = (row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
    slope = abs(_kernels._h(x_hi, d, *args) - _kernels._h(x_lo, d, *args)) / (x_hi - x_lo)
    return 16.0 * np.finfo(float).eps * scale / slope


def _brackets(row: _kernels.Row, rng: np.random.Generator, count: int):
    """(x_lo, x_hi, d, lo, hi) with h(x_lo) >= 0 > h(x_hi), as the edge search hands them over:
    within one fine interval (or from a radius inside it to its end), either side's memory,
    the depth chosen so that h has a root in the interval."""
    n = row.elements
    m = row.gf.shape[0]
    found = 0
    while found < count:
        j = int(rng.integers(1, m - 1))
        x0, x1 = j * row.df, (j + 1) * row.df
        n_in = int(rng.integers(1, n))
        lo, hi = (0, n_in - 1) if rng.random() < 0.5 else (n_in, n - 1)
        # A root at a random point of the interval: d shifts h uniformly.
        x_root = x0 + rng.uniform(0.0, 1.0) * (x1 - x0)
        d = -_kernels._h(x_root, 0.0, row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
        x_lo, x_hi = (x0, x1) if rng.random() < 0.6 else (x0 + rng.uniform(0.0, 0.9) * (x_root - x0), x1)
        h_lo = _kernels._h(x_lo, d, row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
        h_hi = _kernels._h(x_hi, d, row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
        if not (h_lo >= 0.0 > h_hi):
            continue
        found += 1
        yield x_lo, x_hi, d, lo, hi


@pytest.mark.parametrize("elements", [24, 64, 400])
@pytest.mark.parametrize("smooth", [False, True])
@pytest.mark.parametrize(
    ("kelvin", "viscosities"), [((), ()), ((1e5,), (1e3,)), ((2e5, 5e4, 1e6), (1e2, 1e4, 1e-1))]
)
def test_edge_root_is_within_the_tolerance_of_bisection_with_the_right_signs(
    kelvin, viscosities, smooth, elements
) -> None:
    calls_old = 0
    narrow = 0
    cases = 0
    for seed in range(4):
        row = _row(kelvin, viscosities, seed, smooth, elements)
        rng = np.random.default_rng(500 + seed)
        args = (row.wsum, row.bsum)
        tol = _kernels.EDGE_TOLERANCE * row.dx
        for x_lo, x_hi, d, lo, hi in _brackets(row, rng, 150):
            rest = (lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
            old, n_old = _reference_bisect(x_lo, x_hi, d, *args, *rest)
            new = _kernels._bisect(x_lo, x_hi, d, *args, *rest)
            assert x_lo <= new <= x_hi
            # Where |h'| is small against the rounding of h's terms (fine rows), the sign of
            # h flips at random over more than the tolerance: no finder can do better there.
            band = _rounding_band(row, old, d, lo, hi, x_lo, x_hi)
            narrow += band <= tol
            assert abs(new - old) <= 2.0 * (tol + band), (seed, x_lo, x_hi, d, new - old, band)
            # The returned point is the midpoint of a bracket at most one tolerance wide with
            # h >= 0 at its inner end and h < 0 at its outer end: beyond half a tolerance (and
            # the rounding band) either side, h has those signs.
            inner = max(new - 0.5 * tol - band, x_lo)
            outer = min(new + 0.5 * tol + band, x_hi)
            assert _kernels._h(inner, d, *args, *rest) >= 0.0, (seed, x_lo, x_hi, d, band)
            assert _kernels._h(outer, d, *args, *rest) < 0.0, (seed, x_lo, x_hi, d, band)
            calls_old += n_old
            cases += 1
    assert cases == 4 * 150
    # Most brackets are decided to the tolerance itself, not the rounding band (on the finest
    # row, 400 elements, about half: its tolerance, 5e-19 m, is near the rounding of h).
    assert narrow >= (0.9 if elements <= 64 else 0.4) * cases
    assert calls_old / cases > 25  # the reference really bisected down to the tolerance
