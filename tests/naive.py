"""Plain-numpy references of the numba kernels in `viscoadh_ros.core._kernels`.

Each function restates one kernel the slow, obvious way (dense grids, matrix exponentials,
vectorised interpolation) so the tests can compare the compiled path against it. They take
a `_kernels.Row` for its arrays and constants and never modify it.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from viscoadh_ros.core import _kernels


def trapezoid(y: np.ndarray, x: np.ndarray) -> float:
    """Trapezoidal rule (numpy 1.26 and 2.x spell it differently)."""
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def interior_count(a: float, dx: float, n: int) -> int:
    """Elements with centres below a (at least one when in contact)."""
    if a <= 0.0:
        return 0
    centres = (np.arange(n) + 0.5) * dx
    return max(1, int(np.count_nonzero(centres < a)))


def chain_step(
    l0: np.ndarray, u0: float, u1: float, dt: float, row: _kernels.Row, in_contact: bool
) -> np.ndarray:
    """Exact Kelvin chain update by the matrix exponential of the augmented linear system
    ``d/dt [l, u, s] = [[A, b, 0], [0, 0, 1], [0, 0, 0]] [l, u, s]`` (u linear, slope s)."""
    k = row.e_kelvin.size
    eta = row.e_kelvin / row.rate
    if in_contact:
        a_mat = -(row.e0 * np.ones((k, k)) + np.diag(row.e_kelvin)) / eta[:, None]
        b_vec = row.e0 / eta
    else:
        a_mat = -np.diag(row.rate)
        b_vec = np.zeros(k)
    m = np.zeros((k + 2, k + 2))
    m[:k, :k] = a_mat
    m[:k, k] = b_vec
    m[k, k + 1] = 1.0
    state = np.concatenate([l0, [u0, (u1 - u0) / dt]])
    return (expm(m * dt) @ state)[:k]


def kelvin_update(row: _kernels.Row, n_in: int, d0: float, d1: float, dt: float) -> np.ndarray:
    """New Kelvin state (N, K) after dt: elements below n_in in contact, the rest free."""
    out = row.wl.copy()
    for i in range(row.elements):
        out[i] = chain_step(row.wl[i], d0 - row.g_c[i], d1 - row.g_c[i], dt, row, i < n_in)
    return out


def g_at(row: _kernels.Row, x: np.ndarray) -> np.ndarray:
    fine = np.arange(row.gf.size) * row.df
    return np.interp(x, fine, row.gf)


def side_values(
    row: _kernels.Row, x: np.ndarray, values: np.ndarray, lo: int, hi: int, coef: float, depth: float
) -> np.ndarray:
    """`_kernels._w_side` vectorised: interpolate ``values - coef u`` over elements lo..hi,
    linear extrapolation below lo (exterior towards the edge), minmod-limited linear
    extrapolation above hi (interior towards the edge), hold at the centre and far end."""
    x = np.asarray(x, dtype=np.float64)
    if lo > hi:
        return np.zeros_like(x)
    idx = np.arange(lo, hi + 1)
    dev = values[idx] - coef * (depth - row.g_c[idx])
    p = x / row.dx - 0.5
    inside = np.interp(p, idx.astype(float), dev)
    if lo > 0 and hi > lo:
        below = dev[0] + (p - lo) * (dev[1] - dev[0])
        inside = np.where(p <= lo, below, inside)
    if hi < values.size - 1 and hi > lo:
        slope = dev[-1] - dev[-2]
        if hi - 2 >= lo:
            before = dev[-2] - dev[-3]
            slope = 0.0 if slope * before <= 0.0 else min(slope, before, key=abs)
        inside = np.where(p >= hi, dev[-1] + (p - hi) * slope, inside)
    return coef * (depth - g_at(row, x)) + inside


def gap(row: _kernels.Row, x: np.ndarray, depth: float, radius: float, interior: bool) -> np.ndarray:
    """Criterion gap h(x) with the memory of one side of `radius`."""
    n = row.elements
    n_in = interior_count(radius, row.dx, n)
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    w = side_values(row, x, row.wsum, lo, hi, row.kap if interior else 0.0, depth)
    return depth - g_at(row, x) - w + row.c_crit * np.sqrt(x)


def force(row: _kernels.Row, radius: float, depth: float, points: int = 200001) -> float:
    """2 E0* times the integral of the glass elongation over (0, a), dense trapezoid."""
    if radius <= 0.0:
        return 0.0
    x = np.linspace(0.0, radius, points)
    n_in = interior_count(radius, row.dx, row.elements)
    w = side_values(row, x, row.wsum, 0, n_in - 1, row.kap, depth)
    return 2.0 * row.e0 * trapezoid(depth - g_at(row, x) - w, x)


def stored_energy(row: _kernels.Row, radius: float, depth: float, points: int = 200001) -> float:
    """Integral of E0* l0^2 + sum_k E_k* l_k^2 over the row, dense trapezoid on each side."""
    n = row.elements
    n_in = interior_count(radius, row.dx, n)
    total = 0.0
    for interior, (x0, x1) in ((True, (0.0, radius)), (False, (radius, row.length))):
        if x1 <= x0:
            continue
        x = np.linspace(x0, x1, points)
        lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
        density = np.zeros_like(x)
        lsum = np.zeros_like(x)
        for k in range(row.e_kelvin.size):
            lk = side_values(row, x, row.wl[:, k], lo, hi, row.steady[k] if interior else 0.0, depth)
            lsum += lk
            density += row.e_kelvin[k] * lk**2
        if interior:
            density += row.e0 * (depth - g_at(row, x) - lsum) ** 2
        total += trapezoid(density, x)
    return total


def locate_edge(row: _kernels.Row, radius: float, depth: float, points: int = 400001) -> float:
    """New contact radius by the energy criterion on a dense grid (see `_locate_edge`):
    first touch, else detachment, else attachment."""
    x = np.linspace(0.0, row.length, points)
    reach = min(row.reach, row.length)
    x = x[x <= reach]
    n = row.elements
    if radius <= 0.0:
        touching = np.flatnonzero(
            depth - g_at(row, x) - side_values(row, x, row.wsum, 0, n - 1, 0.0, depth) >= 0.0
        )
        if touching.size == 0:
            return 0.0
        start = x[touching[0]]
        h = gap(row, x, depth, 0.0, interior=False)
        return _outward(x, h, start, reach)
    if gap(row, np.array([radius]), depth, radius, interior=True)[0] < 0.0:  # detachment first
        h = gap(row, x, depth, radius, interior=True)
        below = np.flatnonzero((x < radius) & (h >= 0.0))
        if below.size == 0:
            return 0.0
        j = below[-1]
        x_hi = x[j + 1] if x[j + 1] < radius else radius
        return float(
            x[j] + (x_hi - x[j]) * h[j] / (h[j] - gap(row, np.array([x_hi]), depth, radius, True)[0])
        )
    if radius < reach and gap(row, np.array([radius]), depth, radius, interior=False)[0] > 0.0:
        return _outward(x, gap(row, x, depth, radius, interior=False), radius, reach)
    return radius


def _outward(x: np.ndarray, h: np.ndarray, start: float, reach: float) -> float:
    beyond = np.flatnonzero((x > start) & (h < 0.0))
    if beyond.size == 0:
        return float(reach)
    j = beyond[0]
    x_lo = max(x[j - 1], start)
    return float(x_lo + (x[j] - x_lo) * h[j - 1] / (h[j - 1] - h[j]))
