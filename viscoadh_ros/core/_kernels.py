"""Numba kernels of the time-stepped MDR model (private).

All kernels work in place on preallocated float64 arrays owned by the simulator. The
public wrappers at the bottom validate shapes, dtypes and finiteness *before* entering
numba (a NaN that slips into a compiled loop would spread silently), and `warm_up()`
compiles and calls every kernel once so the first real step does not stall.

Geometry. The 1D MDR row holds N elements at cell centres ``x_i = (i + 1/2) dx`` on
``(0, L]``. The profile ``g`` is also sampled on a fine uniform grid ``xf_j = j * df``
(M points, ``xf_0 = 0``, ``xf_{M-1} = L``) with its running integral ``Gf``; between fine
points it is linear. The contact radius ``a`` is continuous: elements with ``x_i < a``
are in contact ("interior"; at least element 0 when ``a > 0``), the others are exterior.

State. ``wl[i, k]`` is the elongation of Kelvin element k of element i, m; ``wsum[i]``
their sum. Interior glass elongation ``l0 = d - g(x) - wsum``, exterior ``l0 = 0``.

Edge. ``h(x) = d - g(x) - w(x) + c sqrt(x)`` with ``c sqrt(x) = dl_c(x)``, the critical
glass elongation. ``w(x)`` is interpolated linearly between element centres of ONE side
(interior or exterior), held constant beyond that side's last centre: ``h`` is
discontinuous at the edge, and that jump is the sticking zone.
"""

from __future__ import annotations

import math

import numba
import numpy as np

STATUS_OK = 0
STATUS_GROW = 1

#: Edge motion codes written to ``out[OUT_MOTION]`` by `advance`.
MOTION_NONE = 0
MOTION_ATTACH = 1
MOTION_DETACH = 2

OUT_RADIUS = 0
OUT_FORCE = 1
OUT_WORK = 2
OUT_MOTION = 3
OUT_SUBSTEPS = 4
OUT_SIZE = 5

# Below this |lambda dt| the phi functions use their Taylor series: the closed forms lose
# all digits to cancellation there (1 - exp(-x) for x ~ 1e-12).
_SERIES_LIMIT = 1e-4


@numba.njit(cache=True)
def _phi(x: float) -> tuple:
    """Return ``(exp(-x), (1-exp(-x))/x, (x-1+exp(-x))/x^2)`` for x >= 0, safe at both ends."""
    if x < _SERIES_LIMIT:
        return (
            math.exp(-x),
            1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0,
            0.5 - x / 6.0 + x * x / 24.0 - x * x * x / 120.0,
        )
    e = math.exp(-x)
    one_minus = -math.expm1(-x)
    return e, one_minus / x, (x - one_minus) / (x * x)


@numba.njit(cache=True)
def _interior_count(a: float, dx: float, n: int) -> int:
    """Number of elements in contact for radius ``a``: centres below ``a``, >= 1 if a > 0."""
    if a <= 0.0:
        return 0
    count = int(math.ceil(a / dx - 0.5))
    if count < 1:
        count = 1
    if count > n:
        count = n
    return count


@numba.njit(cache=True)
def _g_at(x: float, gf: np.ndarray, df: float) -> float:
    """Profile g at ``x`` by linear interpolation on the fine grid."""
    m = gf.shape[0]
    j = int(x / df)
    if j >= m - 1:
        j = m - 2
    if j < 0:
        j = 0
    t = x / df - j
    return gf[j] + t * (gf[j + 1] - gf[j])


