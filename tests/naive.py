"""Plain-numpy references of the numba kernels in `viscoadh_ros.core._kernels`.

Each function restates one kernel the slow, obvious way (dense grids, matrix exponentials,
vectorised interpolation) so the tests can compare the compiled path against it. They take
a `_kernels.Row` for its arrays and constants and never modify it.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
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


def kelvin_update(
    row: _kernels.Row, n_in: int, d0: float, d1: float, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """New Kelvin state (wl, wb), each (N, K), after dt: elements below n_in in contact, the
    rest free. B is the same chain driven by a unit input."""
    out = row.wl.copy()
    out_b = row.wb.copy()
    for i in range(row.elements):
        out[i] = chain_step(row.wl[i], d0 - row.g_c[i], d1 - row.g_c[i], dt, row, i < n_in)
        out_b[i] = chain_step(row.wb[i], 1.0, 1.0, dt, row, i < n_in)
    return out, out_b


def damper_work(row: _kernels.Row, n_in: int, d0: float, d1: float, dt: float) -> float:
    """Energy the row's dampers dissipate over dt, J: ``2 dx sum_k eta_k* int (dl_k/dt)^2``
    (both half-rows) integrated with the chain by a stiff ODE solver (Radau, tight
    tolerances), element by element: elements below n_in in contact, the rest free."""
    k = row.e_kelvin.size
    if k == 0:
        return 0.0
    eta = row.e_kelvin / row.rate
    total = 0.0
    for i in range(row.elements):
        inside = i < n_in
        if inside:
            a_mat = -(row.e0 * np.ones((k, k)) + np.diag(row.e_kelvin)) / eta[:, None]
            b_vec = row.e0 / eta
        else:
            a_mat = -np.diag(row.rate)
            b_vec = np.zeros(k)
        u0 = d0 - row.g_c[i]
        slope = (d1 - d0) / dt

        def rhs(t, y, a_mat=a_mat, b_vec=b_vec, u0=u0, slope=slope):
            rate = a_mat @ y[:k] + b_vec * (u0 + slope * t)
            return np.concatenate([rate, [float(eta @ rate**2)]])

        scale = max(float(np.max(np.abs(row.wl[i]))), abs(u0), 1e-12)
        solution = solve_ivp(
            rhs,
            (0.0, dt),
            np.concatenate([row.wl[i], [0.0]]),
            method="Radau",
            jac=lambda t, y, a_mat=a_mat: np.block([[a_mat, np.zeros((k, 1))], [np.zeros((1, k + 1))]]),
            rtol=1e-9,
            atol=1e-13 * scale,
        )
        total += 2.0 * row.dx * float(solution.y[k, -1])
    return total


def g_at(row: _kernels.Row, x: np.ndarray) -> np.ndarray:
    fine = np.arange(row.gf.size) * row.df
    return np.interp(x, fine, row.gf)


def _extrapolate(p: np.ndarray, idx: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    """Linear interpolation of node values over p (element index units), with the kernel's
    one-sided extrapolations: linear below the first node (exterior towards the edge),
    minmod-limited linear above the last (interior towards the edge), held at the centre
    and the far end."""
    lo, hi = int(idx[0]), int(idx[-1])
    inside = np.interp(p, idx.astype(float), values)
    if lo > 0 and hi > lo:
        below = values[0] + (p - lo) * (values[1] - values[0])
        inside = np.where(p <= lo, below, inside)
    if hi < size - 1 and hi > lo:
        slope = values[-1] - values[-2]
        if hi - 2 >= lo:
            before = values[-2] - values[-3]
            slope = 0.0 if slope * before <= 0.0 else min(slope, before, key=abs)
        inside = np.where(p >= hi, values[-1] + (p - hi) * slope, inside)
    return inside


def side_values(
    row: _kernels.Row, x: np.ndarray, values: np.ndarray, units: np.ndarray, lo: int, hi: int
) -> np.ndarray:
    """`_kernels._w_side` vectorised: between centres of elements lo..hi the linear
    interpolant of the elongations corrected by the profile's curvature times the
    interpolated B, ``w_lin - (g - g_lin) B_lin``; beyond them A (``values + g_c units``)
    and B extrapolated (`_extrapolate`) and ``w = A - g B``."""
    x = np.asarray(x, dtype=np.float64)
    if lo > hi:
        return np.zeros_like(x)
    idx = np.arange(lo, hi + 1)
    p = x / row.dx - 0.5
    g = g_at(row, x)
    a_x = _extrapolate(p, idx, values[idx] + row.g_c[idx] * units[idx], values.size)
    b_x = _extrapolate(p, idx, units[idx], values.size)
    outside = a_x - g * b_x
    w_lin = np.interp(p, idx.astype(float), values[idx])
    g_lin = np.interp(p, idx.astype(float), row.g_c[idx])
    inside = w_lin - (g - g_lin) * b_x
    return np.where((p > lo) & (p < hi), inside, outside)


def gap(row: _kernels.Row, x: np.ndarray, depth: float, radius: float, interior: bool) -> np.ndarray:
    """Criterion gap h(x) with the memory of one side of `radius`."""
    n = row.elements
    n_in = interior_count(radius, row.dx, n)
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    w = side_values(row, x, row.wsum, row.bsum, lo, hi)
    return depth - g_at(row, x) - w + row.c_crit * np.sqrt(x)


def force(row: _kernels.Row, radius: float, depth: float, points: int = 200001) -> float:
    """2 E0* times the integral of the glass elongation over (0, a), dense trapezoid. The
    last interior element L counts with weight ``s = min(1, 2 (a - x_L) / dx)``, the memory
    read without it (element L-1's extrapolation) with ``1 - s`` scaled by how relaxed element L-1's
    unit memory is (`_kernels._edge_piece`, `_relaxed_share`)."""
    if radius <= 0.0:
        return 0.0
    x = np.linspace(0.0, radius, points)
    n_in = interior_count(radius, row.dx, row.elements)

    def integral(last: int) -> float:
        w = side_values(row, x, row.wsum, row.bsum, 0, last)
        return 2.0 * row.e0 * trapezoid(depth - g_at(row, x) - w, x)

    s = min(1.0, 2.0 * (radius / row.dx - n_in + 0.5))
    if n_in < 2 or s >= 1.0:
        return integral(n_in - 1)
    # The blend's share: 1 - CENTRE_CUT v tau / dx, v tau / dx = -1 / ln(1 - B_{L-1} / kap).
    r = row.bsum[n_in - 2] / row.kap if row.kap > 0.0 else 1.0
    c = 1.0 if r >= 1.0 else 0.0 if r <= 0.0 else max(0.0, 1.0 + _kernels.CENTRE_CUT / np.log1p(-r))
    if c < 1.0 and row.wb.shape[1] > 1:
        # K >= 2: per relaxation mode, weighted by the mode's part of B_{L-1} (`_modal_share`).
        zb = row.p @ row.wb[n_in - 2]
        weights = np.abs(row.p_inv.sum(axis=0) * zb)
        rel = zb / (row.beta / row.lam)
        shares = np.where(
            rel >= 1.0 - _kernels.MODE_RELAXED,
            1.0,
            np.where(
                rel <= 0.0,
                0.0,
                np.maximum(
                    0.0,
                    1.0 + _kernels.CENTRE_CUT / np.log1p(-np.clip(rel, 1e-300, 1.0 - _kernels.MODE_RELAXED)),
                ),
            ),
        )
        c = float(weights @ shares / weights.sum()) if weights.sum() > 0.0 else 0.0
    return integral(n_in - 1) + c * (1.0 - s) * (integral(n_in - 2) - integral(n_in - 1))


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
            lk = side_values(row, x, row.wl[:, k], row.wb[:, k], lo, hi)
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
            depth - g_at(row, x) - side_values(row, x, row.wsum, row.bsum, 0, n - 1) >= 0.0
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
