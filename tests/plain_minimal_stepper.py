"""The bench's minimal stepper written plainly, element by element (0.3.0's version of
viscoadh_ros/bench/reference_stepper.py): the test-only reference that the fast, vectorised
baseline computes the same thing (tests/test_bench.py). Not cached (numba): a test reference."""
from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

#: state slots
_RADIUS, _DEPTH, _COUNT = 0, 1, 2


@numba.njit(cache=False, nogil=True)
def _coefficients(lam, dt, out):  # pragma: no cover - compiled
    """Exact first-order-hold coefficients per mode into out (3, K): exp(-lam dt), the response
    to a constant input and to a unit ramp over dt."""
    for m in range(lam.shape[0]):
        x = lam[m] * dt
        if x < 1e-4:
            out[0, m] = math.exp(-x)
            out[1, m] = dt * (1.0 - x / 2.0 + x * x / 6.0)
            out[2, m] = dt * (0.5 - x / 6.0 + x * x / 24.0)
        else:
            e = math.exp(-x)
            one_minus = -math.expm1(-x)
            out[0, m] = e
            out[1, m] = dt * one_minus / x
            out[2, m] = dt * (x - one_minus) / (x * x)


@numba.njit(cache=False, nogil=True, inline="always")
def _in_contact(kel, w, i, u0, u1, p, p_inv, beta, coef, z):  # pragma: no cover - compiled
    k_count = kel.shape[0]
    for m in range(k_count):
        acc = 0.0
        for k in range(k_count):
            acc += p[m, k] * kel[k, i]
        z[m] = coef[0, m] * acc + beta[m] * (u0 * coef[1, m] + (u1 - u0) * coef[2, m])
    total = 0.0
    for k in range(k_count):
        acc = 0.0
        for m in range(k_count):
            acc += p_inv[k, m] * z[m]
        kel[k, i] = acc
        total += acc
    w[i] = total


@numba.njit(cache=False, nogil=True)
def _step(
    kel, old, w, g, crit, dx, e0, p, p_inv, lam, beta, rate, coef, z, state, dt, d1
):  # pragma: no cover
    """One step to depth d1 over dt; returns the force, N (state updated in place)."""
    k_count, n = kel.shape
    a0 = state[_RADIUS]
    d0 = state[_DEPTH]
    n0 = int(state[_COUNT])
    _coefficients(lam, dt, coef)
    for k in range(k_count):
        coef[3, k] = math.exp(-rate[k] * dt)
    for i in range(n0):
        for k in range(k_count):
            old[k, i] = kel[k, i]
        _in_contact(kel, w, i, d0 - g[i], d1 - g[i], p, p_inv, beta, coef, z)
    for i in range(n0, n):
        total = 0.0
        for k in range(k_count):
            old[k, i] = kel[k, i]
            value = kel[k, i] * coef[3, k]
            kel[k, i] = value
            total += value
        w[i] = total
    # The edge from the criterion at the centres: detachment first, else attachment.
    n1 = n0
    while n1 > 0 and d1 - g[n1 - 1] - w[n1 - 1] + crit[n1 - 1] < 0.0:
        n1 -= 1
    # Out of contact the surface must first touch the indenter (at the apex; a ring of memory
    # touching first is beyond this stepper); then the criterion lets the edge snap out.
    if n1 == n0 and (n0 > 0 or d1 - g[0] - w[0] >= 0.0):
        while n1 < n and d1 - g[n1] - w[n1] + crit[n1] >= 0.0:
            n1 += 1
    if n1 == 0:
        a1 = 0.0
    elif n1 == n:
        a1 = n * dx
    else:
        h_in = d1 - g[n1 - 1] - w[n1 - 1] + crit[n1 - 1]
        h_out = d1 - g[n1] - w[n1] + crit[n1]
        a1 = (n1 - 0.5) * dx + dx * h_in / (h_in - h_out)
    # Cells the edge crossed switch at the crossing time.
    if k_count > 0 and n1 != n0:
        lo, hi = (n0, n1) if n1 > n0 else (n1, n0)
        for i in range(lo, hi):
            xi = (i + 0.5) * dx
            if a0 <= 0.0:
                f = -d0 / (d1 - d0) if d1 != d0 else 0.0
            elif a1 <= 0.0:
                f = 1.0
            else:
                f = (xi - a0) / (a1 - a0)
            f = min(max(f, 0.0), 1.0)
            d_switch = d0 + f * (d1 - d0)
            for k in range(k_count):
                kel[k, i] = old[k, i]
            if n1 > n0:
                for k in range(k_count):
                    kel[k, i] *= math.exp(-rate[k] * f * dt)
                _coefficients(lam, (1.0 - f) * dt, coef)
                _in_contact(kel, w, i, d_switch - g[i], d1 - g[i], p, p_inv, beta, coef, z)
            else:
                _coefficients(lam, f * dt, coef)
                _in_contact(kel, w, i, d0 - g[i], d_switch - g[i], p, p_inv, beta, coef, z)
                total = 0.0
                for k in range(k_count):
                    value = kel[k, i] * math.exp(-rate[k] * (1.0 - f) * dt)
                    kel[k, i] = value
                    total += value
                w[i] = total
    force = 0.0
    if n1 > 0:
        total = 0.0
        for i in range(n1):
            total += d1 - g[i] - w[i]
        # Midpoint cells up to n1 dx, corrected to the interpolated edge with the last value.
        total = total * dx + (a1 - n1 * dx) * (d1 - g[n1 - 1] - w[n1 - 1])
        force = 2.0 * e0 * total
    state[_RADIUS] = a1
    state[_DEPTH] = d1
    state[_COUNT] = n1
    return force