@numba.njit(cache=True)
def _w_side(x: float, wsum: np.ndarray, lo: int, hi: int, dx: float) -> float:
    """Memory w(x) interpolated over elements lo..hi (one side of the edge).

    Towards the edge each side is extrapolated linearly from its two outermost elements:
    a constant hold there gives the criterion h the wrong slope in x, and a receding edge
    of a relaxed contact (w ~ u G0/(G0+G1)) then crawls through the cell up to G0/G1 times
    too slowly. At the centre (symmetry) and at the far end (no memory) w is held.
    """
    if lo > hi:
        return 0.0
    p = x / dx - 0.5
    if p <= lo:
        if lo == 0 or hi == lo:
            return wsum[lo]
        return wsum[lo] + (p - lo) * (wsum[lo + 1] - wsum[lo])
    if p >= hi:
        if hi == wsum.shape[0] - 1 or hi == lo:
            return wsum[hi]
        return wsum[hi] + (p - hi) * (wsum[hi] - wsum[hi - 1])
    i = int(p)
    t = p - i
    return wsum[i] + t * (wsum[i + 1] - wsum[i])


@numba.njit(cache=True)
def _h(x, d, wsum, lo, hi, dx, gf, df, c_crit):
    return d - _g_at(x, gf, df) - _w_side(x, wsum, lo, hi, dx) + c_crit * math.sqrt(x)


@numba.njit(cache=True)
def _bisect(x_lo, x_hi, d, wsum, lo, hi, dx, gf, df, c_crit):
    """Root of h between x_lo (h >= 0) and x_hi (h < 0), to machine precision."""
    for _ in range(80):
        mid = 0.5 * (x_lo + x_hi)
        if mid <= x_lo or mid >= x_hi:
            break
        if _h(mid, d, wsum, lo, hi, dx, gf, df, c_crit) >= 0.0:
            x_lo = mid
        else:
            x_hi = mid
    return 0.5 * (x_lo + x_hi)


@numba.njit(cache=True)
def _scan_out(x_start, d, wsum, lo, hi, dx, gf, df, c_crit, reach):
    """Outermost point of the h >= 0 run that starts at x_start: scan the fine grid outward.

    Returns ``(radius, grow)``; ``grow`` is True when h stays >= 0 up to the end of the
    domain (the contact wants to pass L) and the profile still reaches further.
    """
    m = gf.shape[0]
    j = int(x_start / df) + 1
    prev = x_start
    while j < m:
        xj = j * df
        if xj >= reach:
            if _h(reach, d, wsum, lo, hi, dx, gf, df, c_crit) >= 0.0:
                return reach, False
            return _bisect(prev, reach, d, wsum, lo, hi, dx, gf, df, c_crit), False
        if _h(xj, d, wsum, lo, hi, dx, gf, df, c_crit) < 0.0:
            return _bisect(prev, xj, d, wsum, lo, hi, dx, gf, df, c_crit), False
        prev = xj
        j += 1
    return prev, True


@numba.njit(cache=True)
def _locate_edge(a, d, wsum, dx, gf, df, c_crit, reach):
    """Apply the energy criterion both ways at depth d. Returns (new radius, motion, grow)."""
    n = wsum.shape[0]
    n_in = _interior_count(a, dx, n)
    if a <= 0.0:
        # First touch needs the surface (with its memory) to reach the indenter somewhere;
        # the contact then covers the centre out to the attachment root.
        m = gf.shape[0]
        for j in range(m):
            xj = j * df
            if xj > reach:
                break
            if d - gf[j] - _w_side(xj, wsum, 0, n - 1, dx) >= 0.0:
                radius, grow = _scan_out(xj, d, wsum, 0, n - 1, dx, gf, df, c_crit, reach)
                if radius <= 0.0 and not grow:
                    # Touching exactly at the apex of a profile with g'(0) > 0 and no
                    # adhesion: a zero-area contact is no contact.
                    return 0.0, MOTION_NONE, False
                return radius, MOTION_ATTACH, grow
        return 0.0, MOTION_NONE, False
    # Attachment of exterior elements, judged with the exterior (residual) memory.
    if a < reach and _h(a, d, wsum, n_in, n - 1, dx, gf, df, c_crit) > 0.0:
        radius, grow = _scan_out(a, d, wsum, n_in, n - 1, dx, gf, df, c_crit, reach)
        return radius, MOTION_ATTACH, grow
    # Detachment of interior elements, judged with the interior (crept) memory.
    if _h(a, d, wsum, 0, n_in - 1, dx, gf, df, c_crit) < 0.0:
        j = int(a / df)
        if j * df >= a:
            j -= 1
        upper = a
        while j >= 0:
            xj = j * df
            if _h(xj, d, wsum, 0, n_in - 1, dx, gf, df, c_crit) >= 0.0:
                radius = _bisect(xj, upper, d, wsum, 0, n_in - 1, dx, gf, df, c_crit)
                return radius, MOTION_DETACH, False
            upper = xj
            j -= 1
        return 0.0, MOTION_DETACH, False
    return a, MOTION_NONE, False


