"""An independent reference for the time-stepped core: a plain element-wise MDR stepper.

It shares nothing with `viscoadh_ros.core._kernels` but the MDR profile ``g`` and the
material constants: binary elements (in contact or not) on a fine uniform grid, the energy
criterion checked at element centres only (the outermost interior element lets go when its
glass spring is stretched beyond ``dl_c(x)``, the first exterior one attaches when it would
be stretched less; the first touch needs the surface to reach the indenter), the Kelvin
chains of every element advanced over each substep by the matrix exponential of the
augmented linear system (scipy's ``expm``, an exact update for a depth linear in time, not
the core's modal form), status switches at substep ends, force ``2 E0* dx sum l0`` and the
dissipated energy from the balance input - stored - surface. Its error is first order in dx
and in the substep, so `converged` runs it on a refinement sequence and extrapolates
(Richardson, order 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
from scipy.linalg import expm

from viscoadh_ros.core.profiles import make_profile
from viscoadh_ros.core.rheology import CreepElement


@dataclass(frozen=True)
class ReferenceRun:
    """Per history row: force N, contact radius m (outermost interior centre + dx/2),
    energy dissipated J; ``elements`` and ``substeps`` (per row) of the run."""

    force: np.ndarray
    radius: np.ndarray
    dissipated: np.ndarray
    elements: int
    substeps: int


@numba.njit(cache=True)
def _run(
    g_c, x_c, dx, e0, c2, prop, psi0, psi1, decay, e_kelvin, depths, substeps, force, radius, dissipated
):
    n = g_c.shape[0]
    k_count = e_kelvin.shape[0]
    wl = np.zeros((n, k_count))
    wsum = np.zeros(n)
    tmp = np.zeros(k_count)
    n_c = 0
    d_prev = 0.0
    f_prev = 0.0
    work = 0.0
    for row in range(depths.shape[0]):
        d_row = depths[row]
        steps = substeps if row > 0 else 1
        for s in range(steps):
            da = d_prev + (d_row - d_prev) * s / steps
            db = d_prev + (d_row - d_prev) * (s + 1) / steps
            if row > 0:
                for i in range(n):
                    if i < n_c:
                        u0 = da - g_c[i]
                        u1 = db - g_c[i]
                        for k in range(k_count):
                            acc = psi0[k] * u0 + psi1[k] * u1
                            for j in range(k_count):
                                acc += prop[k, j] * wl[i, j]
                            tmp[k] = acc
                    else:
                        for k in range(k_count):
                            tmp[k] = decay[k] * wl[i, k]
                    total = 0.0
                    for k in range(k_count):
                        wl[i, k] = tmp[k]
                        total += tmp[k]
                    wsum[i] = total
            # The energy criterion at element centres, both ways, until nothing changes.
            while True:
                if n_c > 0:
                    i = n_c - 1
                    if db - g_c[i] - wsum[i] < -math.sqrt(c2 * x_c[i]):
                        n_c -= 1
                        continue
                if n_c == 0:
                    if db - g_c[0] - wsum[0] >= 0.0:
                        n_c = 1
                        continue
                    break
                if n_c < n:
                    i = n_c
                    if db - g_c[i] - wsum[i] >= -math.sqrt(c2 * x_c[i]):
                        n_c += 1
                        if n_c == n:
                            return -1
                        continue
                break
            f = 0.0
            for i in range(n_c):
                f += db - g_c[i] - wsum[i]
            f *= 2.0 * e0 * dx
            work += 0.5 * (f_prev + f) * (db - da)
            f_prev = f
        d_prev = d_row
        force[row] = f_prev
        radius[row] = n_c * dx
        stored = 0.0
        surface = 0.0
        for i in range(n):
            for k in range(k_count):
                stored += e_kelvin[k] * wl[i, k] * wl[i, k]
            if i < n_c:
                l0 = d_row - g_c[i] - wsum[i]
                stored += e0 * l0 * l0
                surface += e0 * c2 * x_c[i]
        dissipated[row] = work - dx * (stored - surface)
    return 0


def run(
    contact: Any, times: np.ndarray, depths: np.ndarray, *, length: float, elements: int, substeps: int
) -> ReferenceRun:
    """Run a depth history (uniform `times`, s; `depths`, m; the first row is reached from
    rest at depth 0 instantly) on `elements` over (0, `length`] m with `substeps` per row."""
    dt = np.diff(times)
    if not np.allclose(dt, dt[0], rtol=1e-9):
        raise ValueError("the reference stepper takes uniform rows")
    h = float(dt[0]) / substeps
    creep = CreepElement.from_config(contact.material)
    e0 = creep.glass_modulus_star
    e_k = np.array([creep.modulus_star(g) for g in creep.kelvin_shear_moduli])
    eta = np.array([creep.modulus_star(v) for v in creep.kelvin_viscosities])
    k = e_k.size
    # Augmented system d/dt [l, u, s] = [[A, b, 0], [0, 0, 1], [0, 0, 0]] [l, u, s].
    m = np.zeros((k + 2, k + 2))
    m[:k, :k] = -(e0 * np.ones((k, k)) + np.diag(e_k)) / eta[:, None]
    m[:k, k] = e0 / eta
    m[k, k + 1] = 1.0
    big = expm(m * h) if k else np.eye(2)
    prop = np.ascontiguousarray(big[:k, :k])
    # l(h) = prop l + E_u u0 + E_s s with s = (u1 - u0)/h.
    psi0 = np.ascontiguousarray(big[:k, k] - big[:k, k + 1] / h)
    psi1 = np.ascontiguousarray(big[:k, k + 1] / h)
    decay = np.exp(-e_k / eta * h) if k else np.zeros(0)
    dx = length / elements
    x_c = (np.arange(elements) + 0.5) * dx
    g_c = np.asarray(make_profile(contact.indenter).g(x_c), dtype=np.float64)
    work = float(contact.adhesion.work_of_adhesion)
    c2 = 2.0 * math.pi * work / e0
    n = depths.size
    force, radius, dissipated = np.zeros(n), np.zeros(n), np.zeros(n)
    status = _run(
        g_c,
        x_c,
        dx,
        e0,
        c2,
        prop,
        psi0,
        psi1,
        decay,
        e_k,
        np.ascontiguousarray(depths, dtype=np.float64),
        int(substeps),
        force,
        radius,
        dissipated,
    )
    if status != 0:
        raise ValueError(f"the contact reached the end of the reference domain ({length} m)")
    return ReferenceRun(force, radius, dissipated, elements, substeps)


def converged(
    contact: Any,
    times: np.ndarray,
    depths: np.ndarray,
    *,
    length: float,
    elements: int,
    substeps: int,
    levels: int = 2,
) -> tuple[ReferenceRun, ReferenceRun]:
    """Runs at (elements, substeps) times 1, 2, ..., 2^(levels-1); returns the finest run and
    its order-1 Richardson extrapolation (2 fine - coarse, per row; radius from the finest)."""
    runs = [
        run(contact, times, depths, length=length, elements=elements * 2**i, substeps=substeps * 2**i)
        for i in range(levels)
    ]
    fine, coarse = runs[-1], runs[-2]
    extrapolated = ReferenceRun(
        2.0 * fine.force - coarse.force,
        fine.radius,
        2.0 * fine.dissipated - coarse.dissipated,
        fine.elements,
        fine.substeps,
    )
    return fine, extrapolated
