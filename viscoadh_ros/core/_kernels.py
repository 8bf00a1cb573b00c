"""Numba kernels of the time-stepped MDR model (private).

All kernels work in place on preallocated float64 arrays owned by the simulator and release
the GIL (`nogil=True`: a long history in a service thread does not block the node). The
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
#: `_advance_rows` stopped before a row that starts from an idle contact (Python drops it).
STATUS_IDLE = 2

#: Edge motion codes written to ``out[OUT_MOTION]`` by `advance`.
MOTION_NONE = 0
MOTION_ATTACH = 1
MOTION_DETACH = 2

OUT_RADIUS = 0
OUT_FORCE = 1
OUT_WORK = 2
OUT_MOTION = 3
OUT_SUBSTEPS = 4
OUT_STORED = 5
OUT_MEMORY = 6
OUT_SIZE = 7

#: Columns of `_advance_rows`'s per-row output: the `out` slots, then the edge gaps.
ROW_GAP_OUTSIDE = OUT_SIZE
ROW_GAP_INSIDE = OUT_SIZE + 1
ROW_SIZE = OUT_SIZE + 2

# Substep attempts per `advance` after which the edge-motion limit is dropped for the rest of
# the step: a guard (never reached in the test suite) so that an edge criterion flipping back
# and forth at any step size cannot stall a node; the step still completes exactly in time.
_MAX_ATTEMPTS = 2000

# Below this |lambda dt| the phi functions use their Taylor series: the closed forms lose
# all digits to cancellation there (1 - exp(-x) for x ~ 1e-12).
_SERIES_LIMIT = 1e-4

#: Edge roots are bisected to this fraction of an element width.
EDGE_TOLERANCE = 1e-12

#: Fine points per block of the first-touch search (`_first_touch`, `Row.gmin`).
TOUCH_BLOCK = 32


@numba.njit(cache=True, nogil=True)
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


@numba.njit(cache=True, nogil=True)
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


@numba.njit(cache=True, nogil=True)
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


@numba.njit(cache=True, nogil=True)
def _w_side(x, values, lo, hi, dx, coef, d, g_c, gf, df):
    """Memory at x from elements lo..hi (one side of the edge), m.

    The node values are split as ``values_i = coef * u_i + v_i`` with ``u = d - g`` and
    ``coef`` the steady in-contact fraction (``1 - E_r*/E0*`` for the sum, ``E_r*/E_k*``
    for Kelvin element k; 0 outside the contact): ``coef * u(x)`` is taken exactly and
    only the deviation ``v`` is interpolated. Otherwise the force of a relaxed contact,
    ``2 E0* int (u - w)``, would carry the interpolation error of w amplified by
    ``E0*/E_r*`` (sign flips at G0/G1 = 1e3).

    Beyond its last element the interior extrapolates its deviation linearly with the
    minmod of its last two slopes: exact for a relaxed (v = 0) or glassy (v = -coef u)
    interior, while a freshly attached last element cannot steer the slope into a
    detach/attach flip-flop (a plain hold is first-order wrong for a glassy edge). The
    exterior is extrapolated linearly towards the edge from its first two elements: an
    element that just let go then sits at the attachment threshold instead of above it.
    At the centre (symmetry) and the far end (no memory) values are held.
    """
    if lo > hi:
        return 0.0
    base = coef * (d - _g_at(x, gf, df)) if coef != 0.0 else 0.0
    p = x / dx - 0.5
    if p <= lo:
        v_lo = values[lo] - coef * (d - g_c[lo])
        if lo == 0 or hi == lo:
            return base + v_lo
        v_next = values[lo + 1] - coef * (d - g_c[lo + 1])
        return base + v_lo + (p - lo) * (v_next - v_lo)
    if p >= hi:
        v_hi = values[hi] - coef * (d - g_c[hi])
        if hi == lo or hi == values.shape[0] - 1:
            return base + v_hi
        slope = v_hi - (values[hi - 1] - coef * (d - g_c[hi - 1]))
        if hi - 2 >= lo:
            # minmod limiter: a freshly attached last element must not steer the slope.
            before = values[hi - 1] - coef * (d - g_c[hi - 1]) - (values[hi - 2] - coef * (d - g_c[hi - 2]))
            slope = 0.0 if slope * before <= 0.0 else (slope if abs(slope) < abs(before) else before)
        return base + v_hi + (p - hi) * slope
    i = int(p)
    t = p - i
    v_i = values[i] - coef * (d - g_c[i])
    v_j = values[i + 1] - coef * (d - g_c[i + 1])
    return base + v_i + t * (v_j - v_i)


@numba.njit(cache=True, nogil=True)
def _h(x, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, kap):
    """Criterion gap h(x) with the memory of elements lo..hi; interior sides pass kap."""
    return d - _g_at(x, gf, df) - _w_side(x, wsum, lo, hi, dx, kap, d, g_c, gf, df) + c_crit * math.sqrt(x)


@numba.njit(cache=True, nogil=True)
def _bisect(x_lo, x_hi, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, kap):
    """Root of h between x_lo (h >= 0) and x_hi (h < 0), to ``EDGE_TOLERANCE * dx``: far
    below the discretisation error, and half the iterations of machine precision."""
    tol = EDGE_TOLERANCE * dx
    for _ in range(80):
        mid = 0.5 * (x_lo + x_hi)
        if mid <= x_lo or mid >= x_hi or x_hi - x_lo <= tol:
            break
        if _h(mid, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, kap) >= 0.0:
            x_lo = mid
        else:
            x_hi = mid
    return 0.5 * (x_lo + x_hi)


@numba.njit(cache=True, nogil=True)
def _scan_out(x_start, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, reach):
    """Outermost point of the h >= 0 run that starts at x_start (exterior memory): scan
    the fine grid outward.

    Returns ``(radius, grow)``; ``grow`` is True when h stays >= 0 up to the end of the
    domain (the contact wants to pass L) and the profile still reaches further.
    """
    m = gf.shape[0]
    j = int(x_start / df) + 1
    prev = x_start
    while j < m:
        xj = j * df
        # A domain that ends at the reach (flat punch: L = a0) must not ask to grow
        # because the last fine point fell a rounding error short of it.
        if xj >= reach * (1.0 - 1e-12):
            if _h(reach, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, 0.0) >= 0.0:
                return reach, False
            return _bisect(prev, reach, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, 0.0), False
        if _h(xj, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, 0.0) < 0.0:
            return _bisect(prev, xj, d, wsum, lo, hi, dx, g_c, gf, df, c_crit, 0.0), False
        prev = xj
        j += 1
    return prev, True


@numba.njit(cache=True, nogil=True)
def _first_touch(d, wsum, dx, g_c, gf, gmin, df, reach):
    """First fine point (index) where the surface with its memory reaches the indenter,
    ``d - g - w >= 0``, or -1 if none up to `reach`.

    Out of contact with memory left this test runs every step, so whole blocks of
    `TOUCH_BLOCK` fine points are skipped when a lower bound of ``g + w`` over the block
    (`gmin` of the block, least memory value its interpolation uses) already rules out a
    touch; the first touching point found is the same as a point-by-point scan."""
    m = gf.shape[0]
    n = wsum.shape[0]
    for b in range(gmin.shape[0]):
        j0 = b * TOUCH_BLOCK
        j1 = min(j0 + TOUCH_BLOCK, m)
        if j0 * df > reach:
            return -1
        # The elements `_w_side` interpolates between over this block, widened by one each
        # side against the rounding of x/dx.
        i0 = max(int(j0 * df / dx - 0.5) - 1, 0)
        i1 = min(int((j1 - 1) * df / dx - 0.5) + 2, n - 1)
        w_least = wsum[i0]
        for i in range(i0 + 1, i1 + 1):
            w_least = min(w_least, wsum[i])
        # Margin: the interpolated w may undershoot its end values by a rounding error.
        margin = 1e-12 * (abs(d) + abs(gmin[b]) + abs(w_least))
        if d - gmin[b] - w_least < -margin:
            continue
        for j in range(j0, j1):
            xj = j * df
            if xj > reach:
                return -1
            if d - gf[j] - _w_side(xj, wsum, 0, n - 1, dx, 0.0, d, g_c, gf, df) >= 0.0:
                return j
    return -1


@numba.njit(cache=True, nogil=True)
def _locate_edge(a, d, wsum, dx, g_c, gf, gmin, df, c_crit, reach, kap):
    """Apply the energy criterion both ways at depth d. Returns (new radius, motion, grow)."""
    n = wsum.shape[0]
    n_in = _interior_count(a, dx, n)
    if a <= 0.0:
        # First touch needs the surface (with its memory) to reach the indenter somewhere;
        # the contact then covers the centre out to the attachment root.
        j = _first_touch(d, wsum, dx, g_c, gf, gmin, df, reach)
        if j < 0:
            return 0.0, MOTION_NONE, False
        radius, grow = _scan_out(j * df, d, wsum, 0, n - 1, dx, g_c, gf, df, c_crit, reach)
        if radius <= 0.0 and not grow:
            # Touching exactly at the apex without adhesion: no area, no contact.
            return 0.0, MOTION_NONE, False
        return radius, MOTION_ATTACH, grow
    # Detachment of interior elements, judged with the interior (crept) memory. It goes
    # first: an over-stretched interior edge cannot hold, whatever the memory outside says.
    # (Elements that just let go sit at the attachment threshold; the other order lets the
    # discretised exterior memory re-attach them and the receding edge chatter.)
    if _h(a, d, wsum, 0, n_in - 1, dx, g_c, gf, df, c_crit, kap) < 0.0:
        j = int(a / df)
        if j * df >= a:
            j -= 1
        upper = a
        while j >= 0:
            xj = j * df
            if _h(xj, d, wsum, 0, n_in - 1, dx, g_c, gf, df, c_crit, kap) >= 0.0:
                radius = _bisect(xj, upper, d, wsum, 0, n_in - 1, dx, g_c, gf, df, c_crit, kap)
                return radius, MOTION_DETACH, False
            upper = xj
            j -= 1
        return 0.0, MOTION_DETACH, False
    # Attachment of exterior elements, judged with the exterior (residual) memory.
    if a < reach and _h(a, d, wsum, n_in, n - 1, dx, g_c, gf, df, c_crit, 0.0) > 0.0:
        radius, grow = _scan_out(a, d, wsum, n_in, n - 1, dx, g_c, gf, df, c_crit, reach)
        return radius, MOTION_ATTACH, grow
    return a, MOTION_NONE, False


@numba.njit(cache=True, nogil=True)
def _deviation_integral(a, d, wsum, n_in, dx, g_c, gf, df, kap):
    """Integral over (0, a) of the interpolated interior deviation v = w - kap u, m^2."""
    if n_in == 0:
        return 0.0
    total = 0.0
    x_prev = 0.0
    v_prev = wsum[0] - kap * (d - g_c[0])
    for i in range(n_in):
        xi = (i + 0.5) * dx
        if xi >= a:
            break
        v_i = wsum[i] - kap * (d - g_c[i])
        if i == 0:
            total += v_i * xi
        else:
            total += 0.5 * (v_prev + v_i) * (xi - x_prev)
        x_prev = xi
        v_prev = v_i
    if a > x_prev:
        if x_prev > 0.0:
            v_edge = _w_side(a, wsum, 0, n_in - 1, dx, kap, d, g_c, gf, df) - kap * (d - _g_at(a, gf, df))
            total += 0.5 * (v_prev + v_edge) * (a - x_prev)
        else:
            total += v_prev * a
    return total


@numba.njit(cache=True, nogil=True)
def _profile_integral(a, gf, gint, df):
    """Integral of g over (0, a), m^2, consistent with the linear fine-grid profile."""
    m = gf.shape[0]
    j = int(a / df)
    if j >= m - 1:
        j = m - 2
    xj = j * df
    return gint[j] + 0.5 * (a - xj) * (gf[j] + _g_at(a, gf, df))


@numba.njit(cache=True, nogil=True)
def _force(a, d, wsum, dx, g_c, gf, gint, df, e0, kap):
    """Normal force ``F = 2 E0* int_0^a (u - w) dx = 2 E0* ((1-kap) int u - int v)``, N."""
    if a <= 0.0:
        return 0.0
    n_in = _interior_count(a, dx, wsum.shape[0])
    u_int = d * a - _profile_integral(a, gf, gint, df)
    return 2.0 * e0 * ((1.0 - kap) * u_int - _deviation_integral(a, d, wsum, n_in, dx, g_c, gf, df, kap))


@numba.njit(cache=True, nogil=True)
def _contact_coefficients(lam, dt, e, phi1, chi):
    """Per-mode coefficients of the exact linear-input update over dt (into e, phi1, chi)."""
    for m in range(lam.shape[0]):
        em, f1, f2 = _phi(lam[m] * dt)
        e[m] = em
        phi1[m] = f1 * dt
        chi[m] = f2 * dt


@numba.njit(cache=True, nogil=True)
def _chain_in_contact(wl, wsum, i, u0, u1, p, p_inv, beta, e, phi1, chi, z):
    """Element i in contact, total elongation u linear from u0 to u1 (coefficients given)."""
    k_count = wl.shape[1]
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


@numba.njit(cache=True, nogil=True)
def _chain_free(wl, wsum, i, decay):
    """Element i out of contact: each Kelvin element creeps back by its factor `decay`."""
    total = 0.0
    for k in range(wl.shape[1]):
        wl[i, k] *= decay[k]
        total += wl[i, k]
    wsum[i] = total


@numba.njit(cache=True, nogil=True)
def _kelvin_update(wl, wsum, n_in, d0, d1, dt, g_c, p, p_inv, lam, beta, rate):
    """Exact update of every Kelvin chain over dt for a depth linear from d0 to d1.

    Interior elements (i < n_in): modal form of ``dl/dt = A l + b u(t)``, ``u = d - g``.
    Exterior elements: free creep-back ``dl_k/dt = -rate_k l_k``.
    """
    n, k_count = wl.shape
    if k_count == 0 or dt <= 0.0:
        return
    e = np.empty(k_count)
    phi1 = np.empty(k_count)
    chi = np.empty(k_count)
    z = np.empty(k_count)
    _contact_coefficients(lam, dt, e, phi1, chi)
    for i in range(n_in):
        _chain_in_contact(wl, wsum, i, d0 - g_c[i], d1 - g_c[i], p, p_inv, beta, e, phi1, chi, z)
    for k in range(k_count):
        e[k] = math.exp(-rate[k] * dt)
    for i in range(n_in, n):
        _chain_free(wl, wsum, i, e)


@numba.njit(cache=True, nogil=True)
def _retime_crossed(wl, wsum, scratch, a0, a1, da, db, dt, dx, g_c, p, p_inv, lam, beta, rate):
    """Redo the substep for the elements the edge crossed, switching them at the crossing.

    `_kelvin_update` treats an element by its status at the substep's start. An element
    the edge passed during the substep really switched part-way: with the edge linear in
    time it is reached at ``f = |x_i - a0| / |a1 - a0|``. Without this, every freshly
    attached element stays glassy for a whole step and the quasistatic indentation force
    is off by about one cell of unrelaxed edge (1-2 % of the pull-off force at N ~ 100).
    Snap-in from no contact happens when the indenter touches: the switch time there is
    taken from the depth crossing zero (``f = -da/(db - da)``); a jump to no contact (the
    fold) is taken at the substep's end.
    """
    n, k_count = wl.shape
    if k_count == 0 or dt <= 0.0:
        return
    n0 = _interior_count(a0, dx, n)
    n1 = _interior_count(a1, dx, n)
    if n0 == n1:
        return
    e = np.empty(k_count)
    phi1 = np.empty(k_count)
    chi = np.empty(k_count)
    z = np.empty(k_count)
    decay = np.empty(k_count)
    lo, hi = (n0, n1) if n1 > n0 else (n1, n0)
    for i in range(lo, hi):
        xi = (i + 0.5) * dx
        if a0 <= 0.0:
            f = -da / (db - da) if db != da else 0.0
        elif a1 <= 0.0:
            f = 1.0
        else:
            f = abs(xi - a0) / abs(a1 - a0)
        f = min(max(f, 0.0), 1.0)
        d_switch = da + f * (db - da)
        for k in range(k_count):
            wl[i, k] = scratch[i, k]
        if n1 > n0:
            first, second = f * dt, (1.0 - f) * dt
            for k in range(k_count):
                decay[k] = math.exp(-rate[k] * first)
            _chain_free(wl, wsum, i, decay)
            _contact_coefficients(lam, second, e, phi1, chi)
            _chain_in_contact(wl, wsum, i, d_switch - g_c[i], db - g_c[i], p, p_inv, beta, e, phi1, chi, z)
        else:
            first, second = f * dt, (1.0 - f) * dt
            _contact_coefficients(lam, first, e, phi1, chi)
            _chain_in_contact(wl, wsum, i, da - g_c[i], d_switch - g_c[i], p, p_inv, beta, e, phi1, chi, z)
            for k in range(k_count):
                decay[k] = math.exp(-rate[k] * second)
            _chain_free(wl, wsum, i, decay)


@numba.njit(cache=True, nogil=True)
def _advance(
    wl,
    wsum,
    scratch,
    dx,
    g_c,
    gf,
    gint,
    gmin,
    df,
    e0,
    c_crit,
    reach,
    p,
    p_inv,
    lam,
    beta,
    rate,
    kap,
    e_kelvin,
    steady,
    out,
    a,
    d0,
    d1,
    dt,
    max_substep,
    max_edge_move,
):
    """Advance the row from depth d0 to d1 (linear in time) over dt with adaptive substeps.

    Arguments: the row's arrays and constants as `Row.kernel_args` orders them, then the
    step's scalars (radius a, d0, d1, dt, max_substep, max_edge_move).

    Substeps are halved while the edge would move more than ``max_edge_move`` (m) in one
    of them, down to ``1e-7 dt``: a true jump (snap-in, the fold at pull-off) is thereby
    located in time and crossed in one tiny substep that does no work. Writes radius,
    force, work input, last motion, substep count, the stored energy at the end
    (`_stored_energy`) and the largest |wsum| to ``out``: in the same compiled call, where
    separate calls cost their dispatch. Returns STATUS_GROW
    (state partly advanced: the caller restores) when the contact needs a larger domain.
    """
    n = wl.shape[0]
    h_min = dt * 1e-7
    step = dt if max_substep <= 0.0 or max_substep > dt else max_substep
    tau = 0.0
    force_prev = _force(a, d0, wsum, dx, g_c, gf, gint, df, e0, kap)
    work = 0.0
    motion = MOTION_NONE
    substeps = 0
    attempts = 0
    if dt <= 0.0:
        new_a, motion, grow = _locate_edge(a, d1, wsum, dx, g_c, gf, gmin, df, c_crit, reach, kap)
        if grow:
            return STATUS_GROW
        force_new = _force(new_a, d1, wsum, dx, g_c, gf, gint, df, e0, kap)
        out[OUT_RADIUS] = new_a
        out[OUT_FORCE] = force_new
        out[OUT_WORK] = 0.5 * (force_prev + force_new) * (d1 - d0)
        out[OUT_MOTION] = motion
        out[OUT_SUBSTEPS] = 0
        out[OUT_STORED] = _stored_energy(new_a, d1, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
        out[OUT_MEMORY] = _memory_peak(wsum)
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
        new_a, sub_motion, grow = _locate_edge(a, db, wsum, dx, g_c, gf, gmin, df, c_crit, reach, kap)
        if grow:
            return STATUS_GROW
        attempts += 1
        if abs(new_a - a) > max_edge_move and h > h_min and attempts < _MAX_ATTEMPTS:
            for i in range(n):
                total = 0.0
                for k in range(wl.shape[1]):
                    wl[i, k] = scratch[i, k]
                    total += wl[i, k]
                wsum[i] = total
            step = 0.5 * h
            continue
        _retime_crossed(wl, wsum, scratch, a, new_a, da, db, h, dx, g_c, p, p_inv, lam, beta, rate)
        force_new = _force(new_a, db, wsum, dx, g_c, gf, gint, df, e0, kap)
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
    out[OUT_STORED] = _stored_energy(a, d1, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
    out[OUT_MEMORY] = _memory_peak(wsum)
    return STATUS_OK


@numba.njit(cache=True, nogil=True)
def _advance_rows(
    wl,
    wsum,
    scratch,
    dx,
    g_c,
    gf,
    gint,
    gmin,
    df,
    e0,
    c_crit,
    reach,
    p,
    p_inv,
    lam,
    beta,
    rate,
    kap,
    e_kelvin,
    steady,
    out,
    backup,
    a,
    t_prev,
    d_prev,
    peak,
    times,
    depths,
    first,
    max_substep,
    max_edge_move,
    idle_limit,
    rows,
):
    """`_advance` over rows ``first..`` of a depth history in one compiled loop.

    Arguments: `Row.kernel_args`, ``backup`` (N, K) scratch for the memory before a row,
    the state before row ``first`` (radius a, time, depth, largest |wsum| ``peak``), the
    history ``times``/``depths`` (n,), the step's limits as `_advance` takes them and
    ``idle_limit`` (m): a contact out of contact whose memory peak is within it is idle.
    Row i of ``rows`` (n, ROW_SIZE) gets the ``out`` slots and the edge gaps with the
    exterior and the interior memory at the new radius (`criterion_gap`).

    Returns ``(i, status)``: all rows done (``i = n``, STATUS_OK), or stopped before row i
    with STATUS_IDLE (idle above the surface: the caller drops the memory, as
    ContactSimulator does) or STATUS_GROW (memory restored, wsum not: the caller
    restores it by its own rule, grows the domain and calls again from row i).
    """
    n = wl.shape[0]
    for i in range(first, times.shape[0]):
        d1 = depths[i]
        if a <= 0.0 and peak <= idle_limit and d1 < 0.0 and d_prev < 0.0:
            return i, STATUS_IDLE
        for j in range(n):
            for k in range(wl.shape[1]):
                backup[j, k] = wl[j, k]
        status = _advance(
            wl,
            wsum,
            scratch,
            dx,
            g_c,
            gf,
            gint,
            gmin,
            df,
            e0,
            c_crit,
            reach,
            p,
            p_inv,
            lam,
            beta,
            rate,
            kap,
            e_kelvin,
            steady,
            out,
            a,
            d_prev,
            d1,
            times[i] - t_prev,
            max_substep,
            max_edge_move,
        )
        if status != STATUS_OK:
            for j in range(n):
                for k in range(wl.shape[1]):
                    wl[j, k] = backup[j, k]
            return i, status
        a = out[OUT_RADIUS]
        peak = out[OUT_MEMORY]
        for k in range(OUT_SIZE):
            rows[i, k] = out[k]
        if a > 0.0:
            # Only a contact's pinned edge needs them (the phase); none without contact.
            n_in = _interior_count(a, dx, n)
            rows[i, ROW_GAP_OUTSIDE] = _h(a, d1, wsum, n_in, n - 1, dx, g_c, gf, df, c_crit, 0.0)
            rows[i, ROW_GAP_INSIDE] = _h(a, d1, wsum, 0, n_in - 1, dx, g_c, gf, df, c_crit, kap)
        t_prev = times[i]
        d_prev = d1
    return times.shape[0], STATUS_OK


@numba.njit(cache=True, nogil=True)
def _remap(wl, a, d, dx, g_c, gf, df, steady, new_dx, out):
    """Kelvin state of a regridded row (element width new_dx) into ``out`` (N', K).

    Each new centre takes the memory of its own side of the edge, interpolated exactly as
    the force and criterion see it (`_w_side`): interpolating across the edge would smear
    the interior/exterior jump that is the sticking zone. Beyond the old domain nothing was
    ever touched: zero memory.
    """
    n, k_count = wl.shape
    n_in = _interior_count(a, dx, n)
    length = n * dx
    for i in range(out.shape[0]):
        x = (i + 0.5) * new_dx
        interior = a > 0.0 and (x < a or i == 0)
        lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
        for k in range(k_count):
            if x > length:
                out[i, k] = 0.0
            else:
                coef = steady[k] if interior else 0.0
                out[i, k] = _w_side(x, wl[:, k], lo, hi, dx, coef, d, g_c, gf, df)


@numba.njit(cache=True, nogil=True)
def _energy_density(x, d, interior, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady):
    """Spring energy per unit length at x, J/m: E0* l0^2 + sum_k E_k* l_k^2 (both half-rows).

    Each l_k is interpolated like w (`_w_side`, steady fraction ``steady[k]`` inside), so
    between two elements the interpolant is itself an exact chain trajectory and this
    density does not grow under relaxation at fixed depth beyond O(dx^2).
    """
    n = wl.shape[0]
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    total = 0.0
    lsum = 0.0
    for k in range(wl.shape[1]):
        coef = steady[k] if interior else 0.0
        lk = _w_side(x, wl[:, k], lo, hi, dx, coef, d, g_c, gf, df)
        lsum += lk
        total += e_kelvin[k] * lk * lk
    if interior:
        l0 = d - _g_at(x, gf, df) - lsum
        total += e0 * l0 * l0
    return total


@numba.njit(cache=True, nogil=True)
def _node_density(g, d, interior, i0, i1, t, wl, g_c, e0, e_kelvin, steady):
    """`_energy_density` at a point of profile height g between element centres i0 <= i1
    of one side (t: the weight of i1), where the memory deviation is the plain linear
    interpolation: the same values without `_w_side`'s branches (the stored energy is
    evaluated every step)."""
    total = 0.0
    lsum = 0.0
    for k in range(wl.shape[1]):
        if interior:
            coef = steady[k]
            v0 = wl[i0, k] - coef * (d - g_c[i0])
            v1 = wl[i1, k] - coef * (d - g_c[i1])
            lk = coef * (d - g) + v0 + t * (v1 - v0)
        else:
            lk = wl[i0, k] + t * (wl[i1, k] - wl[i0, k])
        lsum += lk
        total += e_kelvin[k] * lk * lk
    if interior:
        l0 = d - g - lsum
        total += e0 * l0 * l0
    return total


@numba.njit(cache=True, nogil=True)
def _side_energy(x0, x1, d, interior, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady):
    """Integral of `_energy_density` over (x0, x1) on one side of the edge, J: Simpson on
    each piece between element centres, where the interpolated memory is linear (exact for
    a paraboloid's quartic density, so a few points per element suffice). Pieces between
    two centres of the side take `_node_density`; the end pieces (held or extrapolated
    memory, cut by the edge) the general density."""
    n = wl.shape[0]
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    # When every centre and every midpoint between centres is a fine point (an even number
    # of fine intervals per element, as the simulator builds rows), the profile there is
    # read off the fine grid: `_g_at`'s two divisions per point were most of this loop.
    per_cell = (gf.shape[0] - 1) // n
    on_grid = per_cell * n == gf.shape[0] - 1 and per_cell % 2 == 0
    total = 0.0
    prev = x0
    e_prev = _energy_density(prev, d, interior, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
    for i in range(n + 1):
        xi = (i + 0.5) * dx if i < n else x1
        if xi <= x0:
            continue
        if xi > x1:
            xi = x1
        mid = 0.5 * (prev + xi)
        if i - 1 >= lo and i <= hi and xi == (i + 0.5) * dx and prev == (i - 0.5) * dx:
            if on_grid:
                g_mid = gf[per_cell * i]
                g_i = gf[per_cell * i + per_cell // 2]
            else:
                g_mid = _g_at(mid, gf, df)
                g_i = _g_at(xi, gf, df)
            e_mid = _node_density(g_mid, d, interior, i - 1, i, 0.5, wl, g_c, e0, e_kelvin, steady)
            e_i = _node_density(g_i, d, interior, i, i, 0.0, wl, g_c, e0, e_kelvin, steady)
        else:
            e_mid = _energy_density(mid, d, interior, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
            e_i = _energy_density(xi, d, interior, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
        total += (xi - prev) * (e_prev + 4.0 * e_mid + e_i) / 6.0
        prev, e_prev = xi, e_i
        if xi >= x1:
            break
    return total


@numba.njit(cache=True, nogil=True)
def _memory_peak(wsum):
    """Largest |wsum|, m: whether any memory is left (the simulator's idle test)."""
    peak = 0.0
    for i in range(wsum.shape[0]):
        peak = max(peak, abs(wsum[i]))
    return peak


@numba.njit(cache=True, nogil=True)
def _stored_energy(a, d, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady):
    """Elastic energy in all springs of both half-rows, J: the integral of
    `_energy_density` over the contact (interior memory) and over (a, L) (exterior)."""
    n = wl.shape[0]
    n_in = _interior_count(a, dx, n)
    total = 0.0
    if a > 0.0:
        total += _side_energy(0.0, a, d, True, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
    length = n * dx
    if wl.shape[1] > 0 and a < length:
        total += _side_energy(a, length, d, False, n_in, wl, wsum, dx, g_c, gf, df, e0, e_kelvin, steady)
    return total


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
    """The preallocated arrays of one MDR row, its chain's modal data and constants.

    Keyword arguments (SI): ``dx`` element width, m; ``g_c`` (N,) profile at centres, m;
    ``gf``, ``gint`` (M,) fine profile and its running integral, m and m^2; ``df`` fine
    spacing, m; ``reach`` outermost radius the indenter can touch, m (inf if unbounded);
    ``wl`` (N, K) Kelvin elongations, m; ``p``, ``p_inv`` (K, K), ``lam`` (K,) 1/s,
    ``beta`` (K,) the modal chain (see simulator._modal_chain); ``rate`` (K,) free
    creep-back rates, 1/s; ``e_kelvin`` (K,) Kelvin moduli E_k*, Pa; ``steady`` (K,) steady
    in-contact fractions ``E_r*/E_k*``; ``e0`` glass modulus E0*, Pa; ``c_crit`` critical
    glass elongation per sqrt(m), ``dl_c(x) = c_crit sqrt(x)``.
    """

    def __init__(
        self,
        *,
        dx: float,
        g_c: np.ndarray,
        gf: np.ndarray,
        gint: np.ndarray,
        df: float,
        reach: float,
        wl: np.ndarray,
        p: np.ndarray,
        p_inv: np.ndarray,
        lam: np.ndarray,
        beta: np.ndarray,
        rate: np.ndarray,
        e_kelvin: np.ndarray,
        steady: np.ndarray,
        e0: float,
        c_crit: float,
    ) -> None:
        n, k = wl.shape
        m = gf.shape[0]
        _check_scalars(dx=dx, df=df, e0=e0, c_crit=c_crit)
        if dx <= 0.0 or df <= 0.0 or m < 2 or n < 1:
            raise ValueError("row needs dx > 0, df > 0, at least 1 element and 2 fine points")
        if not reach > 0.0:
            raise ValueError(f"reach must be > 0 (got {reach!r})")
        if e0 <= 0.0 or c_crit < 0.0:
            raise ValueError(f"e0 must be > 0 and c_crit >= 0 (got {e0!r}, {c_crit!r})")
        for name, array, shape in (
            ("g_c", g_c, (n,)),
            ("gf", gf, (m,)),
            ("gint", gint, (m,)),
            ("wl", wl, (n, k)),
            ("p", p, (k, k)),
            ("p_inv", p_inv, (k, k)),
            ("lam", lam, (k,)),
            ("beta", beta, (k,)),
            ("rate", rate, (k,)),
            ("e_kelvin", e_kelvin, (k,)),
            ("steady", steady, (k,)),
        ):
            _check(name, array, shape)
        self.dx, self.df, self.reach = float(dx), float(df), float(reach)
        self.e0, self.c_crit = float(e0), float(c_crit)
        self.g_c, self.gf, self.gint = g_c, gf, gint
        self.wl = np.ascontiguousarray(wl)
        self.wsum = self.wl.sum(axis=1)
        self.scratch = np.empty_like(self.wl)
        self.p, self.p_inv, self.lam, self.beta, self.rate = p, p_inv, lam, beta, rate
        self.e_kelvin, self.steady = e_kelvin, steady
        self.kap = float(steady.sum())
        # Least profile height per block of TOUCH_BLOCK fine points (`_first_touch`).
        self.gmin = np.minimum.reduceat(gf, np.arange(0, m, TOUCH_BLOCK))
        self.out = np.zeros(OUT_SIZE)

    @property
    def kernel_args(self) -> tuple:
        """The row's arrays and constants in the order `_advance` takes them (before the
        step's scalars); the benchmark calls the kernel with the same tuple."""
        return (
            self.wl,
            self.wsum,
            self.scratch,
            self.dx,
            self.g_c,
            self.gf,
            self.gint,
            self.gmin,
            self.df,
            self.e0,
            self.c_crit,
            self.reach,
            self.p,
            self.p_inv,
            self.lam,
            self.beta,
            self.rate,
            self.kap,
            self.e_kelvin,
            self.steady,
            self.out,
        )

    @property
    def elements(self) -> int:
        return self.wl.shape[0]

    @property
    def length(self) -> float:
        """Domain length L, m."""
        return self.dx * self.elements

    def with_memory(self, wl: np.ndarray) -> Row:
        """A new row with the same geometry and chain (shared, never written) and its own
        copy of the Kelvin state `wl` (N, K)."""
        clone = object.__new__(Row)
        clone.__dict__.update(self.__dict__)
        clone.wl = np.empty_like(self.wl)
        clone.wsum = np.empty_like(self.wsum)
        clone.scratch = np.empty_like(self.scratch)
        clone.out = np.zeros(OUT_SIZE)
        clone.set_memory(wl)
        return clone

    def set_memory(self, wl: np.ndarray) -> None:
        """Replace the Kelvin state (N, K) after validation."""
        _check("wl", wl, self.wl.shape)
        self.wl[...] = wl
        self.wsum[...] = wl.sum(axis=1)


def advance(
    row: Row, radius: float, d0: float, d1: float, dt: float, *, max_substep: float, max_edge_move: float
) -> tuple[int, np.ndarray]:
    """Advance `row` in place over dt (s) from depth d0 to d1 (m, linear in time), the
    contact radius starting at `radius` (m).

    Returns ``(status, out)``; ``out[OUT_RADIUS]`` is the new contact radius (m),
    ``out[OUT_FORCE]`` the force (N), ``out[OUT_WORK]`` the work input (J),
    ``out[OUT_STORED]`` the stored energy at the end (J, `stored_energy`). On STATUS_GROW
    the row is partly advanced and must be restored by the caller.
    """
    _check_scalars(radius=radius, d0=d0, d1=d1, dt=dt, max_edge_move=max_edge_move)
    if dt < 0.0 or radius < 0.0 or max_edge_move <= 0.0 or not max_substep >= 0.0:
        raise ValueError("dt, radius and max_substep must be >= 0 and max_edge_move > 0")
    status = _advance(
        *row.kernel_args,
        float(radius),
        float(d0),
        float(d1),
        float(dt),
        float(max_substep),
        float(max_edge_move),
    )
    return int(status), row.out


def force(row: Row, radius: float, depth: float) -> float:
    """Normal force, N, of the row at contact radius (m) and depth (m)."""
    _check_scalars(radius=radius, depth=depth)
    return float(
        _force(
            float(radius), float(depth), row.wsum, row.dx, row.g_c, row.gf, row.gint, row.df, row.e0, row.kap
        )
    )


def locate_edge(row: Row, radius: float, depth: float) -> tuple[float, int, bool]:
    """Apply the energy criterion both ways at `depth` (m) from contact radius `radius` (m):
    ``(new radius m, MOTION_* code, grow)``; grow asks for a larger domain."""
    _check_scalars(radius=radius, depth=depth)
    new_radius, motion, grow = _locate_edge(
        float(radius),
        float(depth),
        row.wsum,
        row.dx,
        row.g_c,
        row.gf,
        row.gmin,
        row.df,
        row.c_crit,
        row.reach,
        row.kap,
    )
    return float(new_radius), int(motion), bool(grow)


def stored_energy(row: Row, radius: float, depth: float) -> float:
    """Elastic energy stored in glass and Kelvin springs of the row, J."""
    _check_scalars(radius=radius, depth=depth)
    return float(
        _stored_energy(
            float(radius),
            float(depth),
            row.wl,
            row.wsum,
            row.dx,
            row.g_c,
            row.gf,
            row.df,
            row.e0,
            row.e_kelvin,
            row.steady,
        )
    )


def criterion_gap(row: Row, x: float, depth: float, radius: float, *, interior: bool) -> float:
    """h(x), m, with the memory of the interior (True) or exterior side of `radius`."""
    _check_scalars(x=x, depth=depth, radius=radius)
    n = row.elements
    n_in = int(_interior_count(float(radius), row.dx, n))
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    return float(
        _h(
            float(x),
            float(depth),
            row.wsum,
            lo,
            hi,
            row.dx,
            row.g_c,
            row.gf,
            row.df,
            row.c_crit,
            row.kap if interior else 0.0,
        )
    )


def kelvin_update(row: Row, n_in: int, d0: float, d1: float, dt: float) -> None:
    """Exact Kelvin-chain update of `row` in place (see `_kelvin_update`)."""
    _check_scalars(d0=d0, d1=d1, dt=dt)
    if not 0 <= n_in <= row.elements:
        raise ValueError(f"n_in must be in [0, {row.elements}] (got {n_in})")
    if dt < 0.0:
        raise ValueError(f"dt must be >= 0 (got {dt!r})")
    _kelvin_update(
        row.wl,
        row.wsum,
        int(n_in),
        float(d0),
        float(d1),
        float(dt),
        row.g_c,
        row.p,
        row.p_inv,
        row.lam,
        row.beta,
        row.rate,
    )


def remap_memory(row: Row, radius: float, depth: float, elements: int, length: float) -> np.ndarray:
    """The Kelvin state of `row` (contact radius m, depth m) on a new grid of `elements`
    over (0, length], shape (elements, K); see `_remap`."""
    _check_scalars(radius=radius, depth=depth, length=length)
    if elements < 1 or not length > 0.0:
        raise ValueError(f"need elements >= 1 and length > 0 (got {elements}, {length!r})")
    out = np.empty((int(elements), row.wl.shape[1]))
    _remap(
        row.wl,
        float(radius),
        float(depth),
        row.dx,
        row.g_c,
        row.gf,
        row.df,
        row.steady,
        float(length) / elements,
        out,
    )
    return out


def warm_up() -> None:
    """Compile (or load from cache) and call every kernel once on a tiny row, so the first
    real step does not stall (about 0.2 s even from the on-disk cache)."""
    n, k, m = 4, 1, 9
    x = (np.arange(n) + 0.5) * 0.25
    xf = np.linspace(0.0, 1.0, m)
    one = np.ones(k)
    row = Row(
        dx=0.25,
        g_c=x**2,
        gf=xf**2,
        gint=xf**3 / 3.0,
        df=float(xf[1]),
        reach=math.inf,
        wl=np.zeros((n, k)),
        p=np.eye(k),
        p_inv=np.eye(k),
        lam=2.0 * one,
        beta=one.copy(),
        rate=one.copy(),
        e_kelvin=one.copy(),
        steady=0.5 * one,
        e0=1.0,
        c_crit=0.1,
    )
    advance(row, 0.0, 0.0, 0.1, 0.01, max_substep=0.0, max_edge_move=0.25)
    force(row, 0.3, 0.1)
    stored_energy(row, 0.3, 0.1)
    criterion_gap(row, 0.3, 0.1, 0.3, interior=True)
    kelvin_update(row, 2, 0.0, 0.1, 0.01)
    remap_memory(row, 0.3, 0.1, 3, 2.0)
    times = np.array([0.0, 0.1, 0.2])
    depths = np.array([0.0, 0.3, 0.1])
    _advance_rows(
        *row.kernel_args,
        np.empty_like(row.wl),
        0.0,
        0.0,
        0.0,
        0.0,
        times,
        depths,
        1,
        0.0,
        0.25,
        0.0,
        np.zeros((times.size, ROW_SIZE)),
    )