@numba.njit(cache=False, nogil=True)
def _run(
    kel, old, w, g, crit, dx, e0, p, p_inv, lam, beta, rate, coef, z, state, dt, depths, forces
):  # pragma: no cover
    """_step over a depth history at a fixed dt, forces written to `forces`."""
    for s in range(depths.shape[0]):
        forces[s] = _step(
            kel, old, w, g, crit, dx, e0, p, p_inv, lam, beta, rate, coef, z, state, dt, depths[s]
        )


class PlainMinimalStepper:
    """One contact on the minimal stepper (see the module docstring).

    g_centres: profile g at the element centres, m, shape (N,); dx: element width, m; e0: glass
    modulus E0*, Pa; e_kelvin, eta_kelvin: Kelvin moduli E_k*, Pa, and dampers eta_k*, Pa s,
    shape (K,) (K = 0: elastic); c_crit: critical glass elongation per sqrt(m),
    ``dl_c(x) = c_crit sqrt(x)``.
    """

    @classmethod
    def on_grid_of(cls, simulator: Any) -> PlainMinimalStepper:
        """The minimal stepper on a time-stepped `ContactSimulator`'s current grid and chain (its
        row must exist): the bench's side-by-side baseline (kernel and replay sections)."""
        model = simulator._model  # the bench reads the product's private grid on purpose
        row = model.row
        return cls(
            g_centres=row.g_c,
            dx=row.dx,
            e0=simulator.physics.e0,
            e_kelvin=model.e_kelvin,
            eta_kelvin=model.e_kelvin / model.rate if model.e_kelvin.size else np.zeros(0),
            c_crit=simulator.physics.c_crit,
        )

    def __init__(
        self,
        *,
        g_centres: FloatArray,
        dx: float,
        e0: float,
        e_kelvin: FloatArray,
        eta_kelvin: FloatArray,
        c_crit: float,
    ) -> None:
        g = np.ascontiguousarray(g_centres, dtype=np.float64)
        n, k = g.size, int(np.size(e_kelvin))
        e_k = np.asarray(e_kelvin, dtype=np.float64).reshape(k)
        eta = np.asarray(eta_kelvin, dtype=np.float64).reshape(k)
        if k:
            # Symmetrise the in-contact chain (D^-1/2 S D^-1/2, S = E0 11^T + diag(E_k)) and
            # diagonalise it: real rates, orthogonal modes.
            root = np.sqrt(eta)
            lam, q = np.linalg.eigh((e0 * np.ones((k, k)) + np.diag(e_k)) / np.outer(root, root))
            self.p = np.ascontiguousarray(q.T * root[None, :])
            self.p_inv = np.ascontiguousarray(q / root[:, None])
            self.beta = np.ascontiguousarray(q.T @ (e0 / root))
            self.lam = np.ascontiguousarray(lam)
            self.rate = e_k / eta
        else:
            self.p = self.p_inv = np.zeros((0, 0))
            self.beta = self.lam = self.rate = np.zeros(0)
        self.g = g
        self.dx = float(dx)
        self.e0 = float(e0)
        self.crit = c_crit * np.sqrt((np.arange(n) + 0.5) * dx)
        self.l = np.zeros((k, n))
        self.old = np.zeros((k, n))
        self.w = np.zeros(n)
        self.coef = np.zeros((4, k))
        self.z = np.zeros(k)
        self.state = np.zeros(3)

    @property
    def radius(self) -> float:
        return float(self.state[_RADIUS])

    def _args(self) -> tuple:
        return (
            self.l,
            self.old,
            self.w,
            self.g,
            self.crit,
            self.dx,
            self.e0,
            self.p,
            self.p_inv,
            self.lam,
            self.beta,
            self.rate,
            self.coef,
            self.z,
            self.state,
        )

    def set_state(self, *, depth: float, radius: float, memory: FloatArray) -> None:
        """Start from a contact at `depth` (m) with `radius` (m) and Kelvin state (N, K)."""
        self.l[...] = np.asarray(memory, dtype=np.float64).T
        self.w[...] = self.l.sum(axis=0)
        self.state[_DEPTH] = depth
        self.state[_RADIUS] = radius
        centres = (np.arange(self.g.size) + 0.5) * self.dx
        self.state[_COUNT] = 0 if radius <= 0.0 else max(1, int(np.count_nonzero(centres < radius)))

    def step(self, dt: float, depth: float) -> float:
        """Advance by dt (s) to `depth` (m); the force, N."""
        return float(_step(*self._args(), float(dt), float(depth)))

    def run(self, dt: float, depths: FloatArray) -> FloatArray:
        """Step through `depths` (m) at a fixed dt (s) in one compiled call; forces, N."""
        forces = np.empty(depths.size)
        _run(*self._args(), float(dt), np.ascontiguousarray(depths, dtype=np.float64), forces)
        return forces