@numba.njit(cache=True)
def _memory_integral(a, wsum, n_in, dx):
    """Integral of the interior memory w_int(x) over (0, a), m^2 (linear between centres)."""
    if n_in == 0:
        return 0.0
    total = 0.0
    x_prev = 0.0
    w_prev = wsum[0]
    for i in range(n_in):
        xi = (i + 0.5) * dx
        if xi >= a:
            break
        if i == 0:
            total += wsum[0] * xi
        else:
            total += 0.5 * (w_prev + wsum[i]) * (xi - x_prev)
        x_prev = xi
        w_prev = wsum[i]
    if a > x_prev:
        w_edge = _w_side(a, wsum, 0, n_in - 1, dx)
        total += 0.5 * (w_prev + w_edge) * (a - x_prev) if x_prev > 0.0 else w_prev * a
    return total


@numba.njit(cache=True)
def _profile_integral(a, gf, gint, df):
    """Integral of g over (0, a), m^2, consistent with the linear fine-grid profile."""
    m = gf.shape[0]
    j = int(a / df)
    if j >= m - 1:
        j = m - 2
    xj = j * df
    return gint[j] + 0.5 * (a - xj) * (gf[j] + _g_at(a, gf, df))


@numba.njit(cache=True)
def _force(a, d, wsum, dx, gf, gint, df, e0):
    """Normal force F = 2 E0* int_0^a l0 dx, N per (modulus unit) -- see `force`."""
    if a <= 0.0:
        return 0.0
    n_in = _interior_count(a, dx, wsum.shape[0])
    return 2.0 * e0 * (d * a - _profile_integral(a, gf, gint, df) - _memory_integral(a, wsum, n_in, dx))


@numba.njit(cache=True)
def _kelvin_update(wl, wsum, n_in, d0, d1, dt, g_c, p, p_inv, lam, beta, rate):
    """Exact update of every Kelvin chain over dt for a depth linear from d0 to d1.

    Interior elements: modal form of ``dl/dt = A l + b u(t)`` with ``u = d - g`` linear.
    Exterior elements: free creep-back ``dl_k/dt = -rate_k l_k``.
    """
    n, k_count = wl.shape
    if k_count == 0 or dt <= 0.0:
        return
    e = np.empty(k_count)
    phi1 = np.empty(k_count)
    chi = np.empty(k_count)
    for m in range(k_count):
        em, f1, f2 = _phi(lam[m] * dt)
        e[m] = em
        phi1[m] = f1 * dt
        chi[m] = f2 * dt
    z = np.empty(k_count)
    for i in range(n_in):
        u0 = d0 - g_c[i]
        u1 = d1 - g_c[i]
        for m in range(k_count):
            acc = 0.0
            for k in range(k_count):
                acc += p[m, k] * wl[i, k]
            z[m] = e[m] * acc + beta[m] * (u0 * phi1[m] + (u1 - u0) * chi[m])
        total = 0.0
        for k in range(k_count):
            acc = 0.0
            for m in range(k_count):
                acc += p_inv[k, m] * z[m]
            wl[i, k] = acc
            total += acc
        wsum[i] = total
    for k in range(k_count):
        e[k] = math.exp(-rate[k] * dt)
    for i in range(n_in, n):
        total = 0.0
        for k in range(k_count):
            wl[i, k] *= e[k]
            total += wl[i, k]
        wsum[i] = total


