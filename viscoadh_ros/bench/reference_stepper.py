"""A minimal compiled MDR stepper: the baseline the product's step is measured against.

Not on the product path. It is the smallest fast correct program of the same model on the same
grid that we know how to write, so the ratio "product step / minimal step" says what the
product's extra machinery costs (its sub-element edge search, substeps, energy bookkeeping,
validation and outputs). A bare read/write loop cannot say that (no stepper reaches that floor),
and neither can a slow baseline (0.3.0's version of this file looped over the Kelvin modes of
each element with a runtime K, which the compiler could not vectorise: ~17 ns per element step
at K = 1 against the ~2.5 ns the issue's own minimal stepper measured, so every ratio against it
flattered the product by several times). The bench states its agreement with the product beside
its time, so a fast baseline that computes something else is seen at once.

The algorithm (one contact, displacement control, depth linear in time over each step):
- N elements at centres ``x_i = (i + 1/2) dx``; the Kelvin elongations are stored mode by mode
  (structure of arrays, ``kel[k, i]``) in two buffers: a step reads one and writes the other
  (no copy), so the state before the step is at hand for the cells the edge crosses;
- the Kelvin chain of an element in contact is updated exactly for a linearly varying input
  (first-order hold): with the chain's modal form (``z = P l``, ``dz/dt = -lam z + beta u``)
  folded into one K x K matrix and two vectors per step length,
  ``l' = M l + v0 u0 + v1 (u1 - u0)``, ``M = P^-1 diag(exp(-lam dt)) P``; out of contact each
  Kelvin element creeps back with ``exp(-G_k dt / eta_k)``; the loops run over the elements
  innermost (contiguous, vectorised), the K x K matrix outermost;
- out of contact nothing attaches until the surface touches the indenter at the apex; then
  the edge is found from the energy criterion at the element centres,
  ``h_i = d - g_i - w_i + dl_c(x_i)`` (detachment of interior elements first, else attachment of
  exterior ones), the radius interpolated linearly between the last ``h >= 0`` and the first
  ``h < 0`` centre;
- the elements the edge crossed in the step are switched at the crossing time (edge linear in
  time), from their state before the step;
- the force ``2 E0* int_0^a (u - w) dx`` is a midpoint sum over the interior plus the partial
  cell to the interpolated edge, ``n1 d - G(n1) - sum w``, with the profile's prefix sums G;
  no substeps, no allocation. Compiled with ``fastmath`` reassociation (the sums are reassociated: the
  compiler vectorises them); `tests/test_bench.py` holds it to a plain element-by-element
  version of the same algorithm.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]

#: state slots: radius, depth, interior count, which buffer holds the state, the step length
#: the cached chain matrices belong to (-1: none)
_RADIUS, _DEPTH, _COUNT, _PARITY, _CACHED_DT = 0, 1, 2, 3, 4
_STATE_SIZE = 5


@numba.njit(cache=True, nogil=True)
def _chain(p, p_inv, lam, beta, rate, tau, out):  # pragma: no cover - compiled
    """Per step length tau into out (K, K + 3): the in-contact update ``l' = M l + v0 u0 +
    v1 (u1 - u0)`` (columns 0..K-1: M; K: v0; K + 1: v1) and the free decay exp(-rate tau)
    (column K + 2)."""
    k_count = lam.shape[0]
    for m in range(k_count):
        x = lam[m] * tau
        if x < 1e-4:
            e = math.exp(-x)
            phi1 = tau * (1.0 - x / 2.0 + x * x / 6.0)
            chi = tau * (0.5 - x / 6.0 + x * x / 24.0)
        else:
            e = math.exp(-x)
            one_minus = -math.expm1(-x)
            phi1 = tau * one_minus / x
            chi = tau * (x - one_minus) / (x * x)
        for k in range(k_count):
            if m == 0:
                for j in range(k_count + 2):
                    out[k, j] = 0.0
            q = p_inv[k, m]
            for j in range(k_count):
                out[k, j] += q * e * p[m, j]
            out[k, k_count] += q * beta[m] * phi1
            out[k, k_count + 1] += q * beta[m] * chi
    for k in range(k_count):
        out[k, k_count + 2] = math.exp(-rate[k] * tau)


@numba.njit(cache=True, nogil=True, inline="always")
def _cell_in_contact(kel, i, u0, u1, mat):  # pragma: no cover - compiled
    """One element's chain in contact over the interval `mat` was built for (in place; column
    K + 3 of `mat` is its scratch)."""
    k_count = kel.shape[0]
    for k in range(k_count):
        mat[k, k_count + 3] = kel[k, i]
    for k in range(k_count):
        value = mat[k, k_count] * u0 + mat[k, k_count + 1] * (u1 - u0)
        for j in range(k_count):
            value += mat[k, j] * mat[j, k_count + 3]
        kel[k, i] = value


#: Reassociation (vectorised sums) and fused multiply-adds; not the no-NaN/no-inf assumptions.
_FAST = {"reassoc", "contract"}


@numba.njit(cache=True, nogil=True, fastmath=_FAST)
def _step(
    kel, w, g, crit, gsum, p, p_inv, lam, beta, rate, mat, part, state, dx, e0, dt, d1
):  # pragma: no cover
    """One step to depth d1 over dt; returns the force, N (state updated in place)."""
    k_count, n = kel.shape[1], kel.shape[2]
    a0 = state[_RADIUS]
    d0 = state[_DEPTH]
    n0 = int(state[_COUNT])
    parity = int(state[_PARITY])
    cur = kel[parity]
    nxt = kel[1 - parity]
    if k_count > 0:
        if state[_CACHED_DT] != dt:
            _chain(p, p_inv, lam, beta, rate, dt, mat)
            state[_CACHED_DT] = dt
        du = d1 - d0
        for k in range(k_count):
            m0 = mat[k, 0]
            c = mat[k, k_count] * d0 + mat[k, k_count + 1] * du
            v0 = mat[k, k_count]
            for i in range(n0):
                nxt[k, i] = m0 * cur[0, i] + c - v0 * g[i]
            for j in range(1, k_count):
                mj = mat[k, j]
                for i in range(n0):
                    nxt[k, i] += mj * cur[j, i]
            decay = mat[k, k_count + 2]
            for i in range(n0, n):
                nxt[k, i] = decay * cur[k, i]
        for i in range(n):
            w[i] = nxt[0, i]
        for k in range(1, k_count):
            for i in range(n):
                w[i] += nxt[k, i]
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
    # Cells the edge crossed switch at the crossing time, from their state before the step.
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
                nxt[k, i] = cur[k, i]
            if n1 > n0:
                _chain(p, p_inv, lam, beta, rate, f * dt, part)
                for k in range(k_count):
                    nxt[k, i] *= part[k, k_count + 2]
                _chain(p, p_inv, lam, beta, rate, (1.0 - f) * dt, part)
                _cell_in_contact(nxt, i, d_switch - g[i], d1 - g[i], part)
            else:
                _chain(p, p_inv, lam, beta, rate, f * dt, part)
                _cell_in_contact(nxt, i, d0 - g[i], d_switch - g[i], part)
                _chain(p, p_inv, lam, beta, rate, (1.0 - f) * dt, part)
                for k in range(k_count):
                    nxt[k, i] *= part[k, k_count + 2]
            total = 0.0
            for k in range(k_count):
                total += nxt[k, i]
            w[i] = total
    force = 0.0
    if n1 > 0:
        total_w = 0.0
        for i in range(n1):
            total_w += w[i]
        total = n1 * d1 - gsum[n1] - total_w
        # Midpoint cells up to n1 dx, corrected to the interpolated edge with the last value.
        total = total * dx + (a1 - n1 * dx) * (d1 - g[n1 - 1] - w[n1 - 1])
        force = 2.0 * e0 * total
    state[_RADIUS] = a1
    state[_DEPTH] = d1
    state[_COUNT] = n1
    state[_PARITY] = 1 - parity
    return force


@numba.njit(cache=True, nogil=True)
def _run(
    kel, w, g, crit, gsum, p, p_inv, lam, beta, rate, mat, part, state, dx, e0, dt, depths, forces
):  # pragma: no cover
    """_step over a depth history at a fixed dt, forces written to `forces`."""
    for s in range(depths.shape[0]):
        forces[s] = _step(
            kel, w, g, crit, gsum, p, p_inv, lam, beta, rate, mat, part, state, dx, e0, dt, depths[s]
        )


class MinimalStepper:
    """One contact on the minimal stepper (see the module docstring).

    g_centres: profile g at the element centres, m, shape (N,); dx: element width, m; e0: glass
    modulus E0*, Pa; e_kelvin, eta_kelvin: Kelvin moduli E_k*, Pa, and dampers eta_k*, Pa s,
    shape (K,) (K = 0: elastic); c_crit: critical glass elongation per sqrt(m),
    ``dl_c(x) = c_crit sqrt(x)``.
    """

    @classmethod
    def on_grid_of(cls, simulator: Any) -> MinimalStepper:
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
        self.gsum = np.concatenate(([0.0], np.cumsum(g)))
        self.dx = float(dx)
        self.e0 = float(e0)
        self.crit = c_crit * np.sqrt((np.arange(n) + 0.5) * dx)
        self.kel = np.zeros((2, k, n))
        self.w = np.zeros(n)
        self.mat = np.zeros((k, k + 3))
        self.part = np.zeros((k, k + 4))
        self.state = np.zeros(_STATE_SIZE)
        self.state[_CACHED_DT] = -1.0
        self._call = (
            self.kel,
            self.w,
            self.g,
            self.crit,
            self.gsum,
            self.p,
            self.p_inv,
            self.lam,
            self.beta,
            self.rate,
            self.mat,
            self.part,
            self.state,
            self.dx,
            self.e0,
        )

    @property
    def radius(self) -> float:
        return float(self.state[_RADIUS])

    @property
    def memory(self) -> FloatArray:
        """The Kelvin elongations now, (N, K), m."""
        return self.kel[int(self.state[_PARITY])].T.copy()

    def set_state(self, *, depth: float, radius: float, memory: FloatArray) -> None:
        """Start from a contact at `depth` (m) with `radius` (m) and Kelvin state (N, K)."""
        self.state[_PARITY] = 0
        self.kel[0] = np.asarray(memory, dtype=np.float64).T
        self.w[...] = self.kel[0].sum(axis=0)
        self.state[_DEPTH] = depth
        self.state[_RADIUS] = radius
        centres = (np.arange(self.g.size) + 0.5) * self.dx
        self.state[_COUNT] = 0 if radius <= 0.0 else max(1, int(np.count_nonzero(centres < radius)))

    def step(self, dt: float, depth: float) -> float:
        """Advance by dt (s) to `depth` (m); the force, N."""
        return _step(*self._call, float(dt), float(depth))

    def run(self, dt: float, depths: FloatArray) -> FloatArray:
        """Step through `depths` (m) at a fixed dt (s) in one compiled call; forces, N."""
        forces = np.empty(depths.size)
        _run(*self._call, float(dt), np.ascontiguousarray(depths, dtype=np.float64), forces)
        return forces