@numba.njit(cache=True)
def _advance(wl, wsum, scratch, a, d0, d1, dt, dx, g_c, gf, gint, df, e0, c_crit, reach,
             p, p_inv, lam, beta, rate, max_substep, max_edge_move, out):
    """Advance the row from depth d0 to d1 (linear in time) over dt with adaptive substeps.

    Substeps are halved while the edge would move more than ``max_edge_move`` (m) in one
    of them, except for jumps from or to no contact (snap-in, pull-off), which no step
    size resolves. Writes radius, force, work input, last motion and substep count to
    ``out``. Returns STATUS_GROW (state partly advanced: the caller restores) when the
    contact needs a larger domain.
    """
    n = wl.shape[0]
    h_min = dt * 1e-7
    step = dt if max_substep <= 0.0 or max_substep > dt else max_substep
    tau = 0.0
    force_prev = _force(a, d0, wsum, dx, gf, gint, df, e0)
    work = 0.0
    motion = MOTION_NONE
    substeps = 0
    if dt <= 0.0:
        new_a, motion, grow = _locate_edge(a, d1, wsum, dx, gf, df, c_crit, reach)
        if grow:
            return STATUS_GROW
        force_new = _force(new_a, d1, wsum, dx, gf, gint, df, e0)
        out[OUT_RADIUS] = new_a
        out[OUT_FORCE] = force_new
        out[OUT_WORK] = 0.5 * (force_prev + force_new) * (d1 - d0)
        out[OUT_MOTION] = motion
        out[OUT_SUBSTEPS] = 0
        return STATUS_OK
    while tau < dt:
        h = step
        last = tau + h >= dt * (1.0 - 1e-12)
        if last:
            h = dt - tau
        da = d0 + (d1 - d0) * (tau / dt)
        db = d1 if last else d0 + (d1 - d0) * ((tau + h) / dt)
        for i in range(n):
            for k in range(wl.shape[1]):
                scratch[i, k] = wl[i, k]
        n_in = _interior_count(a, dx, n)
        _kelvin_update(wl, wsum, n_in, da, db, h, g_c, p, p_inv, lam, beta, rate)
        new_a, sub_motion, grow = _locate_edge(a, db, wsum, dx, gf, df, c_crit, reach)
        if grow:
            return STATUS_GROW
        if abs(new_a - a) > max_edge_move and a > 0.0 and new_a > 0.0 and h > h_min:
            for i in range(n):
                total = 0.0
                for k in range(wl.shape[1]):
                    wl[i, k] = scratch[i, k]
                    total += wl[i, k]
                wsum[i] = total
            step = 0.5 * h
            continue
        force_new = _force(new_a, db, wsum, dx, gf, gint, df, e0)
        work += 0.5 * (force_prev + force_new) * (db - da)
        force_prev = force_new
        if sub_motion != MOTION_NONE:
            motion = sub_motion
        a = new_a
        tau += h
        substeps += 1
        step = min(2.0 * h, dt if max_substep <= 0.0 else max_substep)
    out[OUT_RADIUS] = a
    out[OUT_FORCE] = force_prev
    out[OUT_WORK] = work
    out[OUT_MOTION] = motion
    out[OUT_SUBSTEPS] = substeps
    return STATUS_OK


@numba.njit(cache=True)
def _stored_energy(a, d, wl, wsum, dx, gf, df, e0, e_kelvin):
    """Elastic energy in all springs of both half-rows, J: E0* int_0^a l0^2 + sum E_k* l_k^2 dx."""
    n = wl.shape[0]
    glass = 0.0
    if a > 0.0:
        n_in = _interior_count(a, dx, n)
        j_last = int(a / df)
        x_prev = 0.0
        l_prev = d - gf[0] - _w_side(0.0, wsum, 0, n_in - 1, dx)
        for j in range(1, j_last + 2):
            xj = min(j * df, a)
            lj = d - _g_at(xj, gf, df) - _w_side(xj, wsum, 0, n_in - 1, dx)
            glass += 0.5 * (l_prev * l_prev + lj * lj) * (xj - x_prev)
            x_prev = xj
            l_prev = lj
            if xj >= a:
                break
    kelvin = 0.0
    for i in range(n):
        for k in range(wl.shape[1]):
            kelvin += e_kelvin[k] * wl[i, k] * wl[i, k]
    return e0 * glass + kelvin * dx


# ----------------------------------------------------------------------------------------
# Public wrappers: validate, then call the compiled kernel.


def _check(name: str, array: np.ndarray, shape: tuple[int, ...]) -> None:
    if not isinstance(array, np.ndarray) or array.dtype != np.float64:
        raise TypeError(f"{name} must be a float64 numpy array")
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape} (got {array.shape})")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite")


def _check_scalars(**values: float) -> None:
    for name, value in values.items():
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite (got {value!r})")


class Row:
    """The preallocated arrays of one MDR row and the chain's modal data (see module doc).

    Attributes (SI): ``dx`` element width, m; ``g_c`` (N,) profile at centres, m; ``gf``,
    ``gint`` (M,) fine profile and its running integral, m and m^2; ``df`` fine spacing, m;
    ``reach`` outermost radius the indenter can touch, m; ``wl`` (N, K) Kelvin elongations;
    ``wsum`` (N,); ``p``, ``p_inv`` (K, K), ``lam``, ``beta``, ``rate`` (K,) chain data.
    """

    def __init__(self, *, dx, g_c, gf, gint, df, reach, wl, p, p_inv, lam, beta, rate,
                 e_kelvin) -> None:
        n, k = wl.shape
        m = gf.shape[0]
        _check_scalars(dx=dx, df=df)
        if dx <= 0.0 or df <= 0.0 or m < 2 or n < 1:
            raise ValueError("row needs dx > 0, df > 0, at least 1 element and 2 fine points")
        if not reach > 0.0:
            raise ValueError(f"reach must be > 0 (got {reach!r})")
        for name, array, shape in (
            ("g_c", g_c, (n,)), ("gf", gf, (m,)), ("gint", gint, (m,)), ("wl", wl, (n, k)),
            ("p", p, (k, k)), ("p_inv", p_inv, (k, k)), ("lam", lam, (k,)),
            ("beta", beta, (k,)), ("rate", rate, (k,)), ("e_kelvin", e_kelvin, (k,)),
        ):
            _check(name, array, shape)
        self.dx, self.df, self.reach = float(dx), float(df), float(reach)
        self.g_c, self.gf, self.gint = g_c, gf, gint
        self.wl = wl
        self.wsum = wl.sum(axis=1)
        self.scratch = np.empty_like(wl)
        self.p, self.p_inv, self.lam, self.beta, self.rate = p, p_inv, lam, beta, rate
        self.e_kelvin = e_kelvin
        self.out = np.zeros(OUT_SIZE)

    @property
    def elements(self) -> int:
        return self.wl.shape[0]

    @property
    def length(self) -> float:
        """Domain length L, m."""
        return self.dx * self.elements

    def set_memory(self, wl: np.ndarray) -> None:
        """Replace the Kelvin state (N, K) after validation."""
        _check("wl", wl, self.wl.shape)
        self.wl[...] = wl
        self.wsum[...] = wl.sum(axis=1)


def advance(row: Row, radius: float, d0: float, d1: float, dt: float, *, e0: float,
            c_crit: float, max_substep: float, max_edge_move: float) -> tuple[int, np.ndarray]:
    """Advance `row` in place over dt (s) from depth d0 to d1 (m, linear in time).

    Returns ``(status, out)``; ``out[OUT_RADIUS]`` is the new contact radius (m),
    ``out[OUT_FORCE]`` the force (N), ``out[OUT_WORK]`` the work input (J). On STATUS_GROW
    the row is partly advanced and must be restored by the caller.
    """
    _check_scalars(radius=radius, d0=d0, d1=d1, dt=dt, e0=e0, c_crit=c_crit,
                   max_edge_move=max_edge_move)
    if dt < 0.0:
        raise ValueError(f"dt must be >= 0 (got {dt!r})")
    if radius < 0.0 or e0 <= 0.0 or c_crit < 0.0:
        raise ValueError("radius and c_crit must be >= 0 and e0 > 0")
    status = _advance(row.wl, row.wsum, row.scratch, float(radius), float(d0), float(d1),
                      float(dt), row.dx, row.g_c, row.gf, row.gint, row.df, float(e0),
                      float(c_crit), row.reach, row.p, row.p_inv, row.lam, row.beta,
                      row.rate, float(max_substep), float(max_edge_move), row.out)
    return int(status), row.out


def force(row: Row, radius: float, depth: float, e0: float) -> float:
    """Normal force, N, of the row at contact radius (m) and depth (m) with glass modulus e0 (Pa)."""
    _check_scalars(radius=radius, depth=depth, e0=e0)
    return float(_force(float(radius), float(depth), row.wsum, row.dx, row.gf, row.gint,
                        row.df, float(e0)))


def stored_energy(row: Row, radius: float, depth: float, e0: float) -> float:
    """Elastic energy stored in glass and Kelvin springs of the row, J."""
    _check_scalars(radius=radius, depth=depth, e0=e0)
    return float(_stored_energy(float(radius), float(depth), row.wl, row.wsum, row.dx,
                                row.gf, row.df, float(e0), row.e_kelvin))


def criterion_gap(row: Row, x: float, depth: float, c_crit: float, interior: bool,
                  radius: float) -> float:
    """h(x) with the memory of the interior (True) or exterior side of `radius`, m."""
    _check_scalars(x=x, depth=depth, c_crit=c_crit, radius=radius)
    n = row.elements
    n_in = int(_interior_count(float(radius), row.dx, n))
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    return float(_h(float(x), float(depth), row.wsum, lo, hi, row.dx, row.gf, row.df,
                    float(c_crit)))


def kelvin_update(row: Row, n_in: int, d0: float, d1: float, dt: float) -> None:
    """Exact Kelvin-chain update of `row` in place (see `_kelvin_update`)."""
    _check_scalars(d0=d0, d1=d1, dt=dt)
    if not 0 <= n_in <= row.elements:
        raise ValueError(f"n_in must be in [0, {row.elements}] (got {n_in})")
    _kelvin_update(row.wl, row.wsum, int(n_in), float(d0), float(d1), float(dt), row.g_c,
                   row.p, row.p_inv, row.lam, row.beta, row.rate)


def warm_up() -> None:
    """Compile (or load from cache) and call every kernel once on a tiny row."""
    n, k, m = 4, 2, 9
    x = (np.arange(n) + 0.5) * 0.25
    xf = np.linspace(0.0, 1.0, m)
    gf = xf**2
    gint = xf**3 / 3.0
    eye = np.eye(k)
    row = Row(dx=0.25, g_c=x**2, gf=gf, gint=gint, df=xf[1], reach=np.inf,
              wl=np.zeros((n, k)), p=eye.copy(), p_inv=eye.copy(), lam=np.ones(k),
              beta=np.ones(k), rate=np.ones(k), e_kelvin=np.ones(k))
    advance(row, 0.0, 0.0, 0.1, 0.01, e0=1.0, c_crit=0.1, max_substep=0.0, max_edge_move=0.25)
    force(row, 0.3, 0.1, 1.0)
    stored_energy(row, 0.3, 0.1, 1.0)
    criterion_gap(row, 0.3, 0.1, 0.1, True, 0.3)
    kelvin_update(row, 2, 0.0, 0.1, 0.01)
