"""Numba kernels of the time-stepped MDR model (private).

All kernels work in place on preallocated float64 arrays owned by the simulator and release
the GIL (`nogil=True`: a long history in a service thread does not block the node). They are
compiled without numba's runtime (`_nrt=False`): they allocate nothing (but `_kelvin_update`,
a test and warm-up entry), and with the runtime every array passed to a compiled callee, every
view taken (``coef[_C_E]``, a reshape) and every tuple unpacked costs an atomic increment and
decrement of its reference count: about 3.7 of the 5.5 us of a one-substep step at N = 64,
K = 1 (0.4.0 round: the same bits, measured side by side in one process). The
public wrappers at the bottom validate shapes, dtypes and finiteness *before* entering
numba (a NaN that slips into a compiled loop would spread silently), and `warm_up()`
compiles and calls every kernel once so the first real step does not stall.

Geometry. The 1D MDR row holds N elements at cell centres ``x_i = (i + 1/2) dx`` on
``(0, L]``. The profile ``g`` is also sampled on a fine uniform grid ``xf_j = j * df``
(M points, ``xf_0 = 0``, ``xf_{M-1} = L``) with its running integral ``Gf``; between fine
points it is linear. The contact radius ``a`` is continuous: elements with ``x_i < a``
are in contact ("interior"; at least element 0 when ``a > 0``), the others are exterior.

State. ``wl[i, k]`` is the elongation of Kelvin element k of element i, m; ``wsum[i]``
their sum (at K = 1 in a row's buffer the same memory as ``wl``, `_state_layout`). Interior
glass elongation ``l0 = d - g(x) - wsum``, exterior ``l0 = 0``.
The chain is linear in its input ``u_i(t) = d(t) - g(x_i)``, so its state splits exactly
as ``wl_i = A_i - g(x_i) B_i``: ``A`` is the chain's response to ``d(t)`` and ``B``
(``wb[i, k]``, sum ``bsum[i]``, dimensionless) its response to a unit input over the same
in/out contact history. ``A`` and ``B`` depend on x only through the element's contact
history (when it attached and let go), which is smooth in x, so the memory between
element centres is ``w(x) = A(x) - g(x) B(x)`` with A and B interpolated linearly: exact
for a glassy (A = B = 0) and a relaxed (A = kap d, B = kap) interior for ANY profile,
second order in between. (Interpolating w itself carried the profile's curvature: a glassy
sphere pressed deep pulled off several percent beyond JKR, issue 10.)

Edge. ``h(x) = d - g(x) - w(x) + c sqrt(x)`` with ``c sqrt(x) = dl_c(x)``, the critical
glass elongation. ``w(x)`` is taken from the elements of ONE side (interior or exterior),
extrapolated beyond that side's last centre: ``h`` is discontinuous at the edge, and
that jump is the sticking zone.

Dissipation. Each step adds non-negative losses (`OUT_DISSIPATED`): the exact viscous
work of every element's dampers over the step (modal form, for a depth linear in time,
or the Kelvin energy an element out of contact loses by creeping back), plus the
adhesion hysteresis of the elements that attach or let go within the step: an element of
width dx attaching at glass elongation l0 (both half-rows hold ``E0* dx l0^2``) while its
annulus gives up the surface energy ``2 pi x w dx = E0* c^2 x dx`` loses the difference.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numba
import numpy as np
from llvmlite import ir as llvm_ir
from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

STATUS_OK = 0
STATUS_GROW = 1
#: `_advance_rows` stopped before a row that starts from an idle contact (Python drops it).
STATUS_IDLE = 2
#: `_step_packed`: the step ran (as STATUS_OK) but its energy input or dissipated energy is not
#: finite (the simulator refuses the step and rolls it back).
STATUS_OVERFLOW = 3

#: `_step_packed`'s per-model constants (`step_params`), by index.
PARAM_MAX_SUBSTEP = 0
PARAM_MAX_EDGE_CELLS = 1
PARAM_E_RELAXED = 2
PARAM_V_C1 = 3
PARAM_V_C2 = 4
PARAM_SIZE = 5

#: Edge motion codes written to ``out[OUT_MOTION]`` by `advance`.
MOTION_NONE = 0
MOTION_ATTACH = 1
MOTION_DETACH = 2

OUT_RADIUS = 0
OUT_FORCE = 1
OUT_WORK = 2
OUT_MOTION = 3
OUT_SUBSTEPS = 4
#: Energy dissipated over the step, J (>= 0: viscous work plus adhesion hysteresis).
OUT_DISSIPATED = 5
OUT_MEMORY = 6
#: Criterion gap h at the new edge with the exterior and the interior memory, m
#: (`criterion_gap`; 0 without contact): the phase of a pinned edge needs them.
OUT_GAP_OUTSIDE = 7
OUT_GAP_INSIDE = 8
#: Profile g at the new edge, m (fine-grid interpolation, as the kernel sees it; 0 without contact).
OUT_G_EDGE = 9
#: Depth at the end of the substep in which the contact last went from touching to none in
#: this step (the fold at pull-off, located in time to JUMP_RESOLUTION of the step), m; NaN when
#: it did not. A force search reads it from a trial that let go (`ContactSimulator._detachment`):
#: where along its path the contact let go tells where the trial that just holds on ends.
OUT_LET_GO = 10
OUT_SIZE = 11

#: Columns of `_advance_rows`'s per-row output: the `out` slots (gaps included).
ROW_GAP_OUTSIDE = OUT_GAP_OUTSIDE
ROW_GAP_INSIDE = OUT_GAP_INSIDE
ROW_SIZE = OUT_SIZE

# Substep attempts per `advance` after which the edge-motion limit is dropped for the rest of
# the step: a guard so that an edge criterion flipping back and forth at any step size cannot
# stall a node; the step still completes exactly in time. It grows with the row
# (`_MAX_ATTEMPTS + _ATTEMPTS_PER_ELEMENT * N`): an edge that sweeps the whole row in one step
# needs about two attempts per element it crosses (one accepted, one rejected doubling), and
# with a flat 2000 a fine row (1024+ elements, e.g. from `numerics.tolerance`) ran out of
# attempts in a fast pull-off, crossed the rest in one substep and dissipated ten times the work
# put in (0.4.0, an outside tester).
_MAX_ATTEMPTS = 2000
_ATTEMPTS_PER_ELEMENT = 4

# Below this |lambda dt| the phi functions use their Taylor series: the closed forms lose
# all digits to cancellation there (1 - exp(-x) for x ~ 1e-12).
_SERIES_LIMIT = 1e-4
# Below this the dissipation integrals `_psi` use their (alternating, fast) series.
_PSI_SERIES_LIMIT = 0.5
#: A series term below this fraction of its sum no longer moves it (`_psi`): 2^-55.
_SUM_SETTLED = 2.0**-55

#: A true jump of the edge (snap-in, the fold at pull-off) is located in time to this
#: fraction of the step: the substep that crosses it is this short (its work is a
#: trapezoid over a depth change this small), found by halving from the whole step (the
#: fold) or, out of contact, centred on the touch time found in closed form (`_touch_time`).
JUMP_RESOLUTION = 1e-4

#: Edge roots are located to this fraction of an element width (`_bisect`).
EDGE_TOLERANCE = 1e-12

#: Fine points per block of the first-touch search (`_first_touch`, `Row.gmin`, `Row.gmax`).
TOUCH_BLOCK = 32

#: The centre-crossing blend (`_edge_piece`) applies with the share ``max(0, 1 - CENTRE_CUT
#: v tau / dx)`` (`_relaxed_share`): in full where the cell behind the edge is relaxed, none
#: once the edge crosses a cell in CENTRE_CUT relaxation times or less (v tau >= dx / CENTRE_CUT).
CENTRE_CUT = 4.0


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _u(index):
    """``index`` (>= 0) as an unsigned integer, for the bounds of element loops that should
    vectorise (0.5.0): numba wraps a negative signed index around (``i < 0: i += n``), and with a
    loop that starts at a runtime bound LLVM cannot prove that never happens, so it saw every
    array access as indirect and vectorised nothing ("unsafe indirect dependence"; the K = 1
    update ran at 4.3 ns per element with a runtime start, 1.9 with a literal 0). An unsigned
    index has no wraparound. Only for bounds known to be >= 0; mix it only with unsigned
    values (numba types uint64 + int64 as float64)."""
    return numba.uint64(index)


@intrinsic
def _float_pointer(typingctx, address):
    """The float64 pointer at integer `address` (for `_view`)."""
    signature = types.CPointer(types.float64)(types.intp)

    def codegen(context, builder, sig, args):
        return builder.inttoptr(args[0], context.get_value_type(sig.return_type))

    return signature, codegen


@intrinsic
def _flat(typingctx, array):
    """The flat view of a C-contiguous float64 array (``array.reshape(array.size)``) built
    from its own data pointer and size (0.6.0): numba's reshape goes through
    `numba_attempt_nocopy_reshape` and its checks, ~30 ns a call and about ten calls a row
    (3 % of `step_depths`). The view borrows the array's owner, as a reshape does."""
    if not (isinstance(array, types.Array) and array.layout == "C" and array.dtype == types.float64):
        return None
    result = types.Array(types.float64, 1, "C")
    signature = result(array)

    def codegen(context, builder, sig, args):
        source = context.make_array(sig.args[0])(context, builder, value=args[0])
        view = context.make_array(sig.return_type)(context, builder)
        size = context.get_constant(types.intp, 1)
        for extent in cgutils.unpack_tuple(builder, source.shape):
            size = builder.mul(size, extent)
        populate_array(
            view,
            data=source.data,
            shape=cgutils.pack_array(builder, [size]),
            strides=cgutils.pack_array(builder, [context.get_constant(types.intp, 8)]),
            itemsize=source.itemsize,
            meminfo=source.meminfo,
            parent=source.parent,
        )
        return impl_ret_borrowed(context, builder, sig.return_type, view._getvalue())

    return signature, codegen


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
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


@numba.njit(cache=True, nogil=True, _nrt=False)
def _psi(x: float) -> tuple:
    """Integrals for the damper work over a step of length h with ``x = lam h``, E = exp(-lam t),
    F = (1 - E)/lam: ``(int E^2, int E F / h, int F^2 / h^2) / h`` =
    ``(phi1(2x), (phi1(x) - phi1(2x))/x, (1 - 2 phi1(x) + phi1(2x))/x^2)``, x >= 0."""
    if x < _PSI_SERIES_LIMIT:
        # Term m of each: (-x)^m times 2^m/(m+1)!, (2^(m+1) - 1)/(m+2)!, (2^(m+2) - 2)/(m+3)!;
        # 24 terms leave < 1e-18 for x < 0.5.
        #
        # The sums stop once a term of each is below 2^-55 of its sum (0.10.0): the same bits
        # as all 24 terms. A sum s in [2^e, 2^(e+1)) has neighbours at least 2^(e-53) away, so
        # a term below 2^(e-54) > 2^-55 |s| rounds back to s; the terms shrink by at least
        # 2x / (m + 2) < 1/2 per step (x < 0.5), so every later term does too and s no longer
        # moves. At the substeps of a racing edge (x = lam h ~ 1e-6) that is 4 terms, not 24:
        # the series was ~90 ns of a mode's coefficients (`_contact_coefficients`, computed
        # for every crossed element's partial length and every deferred force; issue 13).
        ee = 0.0
        ef = 0.0
        ff = 0.0
        power = 1.0
        two = 1.0
        f1 = 1.0
        for m in range(24):
            f1 *= m + 1
            f2 = f1 * (m + 2)
            f3 = f2 * (m + 3)
            t_ee = power * two / f1
            t_ef = power * (2.0 * two - 1.0) / f2
            t_ff = power * (4.0 * two - 2.0) / f3
            if m > 0 and (
                abs(t_ee) < _SUM_SETTLED * abs(ee)
                and abs(t_ef) < _SUM_SETTLED * abs(ef)
                and abs(t_ff) < _SUM_SETTLED * abs(ff)
            ):
                break
            ee += t_ee
            ef += t_ef
            ff += t_ff
            power *= -x
            two *= 2.0
        return ee, ef, ff
    e1, p1, _ = _phi(x)
    e2, p2, _ = _phi(2.0 * x)
    return p2, (p1 - p2) / x, (1.0 - 2.0 * p1 + p2) / (x * x)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
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


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
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


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _minmod(slope: float, before: float) -> float:
    if slope * before <= 0.0:
        return 0.0
    return slope if abs(slope) < abs(before) else before


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _side_ab(x, values, units, lo, hi, dx, g_c):
    """``(A(x), B(x))`` from the elements lo..hi of one side of the edge.

    ``values`` are elongations at the centres (``wsum`` or one Kelvin column), ``units`` the
    matching unit-input responses B; the node values of A are ``values + g_c units``.
    Between two centres B is linear and the memory is ``w = w_lin - (g - g_lin) B_lin``
    (returned as ``A = w_lin + g_lin B_lin``): the linear interpolant of w corrected by the
    profile's curvature in proportion to how relaxed the chain is. That is exact for a
    glassy (B = 0, w = 0) and a relaxed (B = kap, w = kap u) stretch of elements for any
    profile, and second order where B varies smoothly. (Interpolating A itself would add
    the cross term ``t (1 - t) dg dB``, first order and wrong where B is unresolved: a
    freshly attached edge element of a fast-relaxing body, whose u is ~0 anyway.)
    Beyond its last element the interior extrapolates A and B linearly with the minmod of
    its last two slopes (a freshly attached last element cannot steer the slope into a
    detach/attach flip-flop); the exterior extrapolates them linearly towards the edge from
    its first two elements (an element that just let go then sits at the attachment
    threshold instead of above it). At the centre
    (symmetry) and the far end (no memory) values are held.
    """
    if lo > hi:
        return 0.0, 0.0
    p = x / dx - 0.5
    n = values.shape[0]
    if p <= lo:
        a_lo = values[lo] + g_c[lo] * units[lo]
        b_lo = units[lo]
        if lo == 0 or hi == lo:
            return a_lo, b_lo
        a_nx = values[lo + 1] + g_c[lo + 1] * units[lo + 1]
        b_nx = units[lo + 1]
        return a_lo + (p - lo) * (a_nx - a_lo), b_lo + (p - lo) * (b_nx - b_lo)
    if p >= hi:
        a_hi = values[hi] + g_c[hi] * units[hi]
        b_hi = units[hi]
        if hi == lo or hi == n - 1:
            return a_hi, b_hi
        a_pr = values[hi - 1] + g_c[hi - 1] * units[hi - 1]
        b_pr = units[hi - 1]
        slope_a = a_hi - a_pr
        slope_b = b_hi - b_pr
        if hi - 2 >= lo:
            a_pp = values[hi - 2] + g_c[hi - 2] * units[hi - 2]
            slope_a = _minmod(slope_a, a_pr - a_pp)
            slope_b = _minmod(slope_b, b_pr - units[hi - 2])
        return a_hi + (p - hi) * slope_a, b_hi + (p - hi) * slope_b
    i = int(p)
    if i >= hi:
        i = hi - 1
    t = p - i
    b_x = units[i] + t * (units[i + 1] - units[i])
    # A = w_lin + g_lin B_lin (not A_lin): w = w_lin - (g - g_lin) B_lin, see the docstring.
    w_x = values[i] + t * (values[i + 1] - values[i])
    g_x = g_c[i] + t * (g_c[i + 1] - g_c[i])
    return w_x + g_x * b_x, b_x


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _w_side(x, values, units, lo, hi, dx, g_c, gf, df):
    """Memory ``w(x) = A(x) - g(x) B(x)`` at x from the elements lo..hi of one side, m."""
    a_x, b_x = _side_ab(x, values, units, lo, hi, dx, g_c)
    return a_x - _g_at(x, gf, df) * b_x


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _h(x, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit):
    """Criterion gap h(x) with the memory of elements lo..hi (one side of the edge)."""
    g = _g_at(x, gf, df)
    a_x, b_x = _side_ab(x, wsum, bsum, lo, hi, dx, g_c)
    return d - g - (a_x - g * b_x) + c_crit * math.sqrt(x)


#: Iterations the edge root finder (`_bisect`) may take beyond plain bisection's count:
#: its worst case is that many evaluations of h more than bisection, never unbounded.
_ROOT_SLACK = 3


@numba.njit(cache=True, nogil=True, _nrt=False)
def _bisect(x_lo, x_hi, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit):
    """`_edge_root` without the end values (it evaluates h there)."""
    return _edge_root(x_lo, x_hi, math.nan, math.nan, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _edge_root(x_lo, x_hi, f_lo, f_hi, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit):
    """Root of h between x_lo (h >= 0) and x_hi (h < 0), to ``EDGE_TOLERANCE * dx``: far
    below the discretisation error. Returns the midpoint of a bracket no wider than the
    tolerance whose left end has h >= 0 and right end h < 0, as plain bisection did.

    A bracket spans at most one fine interval, where g is linear and A, B are linear
    between element centres: h is smooth there but for the sqrt and at most a kink or
    two, so secant steps reach the tolerance in a handful of evaluations of h where
    bisection took ~40 (0.8 us per edge, the fixed cost of a substep at small N). The
    steps are safeguarded as in ITP (Oliveira & Takahashi 2020): each is projected
    towards the bracket's midpoint so that after k steps the bracket is at most
    ``tol 2^(n_half + _ROOT_SLACK - k)`` wide (never more than `_ROOT_SLACK` evaluations
    beyond bisection's count), and kept at least ``0.45 tol`` inside the bracket, so a
    secant that has converged to one side closes the bracket with its next step. If the
    end values do not have the signs the caller promised (rounding), plain bisection.

    ``f_lo``/``f_hi`` are h at the ends when the caller has them (NaN: evaluated here; the
    same numbers either way, one or two evaluations fewer).
    """
    tol = EDGE_TOLERANCE * dx
    a = x_lo
    b = x_hi
    if b - a > tol:
        fa = f_lo
        if math.isnan(fa):
            fa = _h(a, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)
        fb = f_hi
        if math.isnan(fb):
            fb = _h(b, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)
        if fa >= 0.0 and fb < 0.0:
            n_half = int(math.ceil(math.log2((b - a) / tol)))
            budget = 0.5 * tol * 2.0 ** (n_half + _ROOT_SLACK)
            margin = 0.45 * tol
            # The two latest evaluations (the secant's points).
            x1, f1, x2, f2 = a, fa, b, fb
            for _ in range(n_half + _ROOT_SLACK + 1):
                width = b - a
                mid = 0.5 * (a + b)
                if width <= tol or mid <= a or mid >= b:
                    break
                x = mid
                if f1 != f2:
                    x = x2 - f2 * (x2 - x1) / (f2 - f1)
                if not (a < x < b):
                    # Regula falsi: strictly inside (fa >= 0 > fb).
                    x = a + width * (fa / (fa - fb))
                # Projection: never leave the bisection budget of this step.
                radius = budget - 0.5 * width
                if x > mid + radius:
                    x = mid + radius
                elif x < mid - radius:
                    x = mid - radius
                # Keep clear of the ends: the step after a converged one closes the bracket.
                if x < a + margin:
                    x = a + margin
                elif x > b - margin:
                    x = b - margin
                fx = _h(x, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)
                if fx >= 0.0:
                    a = x
                    fa = fx
                else:
                    b = x
                    fb = fx
                x1, f1, x2, f2 = x2, f2, x, fx
                budget *= 0.5
            return 0.5 * (a + b)
    for _ in range(80):
        mid = 0.5 * (a + b)
        if mid <= a or mid >= b or b - a <= tol:
            break
        if _h(mid, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit) >= 0.0:
            a = mid
        else:
            b = mid
    return 0.5 * (a + b)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _h_bounds(b, d, wsum, bsum, lo, hi, dx, g_c, gf, gmin, gmax, df, c_crit):
    """Lower and upper bounds of h at the fine points of block b (`TOUCH_BLOCK` points)
    with the memory of elements lo..hi, m.

    ``h = d - A(x) + c sqrt(x) - g(x) (1 - B(x))``; B (`_side_ab`) is linear between element
    centres and on the extrapolated ends, A too up to the chord correction below, so at the
    block's points they lie between their values at the block's end points and at the
    centres inside it (A widened by that correction); g lies in
    the block's ``[gmin, gmax]``; sqrt is increasing. A margin covers the rounding of the
    interpolations, so a bound never excludes a point the point-by-point test would find.
    """
    m = gf.shape[0]
    j0 = b * TOUCH_BLOCK
    j1 = min(j0 + TOUCH_BLOCK, m) - 1
    x0 = j0 * df
    x1 = j1 * df
    a_lo, b_lo = _side_ab(x0, wsum, bsum, lo, hi, dx, g_c)
    a_hi, b_hi = _side_ab(x1, wsum, bsum, lo, hi, dx, g_c)
    a_least = min(a_lo, a_hi)
    a_most = max(a_lo, a_hi)
    b_least = min(b_lo, b_hi)
    b_most = max(b_lo, b_hi)
    i_first = max(int(math.ceil(x0 / dx - 0.5)), lo)
    i_last = min(int(x1 / dx - 0.5), hi)
    for i in range(i_first, i_last + 1):
        a_i = wsum[i] + g_c[i] * bsum[i]
        a_least = min(a_least, a_i)
        a_most = max(a_most, a_i)
        b_least = min(b_least, bsum[i])
        b_most = max(b_most, bsum[i])
    # Between two centres A = w_lin + g_lin B_lin is not linear: it departs from the chord
    # of its node values by t (1 - t) dg dB, at most |dg dB| / 4.
    slack = 0.0
    for i in range(max(i_first - 1, lo), min(i_last, hi - 1) + 1):
        slack = max(slack, 0.25 * abs((g_c[i + 1] - g_c[i]) * (bsum[i + 1] - bsum[i])))
    a_least -= slack
    a_most += slack
    p1 = gmin[b] * (1.0 - b_most)
    p2 = gmin[b] * (1.0 - b_least)
    p3 = gmax[b] * (1.0 - b_most)
    p4 = gmax[b] * (1.0 - b_least)
    prod_least = min(min(p1, p2), min(p3, p4))
    prod_most = max(max(p1, p2), max(p3, p4))
    margin = 1e-12 * (abs(d) + abs(a_most) + abs(a_least) + abs(gmax[b]) + c_crit * math.sqrt(x1))
    lower = d - a_most + c_crit * math.sqrt(x0) - prod_most - margin
    upper = d - a_least + c_crit * math.sqrt(x1) - prod_least + margin
    return lower, upper


@numba.njit(cache=True, nogil=True, _nrt=False)
def _scan_out(x_start, d, wsum, bsum, lo, hi, dx, g_c, gf, gmin, gmax, df, c_crit, reach, x_stop):
    """Outermost point of the h >= 0 run that starts at x_start (exterior memory): the
    first fine point beyond x_start where h < 0, its root against the point before (`_edge_root`).

    Whole blocks of `TOUCH_BLOCK` fine points whose lower bound of h (`_h_bounds`) is >= 0
    are stepped over: the same point as a point-by-point scan, found in O(blocks + points
    of one block) (a snap-in or a fast edge no longer scans the fine grid per substep).

    Returns ``(radius, grow)``; ``grow`` is True when h stays >= 0 up to the end of the
    domain (the contact wants to pass L) and the profile still reaches further. Once the
    run is known to pass ``x_stop`` the scan stops and returns a point beyond it (the
    caller only needs to know that the edge moved that far).
    """
    m = gf.shape[0]
    j = int(x_start / df) + 1
    prev = x_start
    h_prev = math.nan  # h at prev when known (the root finder's end value)
    while j < m:
        if prev > x_stop:
            return prev, False
        if j % TOUCH_BLOCK == 0:
            b = j // TOUCH_BLOCK
            j_end = min(j + TOUCH_BLOCK, m) - 1
            if j_end * df < reach * (1.0 - 1e-12):
                lower, _ = _h_bounds(b, d, wsum, bsum, lo, hi, dx, g_c, gf, gmin, gmax, df, c_crit)
                if lower >= 0.0:
                    prev = j_end * df
                    h_prev = math.nan
                    j = j_end + 1
                    continue
        xj = j * df
        # A domain that ends at the reach (flat punch: L = a0) must not ask to grow
        # because the last fine point fell a rounding error short of it.
        if xj >= reach * (1.0 - 1e-12):
            h_reach = _h(reach, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)
            if h_reach >= 0.0:
                return reach, False
            root = _edge_root(prev, reach, h_prev, h_reach, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)
            return root, False
        h_j = _h(xj, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit)
        if h_j < 0.0:
            return _edge_root(prev, xj, h_prev, h_j, d, wsum, bsum, lo, hi, dx, g_c, gf, df, c_crit), False
        prev = xj
        h_prev = h_j
        j += 1
    return prev, True


#: Blocks per group of the first-touch search's coarse screen (`_group_cannot_touch`).
_TOUCH_GROUP = 16


@numba.njit(cache=True, nogil=True, _nrt=False)
def _group_cannot_touch(b0, b1, d, wsum, bsum, dx, g_c, gmin, gmax, df, m):
    """True if no fine point of blocks b0..b1-1 can touch: `_first_touch`'s block test with
    the extremes over all those blocks. Every operand of the group's lower bound is at most
    the block's (min over a superset; each corner product and sum rounds monotonically) and
    every operand of its margin at least the block's, so a group it rules out has no block
    that `_first_touch`'s own test would search."""
    n = wsum.shape[0]
    j0 = b0 * TOUCH_BLOCK
    j1 = min(b1 * TOUCH_BLOCK, m)
    i0 = max(int(j0 * df / dx - 0.5) - 1, 0)
    i1 = min(int((j1 - 1) * df / dx - 0.5) + 2, n - 1)
    w_least = wsum[i0]
    w_abs = abs(wsum[i0])
    b_least = bsum[i0]
    b_most = bsum[i0]
    gc_least = g_c[i0]
    gc_most = g_c[i0]
    gc_abs = abs(g_c[i0])
    for i in range(i0 + 1, i1 + 1):
        w_least = min(w_least, wsum[i])
        w_abs = max(w_abs, abs(wsum[i]))
        b_least = min(b_least, bsum[i])
        b_most = max(b_most, bsum[i])
        gc_least = min(gc_least, g_c[i])
        gc_most = max(gc_most, g_c[i])
        gc_abs = max(gc_abs, abs(g_c[i]))
    g_least = gmin[b0]
    g_most = gmax[b0]
    g_abs = abs(gmin[b0])
    for b in range(b0 + 1, b1):
        g_least = min(g_least, gmin[b])
        g_most = max(g_most, gmax[b])
        g_abs = max(g_abs, abs(gmin[b]))
    lower = (
        w_least
        + min(
            g_least * (1.0 - b_most),
            g_least * (1.0 - b_least),
            g_most * (1.0 - b_most),
            g_most * (1.0 - b_least),
        )
        + min(gc_least * b_least, gc_least * b_most, gc_most * b_least, gc_most * b_most)
    )
    margin = 1e-12 * (abs(d) + g_abs + (w_abs + gc_abs))
    return d - lower < -margin


@numba.njit(cache=True, nogil=True, _nrt=False)
def _first_touch(d, wsum, bsum, dx, g_c, gf, gmin, gmax, df, reach):
    """First fine point (index) where the surface with its memory reaches the indenter,
    ``d - g - w >= 0``, or -1 if none up to `reach`.

    Out of contact with memory left this test runs every step, so whole blocks of
    `TOUCH_BLOCK` fine points are skipped when a lower bound of ``g + w`` over the block
    (from `gmin`/`gmax` of the block and the extreme node values its interpolation uses)
    already rules out a touch; the first touching point found is the same as a
    point-by-point scan."""
    m = gf.shape[0]
    n = wsum.shape[0]
    blocks = gmin.shape[0]
    b = 0
    while b < blocks:
        j0 = b * TOUCH_BLOCK
        j1 = min(j0 + TOUCH_BLOCK, m)
        if j0 * df > reach:
            return -1
        if b % _TOUCH_GROUP == 0:
            # A group of blocks at once: its bound is below every block's own (its element
            # range, g range and B range contain theirs; rounding is monotone) and its
            # margin above theirs, so a group ruled out holds no block the loop below would
            # search (the same first point, about one read per element instead of four).
            # A group ruled out is stepped over whole (0.10.0: the loop went through its
            # blocks one by one, ~2 ns each, a third of a search at N = 8192; a block past
            # `reach` there only returned -1 earlier than the next block does).
            b_end = min(b + _TOUCH_GROUP, blocks)
            if _group_cannot_touch(b, b_end, d, wsum, bsum, dx, g_c, gmin, gmax, df, m):
                b = b_end
                continue
        # The elements `_side_ab` interpolates between over this block, widened by one each
        # side against the rounding of x/dx.
        i0 = max(int(j0 * df / dx - 0.5) - 1, 0)
        i1 = min(int((j1 - 1) * df / dx - 0.5) + 2, n - 1)
        w_least = wsum[i0]
        b_least = bsum[i0]
        b_most = bsum[i0]
        gc_least = g_c[i0]
        gc_most = g_c[i0]
        for i in range(i0 + 1, i1 + 1):
            w_least = min(w_least, wsum[i])
            b_least = min(b_least, bsum[i])
            b_most = max(b_most, bsum[i])
            gc_least = min(gc_least, g_c[i])
            gc_most = max(gc_most, g_c[i])
        # g + w = g (1 - B) + w_lin + g_lin B: each product at least its least corner.
        lower = (
            w_least
            + min(
                gmin[b] * (1.0 - b_most),
                gmin[b] * (1.0 - b_least),
                gmax[b] * (1.0 - b_most),
                gmax[b] * (1.0 - b_least),
            )
            + min(gc_least * b_least, gc_least * b_most, gc_most * b_least, gc_most * b_most)
        )
        a_least = abs(w_least) + abs(gc_most)
        # Margin: the interpolated values may undershoot their end values by a rounding error.
        margin = 1e-12 * (abs(d) + abs(gmin[b]) + abs(a_least))
        b += 1
        if d - lower < -margin:
            continue
        for j in range(j0, j1):
            xj = j * df
            if xj > reach:
                return -1
            if d - gf[j] - _w_side(xj, wsum, bsum, 0, n - 1, dx, g_c, gf, df) >= 0.0:
                return j
    return -1


@numba.njit(cache=True, nogil=True, _nrt=False)
def _locate_edge(a, d, wsum, bsum, dx, g_c, gf, gmin, gmax, df, c_crit, reach, max_move):
    """Apply the energy criterion both ways at depth d. Returns (new radius, motion, grow).

    An edge that moves more than ``max_move`` (m; inf: no limit) is not located: a radius
    beyond that distance is returned (the caller halves the substep anyway), so a substep
    that a jump rejects costs O(max_move), not a scan to the far root and its bisection."""
    n = wsum.shape[0]
    n_in = _interior_count(a, dx, n)
    if a <= 0.0:
        # First touch needs the surface (with its memory) to reach the indenter somewhere;
        # the contact then covers the centre out to the attachment root.
        j = _first_touch(d, wsum, bsum, dx, g_c, gf, gmin, gmax, df, reach)
        if j < 0:
            return 0.0, MOTION_NONE, False
        radius, grow = _scan_out(
            j * df, d, wsum, bsum, 0, n - 1, dx, g_c, gf, gmin, gmax, df, c_crit, reach, max_move
        )
        if radius <= 0.0 and not grow:
            # Touching exactly at the apex without adhesion: no area, no contact.
            return 0.0, MOTION_NONE, False
        return radius, MOTION_ATTACH, grow
    # Detachment of interior elements, judged with the interior (crept) memory. It goes
    # first: an over-stretched interior edge cannot hold, whatever the memory outside says.
    # (Elements that just let go sit at the attachment threshold; the other order lets the
    # discretised exterior memory re-attach them and the receding edge chatter.)
    h_upper = _h(a, d, wsum, bsum, 0, n_in - 1, dx, g_c, gf, df, c_crit)
    if h_upper < 0.0:
        # Inward, the first fine point where h >= 0; whole blocks whose upper bound of h is
        # below 0 (`_h_bounds`) are stepped over (the same point as point by point).
        j = int(a / df)
        if j * df >= a:
            j -= 1
        upper = a
        while j >= 0:
            if upper < a - max_move:
                return upper, MOTION_DETACH, False
            if (j + 1) % TOUCH_BLOCK == 0:
                b = j // TOUCH_BLOCK
                _, top = _h_bounds(b, d, wsum, bsum, 0, n_in - 1, dx, g_c, gf, gmin, gmax, df, c_crit)
                if top < 0.0:
                    upper = b * TOUCH_BLOCK * df
                    h_upper = math.nan
                    j = b * TOUCH_BLOCK - 1
                    continue
            xj = j * df
            h_j = _h(xj, d, wsum, bsum, 0, n_in - 1, dx, g_c, gf, df, c_crit)
            if h_j >= 0.0:
                args = (d, wsum, bsum, 0, n_in - 1, dx, g_c, gf, df, c_crit)
                return _edge_root(xj, upper, h_j, h_upper, *args), MOTION_DETACH, False
            upper = xj
            h_upper = h_j
            j -= 1
        return 0.0, MOTION_DETACH, False
    # Attachment of exterior elements, judged with the exterior (residual) memory.
    if a < reach and _h(a, d, wsum, bsum, n_in, n - 1, dx, g_c, gf, df, c_crit) > 0.0:
        radius, grow = _scan_out(
            a, d, wsum, bsum, n_in, n - 1, dx, g_c, gf, gmin, gmax, df, c_crit, reach, a + max_move
        )
        return radius, MOTION_ATTACH, grow
    return a, MOTION_NONE, False


@numba.njit(cache=True, nogil=True, _nrt=False)
def _profile_integral(a, gf, gint, df):
    """Integral of g over (0, a), m^2, consistent with the linear fine-grid profile."""
    m = gf.shape[0]
    j = int(a / df)
    if j >= m - 1:
        j = m - 2
    xj = j * df
    return gint[j] + 0.5 * (a - xj) * (gf[j] + _g_at(a, gf, df))


def force_weights_size(n: int) -> int:
    """Length of a row's force weights (`_fill_force_weights`) for `n` elements."""
    return 3 * n + 2


@numba.njit(cache=True, nogil=True, _nrt=False)
def _fill_force_weights(g_c, gf, gint, df, dx, out):
    """The grid's weights of `_deviation_integral` in its sum form (0.7.0), into ``out``
    (3 n + 2,): ``cb`` (n,) | ``q`` (n + 1,) | ``e`` (n + 1,).

    Simpson's piece between the centres of elements j-1 and j (its midpoint g at ``j dx``,
    `_g_between`) is ``dx (f_{j-1} + f_j)/2 + q_j (B_{j-1} + B_j) - kap d dx + kap r_j`` with
    ``f = wsum - kap (d - g_c)`` at the centres, ``q_j = dx (g_{j-1} + g_j - 2 g_mid)/6`` and
    ``r_j = dx (g_{j-1} + g_j + 4 g_mid)/6`` (`_block_change` derives it). Up to the edge's
    last interior centre L-1, with element 0's held piece (0, x0):
    ``dx sum_{i<L} f_i - dx/2 (wsum_{L-1} - kap d) + sum_{i<L} cb_i B_i - q_L B_{L-1} + kap e_L``
    where ``cb_i = q_i + q_{i+1}`` (``q_0 = q_n = 0``; ``cb_0`` adds ``g_0 x0 - G(x0)``) and
    ``e_L = sum_{i<L} (r_i - dx g_i)`` (``r_0 = G(x0)``, G the profile's integral). The
    weights depend on the grid alone: written when a row's grid is (`Row`, `Row.regrid`)."""
    n = g_c.shape[0]
    qo = n
    eo = 2 * n + 1
    x0 = 0.5 * dx
    g_x0 = _profile_integral(x0, gf, gint, df)
    out[qo] = 0.0
    for j in range(1, n):
        gm = _g_between(j, gf, df, dx, n)
        out[qo + j] = dx * (g_c[j - 1] + g_c[j] - 2.0 * gm) / 6.0
    out[qo + n] = 0.0
    for i in range(n):
        out[i] = out[qo + i] + out[qo + i + 1]
    out[0] += g_c[0] * x0 - g_x0
    e = 0.0
    out[eo] = 0.0
    for i in range(n):
        if i == 0:
            r = g_x0
        else:
            gm = _g_between(i, gf, df, dx, n)
            r = dx * (g_c[i - 1] + g_c[i] + 4.0 * gm) / 6.0
        e += r - dx * g_c[i]
        out[eo + i + 1] = e


# The one kernel function compiled with a fast-math flag, and only `reassoc`: the two sums may be
# taken in any order, so the compiler vectorises them (~0.18 ns per element against ~0.58 in
# four hand-written lanes, 0.7.0). No other flag (NaN/inf semantics and contraction stay
# IEEE). The order it picks is fixed for a build on a machine: the same inputs give the same
# bits run after run; another CPU's vector width may round the sums differently (by ~N eps of
# them: the golden files allow 1e-11, tests/golden_tolerance.py).
@numba.njit(cache=True, nogil=True, _nrt=False, fastmath={"reassoc"})
def _weighted_sums(lo, hi, wsum, bsum, g_c, cb, kap, kd):
    """``(sum f_i, sum cb_i B_i)`` over elements lo..hi-1, ``f_i = wsum_i + kap g_i - kd``
    (the memory's deviation from relaxed at the centre, ``kd = kap d``): one streaming pass of
    multiply-adds (no profile gather, no division)."""
    sum_f = 0.0
    sum_b = 0.0
    for i in range(lo, hi):
        sum_f += (wsum[i] + kap * g_c[i]) - kd
        sum_b += cb[i] * bsum[i]
    return sum_f, sum_b


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _simpson_tail(x0, f0, a, d, wsum, bsum, last, dx, g_c, gf, df, kap):
    """Simpson's rule for the deviation from ``x0`` (value ``f0`` there) to the edge, A and B
    extrapolated beyond the centre of element ``last`` (`_side_ab`, elements 0..last)."""
    mid = 0.5 * (x0 + a)
    a_x, b_x = _side_ab(mid, wsum, bsum, 0, last, dx, g_c)
    f_mid = (a_x - kap * d) - _g_at(mid, gf, df) * (b_x - kap)
    a_x, b_x = _side_ab(a, wsum, bsum, 0, last, dx, g_c)
    f_a = (a_x - kap * d) - _g_at(a, gf, df) * (b_x - kap)
    return (a - x0) * (f0 + 4.0 * f_mid + f_a) / 6.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _edge_piece(a, d, wsum, bsum, n_in, dx, g_c, gf, df, kap, wb, p, p_inv, lam, beta):
    """The deviation integral's part past the last interior centre ``x_L`` (element
    L = n_in - 1): Simpson's piece up to the edge (A and B extrapolated, `_side_ab`), blended
    with weight ``1 - s`` towards the same span read without element L (A and B extrapolated
    from element L-1 over its last cell and on to the edge) less that cell's piece, where
    ``s = min(1, 2 (a - x_L) / dx)`` is the share of element L's cell's outer half the edge
    covers; 0 if the edge is not past ``x_L``.

    The blend makes the force continuous as the edge crosses a centre. Element L joins the
    interior there with its own state, which a freshly attached element has from the moment
    it touched: glassy, while the interior behind it is relaxed (a slow press of a
    viscoelastic body: the true memory leaves relaxed only within ``v tau`` of the edge,
    far less than dx). Read at once, the linear interpolation spread that glassy node over
    the whole cell behind it and the force dropped by up to 0.1 of the pull-off force at
    `fast`, recovering as the element relaxed (an outside tester, 0.11.0). With the blend
    the memory read up to the edge is continuous in the edge position: at ``x_L`` (s = 0:
    the reading without element L, as before the crossing) and from the cell's end on
    (s = 1: with it, as after the next crossing). Glassy and relaxed interiors read the same
    either way (A and B exact), and an elastic row has no memory. (s rising over the whole
    cell, not its outer half, extrapolated element L-1 twice as far: the pull-off of a deep
    cone that lets go from a few elements moved 0.06 % further from the reference.)"""
    x_last = (n_in - 0.5) * dx
    if a <= x_last:
        return 0.0
    last = n_in - 1
    f_last = wsum[last] - kap * (d - g_c[last])
    piece = _simpson_tail(x_last, f_last, a, d, wsum, bsum, last, dx, g_c, gf, df, kap)
    # Element L's weight: the share of its cell's outer half the edge covers.
    s = 2.0 * (a - x_last) / dx
    if n_in < 2 or s >= 1.0:
        return piece
    # Without element L: the cell (x_{L-1}, x_L) as the sum over the interior took it
    # (`_deviation_integral`'s Simpson piece) is replaced by element L-1's extrapolation.
    prev = last - 1
    f_prev = wsum[prev] - kap * (d - g_c[prev])
    b_mid = 0.5 * (bsum[prev] + bsum[last])
    a_mid = 0.5 * (wsum[prev] + wsum[last]) + 0.5 * (g_c[prev] + g_c[last]) * b_mid
    f_mid = (a_mid - kap * d) - _g_between(last, gf, df, dx, wsum.shape[0]) * (b_mid - kap)
    cell = dx * (f_prev + 4.0 * f_mid + f_last) / 6.0
    without = _simpson_tail(x_last - dx, f_prev, a, d, wsum, bsum, prev, dx, g_c, gf, df, kap)
    share = _relaxed_share(bsum[prev], kap)
    if share < 1.0 and wb.shape[1] > 1:
        share = _modal_share(wb, prev, p, p_inv, lam, beta)
    return piece + (1.0 - s) * share * (without - cell - piece)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _relaxed_share(b_prev, b_relaxed):
    """How much of `_edge_piece`'s correction applies: ``max(0, 1 - CENTRE_CUT v tau / dx)``,
    with ``v tau / dx`` (how far behind the edge the memory is still unrelaxed, in cells) read
    from element L-1's unit memory B: B starts at 0 when an element attaches and relaxes
    towards ``kap`` whatever the depth does, so an element attached one cell's passage ago
    holds ``r = B / kap = 1 - exp(-dx / (v tau))`` and ``v tau / dx = -1 / ln(1 - r)``. A
    relaxed cell behind the edge (a slow press, v tau << dx: r = 1 to rounding) takes the full
    blend, which removes the jump; a cell the edge crossed within four relaxation times
    (v tau >= dx / 4, r <= 1 - e^-4) none: there the memory behind the edge is not
    relaxed, element L-1 read on to the edge overshoots, and the old reading is closer to 8192
    elements. Measured against 8192 elements (benchmarks/centre_accuracy.py, round
    0.11.0-centre.md, sessions 11 and 12): on the rows the blend moves of the finger's
    force-search press (v tau ~ dx), the full blend took the mean error from 2.0e-3 to 6.2e-3 of
    the pull-off force and a cut at 2 from 2.8e-3 to 3.7e-3, while this cut leaves that press as
    it was; it brings the finger's press-pull (v tau between dx / 8 and dx / 4) from 1.13e-2 to
    6.2e-3 (largest) and a press of 50 retardation times at `balanced` from 1.13e-2 to 6.3e-3,
    which cuts at 8 and 16 leave as 0.11.0 had them. B at or beyond relaxed takes the full
    blend, none at or below 0."""
    if b_relaxed <= 0.0:
        return 1.0
    return _share_at(b_prev / b_relaxed, 1.0)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _share_at(r, relaxed_from):
    """The blend's share for a unit memory at ``r`` of its relaxed level (one relaxation
    time): 1 from ``relaxed_from`` on, 0 at or below 0, else ``max(0, 1 + CENTRE_CUT / ln(1 -
    r))`` (see `_relaxed_share`). `_relaxed_share` and `_modal_share`'s modes read it."""
    if r >= relaxed_from:
        return 1.0
    if r <= 0.0:
        return 0.0
    return max(0.0, 1.0 + CENTRE_CUT / math.log1p(-r))


#: `_modal_share`: a mode whose unit memory is within this fraction of its relaxed level counts
#: as relaxed (the modal transform's rounding: a relaxed mode of a K = 2 chain read 1 - 1.1e-14).
MODE_RELAXED = 1e-12


@numba.njit(cache=True, nogil=True, _nrt=False)
def _modal_share(wb, prev, p, p_inv, lam, beta):
    """`_relaxed_share` for a chain of K >= 2 Kelvin elements, per relaxation mode: mode m's
    unit memory ``zb_m = sum_k p[m, k] wb[prev, k]`` relaxes towards ``beta_m / lam_m`` with
    its own time, and its share (``max(0, 1 - CENTRE_CUT lam_m^-1 v / dx)`` read from its
    ``r_m``, as `_relaxed_share`; 1 within MODE_RELAXED of relaxed) is weighted by how much of
    element L-1's total unit memory it carries, ``|sum_k p_inv[k, m] zb_m|``: what a glassy
    element L reads against. A mode far slower than the press carries almost nothing at L-1
    (it has not left glassy anywhere near the edge) and no longer switches the blend off,
    which the total ``B_{L-1} / kap`` did (an outside tester, 0.12.0: a standard solid plus a
    1e4 s element, jump 5.7e-2 of the pull-off force at `fast`)."""
    k_count = wb.shape[1]
    num = 0.0
    den = 0.0
    for m in range(k_count):
        zb = 0.0
        for k in range(k_count):
            zb += p[m, k] * wb[prev, k]
        col = 0.0
        for k in range(k_count):
            col += p_inv[k, m]
        weight = abs(col * zb)
        relaxed = beta[m] / lam[m]
        share = 1.0 if relaxed == 0.0 else _share_at(zb / relaxed, 1.0 - MODE_RELAXED)
        num += weight * share
        den += weight
    if den <= 0.0:
        return 0.0
    return num / den


@numba.njit(cache=True, nogil=True, _nrt=False)
def _deviation_integral(a, d, wsum, bsum, n_in, dx, g_c, gf, gint, df, kap, buf, wb, p, p_inv, lam, beta):
    """Integral over (0, a) of the interior memory's deviation from relaxed,
    ``dev = w - kap u = (A - kap d) - g (B - kap)``, m^2.

    Below the first centre A and B are held: exact with the profile's integral. Between
    centres (where ``dev = wsum - kap u`` at the nodes) and on the extrapolated piece up to
    the edge A and B are linear: Simpson, exact for a paraboloid or a cone. The relaxed part
    ``kap u`` is integrated exactly by the caller.

    ``buf``: work space of at least ``n_in`` floats (its contents are overwritten), or empty.
    With it the Simpson terms of the cells are computed in one loop that vectorises (0.6.0;
    the profile at the cell ends gathered first) and summed in a second, in the same order:
    the same bits as the one loop without it, which ran at ~2.8 ns per element against ~1.4
    (the terms' ~25 scalar operations and a division each, not the serial sum, bound it)."""
    if n_in == 0:
        return 0.0
    x0 = 0.5 * dx
    first = a if a < x0 else x0
    total = (wsum[0] + g_c[0] * bsum[0] - kap * d) * first - (bsum[0] - kap) * _profile_integral(
        first, gf, gint, df
    )
    if a <= x0:
        return total
    m = gf.shape[0]
    n = wsum.shape[0]
    if gint.shape[0] == m + 3 * n + 2:
        # The row's force weights follow the profile's integral (`Row`'s kernel arguments):
        # the sum form (`_fill_force_weights`), the same integral to rounding (0.7.0).
        cb = gint[m : m + n]
        q_last = gint[m + n + n_in]
        e_last = gint[m + 2 * n + 1 + n_in]
        sum_f, sum_b = _weighted_sums(0, n_in, wsum, bsum, g_c, cb, kap, kap * d)
        last = n_in - 1
        total = dx * sum_f - 0.5 * dx * (wsum[last] - kap * d) + (sum_b - q_last * bsum[last]) + kap * e_last
        return total + _edge_piece(a, d, wsum, bsum, n_in, dx, g_c, gf, df, kap, wb, p, p_inv, lam, beta)
    per_cell = (m - 1) // wsum.shape[0]
    on_grid = per_cell * wsum.shape[0] == m - 1
    if buf.shape[0] >= n_in:
        one = _u(1)
        end = _u(n_in)
        if on_grid:
            stride = _u(per_cell)
            for i in range(one, end):
                buf[i] = gf[stride * i]
        else:
            for i in range(1, n_in):
                buf[i] = _g_at(i * dx, gf, df)
        for i in range(one, end):
            f_prev = wsum[i - one] - kap * (d - g_c[i - one])
            f_i = wsum[i] - kap * (d - g_c[i])
            b_mid = 0.5 * (bsum[i - one] + bsum[i])
            a_mid = 0.5 * (wsum[i - one] + wsum[i]) + 0.5 * (g_c[i - one] + g_c[i]) * b_mid
            f_mid = (a_mid - kap * d) - buf[i] * (b_mid - kap)
            buf[i] = dx * (f_prev + 4.0 * f_mid + f_i) / 6.0
        for i in range(one, end):
            total += buf[i]
    else:
        f_prev = wsum[0] - kap * (d - g_c[0])
        for i in range(1, n_in):
            f_i = wsum[i] - kap * (d - g_c[i])
            b_mid = 0.5 * (bsum[i - 1] + bsum[i])
            a_mid = 0.5 * (wsum[i - 1] + wsum[i]) + 0.5 * (g_c[i - 1] + g_c[i]) * b_mid
            g_mid = gf[per_cell * i] if on_grid else _g_at(i * dx, gf, df)
            f_mid = (a_mid - kap * d) - g_mid * (b_mid - kap)
            total += dx * (f_prev + 4.0 * f_mid + f_i) / 6.0
            f_prev = f_i
    return total + _edge_piece(a, d, wsum, bsum, n_in, dx, g_c, gf, df, kap, wb, p, p_inv, lam, beta)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _force(a, d, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, buf, wb, p, p_inv, lam, beta):
    """Normal force ``F = 2 E0* int_0^a (u - w) dx = 2 E0* ((1-kap) int u - int dev)``, N,
    with ``dev = w - kap u`` the memory's deviation from relaxed (zero when relaxed, so
    the relaxed force carries no interpolation error amplified by E0*/E_r*). ``buf``: as
    `_deviation_integral` takes it (the kernels pass ``diss``, free whenever they ask for a
    force: its losses are summed by then)."""
    if a <= 0.0:
        return 0.0
    n_in = _interior_count(a, dx, wsum.shape[0])
    u_int = d * a - _profile_integral(a, gf, gint, df)
    if kap == 0.0:
        return 2.0 * e0 * u_int  # no Kelvin element: no memory
    dev = _deviation_integral(
        a, d, wsum, bsum, n_in, dx, g_c, gf, gint, df, kap, buf, wb, p, p_inv, lam, beta
    )
    return 2.0 * e0 * ((1.0 - kap) * u_int - dev)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _contact_coefficients(lam, dt, e, phi1, chi, cee, cef, cff):
    """Per-mode coefficients of the exact linear-input update over dt (e, phi1, chi) and
    of the damper work over it (cee, cef, cff; see `_chain_in_contact`)."""
    for m in range(lam.shape[0]):
        x = lam[m] * dt
        em, f1, f2 = _phi(x)
        e[m] = em
        phi1[m] = f1 * dt
        chi[m] = f2 * dt
        p_ee, p_ef, p_ff = _psi(x)
        cee[m] = p_ee * dt
        cef[m] = p_ef * dt * dt
        cff[m] = p_ff * dt * dt * dt


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _chain_in_contact(
    wl, wsum, wb, bsum, i, u0, u1, slope, p, p_inv, lam, beta, e, phi1, chi, cee, cef, cff, z, zb
):
    """Element i in contact over one interval, total elongation u linear from u0 to u1
    (``slope`` = du/dt; coefficients from `_contact_coefficients` for its length).

    Modes ``z = P l`` obey ``dz/dt = -lam z + beta u``; B the same with u = 1. Returns the
    damper work of the element per unit width over the interval, ``sum_k eta_k int
    (dl_k/dt)^2 = sum_m int (dz_m/dt)^2`` (P makes the damper metric the identity), with
    ``dz/dt = zeta0 E(t) + beta slope F(t)``: a sum of non-negative terms (each term is the
    integral of a square; rounding below zero is cut)."""
    k_count = wl.shape[1]
    return _chain_in_contact_k(
        wl, wsum, wb, bsum, i, u0, u1, slope, p, p_inv, lam, beta, e, phi1, chi, cee, cef, cff, z, zb, k_count
    )


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _chain_in_contact_k(
    wl, wsum, wb, bsum, i, u0, u1, slope, p, p_inv, lam, beta, e, phi1, chi, cee, cef, cff, z, zb, k_count
):
    """`_chain_in_contact` with the Kelvin count ``k_count`` (= wl.shape[1]) given: called with a
    literal K (`_update_range`) the mode loops have a known length and are unrolled (0.5.0).
    The same operations in the same order either way (the same bits)."""
    work = 0.0
    for m in range(k_count):
        acc = 0.0
        acc_b = 0.0
        for k in range(k_count):
            acc += p[m, k] * wl[i, k]
            acc_b += p[m, k] * wb[i, k]
        z[m] = e[m] * acc + beta[m] * (u0 * phi1[m] + (u1 - u0) * chi[m])
        zb[m] = e[m] * acc_b + beta[m] * phi1[m]
        zeta0 = beta[m] * u0 - lam[m] * acc
        b = beta[m] * slope
        q = zeta0 * zeta0 * cee[m] + 2.0 * zeta0 * b * cef[m] + b * b * cff[m]
        if q > 0.0:
            work += q
    total = 0.0
    total_b = 0.0
    for k in range(k_count):
        acc = 0.0
        acc_b = 0.0
        for m in range(k_count):
            acc += p_inv[k, m] * z[m]
            acc_b += p_inv[k, m] * zb[m]
        wl[i, k] = acc
        wb[i, k] = acc_b
        total += acc
        total_b += acc_b
    wsum[i] = total
    bsum[i] = total_b
    return work


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _chain_free(wl, wsum, wb, bsum, i, decay, e_kelvin):
    """Element i out of contact: each Kelvin element creeps back by its factor `decay`.
    Returns the Kelvin energy per unit width its dampers took, ``sum_k E_k (l^2 - l'^2)``."""
    return _chain_free_k(wl, wsum, wb, bsum, i, decay, e_kelvin, wl.shape[1])


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _chain_free_k(wl, wsum, wb, bsum, i, decay, e_kelvin, k_count):
    """`_chain_free` with the Kelvin count given (see `_chain_in_contact_k`)."""
    total = 0.0
    total_b = 0.0
    lost = 0.0
    for k in range(k_count):
        before = wl[i, k]
        wl[i, k] = before * decay[k]
        wb[i, k] *= decay[k]
        lost += e_kelvin[k] * (before * before - wl[i, k] * wl[i, k])
        total += wl[i, k]
        total_b += wb[i, k]
    wsum[i] = total
    bsum[i] = total_b
    return lost


#: Rows of a row's coefficient workspace (`Row.coef`, shape (COEF_ROWS, max(K, 1)), one column
#: per Kelvin mode): the exact in-contact update over the current substep length (e, phi1, chi)
#: and its damper work (cee, cef, cff), the free creep-back decay over it, then the same for
#: `_retime_crossed`'s partial lengths, then the modal vectors z, zb; ``coef[_C_SUBSTEP, 0]``
#: holds the substep length the first set belongs to (NaN: none): a row stepped at a fixed dt
#: computes them once. (One array, not two: each array argument costs the call from Python.)
_C_E, _C_PHI1, _C_CHI, _C_EE, _C_EF, _C_FF, _C_DECAY = 0, 1, 2, 3, 4, 5, 6
_C_RETIME = 7
_C_Z, _C_ZB = 14, 15
_C_SUBSTEP = 16
#: `_advance_from`'s deferred elements: the in-contact coefficients and free decays over the time
#: from the step's start to the current substep's (rows as the first set), the length they
#: belong to in ``coef[_C_DEFER_LEN, 0]`` (set to NaN at every step's start), and the sums of the
#: deferred interior block's step-start Kelvin state that its part of the force needs
#: (`_block_change`): ``sum_i wl[i, k]`` and ``sum_i cb_i wb[i, k]``.
_C_DEFER = 17
_C_DEFER_LEN = 24
_C_AW, _C_AB = 25, 26
#: The first set (rows _C_E .. _C_DECAY) of the last `_COEF_SLOTS` distinct substep lengths
#: (0.6.0): slot s spans rows ``_C_CACHE + _C_SLOT_ROWS s`` (its length in column 0, NaN: empty)
#: and the 7 rows after it; ``coef[_C_CACHE_NEXT, 0]`` is the slot the next new length takes
#: (round robin). Stamped histories give step lengths that differ in their last bits (a 1 kHz
#: log from t = 1 s: 5-8 distinct values, changing on 2 of 3 rows), and the one set above was
#: computed again on each change (`_psi`'s series, the exponentials).
_COEF_SLOTS = 8
_C_SLOT_ROWS = 8
_C_CACHE = 27
_C_CACHE_NEXT = _C_CACHE + _COEF_SLOTS * _C_SLOT_ROWS
COEF_ROWS = _C_CACHE_NEXT + 1


def coefficient_workspace(kelvin: int) -> np.ndarray:
    """A fresh `Row.coef` for a chain of `kelvin` Kelvin elements (holding no substep yet)."""
    coef = np.zeros((COEF_ROWS, max(kelvin, 1)))
    _clear_coefficients(coef)
    return coef


@numba.njit(cache=True, nogil=True, _nrt=False)
def _clear_coefficients(coef):
    """Mark ``coef`` as holding no substep length (neither the current set nor a cached one)."""
    coef[_C_SUBSTEP, 0] = math.nan
    for slot in range(_COEF_SLOTS):
        coef[_C_CACHE + _C_SLOT_ROWS * slot, 0] = math.nan
    coef[_C_CACHE_NEXT, 0] = 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _substep_coefficients(lam, rate, h, coef):
    """The in-contact coefficients and free decays over a substep of length h into ``coef``
    (`_contact_coefficients`, ``exp(-rate h)``), unless they already hold those of h; taken
    from the cache of recent lengths when it holds exactly h (the same numbers: a function
    of lam, rate and h only)."""
    if coef[_C_SUBSTEP, 0] == h:
        return
    k_count = rate.shape[0]
    for slot in range(_COEF_SLOTS):
        base = _C_CACHE + _C_SLOT_ROWS * slot
        if coef[base, 0] == h:
            for row in range(_C_DECAY + 1):
                for k in range(k_count):
                    coef[_C_E + row, k] = coef[base + 1 + row, k]
            coef[_C_SUBSTEP, 0] = h
            return
    _contact_coefficients(
        lam, h, coef[_C_E], coef[_C_PHI1], coef[_C_CHI], coef[_C_EE], coef[_C_EF], coef[_C_FF]
    )
    decay = coef[_C_DECAY]
    for k in range(k_count):
        decay[k] = math.exp(-rate[k] * h)
    coef[_C_SUBSTEP, 0] = h
    slot = int(coef[_C_CACHE_NEXT, 0])
    base = _C_CACHE + _C_SLOT_ROWS * slot
    for row in range(_C_DECAY + 1):
        for k in range(k_count):
            coef[base + 1 + row, k] = coef[_C_E + row, k]
    coef[base, 0] = h
    coef[_C_CACHE_NEXT, 0] = (slot + 1) % _COEF_SLOTS


@intrinsic
def _four_lanes(typingctx, values, magnitudes, start, groups, peak):
    """``(s0, s1, s2, s3, p0, p1, p2, p3)``: lane r holds ``0.0 + values[start + r] +
    values[start + 4 + r] + ...`` (in that order) over ``groups`` groups of four, and
    ``max(peak, |magnitudes[start + r]|, |magnitudes[start + 4 + r]|, ...)`` as numba's
    ``max(p, abs(x))`` takes it (``abs(x) > p ? abs(x) : p``), for `_sum_losses` (0.10.0).
    The four lanes are one 4-wide vector, so the loop is vector code (numba runs LLVM without
    its SLP vectoriser, and the loop vectoriser may not reorder a float sum): every lane's
    additions are the scalar loop's, in the same order, so the same bits. ``values`` and
    ``magnitudes`` are 1D C float64 arrays holding ``start + 4 groups`` elements (unchecked)."""
    array = types.Array(types.float64, 1, "C")
    if values != array or magnitudes != array:
        return None
    signature = types.UniTuple(types.float64, 8)(values, magnitudes, types.intp, types.intp, types.float64)

    def codegen(context, builder, sig, args):
        source = context.make_array(sig.args[0])(context, builder, value=args[0])
        other = context.make_array(sig.args[1])(context, builder, value=args[1])
        first, count, peak_value = args[2], args[3], args[4]
        f64 = llvm_ir.DoubleType()
        v4 = llvm_ir.VectorType(f64, 4)
        fabs = cgutils.get_or_insert_function(
            builder.module, llvm_ir.FunctionType(v4, [v4]), "llvm.fabs.v4f64"
        )
        spread = llvm_ir.Constant(v4, llvm_ir.Undefined)
        for lane in range(4):
            spread = builder.insert_element(spread, peak_value, llvm_ir.Constant(llvm_ir.IntType(32), lane))
        sums = cgutils.alloca_once_value(builder, llvm_ir.Constant(v4, [0.0, 0.0, 0.0, 0.0]))
        peaks = cgutils.alloca_once_value(builder, spread)
        four = llvm_ir.Constant(first.type, 4)
        with cgutils.for_range(builder, count) as loop:
            at = builder.add(first, builder.mul(loop.index, four))
            lane_values = builder.load(cgutils.gep(builder, source.data, at), align=8, typ=v4)
            lane_magnitudes = builder.load(cgutils.gep(builder, other.data, at), align=8, typ=v4)
            builder.store(builder.fadd(builder.load(sums), lane_values), sums)
            magnitude = builder.call(fabs, [lane_magnitudes])
            before = builder.load(peaks)
            builder.store(
                builder.select(builder.fcmp_ordered(">", magnitude, before), magnitude, before), peaks
            )
        total = builder.load(sums)
        top = builder.load(peaks)
        lanes = [builder.extract_element(total, llvm_ir.Constant(llvm_ir.IntType(32), r)) for r in range(4)]
        lanes += [builder.extract_element(top, llvm_ir.Constant(llvm_ir.IntType(32), r)) for r in range(4)]
        return context.make_tuple(builder, sig.return_type, lanes)

    return signature, codegen


def _group_loop(free):
    """The intrinsic that updates ``groups`` groups of four K = 1 elements from ``start`` as
    4-wide vectors and sums their losses and |wsum| into the lanes of `_sum_losses` (given and
    returned as ``(s0, s1, s2, s3, p0, p1, p2, p3)``), for `_update_range_one` (0.10.0):
    in contact (``free`` False; ``c`` = d0, d1, p00, q00, lam0, beta0, e_0, phi1_0, chi_0,
    cee_0, cef_0, 2 b, b b cff_0, beta0 phi1_0, 2 dx) or out of it (``c`` = decay_0, ek_0, dx).
    Each vector operation is the scalar loop's, in its order (IEEE operations lane by lane:
    the same bits), with ``diss`` written if ``store``. Numba runs LLVM without its SLP
    vectoriser and the loop vectoriser may not reorder a float sum, so a loop that sums as
    it goes stays scalar: written as vectors, the lanes' sums ride on the update instead of
    a second pass over ``diss`` and ``wsum`` whose chain of additions is its whole cost."""
    array = types.Array(types.float64, 1, "C")
    lanes_type = types.UniTuple(types.float64, 8)

    def typer(typingctx, w, u, wsum, bsum, diss, g_c, start, groups, c, lanes, store):
        for value in (w, u, wsum, bsum, diss, g_c):
            if value != array:
                return None
        if not isinstance(c, types.UniTuple) or c.dtype != types.float64 or c.count != (3 if free else 15):
            return None
        return lanes_type(
            w, u, wsum, bsum, diss, g_c, types.intp, types.intp, c, lanes_type, types.boolean
        ), _codegen

    def _codegen(context, builder, sig, args):
        data = [context.make_array(sig.args[j])(context, builder, value=args[j]).data for j in range(6)]
        w, u, wsum, bsum, diss, g_c = data
        first, count, constants, initial, store = args[6:]
        # At K = 1 a row's wsum and bsum are wl and wb themselves (`_state_layout`): then
        # the sums are not stored apart, and the one slot holds the sum's value (0.0 + x).
        alias_w = builder.icmp_unsigned("==", wsum, w)
        alias_b = builder.icmp_unsigned("==", bsum, u)
        f64 = llvm_ir.DoubleType()
        v4 = llvm_ir.VectorType(f64, 4)
        i32 = llvm_ir.IntType(32)
        fabs = cgutils.get_or_insert_function(
            builder.module, llvm_ir.FunctionType(v4, [v4]), "llvm.fabs.v4f64"
        )

        def splat(value):
            vector = llvm_ir.Constant(v4, llvm_ir.Undefined)
            for lane in range(4):
                vector = builder.insert_element(vector, value, llvm_ir.Constant(i32, lane))
            return vector

        c = [splat(builder.extract_value(constants, j)) for j in range(sig.args[8].count)]
        zero = llvm_ir.Constant(v4, [0.0, 0.0, 0.0, 0.0])
        start_sums = llvm_ir.Constant(v4, llvm_ir.Undefined)
        start_peaks = llvm_ir.Constant(v4, llvm_ir.Undefined)
        for lane in range(4):
            index = llvm_ir.Constant(i32, lane)
            start_sums = builder.insert_element(start_sums, builder.extract_value(initial, lane), index)
            start_peaks = builder.insert_element(start_peaks, builder.extract_value(initial, 4 + lane), index)
        sums = cgutils.alloca_once_value(builder, start_sums)
        peaks = cgutils.alloca_once_value(builder, start_peaks)
        four = llvm_ir.Constant(first.type, 4)
        add, sub, mul = builder.fadd, builder.fsub, builder.fmul
        with cgutils.for_range(builder, count) as loop:
            at = builder.add(first, builder.mul(loop.index, four))

            def load(pointer):
                return builder.load(cgutils.gep(builder, pointer, at), align=8, typ=v4)

            def store_to(pointer, value):
                address = builder.bitcast(cgutils.gep(builder, pointer, at), v4.as_pointer())
                builder.store(value, address, align=8)

            if free:
                decay_0, ek_0, dx = c
                before = load(w)
                after = mul(before, decay_0)
                after_b = mul(load(u), decay_0)
                total = add(zero, after)
                total_b = add(zero, after_b)
                store_to(w, builder.select(alias_w, total, after))
                store_to(u, builder.select(alias_b, total_b, after_b))
                with builder.if_then(builder.not_(alias_w)):
                    store_to(wsum, total)
                with builder.if_then(builder.not_(alias_b)):
                    store_to(bsum, total_b)
                loss = mul(dx, add(zero, mul(ek_0, sub(mul(before, before), mul(after, after)))))
            else:
                (
                    d0,
                    d1,
                    p00,
                    q00,
                    lam0,
                    beta0,
                    e_0,
                    phi1_0,
                    chi_0,
                    cee_0,
                    cef_0,
                    b2,
                    bb_cff,
                    beta_phi,
                    two_dx,
                ) = c
                g = load(g_c)
                u0 = sub(d0, g)
                u1 = sub(d1, g)
                acc = mul(p00, load(w))
                acc_b = mul(p00, load(u))
                z0 = add(mul(e_0, acc), mul(beta0, add(mul(u0, phi1_0), mul(sub(u1, u0), chi_0))))
                zb0 = add(mul(e_0, acc_b), beta_phi)
                zeta0 = sub(mul(beta0, u0), mul(lam0, acc))
                q = add(add(mul(mul(zeta0, zeta0), cee_0), mul(mul(zeta0, b2), cef_0)), bb_cff)
                work = builder.select(builder.fcmp_ordered(">", q, zero), q, zero)
                new = add(zero, mul(q00, z0))
                new_b = add(zero, mul(q00, zb0))
                # new, new_b are never -0.0 (0.0 + x): the same value as their sums.
                store_to(w, new)
                store_to(u, new_b)
                total = add(zero, new)
                with builder.if_then(builder.not_(alias_w)):
                    store_to(wsum, total)
                with builder.if_then(builder.not_(alias_b)):
                    store_to(bsum, add(zero, new_b))
                loss = mul(two_dx, work)
            with builder.if_then(store):
                store_to(diss, loss)
            builder.store(add(builder.load(sums), loss), sums)
            magnitude = builder.call(fabs, [total])
            top = builder.load(peaks)
            builder.store(builder.select(builder.fcmp_ordered(">", magnitude, top), magnitude, top), peaks)
        total_sums = builder.load(sums)
        total_peaks = builder.load(peaks)
        lanes = [builder.extract_element(total_sums, llvm_ir.Constant(i32, r)) for r in range(4)]
        lanes += [builder.extract_element(total_peaks, llvm_ir.Constant(i32, r)) for r in range(4)]
        return context.make_tuple(builder, sig.return_type, lanes)

    return intrinsic(typer)


_groups_in = _group_loop(False)
_groups_free = _group_loop(True)


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _sum_losses(diss, wsum, lo, hi, total, peak):
    """``(total + sum(diss[lo:hi]), max(peak, max |wsum[lo:hi]|))`` in four interleaved lanes
    (0.4.0): one chain of additions in index order waited ~4 cycles per element for the one
    before (as long as the whole K = 1 update). The maxima are the same in any order; the sum
    of the losses is rounded otherwise (non-negative terms: the same value to ~1e-16 of it,
    still >= 0; tests/golden_tolerance.py). Element ``lo + 4 j + r`` goes to lane r, the last
    ``(hi - lo) % 4`` to lane 0; the lanes are one vector (`_four_lanes`, 0.10.0: the scalar
    lanes cost about as much as the vectorised K = 1 update they follow)."""
    groups = max(hi - lo, 0) // 4
    s0, s1, s2, s3, p0, p1, p2, p3 = _four_lanes(diss, wsum, lo, groups, peak)
    one = _u(1)
    end = _u(hi)
    i = _u(lo + 4 * groups)
    while i < end:
        s0 += diss[i]
        p0 = max(p0, abs(wsum[i]))
        i += one
    return total + ((s0 + s1) + (s2 + s3)), max(max(p0, p1), max(p2, p3))


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _one_element(w, u, wsum, bsum, diss, g_c, i, mid, c_in, c_free):
    """Element i of `_update_range_one` alone (in contact if i < mid; ``c_in``, ``c_free`` as
    `_group_loop`'s ``c``): the vector loops' operations on one element. Returns its loss, J,
    and the |wsum| it leaves, m."""
    if i < mid:
        d0, d1, p00, q00, lam0, beta0, e_0, phi1_0, chi_0, cee_0, cef_0, b2, bb_cff, beta_phi, two_dx = c_in
        u0 = d0 - g_c[i]
        u1 = d1 - g_c[i]
        acc = p00 * w[i]
        acc_b = p00 * u[i]
        z0 = e_0 * acc + beta0 * (u0 * phi1_0 + (u1 - u0) * chi_0)
        zb0 = e_0 * acc_b + beta_phi
        zeta0 = beta0 * u0 - lam0 * acc
        q = zeta0 * zeta0 * cee_0 + zeta0 * b2 * cef_0 + bb_cff
        work = q if q > 0.0 else 0.0
        new = 0.0 + q00 * z0
        new_b = 0.0 + q00 * zb0
        w[i] = new
        u[i] = new_b
        total = 0.0 + new
        wsum[i] = total
        bsum[i] = 0.0 + new_b
        loss = two_dx * work
    else:
        decay_0, ek_0, dx = c_free
        before = w[i]
        after = before * decay_0
        w[i] = after
        u[i] = u[i] * decay_0
        total = 0.0 + after
        wsum[i] = total
        bsum[i] = 0.0 + u[i]
        loss = dx * (0.0 + ek_0 * (before * before - after * after))
    diss[i] = loss
    return loss, abs(total)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_range_one(
    wl,
    wsum,
    wb,
    bsum,
    diss,
    lo,
    hi,
    n_in,
    d0,
    d1,
    slope,
    g_c,
    p,
    p_inv,
    lam,
    beta,
    coef,
    e_kelvin,
    dx,
    total,
    peak,
    store,
):
    """`_update_range` for one Kelvin element (K = 1), written so the compiler vectorises it:
    flat arrays, the element loops free of the running sums (taken after, `_sum_losses`).
    Each expression is `_chain_in_contact`'s / `_chain_free`'s with K = 1 spelled out,
    operation for operation (``0.0 + x`` included: it turns -0.0 into 0.0), so the results
    are the same bits, but for three operations that cannot change one (0.10.0, 3 of ~32 in
    the in-contact loop, which is bound by its arithmetic):

    - the mode ``acc = p00 w`` without ``0.0 +``: it differs from ``0.0 + p00 w`` only as -0.0
      against 0.0, and no output sees that sign: ``zeta0`` enters the work only squared or
      times a term that is added to ``zeta0^2 cee`` (a zero ``zeta0`` leaves ``q`` the same),
      and ``z0`` (``e acc + ...``) leaves only through ``0.0 + q00 z0`` (0.0 either way);
    - the work ``q`` where ``q > 0`` is ``0.0 + q`` (positive, not zero);
    - ``2 zeta0 b`` as ``zeta0 (2 b)`` with ``2 b`` once per call: doubling is exact, so both
      round the same exact product (unless 2 b or 2 zeta0 overflows)."""
    w = _flat(wl)
    u = _flat(wb)
    p00 = p[0, 0]
    q00 = p_inv[0, 0]
    lam0 = lam[0]
    beta0 = beta[0]
    e_0 = coef[_C_E, 0]
    phi1_0 = coef[_C_PHI1, 0]
    chi_0 = coef[_C_CHI, 0]
    cee_0 = coef[_C_EE, 0]
    cef_0 = coef[_C_EF, 0]
    cff_0 = coef[_C_FF, 0]
    decay_0 = coef[_C_DECAY, 0]
    ek_0 = e_kelvin[0]
    b = beta0 * slope
    b2 = 2.0 * b
    bb_cff = b * b * cff_0
    c_in = (
        d0,
        d1,
        p00,
        q00,
        lam0,
        beta0,
        e_0,
        phi1_0,
        chi_0,
        cee_0,
        cef_0,
        b2,
        bb_cff,
        beta0 * phi1_0,
        2.0 * dx,
    )
    c_free = (decay_0, ek_0, dx)
    lanes = (0.0, 0.0, 0.0, 0.0, peak, peak, peak, peak)
    mid = max(min(hi, n_in), lo)
    # Whole groups of four in contact, the group the edge splits (element by element), whole
    # groups out of contact, the rest (element by element, lane 0): `_sum_losses`'s lanes.
    start = lo
    groups = (mid - lo) // 4
    lanes = _groups_in(w, u, wsum, bsum, diss, g_c, start, groups, c_in, lanes, store)
    start += 4 * groups
    s0, s1, s2, s3, p0, p1, p2, p3 = lanes
    if start < mid and start + 4 <= hi:
        loss, top = _one_element(w, u, wsum, bsum, diss, g_c, start, mid, c_in, c_free)
        s0 += loss
        p0 = max(p0, top)
        loss, top = _one_element(w, u, wsum, bsum, diss, g_c, start + 1, mid, c_in, c_free)
        s1 += loss
        p1 = max(p1, top)
        loss, top = _one_element(w, u, wsum, bsum, diss, g_c, start + 2, mid, c_in, c_free)
        s2 += loss
        p2 = max(p2, top)
        loss, top = _one_element(w, u, wsum, bsum, diss, g_c, start + 3, mid, c_in, c_free)
        s3 += loss
        p3 = max(p3, top)
        start += 4
    groups = max(hi - start, 0) // 4
    lanes = _groups_free(
        w, u, wsum, bsum, diss, g_c, start, groups, c_free, (s0, s1, s2, s3, p0, p1, p2, p3), store
    )
    start += 4 * groups
    s0, s1, s2, s3, p0, p1, p2, p3 = lanes
    for i in range(start, hi):
        loss, top = _one_element(w, u, wsum, bsum, diss, g_c, i, mid, c_in, c_free)
        s0 += loss
        p0 = max(p0, top)
    return total + ((s0 + s1) + (s2 + s3)), max(max(p0, p1), max(p2, p3))


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _update_range(
    wl,
    wsum,
    wb,
    bsum,
    diss,
    lo,
    hi,
    n_in,
    d0,
    d1,
    slope,
    g_c,
    p,
    p_inv,
    lam,
    beta,
    coef,
    e_kelvin,
    dx,
    total,
    peak,
    store=True,
):
    """`_kelvin_update` of elements lo..hi-1 with the coefficients in ``coef`` (one substep,
    `_substep_coefficients`); returns ``(total, peak)``: ``total`` plus the energy they
    dissipated, J (K <= 4: in four lanes, `_sum_losses`; K > 4: element by element in index
    order), and the larger of ``peak`` and their largest |wsum|, m. ``diss[i]`` gets element
    i's loss; with ``store`` False it may not (K = 1 leaves it out: `_advance_from` reads
    ``diss`` per element only over a substep's trial window, 0.10.0)."""
    k_count = wl.shape[1]
    args = (wl, wsum, wb, bsum, diss, lo, hi, n_in, d0, d1, slope, g_c, p, p_inv, lam, beta, coef)
    args = (*args, e_kelvin, dx)
    if k_count == 1:
        return _update_range_one(*args, total, peak, store)
    if k_count < 2 or k_count > 4:
        return _update_range_k(*args, total, peak, k_count)
    # K = 2, 3, 4: the element loops written out per K (generated, `_update_in_4`...): the modes
    # in registers, no workspace, a known stride, so the compiler vectorises across elements;
    # the losses and the peak summed after (0.5.0), in four lanes since 0.7.0 as for K = 1
    # (`_sum_losses`: one chain in index order cost ~0.9 ns per element, the lanes ~0.3).
    mid = max(min(hi, n_in), lo)
    end = max(hi, mid)
    in_args = (wl, wsum, wb, bsum, diss, lo, mid, d0, d1, slope, g_c, p, p_inv, lam, beta, coef, dx)
    free_args = (wl, wsum, wb, bsum, diss, mid, end, coef[_C_DECAY], e_kelvin, dx)
    if k_count == 2:
        _update_in_2(*in_args)
        _update_free_2(*free_args)
    elif k_count == 3:
        _update_in_3(*in_args)
        _update_free_3(*free_args)
    else:
        _update_in_4(*in_args)
        _update_free_4(*free_args)
    return _sum_losses(diss, wsum, lo, end, total, peak)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_range_k(
    wl,
    wsum,
    wb,
    bsum,
    diss,
    lo,
    hi,
    n_in,
    d0,
    d1,
    slope,
    g_c,
    p,
    p_inv,
    lam,
    beta,
    coef,
    e_kelvin,
    dx,
    total,
    peak,
    k_count,
):
    """`_update_range` for K >= 2 Kelvin elements, ``k_count`` = wl.shape[1] (a literal from
    `_update_range` for small K); the element loops over unsigned indices (`_u`)."""
    e = coef[_C_E]
    phi1 = coef[_C_PHI1]
    chi = coef[_C_CHI]
    cee = coef[_C_EE]
    cef = coef[_C_EF]
    cff = coef[_C_FF]
    decay = coef[_C_DECAY]
    z = coef[_C_Z]
    zb = coef[_C_ZB]
    for i in range(_u(lo), _u(max(min(hi, n_in), lo))):
        work = _chain_in_contact_k(
            wl,
            wsum,
            wb,
            bsum,
            i,
            d0 - g_c[i],
            d1 - g_c[i],
            slope,
            p,
            p_inv,
            lam,
            beta,
            e,
            phi1,
            chi,
            cee,
            cef,
            cff,
            z,
            zb,
            k_count,
        )
        diss[i] = 2.0 * dx * work
        total += diss[i]
        peak = max(peak, abs(wsum[i]))
    for i in range(_u(max(lo, n_in)), _u(max(hi, lo, n_in))):
        diss[i] = dx * _chain_free_k(wl, wsum, wb, bsum, i, decay, e_kelvin, k_count)
        total += diss[i]
        peak = max(peak, abs(wsum[i]))
    return total, peak


# --- generated by scripts/gen_kelvin_update.py: do not edit by hand ---


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_in_2(wl, wsum, wb, bsum, diss, lo, mid, d0, d1, slope, g_c, p, p_inv, lam, beta, coef, dx):
    """In-contact elements lo..mid-1 of `_update_range_k` for K = 2, written out."""
    w = _flat(wl)
    v = _flat(wb)
    p00 = p[0, 0]
    p01 = p[0, 1]
    p10 = p[1, 0]
    p11 = p[1, 1]
    q00 = p_inv[0, 0]
    q01 = p_inv[0, 1]
    q10 = p_inv[1, 0]
    q11 = p_inv[1, 1]
    lam0 = lam[0]
    beta0 = beta[0]
    e0 = coef[_C_E, 0]
    phi0 = coef[_C_PHI1, 0]
    chi0 = coef[_C_CHI, 0]
    cee0 = coef[_C_EE, 0]
    cef0 = coef[_C_EF, 0]
    cff0 = coef[_C_FF, 0]
    lam1 = lam[1]
    beta1 = beta[1]
    e1 = coef[_C_E, 1]
    phi1 = coef[_C_PHI1, 1]
    chi1 = coef[_C_CHI, 1]
    cee1 = coef[_C_EE, 1]
    cef1 = coef[_C_EF, 1]
    cff1 = coef[_C_FF, 1]
    two_b0 = 2.0 * (beta0 * slope)
    two_b1 = 2.0 * (beta1 * slope)
    two_dx = 2.0 * dx
    for i in range(_u(lo), _u(mid)):
        at = i * _u(2)
        w0 = w[at]
        v0 = v[at]
        w1 = w[at + _u(1)]
        v1 = v[at + _u(1)]
        u0 = d0 - g_c[i]
        u1 = d1 - g_c[i]
        acc = p00 * w0
        acc_b = p00 * v0
        acc = acc + p01 * w1
        acc_b = acc_b + p01 * v1
        z0 = e0 * acc + beta0 * (u0 * phi0 + (u1 - u0) * chi0)
        zb0 = e0 * acc_b + beta0 * phi0
        zeta = beta0 * u0 - lam0 * acc
        b = beta0 * slope
        q = zeta * zeta * cee0 + zeta * two_b0 * cef0 + b * b * cff0
        work = q if q > 0.0 else 0.0
        acc = p10 * w0
        acc_b = p10 * v0
        acc = acc + p11 * w1
        acc_b = acc_b + p11 * v1
        z1 = e1 * acc + beta1 * (u0 * phi1 + (u1 - u0) * chi1)
        zb1 = e1 * acc_b + beta1 * phi1
        zeta = beta1 * u0 - lam1 * acc
        b = beta1 * slope
        q = zeta * zeta * cee1 + zeta * two_b1 * cef1 + b * b * cff1
        work = work + q if q > 0.0 else work
        total = 0.0
        total_b = 0.0
        acc = 0.0 + q00 * z0
        acc_b = 0.0 + q00 * zb0
        acc = acc + q01 * z1
        acc_b = acc_b + q01 * zb1
        w[at] = acc
        v[at] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        acc = 0.0 + q10 * z0
        acc_b = 0.0 + q10 * zb0
        acc = acc + q11 * z1
        acc_b = acc_b + q11 * zb1
        w[at + _u(1)] = acc
        v[at + _u(1)] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        wsum[i] = total
        bsum[i] = total_b
        diss[i] = two_dx * work


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_free_2(wl, wsum, wb, bsum, diss, lo, hi, decay, e_kelvin, dx):
    """Out-of-contact elements lo..hi-1 of `_update_range_k` for K = 2, written out."""
    w = _flat(wl)
    v = _flat(wb)
    decay0 = decay[0]
    ek0 = e_kelvin[0]
    decay1 = decay[1]
    ek1 = e_kelvin[1]
    for i in range(_u(lo), _u(hi)):
        at = i * _u(2)
        total = 0.0
        total_b = 0.0
        lost = 0.0
        before = w[at]
        after = before * decay0
        w[at] = after
        after_b = v[at] * decay0
        v[at] = after_b
        lost = lost + ek0 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        before = w[at + _u(1)]
        after = before * decay1
        w[at + _u(1)] = after
        after_b = v[at + _u(1)] * decay1
        v[at + _u(1)] = after_b
        lost = lost + ek1 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        wsum[i] = total
        bsum[i] = total_b
        diss[i] = dx * lost


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_in_3(wl, wsum, wb, bsum, diss, lo, mid, d0, d1, slope, g_c, p, p_inv, lam, beta, coef, dx):
    """In-contact elements lo..mid-1 of `_update_range_k` for K = 3, written out."""
    w = _flat(wl)
    v = _flat(wb)
    p00 = p[0, 0]
    p01 = p[0, 1]
    p02 = p[0, 2]
    p10 = p[1, 0]
    p11 = p[1, 1]
    p12 = p[1, 2]
    p20 = p[2, 0]
    p21 = p[2, 1]
    p22 = p[2, 2]
    q00 = p_inv[0, 0]
    q01 = p_inv[0, 1]
    q02 = p_inv[0, 2]
    q10 = p_inv[1, 0]
    q11 = p_inv[1, 1]
    q12 = p_inv[1, 2]
    q20 = p_inv[2, 0]
    q21 = p_inv[2, 1]
    q22 = p_inv[2, 2]
    lam0 = lam[0]
    beta0 = beta[0]
    e0 = coef[_C_E, 0]
    phi0 = coef[_C_PHI1, 0]
    chi0 = coef[_C_CHI, 0]
    cee0 = coef[_C_EE, 0]
    cef0 = coef[_C_EF, 0]
    cff0 = coef[_C_FF, 0]
    lam1 = lam[1]
    beta1 = beta[1]
    e1 = coef[_C_E, 1]
    phi1 = coef[_C_PHI1, 1]
    chi1 = coef[_C_CHI, 1]
    cee1 = coef[_C_EE, 1]
    cef1 = coef[_C_EF, 1]
    cff1 = coef[_C_FF, 1]
    lam2 = lam[2]
    beta2 = beta[2]
    e2 = coef[_C_E, 2]
    phi2 = coef[_C_PHI1, 2]
    chi2 = coef[_C_CHI, 2]
    cee2 = coef[_C_EE, 2]
    cef2 = coef[_C_EF, 2]
    cff2 = coef[_C_FF, 2]
    two_b0 = 2.0 * (beta0 * slope)
    two_b1 = 2.0 * (beta1 * slope)
    two_b2 = 2.0 * (beta2 * slope)
    two_dx = 2.0 * dx
    for i in range(_u(lo), _u(mid)):
        at = i * _u(3)
        w0 = w[at]
        v0 = v[at]
        w1 = w[at + _u(1)]
        v1 = v[at + _u(1)]
        w2 = w[at + _u(2)]
        v2 = v[at + _u(2)]
        u0 = d0 - g_c[i]
        u1 = d1 - g_c[i]
        acc = p00 * w0
        acc_b = p00 * v0
        acc = acc + p01 * w1
        acc_b = acc_b + p01 * v1
        acc = acc + p02 * w2
        acc_b = acc_b + p02 * v2
        z0 = e0 * acc + beta0 * (u0 * phi0 + (u1 - u0) * chi0)
        zb0 = e0 * acc_b + beta0 * phi0
        zeta = beta0 * u0 - lam0 * acc
        b = beta0 * slope
        q = zeta * zeta * cee0 + zeta * two_b0 * cef0 + b * b * cff0
        work = q if q > 0.0 else 0.0
        acc = p10 * w0
        acc_b = p10 * v0
        acc = acc + p11 * w1
        acc_b = acc_b + p11 * v1
        acc = acc + p12 * w2
        acc_b = acc_b + p12 * v2
        z1 = e1 * acc + beta1 * (u0 * phi1 + (u1 - u0) * chi1)
        zb1 = e1 * acc_b + beta1 * phi1
        zeta = beta1 * u0 - lam1 * acc
        b = beta1 * slope
        q = zeta * zeta * cee1 + zeta * two_b1 * cef1 + b * b * cff1
        work = work + q if q > 0.0 else work
        acc = p20 * w0
        acc_b = p20 * v0
        acc = acc + p21 * w1
        acc_b = acc_b + p21 * v1
        acc = acc + p22 * w2
        acc_b = acc_b + p22 * v2
        z2 = e2 * acc + beta2 * (u0 * phi2 + (u1 - u0) * chi2)
        zb2 = e2 * acc_b + beta2 * phi2
        zeta = beta2 * u0 - lam2 * acc
        b = beta2 * slope
        q = zeta * zeta * cee2 + zeta * two_b2 * cef2 + b * b * cff2
        work = work + q if q > 0.0 else work
        total = 0.0
        total_b = 0.0
        acc = 0.0 + q00 * z0
        acc_b = 0.0 + q00 * zb0
        acc = acc + q01 * z1
        acc_b = acc_b + q01 * zb1
        acc = acc + q02 * z2
        acc_b = acc_b + q02 * zb2
        w[at] = acc
        v[at] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        acc = 0.0 + q10 * z0
        acc_b = 0.0 + q10 * zb0
        acc = acc + q11 * z1
        acc_b = acc_b + q11 * zb1
        acc = acc + q12 * z2
        acc_b = acc_b + q12 * zb2
        w[at + _u(1)] = acc
        v[at + _u(1)] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        acc = 0.0 + q20 * z0
        acc_b = 0.0 + q20 * zb0
        acc = acc + q21 * z1
        acc_b = acc_b + q21 * zb1
        acc = acc + q22 * z2
        acc_b = acc_b + q22 * zb2
        w[at + _u(2)] = acc
        v[at + _u(2)] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        wsum[i] = total
        bsum[i] = total_b
        diss[i] = two_dx * work


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_free_3(wl, wsum, wb, bsum, diss, lo, hi, decay, e_kelvin, dx):
    """Out-of-contact elements lo..hi-1 of `_update_range_k` for K = 3, written out."""
    w = _flat(wl)
    v = _flat(wb)
    decay0 = decay[0]
    ek0 = e_kelvin[0]
    decay1 = decay[1]
    ek1 = e_kelvin[1]
    decay2 = decay[2]
    ek2 = e_kelvin[2]
    for i in range(_u(lo), _u(hi)):
        at = i * _u(3)
        total = 0.0
        total_b = 0.0
        lost = 0.0
        before = w[at]
        after = before * decay0
        w[at] = after
        after_b = v[at] * decay0
        v[at] = after_b
        lost = lost + ek0 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        before = w[at + _u(1)]
        after = before * decay1
        w[at + _u(1)] = after
        after_b = v[at + _u(1)] * decay1
        v[at + _u(1)] = after_b
        lost = lost + ek1 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        before = w[at + _u(2)]
        after = before * decay2
        w[at + _u(2)] = after
        after_b = v[at + _u(2)] * decay2
        v[at + _u(2)] = after_b
        lost = lost + ek2 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        wsum[i] = total
        bsum[i] = total_b
        diss[i] = dx * lost


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_in_4(wl, wsum, wb, bsum, diss, lo, mid, d0, d1, slope, g_c, p, p_inv, lam, beta, coef, dx):
    """In-contact elements lo..mid-1 of `_update_range_k` for K = 4, written out."""
    w = _flat(wl)
    v = _flat(wb)
    p00 = p[0, 0]
    p01 = p[0, 1]
    p02 = p[0, 2]
    p03 = p[0, 3]
    p10 = p[1, 0]
    p11 = p[1, 1]
    p12 = p[1, 2]
    p13 = p[1, 3]
    p20 = p[2, 0]
    p21 = p[2, 1]
    p22 = p[2, 2]
    p23 = p[2, 3]
    p30 = p[3, 0]
    p31 = p[3, 1]
    p32 = p[3, 2]
    p33 = p[3, 3]
    q00 = p_inv[0, 0]
    q01 = p_inv[0, 1]
    q02 = p_inv[0, 2]
    q03 = p_inv[0, 3]
    q10 = p_inv[1, 0]
    q11 = p_inv[1, 1]
    q12 = p_inv[1, 2]
    q13 = p_inv[1, 3]
    q20 = p_inv[2, 0]
    q21 = p_inv[2, 1]
    q22 = p_inv[2, 2]
    q23 = p_inv[2, 3]
    q30 = p_inv[3, 0]
    q31 = p_inv[3, 1]
    q32 = p_inv[3, 2]
    q33 = p_inv[3, 3]
    lam0 = lam[0]
    beta0 = beta[0]
    e0 = coef[_C_E, 0]
    phi0 = coef[_C_PHI1, 0]
    chi0 = coef[_C_CHI, 0]
    cee0 = coef[_C_EE, 0]
    cef0 = coef[_C_EF, 0]
    cff0 = coef[_C_FF, 0]
    lam1 = lam[1]
    beta1 = beta[1]
    e1 = coef[_C_E, 1]
    phi1 = coef[_C_PHI1, 1]
    chi1 = coef[_C_CHI, 1]
    cee1 = coef[_C_EE, 1]
    cef1 = coef[_C_EF, 1]
    cff1 = coef[_C_FF, 1]
    lam2 = lam[2]
    beta2 = beta[2]
    e2 = coef[_C_E, 2]
    phi2 = coef[_C_PHI1, 2]
    chi2 = coef[_C_CHI, 2]
    cee2 = coef[_C_EE, 2]
    cef2 = coef[_C_EF, 2]
    cff2 = coef[_C_FF, 2]
    lam3 = lam[3]
    beta3 = beta[3]
    e3 = coef[_C_E, 3]
    phi3 = coef[_C_PHI1, 3]
    chi3 = coef[_C_CHI, 3]
    cee3 = coef[_C_EE, 3]
    cef3 = coef[_C_EF, 3]
    cff3 = coef[_C_FF, 3]
    two_b0 = 2.0 * (beta0 * slope)
    two_b1 = 2.0 * (beta1 * slope)
    two_b2 = 2.0 * (beta2 * slope)
    two_b3 = 2.0 * (beta3 * slope)
    two_dx = 2.0 * dx
    for i in range(_u(lo), _u(mid)):
        at = i * _u(4)
        w0 = w[at]
        v0 = v[at]
        w1 = w[at + _u(1)]
        v1 = v[at + _u(1)]
        w2 = w[at + _u(2)]
        v2 = v[at + _u(2)]
        w3 = w[at + _u(3)]
        v3 = v[at + _u(3)]
        u0 = d0 - g_c[i]
        u1 = d1 - g_c[i]
        acc = p00 * w0
        acc_b = p00 * v0
        acc = acc + p01 * w1
        acc_b = acc_b + p01 * v1
        acc = acc + p02 * w2
        acc_b = acc_b + p02 * v2
        acc = acc + p03 * w3
        acc_b = acc_b + p03 * v3
        z0 = e0 * acc + beta0 * (u0 * phi0 + (u1 - u0) * chi0)
        zb0 = e0 * acc_b + beta0 * phi0
        zeta = beta0 * u0 - lam0 * acc
        b = beta0 * slope
        q = zeta * zeta * cee0 + zeta * two_b0 * cef0 + b * b * cff0
        work = q if q > 0.0 else 0.0
        acc = p10 * w0
        acc_b = p10 * v0
        acc = acc + p11 * w1
        acc_b = acc_b + p11 * v1
        acc = acc + p12 * w2
        acc_b = acc_b + p12 * v2
        acc = acc + p13 * w3
        acc_b = acc_b + p13 * v3
        z1 = e1 * acc + beta1 * (u0 * phi1 + (u1 - u0) * chi1)
        zb1 = e1 * acc_b + beta1 * phi1
        zeta = beta1 * u0 - lam1 * acc
        b = beta1 * slope
        q = zeta * zeta * cee1 + zeta * two_b1 * cef1 + b * b * cff1
        work = work + q if q > 0.0 else work
        acc = p20 * w0
        acc_b = p20 * v0
        acc = acc + p21 * w1
        acc_b = acc_b + p21 * v1
        acc = acc + p22 * w2
        acc_b = acc_b + p22 * v2
        acc = acc + p23 * w3
        acc_b = acc_b + p23 * v3
        z2 = e2 * acc + beta2 * (u0 * phi2 + (u1 - u0) * chi2)
        zb2 = e2 * acc_b + beta2 * phi2
        zeta = beta2 * u0 - lam2 * acc
        b = beta2 * slope
        q = zeta * zeta * cee2 + zeta * two_b2 * cef2 + b * b * cff2
        work = work + q if q > 0.0 else work
        acc = p30 * w0
        acc_b = p30 * v0
        acc = acc + p31 * w1
        acc_b = acc_b + p31 * v1
        acc = acc + p32 * w2
        acc_b = acc_b + p32 * v2
        acc = acc + p33 * w3
        acc_b = acc_b + p33 * v3
        z3 = e3 * acc + beta3 * (u0 * phi3 + (u1 - u0) * chi3)
        zb3 = e3 * acc_b + beta3 * phi3
        zeta = beta3 * u0 - lam3 * acc
        b = beta3 * slope
        q = zeta * zeta * cee3 + zeta * two_b3 * cef3 + b * b * cff3
        work = work + q if q > 0.0 else work
        total = 0.0
        total_b = 0.0
        acc = 0.0 + q00 * z0
        acc_b = 0.0 + q00 * zb0
        acc = acc + q01 * z1
        acc_b = acc_b + q01 * zb1
        acc = acc + q02 * z2
        acc_b = acc_b + q02 * zb2
        acc = acc + q03 * z3
        acc_b = acc_b + q03 * zb3
        w[at] = acc
        v[at] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        acc = 0.0 + q10 * z0
        acc_b = 0.0 + q10 * zb0
        acc = acc + q11 * z1
        acc_b = acc_b + q11 * zb1
        acc = acc + q12 * z2
        acc_b = acc_b + q12 * zb2
        acc = acc + q13 * z3
        acc_b = acc_b + q13 * zb3
        w[at + _u(1)] = acc
        v[at + _u(1)] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        acc = 0.0 + q20 * z0
        acc_b = 0.0 + q20 * zb0
        acc = acc + q21 * z1
        acc_b = acc_b + q21 * zb1
        acc = acc + q22 * z2
        acc_b = acc_b + q22 * zb2
        acc = acc + q23 * z3
        acc_b = acc_b + q23 * zb3
        w[at + _u(2)] = acc
        v[at + _u(2)] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        acc = 0.0 + q30 * z0
        acc_b = 0.0 + q30 * zb0
        acc = acc + q31 * z1
        acc_b = acc_b + q31 * zb1
        acc = acc + q32 * z2
        acc_b = acc_b + q32 * zb2
        acc = acc + q33 * z3
        acc_b = acc_b + q33 * zb3
        w[at + _u(3)] = acc
        v[at + _u(3)] = acc_b
        total = total + acc
        total_b = total_b + acc_b
        wsum[i] = total
        bsum[i] = total_b
        diss[i] = two_dx * work


@numba.njit(cache=True, nogil=True, _nrt=False)
def _update_free_4(wl, wsum, wb, bsum, diss, lo, hi, decay, e_kelvin, dx):
    """Out-of-contact elements lo..hi-1 of `_update_range_k` for K = 4, written out."""
    w = _flat(wl)
    v = _flat(wb)
    decay0 = decay[0]
    ek0 = e_kelvin[0]
    decay1 = decay[1]
    ek1 = e_kelvin[1]
    decay2 = decay[2]
    ek2 = e_kelvin[2]
    decay3 = decay[3]
    ek3 = e_kelvin[3]
    for i in range(_u(lo), _u(hi)):
        at = i * _u(4)
        total = 0.0
        total_b = 0.0
        lost = 0.0
        before = w[at]
        after = before * decay0
        w[at] = after
        after_b = v[at] * decay0
        v[at] = after_b
        lost = lost + ek0 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        before = w[at + _u(1)]
        after = before * decay1
        w[at + _u(1)] = after
        after_b = v[at + _u(1)] * decay1
        v[at + _u(1)] = after_b
        lost = lost + ek1 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        before = w[at + _u(2)]
        after = before * decay2
        w[at + _u(2)] = after
        after_b = v[at + _u(2)] * decay2
        v[at + _u(2)] = after_b
        lost = lost + ek2 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        before = w[at + _u(3)]
        after = before * decay3
        w[at + _u(3)] = after
        after_b = v[at + _u(3)] * decay3
        v[at + _u(3)] = after_b
        lost = lost + ek3 * (before * before - after * after)
        total = total + after
        total_b = total_b + after_b
        wsum[i] = total
        bsum[i] = total_b
        diss[i] = dx * lost


# --- end of generated code ---


@numba.njit(cache=True, nogil=True)  # allocates its workspace: needs the runtime
def _kelvin_update(wl, wsum, wb, bsum, diss, n_in, d0, d1, dt, g_c, p, p_inv, lam, beta, rate, e_kelvin, dx):
    """Exact update of every Kelvin chain over dt for a depth linear from d0 to d1.

    Interior elements (i < n_in): modal form of ``dl/dt = A l + b u(t)``, ``u = d - g``.
    Exterior elements: free creep-back ``dl_k/dt = -rate_k l_k``. ``diss[i]`` gets the
    energy element i dissipated, J (both half-rows: 2 dx times the damper work per width
    for the glass-spring-driven chain, dx times the Kelvin energy lost creeping back).
    `_advance` runs the same update range by range (`_update_range`).
    """
    n, k_count = wl.shape
    if k_count == 0 or dt <= 0.0:
        for i in range(n):
            diss[i] = 0.0
        return
    coef = np.empty((COEF_ROWS, k_count))
    _clear_coefficients(coef)
    _substep_coefficients(lam, rate, dt, coef)
    _update_range(
        wl,
        wsum,
        wb,
        bsum,
        diss,
        0,
        n,
        n_in,
        d0,
        d1,
        (d1 - d0) / dt,
        g_c,
        p,
        p_inv,
        lam,
        beta,
        coef,
        e_kelvin,
        dx,
        0.0,
        0.0,
    )


@numba.njit(cache=True, nogil=True, _nrt=False)
def _retime_crossed(
    wl,
    wsum,
    wb,
    bsum,
    scratch,
    scratch_b,
    diss,
    coef,
    a0,
    a1,
    da,
    db,
    dt,
    dx,
    g_c,
    p,
    p_inv,
    lam,
    beta,
    rate,
    e_kelvin,
    e0,
    c_crit,
    gf,
    df,
):
    """Redo the substep for the elements the edge crossed, switching them at the crossing;
    returns their adhesion hysteresis, J (signed: the caller cuts a substep's sum at 0).

    `_kelvin_update` treats an element by its status at the substep's start. An element
    the edge passed during the substep really switched part-way: with the edge linear in
    time it is reached at ``f = |x_i - a0| / |a1 - a0|``. Without this, every freshly
    attached element stays glassy for a whole step and the quasistatic indentation force
    is off by about one cell of unrelaxed edge (1-2 % of the pull-off force at N ~ 100).
    Snap-in from no contact happens when the indenter touches: the switch time there is
    taken from the depth crossing zero (``f = -da/(db - da)``); a jump to no contact (the
    fold) is taken at the substep's end. At the switch the element's glass spring takes
    (attach) or gives up (let go) ``E0* dx l0^2`` while its annulus gives up or regains
    the surface energy ``E0* c^2 x dx``: the difference is lost. A let-go from a contact at
    most FOLD_FINE_CELLS elements wide gives up its glass energy on the fine profile instead
    (`_fold_energy`): per element, the last one counted whole (the edge mid-way across it)
    overstated the loss of a let-go from a contact about one element wide by up to 70x the
    exact JKR loss (a blunt cone pressed deep, so the domain's elements are wider than the
    contact at pull-off; an outside tester, 0.8.0).

    Reads the crossed elements' state from before the substep in ``scratch``/``scratch_b``
    and works in the retime rows of the workspace ``coef`` (`COEF_ROWS`); allocates nothing.
    """
    n, k_count = wl.shape
    n0 = _interior_count(a0, dx, n)
    n1 = _interior_count(a1, dx, n)
    if n0 == n1:
        return 0.0
    e = coef[_C_RETIME + _C_E]
    phi1 = coef[_C_RETIME + _C_PHI1]
    chi = coef[_C_RETIME + _C_CHI]
    cee = coef[_C_RETIME + _C_EE]
    cef = coef[_C_RETIME + _C_EF]
    cff = coef[_C_RETIME + _C_FF]
    decay = coef[_C_RETIME + _C_DECAY]
    z = coef[_C_Z]
    zb = coef[_C_ZB]
    slope = (db - da) / dt if dt > 0.0 else 0.0
    hysteresis = 0.0
    lo, hi = (n0, n1) if n1 > n0 else (n1, n0)
    # The lengths the retime coefficients and decays in ``coef`` were last computed for: the
    # elements of a snap-in from no contact or of a fold to none all switch at the same f, so
    # they are computed once, not once per element (the same numbers either way).
    coef_length = math.nan
    decay_length = math.nan
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
        total = 0.0
        total_b = 0.0
        for k in range(k_count):
            wl[i, k] = scratch[i, k]
            wb[i, k] = scratch_b[i, k]
            total += wl[i, k]
            total_b += wb[i, k]
        wsum[i] = total
        bsum[i] = total_b
        first, second = f * dt, (1.0 - f) * dt
        lost = 0.0
        if n1 > n0:
            if first != decay_length:
                for k in range(k_count):
                    decay[k] = math.exp(-rate[k] * first)
                decay_length = first
            lost += dx * _chain_free(wl, wsum, wb, bsum, i, decay, e_kelvin)
            l0 = d_switch - g_c[i] - wsum[i]
            hysteresis += e0 * dx * (c_crit * c_crit * xi - l0 * l0)
            if k_count:
                if second != coef_length:
                    _contact_coefficients(lam, second, e, phi1, chi, cee, cef, cff)
                    coef_length = second
                lost += (
                    2.0
                    * dx
                    * _chain_in_contact(
                        wl,
                        wsum,
                        wb,
                        bsum,
                        i,
                        d_switch - g_c[i],
                        db - g_c[i],
                        slope,
                        p,
                        p_inv,
                        lam,
                        beta,
                        e,
                        phi1,
                        chi,
                        cee,
                        cef,
                        cff,
                        z,
                        zb,
                    )
                )
        else:
            if k_count:
                if first != coef_length:
                    _contact_coefficients(lam, first, e, phi1, chi, cee, cef, cff)
                    coef_length = first
                lost += (
                    2.0
                    * dx
                    * _chain_in_contact(
                        wl,
                        wsum,
                        wb,
                        bsum,
                        i,
                        da - g_c[i],
                        d_switch - g_c[i],
                        slope,
                        p,
                        p_inv,
                        lam,
                        beta,
                        e,
                        phi1,
                        chi,
                        cee,
                        cef,
                        cff,
                        z,
                        zb,
                    )
                )
            l0 = d_switch - g_c[i] - wsum[i]
            hysteresis += e0 * dx * (l0 * l0 - c_crit * c_crit * xi)
            if second != decay_length:
                for k in range(k_count):
                    decay[k] = math.exp(-rate[k] * second)
                decay_length = second
            lost += dx * _chain_free(wl, wsum, wb, bsum, i, decay, e_kelvin)
        diss[i] = lost
    if a1 <= 0.0 < a0 and n0 <= FOLD_FINE_CELLS:
        hysteresis = _fold_energy(a0, db, wsum, dx, gf, df, e0, c_crit)
    return hysteresis


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _adhesion_loss(hysteresis, a0, a1, max_edge_move):
    """The adhesion loss of a substep whose edge went from `a0` to `a1` (m), given the signed
    hysteresis `_retime_crossed` computed for the elements it crossed, J.

    Only a jump loses: a snap-in from no contact, a let-go to none, or an edge that moved
    more than the motion limit `max_edge_move` in a substep of the shortest length (the fold
    of a pull-off, a partial snap). An edge that moved continuously switched each element it
    crossed where the criterion holds, and there the element's glass energy equals the
    surface energy of its annulus: no loss in the model. What `_retime_crossed` computes for
    such an element (its glass elongation at a switch depth interpolated linearly in time) is
    a discretisation residue of either sign; cut at zero substep by substep it summed to
    +27 % .. +111 % of the exact (JKR) loss of an elastic cycle pressed deep on a steep cone
    at `balanced` (an outside tester, 0.9.0), and signed it was as large the other way.
    0.10.0: continuous crossings lose nothing; a jump's hysteresis is cut at zero, as
    before (the dissipated energy never falls)."""
    if 0.0 < a0 and 0.0 < a1 and abs(a1 - a0) <= max_edge_move:
        return 0.0
    return max(hysteresis, 0.0)


#: A let-go from a contact at most this many elements wide takes its loss on the fine profile
#: (`_retime_crossed`, `_fold_energy`).
FOLD_FINE_CELLS = 4


@numba.njit(cache=True, nogil=True, _nrt=False)
def _fold_energy(a, d, wsum, dx, gf, df, e0, c_crit):
    """``E0* (int_0^a (d - g(x) - w(x))^2 dx - c^2 a^2 / 2)``, J: the glass energy a contact
    of radius `a` (m) at depth `d` (m) gives up when it lets go at once, less the surface
    energy it regains; ``w(x)`` the Kelvin elongation of the element holding x (``wsum``),
    g on the fine profile (trapezoids between its points, the last one cut at a)."""
    n = wsum.shape[0]
    m = gf.shape[0]
    last = min(int(a / df), m - 1)
    total = 0.0
    x0 = 0.0
    for j in range(1, last + 1):
        x1 = j * df
        w = wsum[min(int((x0 + 0.5 * df) / dx), n - 1)]
        l0 = d - gf[j - 1] - w
        l1 = d - gf[j] - w
        total += 0.5 * (l0 * l0 + l1 * l1) * df
        x0 = x1
    if a > x0:
        w = wsum[min(int((0.5 * (x0 + a)) / dx), n - 1)]
        l0 = d - gf[last] - w
        l1 = d - _g_at(a, gf, df) - w
        total += 0.5 * (l0 * l0 + l1 * l1) * (a - x0)
    return e0 * (total - 0.5 * c_crit * c_crit * a * a)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _copy_state(src, src_b, dst, dst_b):
    """Copy the memory (wl, wb) into (dst, dst_b); all C-contiguous (N, K)."""
    _copy_range(src, src_b, dst, dst_b, 0, src.shape[0])


@numba.njit(cache=True, nogil=True, _nrt=False)
def _copy_range(src, src_b, dst, dst_b, lo, hi):
    """`_copy_state` of elements lo..hi-1, as flat copies (a loop over (i, k) with a runtime K
    does not vectorise: 6 ns per element against 0.5)."""
    k_count = src.shape[1]
    flat_src = _flat(src)
    flat_dst = _flat(dst)
    for j in range(_u(lo * k_count), _u(hi * k_count)):
        flat_dst[j] = flat_src[j]
    flat_src = _flat(src_b)
    flat_dst = _flat(dst_b)
    for j in range(_u(lo * k_count), _u(hi * k_count)):
        flat_dst[j] = flat_src[j]


@numba.njit(cache=True, nogil=True, _nrt=False)
def _restore_range(wl, wsum, wb, bsum, src, src_b, lo, hi):
    """`_restore_state` of elements lo..hi-1."""
    _copy_range(src, src_b, wl, wb, lo, hi)
    for i in range(lo, hi):
        total = 0.0
        total_b = 0.0
        for k in range(wl.shape[1]):
            total += wl[i, k]
            total_b += wb[i, k]
        wsum[i] = total
        bsum[i] = total_b


@numba.njit(cache=True, nogil=True, _nrt=False)
def _restore_state(wl, wsum, wb, bsum, src, src_b):
    _restore_range(wl, wsum, wb, bsum, src, src_b, 0, wl.shape[0])


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _edge_outputs(a, d, wsum, bsum, dx, g_c, gf, df, c_crit, out):
    """Write the edge gaps on both sides and g at the edge into ``out`` (zeros without contact)."""
    if a > 0.0:
        n = wsum.shape[0]
        n_in = _interior_count(a, dx, n)
        out[OUT_GAP_OUTSIDE] = _h(a, d, wsum, bsum, n_in, n - 1, dx, g_c, gf, df, c_crit)
        out[OUT_GAP_INSIDE] = _h(a, d, wsum, bsum, 0, n_in - 1, dx, g_c, gf, df, c_crit)
        out[OUT_G_EDGE] = _g_at(a, gf, df)
    else:
        out[OUT_GAP_OUTSIDE] = 0.0
        out[OUT_GAP_INSIDE] = 0.0
        out[OUT_G_EDGE] = 0.0


@numba.njit(cache=True, nogil=True, _nrt=False)
def _trial_window(a, n_in, n, dx, df, max_move):
    """Elements ``lo..hi-1`` that a substep trial must update before `_locate_edge` with the
    motion limit ``max_move`` (m) from the radius ``a > 0``: every element that search reads.

    The limited search only looks near the edge: inward (detachment) it stops once it is
    more than max_move inside a, outward (attachment, `_scan_out`) once beyond a + max_move;
    each scan may overshoot that by one block of `TOUCH_BLOCK` fine points (`_h_bounds`) plus
    one fine point, and `_side_ab`/`_h_bounds` read up to two elements beyond a point (the
    interior's extrapolation three back from its last element, the exterior's two ahead of
    its first). The window covers that reach doubled, plus three elements each side.
    """
    span = max_move + 2.0 * (TOUCH_BLOCK + 2) * df
    x_lo = a - span
    x_hi = a + span
    lo = 0
    if x_lo > 0.0:
        lo = max(int(x_lo / dx - 0.5) - 3, 0)
    hi = n
    if x_hi < n * dx:
        hi = min(int(x_hi / dx - 0.5) + 4, n)
    lo = min(lo, max(n_in - 4, 0))
    hi = max(hi, min(n_in + 3, n))
    return lo, hi


#: `_advance_from` brings every deferred element to the current time and defers again from there
#: once the union of the trial windows since the deferral's origin (kept current, so updated by
#: every accepted substep) spans more than ``_DEFER_SPAN sqrt(N)`` elements: an edge racing
#: across T elements in S substeps then costs ~S (C/2) + N T / C element updates with C that
#: span, instead of ~S T / 2.
_DEFER_SPAN = 2.0


#: Touch times `_advance_from` may plan in one step (`_touch_time`) before it falls back to
#: halving the substep: each plan ends the step's search earlier by at least half a jump
#: substep, and one or two suffice unless the first touch hops between distant points.
_MAX_TOUCH_PLANS = 8


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _touch_gap(s, tau, dt, d0, d1, g_j, modes, rate):
    """``d - g - w`` at one fine point a time s after tau of a row out of contact, its memory
    ``w = sum_k modes[k] exp(-rate[k] s)`` (each Kelvin element creeps back freely)."""
    w = 0.0
    for k in range(rate.shape[0]):
        w += modes[k] * math.exp(-rate[k] * s)
    return d0 + (d1 - d0) * ((tau + s) / dt) - g_j - w


@numba.njit(cache=True, nogil=True, _nrt=False)
def _touch_time(j, tau, h, dt, d0, d1, wl, wb, dx, g_c, gf, df, rate, modes):
    """When, within ``[0, h]`` after tau, fine point j of a row out of contact (radius 0)
    reaches the indenter, s: the end of a bracket no wider than ``1e-3 JUMP_RESOLUTION dt``
    where the gap ``d - g - w`` (`_first_touch`'s test) changes sign.

    Out of contact every Kelvin element creeps back freely, and the whole row's memory at a
    point is linear in the element values (`_side_ab` between centres, held beyond the
    ends), so the memory at point j is a sum of one decaying exponential per mode, exact in
    closed form at any time: the touch is found without updating the row (O(K) per trial
    time instead of O(N K) plus a first-touch search). ``modes`` (K) is scratch. Returns 0 if
    the point touches at tau already, h if it does not touch by tau + h (rounding)."""
    n, k_count = wl.shape
    xj = j * df
    g_j = gf[j]
    g_x = _g_at(xj, gf, df)
    for k in range(k_count):
        a_k, b_k = _side_ab(xj, wl[:, k], wb[:, k], 0, n - 1, dx, g_c)
        modes[k] = a_k - g_x * b_k
    if _touch_gap(0.0, tau, dt, d0, d1, g_j, modes, rate) >= 0.0:
        return 0.0
    if _touch_gap(h, tau, dt, d0, d1, g_j, modes, rate) < 0.0:
        return h
    lo = 0.0
    hi = h
    tol = 1e-3 * JUMP_RESOLUTION * dt
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if hi - lo <= tol or mid <= lo or mid >= hi:
            break
        if _touch_gap(mid, tau, dt, d0, d1, g_j, modes, rate) >= 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@numba.njit(cache=True, nogil=True, _nrt=False)
def _touch_step(j, tau, h, h_min, dt, d0, d1, wl, wb, dx, g_c, gf, df, rate, coef):
    """The substep to try from tau after a trial of length h out of contact touched at fine
    point j (`_advance_from`): up to half a jump substep (``h_min``) before the point's touch
    time (`_touch_time`), so that the jump substep of length ``h_min`` that follows is
    centred on the touch; ``h_min`` itself (the jump substep) if the touch is that close.

    A trial that ends there is checked as any other: if another point touches earlier it is
    rejected and the touch is planned again from that point (each plan ends at least half a
    jump substep earlier); if it touches within the motion limit it is accepted in contact."""
    s = _touch_time(j, tau, h, dt, d0, d1, wl, wb, dx, g_c, gf, df, rate, coef[_C_Z])
    before = s - 0.5 * h_min
    if before <= 0.0:
        return h_min
    return before


@numba.njit(cache=True, nogil=True, _nrt=False)
def _defer_coefficients(lam, rate, t, coef):
    """The in-contact coefficients and free decays over the time t since the step's start into
    the deferred set of ``coef`` (rows ``_C_DEFER + _C_E`` ...), unless they hold those of t."""
    if coef[_C_DEFER_LEN, 0] == t:
        return
    _contact_coefficients(
        lam,
        t,
        coef[_C_DEFER + _C_E],
        coef[_C_DEFER + _C_PHI1],
        coef[_C_DEFER + _C_CHI],
        coef[_C_DEFER + _C_EE],
        coef[_C_DEFER + _C_EF],
        coef[_C_DEFER + _C_FF],
    )
    decay = coef[_C_DEFER + _C_DECAY]
    for k in range(rate.shape[0]):
        decay[k] = math.exp(-rate[k] * t)
    coef[_C_DEFER_LEN, 0] = t


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _g_between(j, gf, df, dx, n):
    """g at ``j dx`` (between elements j-1 and j) as `_deviation_integral` takes it."""
    m = gf.shape[0]
    per_cell = (m - 1) // n
    if per_cell * n == m - 1:
        return gf[per_cell * j]
    return _g_at(j * dx, gf, df)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _block_change(sign, lo, hi, wl, wb, g_c, gf, gint, df, dx, coef):
    """Add ``sign`` times the part of elements lo..hi-1 (interior, not the last three) in the
    deferred block's sums: ``coef[_C_AW, k] += sum wl[i, k]``, ``coef[_C_AB, k] += sum cb_i
    wb[i, k]``; returns the matching sums ``(sum g_i, sum cb_i, sum r_i)``.

    `_deviation_integral` is linear in (wsum, bsum): its part up to the centre of element L-1
    plus element L-1's share of the next Simpson piece is ``sum_{i<L} (dx wsum_i + cb_i
    bsum_i) - kap d (L - 1/2) dx + kap sum_{i<L} r_i`` with, per piece j (between elements
    j-1 and j, g_mid at j dx), ``q_j = dx (g_{j-1} + g_j - 2 g_mid) / 6`` and ``r_j = dx
    (g_{j-1} + g_j + 4 g_mid) / 6``: ``cb_i = q_i + q_{i+1}`` (``cb_0 = g_0 x0 - G(x0) +
    q_1``), ``r_0 = G(x0)`` (G: the profile's integral, x0 the first centre)."""
    n, k_count = wl.shape
    if hi <= lo:
        return 0.0, 0.0, 0.0
    m = gf.shape[0]
    per_cell = (m - 1) // n
    on_grid = per_cell * n == m - 1
    x0 = 0.5 * dx
    sum_g = 0.0
    sum_cb = 0.0
    sum_r = 0.0
    # g at the cell boundaries read once each; the sums in the modal scratch rows, then added.
    gm = 0.0
    if lo > 0:
        gm = gf[per_cell * lo] if on_grid else _g_at(lo * dx, gf, df)
    for k in range(k_count):
        coef[_C_Z, k] = 0.0
        coef[_C_ZB, k] = 0.0
    acc_w = 0.0
    acc_b = 0.0
    for i in range(lo, hi):
        gm_next = gf[per_cell * (i + 1)] if on_grid else _g_at((i + 1) * dx, gf, df)
        g_i = g_c[i]
        cb = dx * (g_i + g_c[i + 1] - 2.0 * gm_next) / 6.0
        if i == 0:
            g_x0 = _profile_integral(x0, gf, gint, df)
            cb += g_i * x0 - g_x0
            r = g_x0
        else:
            cb += dx * (g_c[i - 1] + g_i - 2.0 * gm) / 6.0
            r = dx * (g_c[i - 1] + g_i + 4.0 * gm) / 6.0
        gm = gm_next
        if k_count == 1:
            acc_w += wl[i, 0]
            acc_b += cb * wb[i, 0]
        else:
            for k in range(k_count):
                coef[_C_Z, k] += wl[i, k]
                coef[_C_ZB, k] += cb * wb[i, k]
        sum_g += g_i
        sum_cb += cb
        sum_r += r
    if k_count == 1:
        coef[_C_Z, 0] = acc_w
        coef[_C_ZB, 0] = acc_b
    for k in range(k_count):
        coef[_C_AW, k] += sign * coef[_C_Z, k]
        coef[_C_AB, k] += sign * coef[_C_ZB, k]
    return sign * sum_g, sign * sum_cb, sign * sum_r


@numba.njit(cache=True, nogil=True, _nrt=False)
def _block_deviation(block, d0, d, kap, dx, p, p_inv, beta, coef, sum_g, sum_cb, sum_r):
    """The deferred block's part of `_deviation_integral` (elements 0..block-1, see
    `_block_change`) at depth d, its elements still at the step's start (depth d0) and the
    deferred coefficients in ``coef`` those of the time since: per mode the block's sums
    evolve as its elements do, ``sum c_i z_i(t) = e sum c_i z_i(0) + beta (phi1 sum c_i
    u_i(0) + chi (d - d0) sum c_i)`` (the exact update for a depth linear in time), O(K^2)."""
    k_count = p.shape[0]
    weight = block * dx
    u_sum = d0 * weight - dx * sum_g
    total = 0.0
    for m in range(k_count):
        s_m = 0.0
        zw = 0.0
        zb = 0.0
        for k in range(k_count):
            s_m += p_inv[k, m]
            zw += p[m, k] * coef[_C_AW, k]
            zb += p[m, k] * coef[_C_AB, k]
        e = coef[_C_DEFER + _C_E, m]
        phi1 = coef[_C_DEFER + _C_PHI1, m]
        chi = coef[_C_DEFER + _C_CHI, m]
        wpart = e * dx * zw + beta[m] * (phi1 * u_sum + chi * (d - d0) * weight)
        bpart = e * zb + beta[m] * phi1 * sum_cb
        total += s_m * (wpart + bpart)
    return total - kap * d * (block - 0.5) * dx + kap * sum_r


@numba.njit(cache=True, nogil=True, _nrt=False)
def _deviation_after(a, d, wsum, bsum, n_in, block, dx, g_c, gf, gint, df, kap, wb, p, p_inv, lam, beta):
    """`_deviation_integral` less the deferred block's part (`_block_change`, elements
    0..block-1, 1 <= block <= n_in - 4): element ``block``'s share of the Simpson piece
    before it, the pieces after it and the extrapolated piece up to the edge."""
    n = wsum.shape[0]
    m = gf.shape[0]
    if gint.shape[0] == m + 3 * n + 2:
        # The sum form with the row's force weights (`_deviation_integral`).
        cb = gint[m : m + n]
        q_last = gint[m + n + n_in]
        eo = m + 2 * n + 1
        sum_f, sum_b = _weighted_sums(block, n_in, wsum, bsum, g_c, cb, kap, kap * d)
        last = n_in - 1
        total = dx * sum_f - 0.5 * dx * wsum[last] + (sum_b - q_last * bsum[last])
        total += kap * (gint[eo + n_in] - gint[eo + block])
        return total + _edge_piece(a, d, wsum, bsum, n_in, dx, g_c, gf, df, kap, wb, p, p_inv, lam, beta)
    gm = _g_between(block, gf, df, dx, n)
    g_prev = g_c[block - 1]
    g_b = g_c[block]
    total = 0.5 * dx * wsum[block] + dx * (g_prev + g_b - 2.0 * gm) / 6.0 * bsum[block]
    total += -kap * d * dx + kap * dx * (g_prev + g_b + 4.0 * gm) / 6.0
    m = gf.shape[0]
    per_cell = (m - 1) // n
    on_grid = per_cell * n == m - 1
    f_prev = wsum[block] - kap * (d - g_c[block])
    for i in range(block + 1, n_in):
        f_i = wsum[i] - kap * (d - g_c[i])
        b_mid = 0.5 * (bsum[i - 1] + bsum[i])
        a_mid = 0.5 * (wsum[i - 1] + wsum[i]) + 0.5 * (g_c[i - 1] + g_c[i]) * b_mid
        g_mid = gf[per_cell * i] if on_grid else _g_at(i * dx, gf, df)
        f_mid = (a_mid - kap * d) - g_mid * (b_mid - kap)
        total += dx * (f_prev + 4.0 * f_mid + f_i) / 6.0
        f_prev = f_i
    return total + _edge_piece(a, d, wsum, bsum, n_in, dx, g_c, gf, df, kap, wb, p, p_inv, lam, beta)


@numba.njit(cache=True, nogil=True, _nrt=False)
def _catch_up(
    wl, wsum, wb, bsum, coef, lo, hi, n_in0, d0, d_now, slope, g_c, p, p_inv, lam, beta, e_kelvin, dx
):
    """Bring deferred elements lo..hi-1 (at the step's start) to the current time in one exact
    update over the time since (the deferred coefficients in ``coef``): in contact (i < n_in0)
    from depth d0 to d_now, else creeping back. Returns the energy they dissipated, J: the
    damper work over the union of substeps is the sum of the substeps' (the same integral)."""
    lost = 0.0
    for i in range(lo, hi):
        if i < n_in0:
            work = _chain_in_contact(
                wl,
                wsum,
                wb,
                bsum,
                i,
                d0 - g_c[i],
                d_now - g_c[i],
                slope,
                p,
                p_inv,
                lam,
                beta,
                coef[_C_DEFER + _C_E],
                coef[_C_DEFER + _C_PHI1],
                coef[_C_DEFER + _C_CHI],
                coef[_C_DEFER + _C_EE],
                coef[_C_DEFER + _C_EF],
                coef[_C_DEFER + _C_FF],
                coef[_C_Z],
                coef[_C_ZB],
            )
            lost += 2.0 * dx * work
        else:
            lost += dx * _chain_free(wl, wsum, wb, bsum, i, coef[_C_DEFER + _C_DECAY], e_kelvin)
    return lost


@numba.njit(cache=True, nogil=True, _nrt=False)
def _advance(
    wl,
    wsum,
    wb,
    bsum,
    scratch,
    scratch_b,
    diss,
    coef,
    dx,
    g_c,
    gf,
    gint,
    gmin,
    gmax,
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
    of them, down to ``JUMP_RESOLUTION dt``: a true jump (snap-in, the fold at pull-off) is thereby
    located in time and crossed in one tiny substep that does no work. Out of contact a
    rejected trial is not halved: the touch time of the point that touched is found in closed
    form (`_touch_step`), one substep ends half a jump substep before it and the jump substep
    of ``JUMP_RESOLUTION dt`` crosses it. Writes radius,
    force, work input, last motion, substep count, the energy dissipated over the step
    (>= 0), the largest |wsum|, the edge gaps and g at the edge to ``out``. Returns
    STATUS_GROW (state partly advanced: the caller restores) when the contact needs a larger
    domain.
    """
    force_prev = _force(a, d0, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, diss, wb, p, p_inv, lam, beta)
    return _advance_from(
        wl,
        wsum,
        wb,
        bsum,
        scratch,
        scratch_b,
        diss,
        coef,
        dx,
        g_c,
        gf,
        gint,
        gmin,
        gmax,
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
        out,
        a,
        d0,
        d1,
        dt,
        max_substep,
        max_edge_move,
        force_prev,
        wl[:0],
        wb[:0],
    )


@numba.njit(cache=True, nogil=True, _nrt=False)
def _advance_from(
    wl,
    wsum,
    wb,
    bsum,
    scratch,
    scratch_b,
    diss,
    coef,
    dx,
    g_c,
    gf,
    gint,
    gmin,
    gmax,
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
    out,
    a,
    d0,
    d1,
    dt,
    max_substep,
    max_edge_move,
    force_prev,
    backup,
    backup_b,
):
    """`_advance` given the force at the step's start, ``force_prev`` (N: `_force` at (a, d0)
    on the current memory; `_advance_rows` has it from the row before).

    ``backup``/``backup_b``: (N, K) scratch to restore the memory from on STATUS_GROW, or
    empty ((0, K): the caller restores from its own journal; the memory is then left partly
    advanced). With them a STATUS_GROW returns the memory as it was at the step's start:
    the memory is copied only when a step takes more than one substep (0.6.0; before its
    first accepted substep only the trial window has changed, which ``scratch`` holds, and
    after a step's last substep nothing asks to grow), not once per row by the caller.

    A substep trial with the motion limit (in contact) journals and updates only the window
    of elements the limited edge search reads (`_trial_window`): a rejected trial restores
    that window and costs O(window), not O(N). An accepted one updates the other elements
    with the same coefficients (element by element the same arithmetic as one pass over the
    row) and sums their losses and the memory peak on the way, in index order. Without the
    limit (no contact: the first-touch search reads the whole row; or the shortest substep)
    the trial updates every element.

    When the step takes several substeps (an edge racing across many elements, one substep
    per element crossed), the elements no trial window has reached keep their contact status
    over the whole step, and for them one exact update over the union of the substeps is the
    same as one per substep (the depth is linear over the whole step; the damper work over the
    union is the sum of the substeps'; the free creep-back telescopes): so an accepted substep
    updates only the union of the windows so far ([t_lo, t_hi), contiguous), an element the
    windows reach is first brought to the current time in one update (`_catch_up`), and the
    rest are updated once at the step's end. The force at an intermediate substep takes the
    deferred interior block's part of the deviation integral from per-mode sums of its
    step-start state (`_block_change`, `_block_deviation`: O(K^2)) and the rest from the
    elements (`_deviation_after`). A step in one substep runs the arithmetic of one pass over
    the row, bit for bit; several substeps give the same outputs to rounding (~1e-13 relative,
    tests/test_deferred_substeps.py against the whole-row-per-substep reference).

    The deferral's origin is the step's start, or the end of the last accepted substep that
    left every element current (one that updated the whole row: out of contact, where the
    first-touch search reads every element, or the jump substep of a snap-in or a fold): from
    there the deferred elements keep their contact status, so the same exact update over the
    time since that origin holds. Without it a snap-in from no contact, whose first trials
    cover the whole row, updated every element in every later substep of its step (the edge
    racing on after the jump: ~N/16 substeps at N elements, O(N) each; issue 13, 0.6.0).
    """
    row = (
        wl,
        wsum,
        wb,
        bsum,
        scratch,
        scratch_b,
        diss,
        coef,
        dx,
        g_c,
        gf,
        gint,
        gmin,
        gmax,
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
        out,
    )
    return _advance_body(row, a, d0, d1, dt, max_substep, max_edge_move, force_prev, backup, backup_b)


# Inlined (numba's IR inlining) into `_advance_from` and into `_advance_rows`'s row loop: called,
# each row passed the kernel's 26 arrays and scalars (7-9 words an array, ~180 words on the
# stack) and the callee spilled and reloaded them, ~550 instructions of a K = 0 row of ~3000
# (0.11.0 `rest`). Its arguments as one tuple: CPython compiles a call of more than 30
# arguments as ``f(*args)``, which numba's inliner does not take.
@numba.njit(nogil=True, _nrt=False, inline="always")
def _advance_body(row, a, d0, d1, dt, max_substep, max_edge_move, force_prev, backup, backup_b):
    """`_advance_from`'s body; ``row``: its first 26 arguments (`Row.kernel_args`)."""
    (
        wl,
        wsum,
        wb,
        bsum,
        scratch,
        scratch_b,
        diss,
        coef,
        dx,
        g_c,
        gf,
        gint,
        gmin,
        gmax,
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
        out,
    ) = row
    n, k_count = wl.shape
    keep = backup.shape[0] == n
    h_min = dt * JUMP_RESOLUTION
    step = dt if max_substep <= 0.0 or max_substep > dt else max_substep
    tau = 0.0
    work = 0.0
    lost = 0.0
    motion = MOTION_NONE
    substeps = 0
    attempts = 0
    jumped_before = False
    # Written in the substep that lets go (no loop-carried variable in the substep loop).
    out[OUT_LET_GO] = math.nan
    # Touch times planned this step (`_touch_time`), whether the substep being tried ends
    # just before a planned touch (then the jump substep follows) and whether it is the jump
    # substep that crosses one.
    plans = 0
    jump_next = False
    crossing = False
    # Largest |wsum| after the last accepted substep (summed with its update; K = 0: no memory).
    peak = 0.0
    if dt <= 0.0 and d1 == d0 and (a > 0.0 or _memory_peak(wsum) > 0.0):
        # A repeated sample (no time, the same depth) of a contact with a history is the
        # state as it is: nothing moves. The unlimited edge search below could move an edge
        # that the timed step left on its detachment root (the elements it just released sit
        # at their attachment threshold) and publish another force for the same instant and
        # depth (an outside tester, 0.10.0: a log with every message recorded twice replayed
        # to a pull-off 0.8 % deeper). Without contact or memory the search stays: a contact
        # at rest commanded to its own depth (0 after a reset) snaps in there
        # (docs/ros_interface.md).
        force_same = force_prev if force_prev == force_prev else _force(
            a, d1, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, diss, wb, p, p_inv, lam, beta
        )
        out[OUT_RADIUS] = a
        out[OUT_FORCE] = force_same
        out[OUT_WORK] = 0.0
        out[OUT_MOTION] = MOTION_NONE
        out[OUT_SUBSTEPS] = 0
        out[OUT_DISSIPATED] = 0.0
        out[OUT_MEMORY] = _memory_peak(wsum)
        _edge_outputs(a, d1, wsum, bsum, dx, g_c, gf, df, c_crit, out)
        return STATUS_OK
    if dt <= 0.0:
        new_a, motion, grow = _locate_edge(
            a, d1, wsum, bsum, dx, g_c, gf, gmin, gmax, df, c_crit, reach, math.inf
        )
        if grow:
            return STATUS_GROW
        # The elements that switch at a jump in depth switch at the new depth (from the state
        # journalled here: only the crossed elements are read back).
        n0 = _interior_count(a, dx, n)
        n1 = _interior_count(new_a, dx, n)
        _copy_range(wl, wb, scratch, scratch_b, min(n0, n1), max(n0, n1))
        hysteresis = 0.0
        if n1 != n0:  # (else `_retime_crossed` returns 0, as in the substep loop)
            hysteresis = _retime_crossed(
                wl,
                wsum,
                wb,
                bsum,
                scratch,
                scratch_b,
                diss,
                coef,
                a,
                new_a,
                d1,
                d1,
                0.0,
                dx,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                rate,
                e_kelvin,
                e0,
                c_crit,
                gf,
                df,
            )
        force_new = _force(
            new_a, d1, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, diss, wb, p, p_inv, lam, beta
        )
        out[OUT_RADIUS] = new_a
        out[OUT_FORCE] = force_new
        out[OUT_WORK] = 0.5 * (force_prev + force_new) * (d1 - d0)
        out[OUT_MOTION] = motion
        out[OUT_SUBSTEPS] = 0
        out[OUT_DISSIPATED] = max(hysteresis, 0.0)
        out[OUT_MEMORY] = _memory_peak(wsum)
        out[OUT_LET_GO] = d1 if new_a <= 0.0 < a else math.nan
        _edge_outputs(new_a, d1, wsum, bsum, dx, g_c, gf, df, c_crit, out)
        return STATUS_OK
    # Deferred elements (`_advance_from`'s docstring): [t_lo, t_hi) is the union of the trial
    # windows so far, kept current; the elements outside it are still at the step's start.
    # They are at the deferral's origin: the step's start (time 0, depth d0, n_in0 elements in
    # contact), moved to the end of any accepted substep that leaves every element current
    # (`t0`, `d_org`): the substeps out of contact before a snap-in and its jump substep
    # update the whole row, and the edge that races on after the jump is deferred from there.
    n_in0 = _interior_count(a, dx, n)
    step_slope = (d1 - d0) / dt
    t0 = 0.0
    d_org = d0
    t_lo = n
    t_hi = 0
    coef[_C_DEFER_LEN, 0] = math.nan
    # The deferred interior block [0, block)'s sums (`_block_change`), once a force needs them.
    block = -1
    sum_g = 0.0
    sum_cb = 0.0
    sum_r = 0.0
    while tau < dt:
        h = step
        last = tau + h >= dt * (1.0 - 1e-12)
        if last:
            h = dt - tau
        da = d0 + (d1 - d0) * (tau / dt)
        db = d1 if last else d0 + (d1 - d0) * ((tau + h) / dt)
        n_in = _interior_count(a, dx, n)
        limited = h > h_min and attempts + 1 < _MAX_ATTEMPTS + _ATTEMPTS_PER_ELEMENT * n
        lo, hi = 0, n
        slope = (db - da) / h
        if k_count:
            if limited and a > 0.0:
                lo, hi = _trial_window(a, n_in, n, dx, df, max_edge_move)
            if tau > t0 and (lo < t_lo or hi > t_hi):
                # The window reaches deferred elements: bring them to the current time first
                # (out of the block's sums, which hold their state at the step's start).
                _defer_coefficients(lam, rate, tau - t0, coef)
                if lo < t_lo:
                    if block > lo:
                        dg, dcb, dr = _block_change(-1.0, lo, block, wl, wb, g_c, gf, gint, df, dx, coef)
                        sum_g += dg
                        sum_cb += dcb
                        sum_r += dr
                        block = lo
                    lost += _catch_up(
                        wl,
                        wsum,
                        wb,
                        bsum,
                        coef,
                        lo,
                        t_lo,
                        n_in0,
                        d_org,
                        da,
                        step_slope,
                        g_c,
                        p,
                        p_inv,
                        lam,
                        beta,
                        e_kelvin,
                        dx,
                    )
                if hi > t_hi:
                    lost += _catch_up(
                        wl,
                        wsum,
                        wb,
                        bsum,
                        coef,
                        t_hi,
                        hi,
                        n_in0,
                        d_org,
                        da,
                        step_slope,
                        g_c,
                        p,
                        p_inv,
                        lam,
                        beta,
                        e_kelvin,
                        dx,
                    )
            t_lo = min(t_lo, lo)
            t_hi = max(t_hi, hi)
            _substep_coefficients(lam, rate, h, coef)
            _copy_range(wl, wb, scratch, scratch_b, lo, hi)
            _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                lo,
                hi,
                n_in,
                da,
                db,
                slope,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                coef,
                e_kelvin,
                dx,
                0.0,
                0.0,
            )
        new_a, sub_motion, grow = _locate_edge(
            a,
            db,
            wsum,
            bsum,
            dx,
            g_c,
            gf,
            gmin,
            gmax,
            df,
            c_crit,
            reach,
            max_edge_move if limited else math.inf,
        )
        if grow:
            if keep and k_count:
                if substeps == 0:
                    # Nothing accepted yet: only the trial window changed.
                    _restore_range(wl, wsum, wb, bsum, scratch, scratch_b, lo, hi)
                else:
                    _restore_state(wl, wsum, wb, bsum, backup, backup_b)
            return STATUS_GROW
        attempts += 1
        if limited and (abs(new_a - a) > max_edge_move or (new_a <= 0.0 < a)):
            # Out of contact a rejected trial found the first touch (a snap-in): locate it
            # in time directly instead of halving ~14 times, each a whole-row trial.
            j_touch = -1
            if a <= 0.0 and plans < _MAX_TOUCH_PLANS:
                j_touch = _first_touch(db, wsum, bsum, dx, g_c, gf, gmin, gmax, df, reach)
            if k_count:
                _restore_range(wl, wsum, wb, bsum, scratch, scratch_b, lo, hi)
            step = 0.5 * h
            jump_next = False
            crossing = False
            if j_touch >= 0:
                plans += 1
                step = _touch_step(j_touch, tau, h, h_min, dt, d0, d1, wl, wb, dx, g_c, gf, df, rate, coef)
                jump_next = step > h_min
                crossing = not jump_next
            continue
        # Accepted. The whole step in one substep: the elements before the window (in index
        # order: their losses first) ... Else the current elements outside the window.
        whole = tau == 0.0 and last
        if keep and k_count and substeps == 0 and not whole:
            # The first of several substeps: the memory at the step's start, for a later
            # STATUS_GROW (the window's from the trial journal).
            _copy_state(wl, wb, backup, backup_b)
            _copy_range(scratch, scratch_b, backup, backup_b, lo, hi)
        viscous = 0.0
        if k_count:
            viscous, peak = _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                0 if whole else t_lo,
                lo,
                n_in,
                da,
                db,
                slope,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                coef,
                e_kelvin,
                dx,
                0.0,
                0.0,
                False,
            )
        # `_retime_crossed` returns 0 and changes nothing when the edge crossed no element
        # centre: not called then (its 25 arguments cost ~280 instructions of a row, 0.11.0).
        hysteresis = 0.0
        if _interior_count(new_a, dx, n) != n_in:
            hysteresis = _retime_crossed(
                wl,
                wsum,
                wb,
                bsum,
                scratch,
                scratch_b,
                diss,
                coef,
                a,
                new_a,
                da,
                db,
                h,
                dx,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                rate,
                e_kelvin,
                e0,
                c_crit,
                gf,
                df,
            )
        if k_count:
            # ... the window (retimed where the edge crossed), then the elements after it.
            for i in range(_u(lo), _u(hi)):
                viscous += diss[i]
                peak = max(peak, abs(wsum[i]))
            viscous, peak = _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                hi,
                n if whole else t_hi,
                n_in,
                da,
                db,
                slope,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                coef,
                e_kelvin,
                dx,
                viscous,
                peak,
                False,
            )
            if last and not whole and (t_lo > 0 or t_hi < n):
                # The deferred elements in one update over the whole step (exact for a depth
                # linear in time: the same as one per substep, to rounding).
                _substep_coefficients(lam, rate, dt - t0, coef)
                viscous, peak = _update_range(
                    wl,
                    wsum,
                    wb,
                    bsum,
                    diss,
                    0,
                    t_lo,
                    n_in0,
                    d_org,
                    d1,
                    step_slope,
                    g_c,
                    p,
                    p_inv,
                    lam,
                    beta,
                    coef,
                    e_kelvin,
                    dx,
                    viscous,
                    peak,
                    False,
                )
                viscous, peak = _update_range(
                    wl,
                    wsum,
                    wb,
                    bsum,
                    diss,
                    t_hi,
                    n,
                    n_in0,
                    d_org,
                    d1,
                    step_slope,
                    g_c,
                    p,
                    p_inv,
                    lam,
                    beta,
                    coef,
                    e_kelvin,
                    dx,
                    viscous,
                    peak,
                    False,
                )
            if last:
                t_lo = 0
                t_hi = n
        lost += viscous + _adhesion_loss(hysteresis, a, new_a, max_edge_move)
        n_new = _interior_count(new_a, dx, n)
        if k_count and kap != 0.0 and t_lo > 0 and n_new > 0:
            # The force with the deferred block [0, t_lo) still at the step's start: its part
            # of the deviation integral from its sums in O(K^2), the rest from the elements.
            if n_new - 4 < t_lo:
                # (Not reached while the windows reach 4 elements inside the edge.)
                _defer_coefficients(lam, rate, tau + h - t0, coef)
                cut = max(n_new - 4, 0)
                if block > cut:
                    dg, dcb, dr = _block_change(-1.0, cut, block, wl, wb, g_c, gf, gint, df, dx, coef)
                    sum_g += dg
                    sum_cb += dcb
                    sum_r += dr
                    block = cut
                lost += _catch_up(
                    wl,
                    wsum,
                    wb,
                    bsum,
                    coef,
                    cut,
                    t_lo,
                    n_in0,
                    d_org,
                    db,
                    step_slope,
                    g_c,
                    p,
                    p_inv,
                    lam,
                    beta,
                    e_kelvin,
                    dx,
                )
                t_lo = cut
        if k_count and kap != 0.0 and t_lo > 0 and n_new > 0:
            if block < 0:
                coef[_C_AW, :] = 0.0
                coef[_C_AB, :] = 0.0
                dg, dcb, dr = _block_change(1.0, 0, t_lo, wl, wb, g_c, gf, gint, df, dx, coef)
                sum_g, sum_cb, sum_r = dg, dcb, dr
                block = t_lo
            _defer_coefficients(lam, rate, tau + h - t0, coef)
            dev = _block_deviation(block, d_org, db, kap, dx, p, p_inv, beta, coef, sum_g, sum_cb, sum_r)
            dev += _deviation_after(
                new_a, db, wsum, bsum, n_new, block, dx, g_c, gf, gint, df, kap, wb, p, p_inv, lam, beta
            )
            u_int = db * new_a - _profile_integral(new_a, gf, gint, df)
            force_new = 2.0 * e0 * ((1.0 - kap) * u_int - dev)
        else:
            force_new = _force(
                new_a, db, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, diss, wb, p, p_inv, lam, beta
            )
        work += 0.5 * (force_prev + force_new) * (db - da)
        force_prev = force_new
        if sub_motion != MOTION_NONE:
            motion = sub_motion
        jumped = abs(new_a - a) > max_edge_move
        if new_a <= 0.0 < a:
            out[OUT_LET_GO] = db
        a = new_a
        tau += h
        substeps += 1
        if k_count and not last and t_hi - t_lo > _DEFER_SPAN * math.sqrt(n) and (t_lo > 0 or t_hi < n):
            # The union of the windows has grown long (an edge racing far): every accepted
            # substep updates all of it. Bring the deferred elements to now (one pass over
            # the row) and defer again from here (`_DEFER_SPAN`).
            _substep_coefficients(lam, rate, tau - t0, coef)
            viscous = 0.0
            viscous, _ = _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                0,
                t_lo,
                n_in0,
                d_org,
                db,
                step_slope,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                coef,
                e_kelvin,
                dx,
                viscous,
                0.0,
                False,
            )
            viscous, _ = _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                t_hi,
                n,
                n_in0,
                d_org,
                db,
                step_slope,
                g_c,
                p,
                p_inv,
                lam,
                beta,
                coef,
                e_kelvin,
                dx,
                viscous,
                0.0,
                False,
            )
            lost += viscous
            t_lo = 0
            t_hi = n
        if k_count and t_lo == 0 and t_hi == n and not last:
            # Every element is current (a whole-row substep: out of contact, or the jump
            # substep): the deferral starts again from here.
            t0 = tau
            d_org = db
            n_in0 = n_new
            t_lo = n
            t_hi = 0
            block = -1
        # After an isolated jump (a substep at the shortest length that still moved the edge
        # more than the limit: snap-in or the fold) try the whole rest of the step at once
        # instead of doubling back up from the jump's substep (about 13 more substeps); the
        # halving catches an edge that keeps moving fast. An edge that jumps again right
        # after (racing across many cells) doubles back up as before: restarting from the
        # whole rest after every such substep would halve all the way down each time.
        step = dt if jumped and not jumped_before else 2.0 * h
        if crossing:
            # The planned jump substep crossed the touch: the rest of the step at once, as
            # after any jump, also where the contact then grows without jumping (a touch
            # without adhesion), rather than doubling up from the jump substep.
            step = dt
        crossing = jump_next and a <= 0.0
        if crossing:
            # The substep ended just before a planned touch: the jump substep crosses it.
            step = h_min
        jump_next = False
        jumped_before = jumped
        if max_substep > 0.0 and step > max_substep:
            step = max_substep
    out[OUT_RADIUS] = a
    out[OUT_FORCE] = force_prev
    out[OUT_WORK] = work
    out[OUT_MOTION] = motion
    out[OUT_SUBSTEPS] = substeps
    out[OUT_DISSIPATED] = lost
    # K = 0: no Kelvin element, no memory (wsum stays 0: every write of it is a sum over no
    # modes), so no O(N) scan for its peak (it was more than half of a K = 0 row at N = 4096).
    out[OUT_MEMORY] = peak if k_count else 0.0
    _edge_outputs(a, d1, wsum, bsum, dx, g_c, gf, df, c_crit, out)
    return STATUS_OK


@numba.njit(cache=True, nogil=True, _nrt=False)
def _advance_rows(
    wl,
    wsum,
    wb,
    bsum,
    scratch,
    scratch_b,
    diss,
    coef,
    dx,
    g_c,
    gf,
    gint,
    gmin,
    gmax,
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
    out,
    backup,
    backup_b,
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

    Arguments: `Row.kernel_args`, ``backup``/``backup_b`` (N, K) scratch for the memory
    before a row, the state before row ``first`` (radius a, time, depth, largest |wsum|
    ``peak``), the history ``times``/``depths`` (n,), the step's limits as `_advance` takes
    them and ``idle_limit`` (m): a contact out of contact whose memory peak is within it is
    idle. Row i of ``rows`` (n, ROW_SIZE) gets the ``out`` slots and the edge gaps with the
    exterior and the interior memory at the new radius (`criterion_gap`).

    Returns ``(i, status)``: all rows done (``i = n``, STATUS_OK), or stopped before row i
    with STATUS_IDLE (idle above the surface: the caller drops the memory, as
    ContactSimulator does) or STATUS_GROW (memory restored: the caller grows the domain and
    calls again from row i).

    A row starts from the force the row before ended with (the same memory, radius and
    depth: `_force` would return the same number).
    """
    force_prev = _force(a, d_prev, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, diss, wb, p, p_inv, lam, beta)
    for i in range(first, times.shape[0]):
        d1 = depths[i]
        if a <= 0.0 and peak <= idle_limit and d1 < 0.0 and d_prev < 0.0:
            return i, STATUS_IDLE
        status = _advance_body(
            (
                wl,
                wsum,
                wb,
                bsum,
                scratch,
                scratch_b,
                diss,
                coef,
                dx,
                g_c,
                gf,
                gint,
                gmin,
                gmax,
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
                out,
            ),
            a,
            d_prev,
            d1,
            times[i] - t_prev,
            max_substep,
            max_edge_move,
            force_prev,
            backup,
            backup_b,
        )
        if status != STATUS_OK:
            # `_advance_from` restored the memory (it copies it only for a row of several
            # substeps); the sums from it, as a restore from a whole copy gave them.
            _restore_state(wl, wsum, wb, bsum, wl, wb)
            return i, status
        a = out[OUT_RADIUS]
        peak = out[OUT_MEMORY]
        force_prev = out[OUT_FORCE]
        for k in range(OUT_SIZE):
            rows[i, k] = out[k]
        t_prev = times[i]
        d_prev = d1
    return times.shape[0], STATUS_OK


@numba.njit(cache=True, nogil=True, _nrt=False)
def _remap(wl, wb, a, dx, g_c, new_dx, new_gc, out, out_b):
    """Kelvin state of a regridded row (element width new_dx, profile new_gc at its
    centres) into ``out``/``out_b`` (N', K).

    Each new centre takes A and B of its own side of the edge, interpolated exactly as the
    force and criterion see them (`_side_ab`): interpolating across the edge would smear
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
                out_b[i, k] = 0.0
            else:
                a_x, b_x = _side_ab(x, wl[:, k], wb[:, k], lo, hi, dx, g_c)
                out_b[i, k] = b_x
                out[i, k] = a_x - new_gc[i] * b_x


@numba.njit(cache=True, nogil=True, _nrt=False)
def _energy_density(x, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin):
    """Spring energy per unit length at x, J/m: E0* l0^2 + sum_k E_k* l_k^2 (both half-rows),
    each ``l_k = A_k - g B_k`` interpolated on its side of the edge like the memory."""
    n = wl.shape[0]
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    g = _g_at(x, gf, df)
    total = 0.0
    lsum = 0.0
    for k in range(wl.shape[1]):
        a_x, b_x = _side_ab(x, wl[:, k], wb[:, k], lo, hi, dx, g_c)
        lk = a_x - g * b_x
        lsum += lk
        total += e_kelvin[k] * lk * lk
    if interior:
        l0 = d - g - lsum
        total += e0 * l0 * l0
    return total


@numba.njit(cache=True, nogil=True, _nrt=False)
def _side_energy(x0, x1, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin):
    """Integral of `_energy_density` over (x0, x1) on one side of the edge, J: composite
    Simpson (two panels) on each piece between element centres, where A and B are linear."""
    n = wl.shape[0]
    total = 0.0
    prev = x0
    e_prev = _energy_density(prev, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
    for i in range(n + 1):
        xi = (i + 0.5) * dx if i < n else x1
        if xi <= x0:
            continue
        if xi > x1:
            xi = x1
        q1 = prev + 0.25 * (xi - prev)
        q2 = prev + 0.5 * (xi - prev)
        q3 = prev + 0.75 * (xi - prev)
        e1 = _energy_density(q1, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
        e2 = _energy_density(q2, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
        e3 = _energy_density(q3, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
        e_i = _energy_density(xi, d, interior, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
        total += (xi - prev) * (e_prev + 4.0 * e1 + 2.0 * e2 + 4.0 * e3 + e_i) / 12.0
        prev, e_prev = xi, e_i
        if xi >= x1:
            break
    return total


@numba.njit(cache=True, nogil=True, _nrt=False)
def _memory_peak(wsum):
    """Largest |wsum|, m: whether any memory is left (the simulator's idle test). In four
    lanes over unsigned indices (0.6.0): one chain of maxima waited for the one before, about
    0.6 ns per element, more than half of a K = 0 row at N = 4096 (every K = 0 step ends
    here); the largest value is the same in any order."""
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    p3 = 0.0
    one = _u(1)
    four = _u(4)
    end = _u(wsum.shape[0])
    i = _u(0)
    while i + four <= end:
        p0 = max(p0, abs(wsum[i]))
        p1 = max(p1, abs(wsum[i + one]))
        p2 = max(p2, abs(wsum[i + _u(2)]))
        p3 = max(p3, abs(wsum[i + _u(3)]))
        i += four
    while i < end:
        p0 = max(p0, abs(wsum[i]))
        i += one
    return max(max(p0, p1), max(p2, p3))


@numba.njit(cache=True, nogil=True, _nrt=False)
def _stored_energy(a, d, wl, wb, dx, g_c, gf, df, e0, e_kelvin):
    """Elastic energy in all springs of both half-rows, J: the integral of
    `_energy_density` over the contact (interior memory) and over (a, L) (exterior).
    A diagnostic (computed on demand): the dissipation is a running sum of its own."""
    n = wl.shape[0]
    n_in = _interior_count(a, dx, n)
    total = 0.0
    if a > 0.0:
        total += _side_energy(0.0, a, d, True, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
    length = n * dx
    if wl.shape[1] > 0 and a < length:
        total += _side_energy(a, length, d, False, n_in, wl, wb, dx, g_c, gf, df, e0, e_kelvin)
    return total


@numba.njit(cache=True, nogil=True, _nrt=False)
def _block_extremes(gf, gmin, gmax):
    """Least and largest of each block of `TOUCH_BLOCK` points of ``gf`` (finite) into
    ``gmin``/``gmax``: ``np.minimum.reduceat`` / ``np.maximum.reduceat`` over the block starts
    (the extremes of finite values are exact; test_row_regrid pins them equal)."""
    m = gf.shape[0]
    for b in range(gmin.shape[0]):
        j0 = b * TOUCH_BLOCK
        j1 = min(j0 + TOUCH_BLOCK, m)
        least = gf[j0]
        most = gf[j0]
        for j in range(j0 + 1, j1):
            v = gf[j]
            least = min(least, v)
            most = max(most, v)
        gmin[b] = least
        gmax[b] = most


#: The arrays `Row.regrid` checks, in `_fill_regrid`'s order.
_REGRID_ARRAYS = ("g_c", "gf", "gint", "wl", "wb")


@numba.njit(cache=True, nogil=True, _nrt=False)
def _fill_regrid(const, state, chain_from, g_c, gf, gint, wl, wb, dx, df, e0, c_crit, reach, kap, in_place):
    """`Row.regrid`'s buffers: ``const`` (header, geometry, block extremes, the chain copied
    from the end of ``chain_from``) and ``state`` (zeros on entry: the memory, the coefficient
    workspace holding no substep) in the order of `_const_layout` and `_state_layout`, the
    memory's sums for K <= 1 (K > 1: the caller sums with numpy). ``in_place``: ``gf`` and
    ``gint`` are ``const``'s own slots, already checked finite: neither checked nor copied.
    Returns the index in `_REGRID_ARRAYS` of the first array that is not finite (buffers
    partly written), else -1."""
    if not _all_finite(g_c):
        return 0
    if not in_place:
        for index, values in enumerate((gf, gint)):
            if not _all_finite(values):
                return index + 1
    if not _all_finite(wl.reshape(wl.size)):
        return 3
    if not _all_finite(wb.reshape(wb.size)):
        return 4
    n, k = wl.shape
    m = gf.shape[0]
    blocks = (m + TOUCH_BLOCK - 1) // TOUCH_BLOCK
    const[0] = n
    const[1] = k
    const[2] = m
    const[3] = blocks
    const[4] = dx
    const[5] = df
    const[6] = e0
    const[7] = c_crit
    const[8] = reach
    const[9] = kap
    # Element by element (a slice assignment may copy through a temporary: the runtime).
    at = PACK_HEADER
    for i in range(n):
        const[at + i] = g_c[i]
    at += n
    if not in_place:
        for j in range(m):
            const[at + j] = gf[j]
        for j in range(m):
            const[at + m + j] = gint[j]
    at += 2 * m
    weights = 3 * n + 2
    _fill_force_weights(const[PACK_HEADER : PACK_HEADER + n], gf, gint, df, dx, const[at : at + weights])
    at += weights
    _block_extremes(gf, const[at : at + blocks], const[at + blocks : at + 2 * blocks])
    at += 2 * blocks
    chain = 2 * k * k + 4 * k
    first = chain_from.shape[0] - chain
    for j in range(chain):
        const[at + j] = chain_from[first + j]
    # state: wl, wsum, wb, bsum, scratch, scratch_b, diss, out, txn, txn_b, coef (K = 1: wl,
    # wb, scratch, ...: wsum and bsum are wl and wb, `_state_layout`)
    size = n * k
    if k == 1:
        # numpy's wl.sum(axis=1) over one column: 0.0 + w (a -0.0 becomes +0.0); the slot
        # holds the sum's value.
        for i in range(n):
            total = 0.0
            total += wl[i, 0]
            state[i] = total
            total_b = 0.0
            total_b += wb[i, 0]
            state[n + i] = total_b
    else:
        at = size + n
        for i in range(n):
            for kk in range(k):
                state[i * k + kk] = wl[i, kk]
                state[at + i * k + kk] = wb[i, kk]
    coef_at = state.shape[0] - COEF_ROWS * max(k, 1)
    _clear_coefficients(state[coef_at:].reshape((COEF_ROWS, max(k, 1))))
    return -1


# ----------------------------------------------------------------------------------------
# Public wrappers: validate, then call the compiled kernel.


@numba.njit(cache=True, nogil=True, _nrt=False)
def _all_finite(values):
    """True if every entry of the 1-D array is finite (stops at the first that is not)."""
    for i in range(values.shape[0]):
        if not math.isfinite(values[i]):
            return False
    return True


def _check(name: str, array: np.ndarray, shape: tuple[int, ...]) -> None:
    if not isinstance(array, np.ndarray) or array.dtype != np.float64:
        raise TypeError(f"{name} must be a float64 numpy array")
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape} (got {array.shape})")
    # Compiled on the flat view of a C-contiguous array (one signature, warmed up): ~0.3 us
    # against numpy's ~3 us per array, a dozen arrays per row a domain growth builds.
    finite = _all_finite(array.reshape(-1)) if array.flags.c_contiguous else np.all(np.isfinite(array))
    if not finite:
        raise ValueError(f"{name} must be finite")


def _check_scalars(**values: float) -> None:
    for name, value in values.items():
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite (got {value!r})")


#: Slots of the header at the start of `Row._const` (`_unpack` reads them).
PACK_HEADER = 10


@functools.lru_cache(maxsize=256)
def _state_layout(n: int, k: int) -> tuple[tuple[str, tuple[int, ...]], ...]:
    """The arrays in `Row._state`, in order, with their shapes (`_unpack` mirrors it). At
    K = 1 ``wsum`` and ``bsum`` have no place of their own: they are ``wl`` and ``wb`` seen
    as (N,) (`_STATE_ALIASES`, 0.10.0): the sum over one mode is the mode (as ``0.0 + x``:
    the slot holds the sum's value, -0.0 turned to 0.0), and the K = 1 update then stores
    each element's state once instead of twice (the free elements' loop is bound by its
    stores: about a quarter of the K = 1 update)."""
    if k == 1:
        return (("wl", (n, k)), ("wb", (n, k)), *_state_rest(n, k))
    return (("wl", (n, k)), ("wsum", (n,)), ("wb", (n, k)), ("bsum", (n,)), *_state_rest(n, k))


#: The state views that are another view's memory at K = 1 (`_state_layout`).
_STATE_ALIASES = {"wsum": "wl", "bsum": "wb"}


def _state_rest(n: int, k: int) -> tuple[tuple[str, tuple[int, ...]], ...]:
    """`_state_layout` after the memory and its sums."""
    return (
        ("scratch", (n, k)),
        ("scratch_b", (n, k)),
        ("diss", (n,)),
        ("out", (OUT_SIZE,)),
        ("txn", (n, k)),
        ("txn_b", (n, k)),
        # The kernel's coefficient workspace and the substep length it holds (`COEF_ROWS`).
        ("coef", (COEF_ROWS, max(k, 1))),
    )


@functools.lru_cache(maxsize=256)
def _const_layout(n: int, k: int, m: int, blocks: int) -> tuple[tuple[str, tuple[int, ...]], ...]:
    """The arrays in `Row._const` after the header, in order (`_unpack` mirrors it)."""
    return (
        ("g_c", (n,)),
        ("gf", (m,)),
        ("gint", (m,)),
        # Right after gint: the kernels take gint with the weights as one array (`gint_kernel`).
        ("fweights", (3 * n + 2,)),
        ("gmin", (blocks,)),
        ("gmax", (blocks,)),
        ("p", (k, k)),
        ("p_inv", (k, k)),
        ("lam", (k,)),
        ("beta", (k,)),
        ("rate", (k,)),
        ("e_kelvin", (k,)),
    )


_VIEW_NAMES = frozenset(name for name, _ in _state_layout(1, 1) + _const_layout(1, 1, 2, 1)) | set(
    _STATE_ALIASES
)
#: What a pickled (or deep-copied) row leaves behind: the views and the buffers' addresses.
_NOT_PICKLED = _VIEW_NAMES | {"addresses", "gint_kernel"}


def _arena_size(layout: tuple[tuple[str, tuple[int, ...]], ...], start: int) -> int:
    return start + sum(math.prod(shape) for _, shape in layout)


@functools.lru_cache(maxsize=256)
def _slots(
    start: int, layout: tuple[tuple[str, tuple[int, ...]], ...]
) -> tuple[tuple[str, int, int, tuple[int, ...]], ...]:
    """(name, first, end, shape) of each array of `layout` from `start` on (cached: a domain
    growth rebinds two dozen views and the layout of a row size repeats)."""
    slots = []
    offset = start
    for name, shape in layout:
        size = math.prod(shape)
        slots.append((name, offset, offset + size, shape))
        offset += size
    return tuple(slots)


#: The views `Row.regrid` binds at once (`Row.__getattr__` binds the others on first use).
_EAGER_VIEWS = ("wl", "wsum", "wb", "bsum", "out")


@functools.lru_cache(maxsize=256)
def _row_slots(n: int, k: int, m: int, blocks: int) -> dict[str, tuple[bool, int, int, tuple[int, ...]]]:
    """Every view of a row by name: (in `_state`, first, end, shape). Cached; never mutate."""
    slots = {
        name: (False, first, end, shape)
        for name, first, end, shape in _slots(PACK_HEADER, _const_layout(n, k, m, blocks))
    }
    slots.update(
        {name: (True, first, end, shape) for name, first, end, shape in _slots(0, _state_layout(n, k))}
    )
    if k == 1:
        for name, owner in _STATE_ALIASES.items():
            _, first, end, _ = slots[owner]
            slots[name] = (True, first, end, (n,))
    # What the kernels take as ``gint``: the profile's integral with the force weights after
    # it, one array (`_deviation_integral` reads the weights from there).
    _, first, _, _ = slots["gint"]
    size = m + 3 * n + 2
    slots["gint_kernel"] = (False, first, first + size, (size,))
    return slots


def _views(buffer: np.ndarray, start: int, layout: tuple[tuple[str, tuple[int, ...]], ...]):
    """(name, view) of each array of `layout` in `buffer` from `start` on."""
    for name, first, end, shape in _slots(start, layout):
        yield name, buffer[first:end].reshape(shape)


def _state_views(buffer: np.ndarray, n: int, k: int):
    """(name, view) of each array of a row's state buffer ``buffer`` (`_state_layout`), the
    K = 1 aliases included."""
    for name, first, end, shape in _slots(0, _state_layout(n, k)):
        yield name, buffer[first:end].reshape(shape)
        if k == 1:
            for alias, owner in _STATE_ALIASES.items():
                if name == owner:
                    yield alias, buffer[first:end]


@numba.njit(cache=True, nogil=True, inline="always")
def _view(base, offset, shape):
    """A C-contiguous float64 array of `shape` at element `offset` from address `base`, without
    a reference to its owner: only for views that do not outlive the call that made them
    while the caller holds the buffer (numba's slices and reshapes of the buffer cost
    ~15 ns each in reference counts and reshape checks, 0.35 us per step for the 22 arrays)."""
    return numba.carray(_float_pointer(base + 8 * offset), shape)


@numba.njit(cache=True, nogil=True)
def _unpack(state, const):
    """The row's kernel arguments (as `Row.kernel_args`) and its journal (txn, txn_b) as
    views of its two buffers (`_state_layout`, `_const_layout`, the header). The views do not
    keep the buffers alive: use them only inside the call that received the buffers."""
    return _unpack_at(state.ctypes.data, const.ctypes.data)


@numba.njit(cache=True, nogil=True, inline="always")
def _unpack_at(s, c):
    """`_unpack` of the buffers at addresses `s` (`Row._state`) and `c` (`Row._const`)
    (`Row.addresses`): the caller holds the buffers for the whole call."""
    const = _view(c, 0, PACK_HEADER)
    n = int(const[0])
    k = int(const[1])
    m = int(const[2])
    blocks = int(const[3])
    nk = n * k
    o = 0
    wl = _view(s, o, (n, k))
    # K = 1: wsum and bsum are wl and wb (`_state_layout`).
    sums = 0 if k == 1 else n
    o += nk
    wsum = _view(s, o - nk if k == 1 else o, n)
    o += sums
    wb = _view(s, o, (n, k))
    o += nk
    bsum = _view(s, o - nk if k == 1 else o, n)
    o += sums
    scratch = _view(s, o, (n, k))
    o += nk
    scratch_b = _view(s, o, (n, k))
    o += nk
    diss = _view(s, o, n)
    o += n
    out = _view(s, o, OUT_SIZE)
    o += OUT_SIZE
    txn = _view(s, o, (n, k))
    o += nk
    txn_b = _view(s, o, (n, k))
    o += nk
    coef = _view(s, o, (COEF_ROWS, max(k, 1)))
    q = PACK_HEADER
    g_c = _view(c, q, n)
    q += n
    gf = _view(c, q, m)
    q += m
    # gint and the force weights after it, as one array (`Row.gint_kernel`).
    gint = _view(c, q, m + 3 * n + 2)
    q += m + 3 * n + 2
    gmin = _view(c, q, blocks)
    q += blocks
    gmax = _view(c, q, blocks)
    q += blocks
    p = _view(c, q, (k, k))
    q += k * k
    p_inv = _view(c, q, (k, k))
    q += k * k
    lam = _view(c, q, k)
    q += k
    beta = _view(c, q, k)
    q += k
    rate = _view(c, q, k)
    q += k
    e_kelvin = _view(c, q, k)
    args = (
        wl,
        wsum,
        wb,
        bsum,
        scratch,
        scratch_b,
        diss,
        coef,
        const[4],
        g_c,
        gf,
        gint,
        gmin,
        gmax,
        const[5],
        const[6],
        const[7],
        const[8],
        p,
        p_inv,
        lam,
        beta,
        rate,
        const[9],
        e_kelvin,
        out,
    )
    return args, txn, txn_b


# Releases the GIL like every kernel, although one step takes microseconds. Keeping it was
# tried (0.3.0 round): in-process (`python -m viscoadh_ros.bench.live_profile --contacts 4`,
# logging on) the live thread's CPU per command fell 60 -> 34-41 us, but through DDS
# (`viscoadh bench --sections node`, side by side within minutes) the node's p50 rose
# 1.4-1.8 -> 3.3-3.6 ms and its drops 5-12k -> 25-29k: rclpy's own threads move while the
# kernel runs. Decide threading changes on the DDS measurement, not the in-process profile.
# With the runtime: it makes the views it passes on (`_unpack`, `_view`; views of a raw pointer
# carry no reference count, so the runtime costs nothing here).
@numba.njit(cache=True, nogil=True)
def _advance_packed(state, const, journal, a, d0, d1, dt, max_substep, max_edge_move, force_prev):
    """`_advance` on the row whose buffers are `state` and `const` (`Row._state`,
    `Row._const`), after journalling its memory into ``txn`` when `journal` is true.

    The same kernel on the same arrays as ``_advance(*row.kernel_args, ...)``, called with two
    arrays instead of 19: numba's dispatch checks and unboxes every array argument (about
    60 ns each), which was a microsecond of every step from Python.

    ``force_prev``: the force at (a, d0) on the row's current memory when the caller has it
    (the previous call's ``out[OUT_FORCE]``, the memory untouched since: `_advance_from`),
    NaN to compute it (`_advance`). The same bits either way; a known force saves a whole
    pass over the interior (2 ns per element in contact, a quarter of a K = 1 step)."""
    args, txn, txn_b = _unpack(state, const)
    if journal:
        _copy_state(args[0], args[2], txn, txn_b)
    if math.isnan(force_prev):
        return _advance(*args, a, d0, d1, dt, max_substep, max_edge_move)
    return _advance_from(*args, a, d0, d1, dt, max_substep, max_edge_move, force_prev, txn[:0], txn_b[:0])


#: Phase codes `_step_packed` returns (the values of `simulator.Phase`).
PHASE_NO_CONTACT, PHASE_INDENTING, PHASE_STICKING, PHASE_DETACHING = 0, 1, 2, 3


@numba.njit(cache=True, nogil=True, _nrt=False, inline="always")
def _derived_outputs(radius, r0, rest, d1, dt, outside, inside, g_edge, c_crit, e_relaxed, v_c1, v_c2):
    """A step's derived outputs from the kernel's: ``(phase code, edge speed m/s, effective
    work of adhesion J/m^2, scale separation)``, as `simulator._phase` and
    `ContactSimulator.step` computed them in Python (the same IEEE operations in the same
    order: the same bits). ``rest``: an edge that moved less than this (m) is at rest;
    ``outside``/``inside``/``g_edge``: the edge gaps and g at the edge (read only in contact).
    `_step_packed` per call and `_batch_columns` per row."""
    if radius <= 0.0:
        phase = PHASE_NO_CONTACT
    elif radius > r0 + rest:
        phase = PHASE_INDENTING
    elif radius < r0 - rest:
        phase = PHASE_DETACHING
    else:
        tol = 1e-9 * (abs(d1) + c_crit * math.sqrt(radius) + g_edge)
        if outside >= -tol:
            phase = PHASE_INDENTING
        elif inside <= tol:
            phase = PHASE_DETACHING
        else:
            phase = PHASE_STICKING
    edge_speed = (radius - r0) / dt if dt > 0.0 else 0.0
    u = d1 - g_edge
    if radius > 0.0 and u < 0.0:
        effective = e_relaxed * u * u / (2.0 * math.pi * radius)
    else:
        effective = 0.0
    if edge_speed == 0.0:
        separated = True
    else:
        separated = abs(edge_speed) >= (v_c1 if edge_speed > 0.0 else v_c2)
    return phase, edge_speed, effective, separated


# With the runtime, like `_advance_packed` (the views `_unpack` makes carry no reference
# count). Its return value is a tuple of scalars: boxing it costs less than reading the same
# values back from ``out`` in Python.
@numba.njit(cache=True, nogil=True)
def _step_packed(state, const, params, journal, a, d0, d1, dt, force_prev, r0, energy0, dissipated0):
    """`_advance_packed` on the row whose buffers are at addresses `state` and `const`
    (`Row.addresses`; the caller holds the row for the whole call), `journal`, `a` .. `dt`
    and `force_prev` as there, the model's constants at address `params` (`step_params`:
    max_substep as there, the edge limit as ``max_edge_cells`` elements of this row, and
    for the derived outputs the relaxed modulus E_r*, Pa, and the critical edge speeds
    v_c1, v_c2 (advancing, receding), m/s); then the step's derived outputs from the
    kernel's ``out`` slots, computed as `simulator._phase` and `ContactSimulator.step`
    computed them in Python (the same IEEE operations in the same order: the same bits).
    The simulator's one kernel call per step or force trial. Addresses rather than arrays:
    numba unboxes an array argument in about 0.14 us, an integer in a few ns; the constants
    behind one address rather than five floats (0.12.0 `percall`: each argument is unboxed
    every call).

    r0: the contact radius before the step (the last output's), m; energy0, dissipated0: the
    energy input and the energy dissipated before the step, J (-0.0 each: the step's own
    work and losses, since ``-0.0 + x`` is x for every float x).

    Returns ``(status, radius, force, energy0 + work, substeps, dissipated0 + dissipated,
    memory_peak, (gap_outside, gap_inside, g_edge), phase, edge_speed, effective_work,
    scale_separation_ok)``: the ``out`` slots (``dissipated``: over this step) with the
    sums the simulator forms (the same additions it made in Python), the phase code
    (``PHASE_*``); status STATUS_OVERFLOW for a step that ran but whose two sums are not
    both finite. When status is STATUS_GROW, outputs of a partial step that the caller
    discards (it restores the memory from the journal)."""
    args, txn, txn_b = _unpack_at(state, const)
    constants = _view(params, 0, PARAM_SIZE)
    if journal:
        _copy_state(args[0], args[2], txn, txn_b)
    dx = args[8]
    max_substep = constants[PARAM_MAX_SUBSTEP]
    max_edge_move = constants[PARAM_MAX_EDGE_CELLS] * dx
    if math.isnan(force_prev):
        status = _advance(*args, a, d0, d1, dt, max_substep, max_edge_move)
    else:
        status = _advance_from(
            *args, a, d0, d1, dt, max_substep, max_edge_move, force_prev, txn[:0], txn_b[:0]
        )
    out = args[25]
    energy = energy0 + out[OUT_WORK]
    dissipated = dissipated0 + out[OUT_DISSIPATED]
    if status == STATUS_OK and not (math.isfinite(energy) and math.isfinite(dissipated)):
        status = STATUS_OVERFLOW
    radius = out[OUT_RADIUS]
    outside = out[OUT_GAP_OUTSIDE]
    inside = out[OUT_GAP_INSIDE]
    g_edge = out[OUT_G_EDGE] if radius > 0.0 else 0.0
    # `simulator._phase`: an edge that moved less than twice its location tolerance is at rest.
    phase, edge_speed, effective, separated = _derived_outputs(
        radius,
        r0,
        2.0 * EDGE_TOLERANCE * dx,
        d1,
        dt,
        outside,
        inside,
        g_edge,
        args[16],
        constants[PARAM_E_RELAXED],
        constants[PARAM_V_C1],
        constants[PARAM_V_C2],
    )
    return (
        status,
        radius,
        out[OUT_FORCE],
        energy,
        int(out[OUT_SUBSTEPS]),
        dissipated,
        out[OUT_MEMORY],
        (outside, inside, out[OUT_G_EDGE]),
        phase,
        edge_speed,
        effective,
        separated,
    )


@numba.njit(cache=True, nogil=True)
def _batch_columns(
    d, steps, radius, gaps, rest, work, r0, energy0, c_crit, e_relaxed, v_c1, v_c2, force, dissipated, first
):
    """`ContactSimulator.step_depths`'s derived columns in one compiled pass: ``(phase (uint8),
    edge_speed, effective_work_of_adhesion, energy_input, scale_separation_ok)`` per row from the
    depths ``d``, the time steps ``steps`` (s), the kernel's radius, edge gaps ``gaps`` (n, 3) and
    edge resolutions ``rest`` per row, its work per row, the radius before the first row ``r0``
    and the energy input before it ``energy0``.

    Each element the same IEEE operations in the same order as the numpy expressions it
    replaced (`_derived_outputs`, which `_step_packed` calls per call): the same bits. The
    energy input is the running sum in row order, as ``np.cumsum`` takes it. Those ~25 array
    operations on a 400-row call cost about as much as the kernel's rows at N = 64 (0.11.0
    `rest`).

    A repeated sample (`ContactSimulator._repeats`: no time, the depth of the row before, which
    is not a contact at rest) takes the row before's phase, edge speed, effective work and
    scale separation, as `step` returns the step before. ``force`` and ``dissipated`` per row
    tell rest from a step; ``first`` = (depth before the first row, whether the state before it
    may be repeated (1.0/0.0), its phase code, edge speed, effective work and scale
    separation (1.0/0.0)): the simulator's output before the call."""
    n = d.shape[0]
    phase = np.empty(n, np.uint8)
    edge_speed = np.empty(n)
    effective = np.empty(n)
    energy = np.empty(n)
    ok = np.empty(n, np.bool_)
    before = r0
    total = energy0
    d_before = first[0]
    repeatable = first[1] != 0.0
    code_before = np.uint8(first[2])
    speed_before = first[3]
    effective_before = first[4]
    ok_before = first[5] != 0.0
    for i in range(n):
        radius_i = radius[i]
        if steps[i] == 0.0 and d[i] == d_before and repeatable:
            phase[i] = code_before
            edge_speed[i] = speed_before
            effective[i] = effective_before
            ok[i] = ok_before
            total = total + work[i]
            energy[i] = total
            before = radius_i
            continue
        code, speed, effect, separated = _derived_outputs(
            radius_i, before, rest[i], d[i], steps[i], gaps[i, 0], gaps[i, 1], gaps[i, 2], c_crit, e_relaxed,
            v_c1, v_c2,
        )
        phase[i] = code
        edge_speed[i] = speed
        effective[i] = effect
        ok[i] = separated
        total = total + work[i]
        energy[i] = total
        before = radius_i
        d_before = d[i]
        repeatable = not (radius_i == 0.0 and force[i] == 0.0 and total == 0.0 and dissipated[i] == 0.0)
        code_before = code
        speed_before = speed
        effective_before = effect
        ok_before = separated
    return phase, edge_speed, effective, energy, ok


#: `_step_packed`'s argument types: its one compiled version, whose entry point
#: (`step_entry`) the simulator calls directly.
_STEP_SIGNATURE = (types.intp, types.intp, types.intp, types.boolean) + (types.float64,) * 8


@functools.cache
def step_entry():
    """`_step_packed`'s compiled entry point for `_STEP_SIGNATURE`, called without numba's
    dispatcher: the dispatcher types every argument to pick the version (about 0.3 us of a
    0.6 us call with 14 arguments, `benchmarks/dispatch_options.py`); the entry point
    only unboxes them. The caller must pass exactly these types (a row's two
    `Row.addresses`, the address of a `step_params` array, a bool, then 8 floats): an array
    or None where a number belongs is a TypeError, but no address is checked."""
    return _step_packed.compile(_STEP_SIGNATURE)


def step_params(
    max_substep: float, max_edge_cells: float, e_relaxed: float, v_c1: float, v_c2: float
) -> np.ndarray:
    """The constants `_step_packed` reads at its ``params`` address (``PARAM_*``): the caller
    keeps the array alive while it passes its address (``array.ctypes.data``)."""
    params = np.empty(PARAM_SIZE)
    params[PARAM_MAX_SUBSTEP] = max_substep
    params[PARAM_MAX_EDGE_CELLS] = max_edge_cells
    params[PARAM_E_RELAXED] = e_relaxed
    params[PARAM_V_C1] = v_c1
    params[PARAM_V_C2] = v_c2
    return params


def regrid_buffer(n: int, k: int, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A constant buffer for `Row.regrid` (``const=``) of a row of `n` elements, `k` Kelvin
    elements and `m` fine points, and views of its ``gf`` and ``gint`` slots: the fine
    profile written there ahead (`_TimeStepped._prepare_growth`) is not copied again."""
    blocks = (m + TOUCH_BLOCK - 1) // TOUCH_BLOCK
    const = np.empty(_arena_size(_const_layout(n, k, m, blocks), PACK_HEADER))
    slots = _row_slots(n, k, m, blocks)
    views = []
    for name in ("gf", "gint"):
        _, first, end, _shape = slots[name]
        views.append(const[first:end])
    return const, views[0], views[1]


class Row:
    """The preallocated arrays of one MDR row, its chain's modal data and constants.

    Keyword arguments (SI): ``dx`` element width, m; ``g_c`` (N,) profile at centres, m;
    ``gf``, ``gint`` (M,) fine profile and its running integral, m and m^2; ``df`` fine
    spacing, m; ``reach`` outermost radius the indenter can touch, m (inf if unbounded);
    ``wl`` (N, K) Kelvin elongations, m; ``wb`` (N, K) their unit-input responses B
    (dimensionless; None: zeros, a body that never touched); ``p``, ``p_inv`` (K, K),
    ``lam`` (K,) 1/s, ``beta`` (K,) the modal chain (see simulator._modal_chain); ``rate``
    (K,) free creep-back rates, 1/s; ``e_kelvin`` (K,) Kelvin moduli E_k*, Pa; ``steady``
    (K,) steady in-contact fractions ``E_r*/E_k*`` (``kap`` is their sum); ``e0`` glass
    modulus E0*, Pa; ``c_crit`` critical glass elongation per sqrt(m),
    ``dl_c(x) = c_crit sqrt(x)``.
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
        wb: np.ndarray | None = None,
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
        if wb is None:
            wb = np.zeros_like(wl)
        for name, array, shape in (
            ("g_c", g_c, (n,)),
            ("gf", gf, (m,)),
            ("gint", gint, (m,)),
            ("wl", wl, (n, k)),
            ("wb", wb, (n, k)),
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
        self.steady = steady
        self.kap = float(steady.sum())
        # Every array the kernel takes lives in one of two float64 buffers (`_advance_packed`):
        # `_const` (header, geometry and chain; shared by `with_memory` clones, never written)
        # and `_state` (what a step writes; each clone has its own). The attributes below are
        # views into them.
        blocks = (m + TOUCH_BLOCK - 1) // TOUCH_BLOCK
        self._const = np.empty(_arena_size(_const_layout(n, k, m, blocks), PACK_HEADER))
        self._const[:PACK_HEADER] = (
            n,
            k,
            m,
            blocks,
            self.dx,
            self.df,
            self.e0,
            self.c_crit,
            self.reach,
            self.kap,
        )
        self._state = np.zeros(_arena_size(_state_layout(n, k), 0))
        self._attach_views()
        self.coef[...] = coefficient_workspace(k)
        self.g_c[...] = g_c
        self.gf[...] = gf
        self.gint[...] = gint
        _fill_force_weights(self.g_c, self.gf, self.gint, self.df, self.dx, self.fweights)
        # Least and largest profile height per block of TOUCH_BLOCK fine points (`_first_touch`).
        self.gmin[...] = np.minimum.reduceat(gf, np.arange(0, m, TOUCH_BLOCK))
        self.gmax[...] = np.maximum.reduceat(gf, np.arange(0, m, TOUCH_BLOCK))
        self.p[...], self.p_inv[...], self.lam[...], self.beta[...] = p, p_inv, lam, beta
        self.rate[...], self.e_kelvin[...] = rate, e_kelvin
        self.wl[...] = wl
        self.wb[...] = wb
        self.wsum[...] = self.wl.sum(axis=1)
        self.bsum[...] = self.wb.sum(axis=1)
        # `txn`, `txn_b`: the simulator's transaction journal, the memory before a step's first
        # kernel call; `scratch`, `scratch_b`, `diss`, `out`: the kernel's work and output slots.
        self._kernel_args: tuple | None = None

    def regrid(
        self,
        *,
        dx: float,
        g_c: np.ndarray,
        gf: np.ndarray,
        gint: np.ndarray,
        df: float,
        reach: float,
        wl: np.ndarray,
        wb: np.ndarray | None = None,
        const: np.ndarray | None = None,
    ) -> Row:
        """A new row of this row's chain and constants (``p`` .. ``e_kelvin``, ``steady``,
        ``e0``, ``c_crit``: copied, already checked) on a new grid: the arguments as for
        `Row` (``wl`` keeps this row's Kelvin count). The same buffers, bit for bit, as
        `Row` given this row's chain; cheaper (a domain growth builds one inside a step):
        the chain is copied as one block and not checked again, the block extremes of the
        fine profile are one compiled pass. ``const``: the new row's constant buffer from
        `regrid_buffer` (its ``gf``/``gint`` slots may be the arrays passed, filled ahead),
        taken over by the row; None: a new one."""
        k = self.wl.shape[1]
        if wl.ndim != 2 or wl.shape[1] != k:
            raise ValueError(f"wl must have shape (N, {k}) (got {getattr(wl, 'shape', None)})")
        n = wl.shape[0]
        m = gf.shape[0]
        _check_scalars(dx=dx, df=df)
        if dx <= 0.0 or df <= 0.0 or m < 2 or n < 1:
            raise ValueError("row needs dx > 0, df > 0, at least 1 element and 2 fine points")
        if not reach > 0.0:
            raise ValueError(f"reach must be > 0 (got {reach!r})")
        if wb is None:
            wb = np.zeros_like(wl)
        arrays = (g_c, gf, gint, wl, wb)
        for name, array, shape in zip(
            _REGRID_ARRAYS, arrays, ((n,), (m,), (m,), (n, k), (n, k)), strict=True
        ):
            if not isinstance(array, np.ndarray) or array.dtype != np.float64:
                raise TypeError(f"{name} must be a float64 numpy array")
            if array.shape != shape:
                raise ValueError(f"{name} must have shape {shape} (got {array.shape})")
        row = object.__new__(Row)
        row.dx, row.df, row.reach = float(dx), float(df), float(reach)
        row.e0, row.c_crit = self.e0, self.c_crit
        row.steady = self.steady
        row.kap = self.kap
        blocks = (m + TOUCH_BLOCK - 1) // TOUCH_BLOCK
        size = _arena_size(_const_layout(n, k, m, blocks), PACK_HEADER)
        in_place = False
        if const is None:
            const = np.empty(size)
        elif not (
            isinstance(const, np.ndarray)
            and const.dtype == np.float64
            and const.shape == (size,)
            and const.flags.c_contiguous
        ):
            raise ValueError(f"const must be a contiguous float64 array of shape ({size},)")
        else:
            # The fine profile already in its slots of ``const`` (`regrid_buffer`): checked
            # here with numpy (one vectorised pass each), not copied onto itself.
            slots = _row_slots(n, k, m, blocks)
            address = const.ctypes.data
            in_place = all(
                array.ctypes.data == address + 8 * slots[name][1] and array.strides == (8,)
                for name, array in (("gf", gf), ("gint", gint))
            )
            if in_place:
                for name, array in (("gf", gf), ("gint", gint)):
                    if not np.isfinite(array).all():
                        raise ValueError(f"{name} must be finite")
        row._const = const
        row._state = np.zeros(_arena_size(_state_layout(n, k), 0))
        # One compiled call checks the arrays are finite and fills both buffers (a growth
        # builds this row inside a step, where each Python statement costs microseconds);
        # the views are bound on first use (`__getattr__`).
        bad = _fill_regrid(
            row._const,
            row._state,
            self._const,
            *(np.ascontiguousarray(array) for array in arrays),
            row.dx,
            row.df,
            row.e0,
            row.c_crit,
            row.reach,
            row.kap,
            in_place,
        )
        if bad >= 0:
            raise ValueError(f"{_REGRID_ARRAYS[bad]} must be finite")
        # The views a step reads at once (the memory, the output slots); the others on
        # first use.
        slots = row._slots = _row_slots(n, k, m, blocks)
        state = row._state
        for name in _EAGER_VIEWS:
            _, first, end, shape = slots[name]
            setattr(row, name, state[first:end].reshape(shape))
        if k > 1:
            # numpy's own summation order (the compiled fill sums K <= 1 as numpy does).
            np.sum(row.wl, axis=1, out=row.wsum)
            np.sum(row.wb, axis=1, out=row.bsum)
        row._kernel_args = None
        return row

    def __getattr__(self, name: str) -> Any:
        """An array view not bound yet (`regrid` binds them on first use): bind it now. Also
        ``addresses``: the addresses of ``(_state, _const)`` (`_step_packed` takes them),
        found on first use (``ndarray.ctypes`` costs about a microsecond) and kept; never
        copied to another row (`with_memory`, pickling)."""
        fields = self.__dict__
        if name == "addresses" and "_state" in fields:
            addresses = fields["addresses"] = (
                fields["_state"].ctypes.data,
                fields["_const"].ctypes.data,
            )
            return addresses
        slots = fields.get("_slots")
        if slots is not None and name in slots:
            in_state, first, end, shape = slots[name]
            view = fields["_state" if in_state else "_const"][first:end].reshape(shape)
            fields[name] = view
            return view
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def _attach_views(self) -> None:
        """(Re)bind the array attributes to their places in `_const` and `_state`."""
        n, k, m, blocks = (int(v) for v in self._const[:4])
        for name, view in _views(self._const, PACK_HEADER, _const_layout(n, k, m, blocks)):
            setattr(self, name, view)
        for name, view in _state_views(self._state, n, k):
            setattr(self, name, view)
        _, first, end, _ = _row_slots(n, k, m, blocks)["gint_kernel"]
        self.gint_kernel = self._const[first:end]

    def __getstate__(self) -> dict:
        # Pickling or deep-copying the views would cut them from their buffers: keep the
        # buffers and the scalars, rebind the views on load.
        kept = {key: value for key, value in self.__dict__.items() if key not in _NOT_PICKLED}
        kept["_kernel_args"] = None
        return kept

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._attach_views()

    @property
    def kernel_args(self) -> tuple:
        """The row's arrays and constants in the order `_advance` takes them (before the
        step's scalars); the benchmark calls the kernel with the same tuple. Built once per
        row (the arrays are only ever written in place)."""
        args = self._kernel_args
        if args is None:
            args = self._kernel_args = self._build_kernel_args()
        return args

    def _build_kernel_args(self) -> tuple:
        return (
            self.wl,
            self.wsum,
            self.wb,
            self.bsum,
            self.scratch,
            self.scratch_b,
            self.diss,
            self.coef,
            self.dx,
            self.g_c,
            self.gf,
            self.gint_kernel,
            self.gmin,
            self.gmax,
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
            self.out,
        )

    @property
    def elements(self) -> int:
        return self.wl.shape[0]

    @property
    def length(self) -> float:
        """Domain length L, m."""
        return self.dx * self.elements

    def memory(self) -> tuple[np.ndarray, np.ndarray]:
        """Copies of the Kelvin state: elongations ``wl`` and unit responses ``wb``, (N, K)."""
        return self.wl.copy(), self.wb.copy()

    def with_memory(self, wl: np.ndarray, wb: np.ndarray | None = None) -> Row:
        """A new row with the same geometry and chain (shared, never written) and its own
        copy of the Kelvin state `wl`, `wb` (N, K; wb None: zeros)."""
        clone = object.__new__(Row)
        clone.__dict__.update(self.__dict__)
        clone.__dict__.pop("addresses", None)  # its own state buffer
        clone._state = np.zeros_like(self._state)
        for name, view in _state_views(clone._state, *self.wl.shape):
            setattr(clone, name, view)
        clone.coef[...] = coefficient_workspace(self.wl.shape[1])
        clone._kernel_args = None
        clone.set_memory(wl, wb)
        return clone

    def set_memory(self, wl: np.ndarray, wb: np.ndarray | None = None) -> None:
        """Replace the Kelvin state (N, K each; wb None: zeros) after validation."""
        _check("wl", wl, self.wl.shape)
        if wb is not None:
            _check("wb", wb, self.wb.shape)
        self.wl[...] = wl
        self.wsum[...] = wl.sum(axis=1)
        if wb is None:
            self.wb[...] = 0.0
            self.bsum[...] = 0.0
        else:
            self.wb[...] = wb
            self.bsum[...] = wb.sum(axis=1)


def advance(
    row: Row, radius: float, d0: float, d1: float, dt: float, *, max_substep: float, max_edge_move: float
) -> tuple[int, np.ndarray]:
    """Advance `row` in place over dt (s) from depth d0 to d1 (m, linear in time), the
    contact radius starting at `radius` (m).

    Returns ``(status, out)``; ``out[OUT_RADIUS]`` is the new contact radius (m),
    ``out[OUT_FORCE]`` the force (N), ``out[OUT_WORK]`` the work input (J),
    ``out[OUT_DISSIPATED]`` the energy dissipated over the step (J, >= 0). On STATUS_GROW
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
            float(radius),
            float(depth),
            row.wsum,
            row.bsum,
            row.dx,
            row.g_c,
            row.gf,
            row.gint_kernel,
            row.df,
            row.e0,
            row.kap,
            _NO_BUFFER,
            row.wb,
            row.p,
            row.p_inv,
            row.lam,
            row.beta,
        )
    )


#: An empty work space: `_deviation_integral`'s one loop (the same bits as with a buffer).
_NO_BUFFER = np.empty(0)


def locate_edge(row: Row, radius: float, depth: float) -> tuple[float, int, bool]:
    """Apply the energy criterion both ways at `depth` (m) from contact radius `radius` (m):
    ``(new radius m, MOTION_* code, grow)``; grow asks for a larger domain."""
    _check_scalars(radius=radius, depth=depth)
    new_radius, motion, grow = _locate_edge(
        float(radius),
        float(depth),
        row.wsum,
        row.bsum,
        row.dx,
        row.g_c,
        row.gf,
        row.gmin,
        row.gmax,
        row.df,
        row.c_crit,
        row.reach,
        math.inf,
    )
    return float(new_radius), int(motion), bool(grow)


def stored_energy(row: Row, radius: float, depth: float) -> float:
    """Elastic energy stored in glass and Kelvin springs of the row, J."""
    _check_scalars(radius=radius, depth=depth)
    return float(
        _stored_energy(
            float(radius), float(depth), row.wl, row.wb, row.dx, row.g_c, row.gf, row.df, row.e0, row.e_kelvin
        )
    )


def criterion_gap(row: Row, x: float, depth: float, radius: float, *, interior: bool) -> float:
    """h(x), m, with the memory of the interior (True) or exterior side of `radius`."""
    _check_scalars(x=x, depth=depth, radius=radius)
    n = row.elements
    n_in = int(_interior_count(float(radius), row.dx, n))
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    return float(
        _h(float(x), float(depth), row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df, row.c_crit)
    )


def memory_at(row: Row, x: float, radius: float, *, interior: bool) -> float:
    """Memory w(x), m, as the criterion and force see it on one side of `radius`."""
    _check_scalars(x=x, radius=radius)
    n = row.elements
    n_in = int(_interior_count(float(radius), row.dx, n))
    lo, hi = (0, n_in - 1) if interior else (n_in, n - 1)
    return float(_w_side(float(x), row.wsum, row.bsum, lo, hi, row.dx, row.g_c, row.gf, row.df))


def kelvin_update(row: Row, n_in: int, d0: float, d1: float, dt: float) -> float:
    """Exact Kelvin-chain update of `row` in place (see `_kelvin_update`); returns the
    energy its dampers dissipated, J."""
    _check_scalars(d0=d0, d1=d1, dt=dt)
    if not 0 <= n_in <= row.elements:
        raise ValueError(f"n_in must be in [0, {row.elements}] (got {n_in})")
    if dt < 0.0:
        raise ValueError(f"dt must be >= 0 (got {dt!r})")
    _kelvin_update(
        row.wl,
        row.wsum,
        row.wb,
        row.bsum,
        row.diss,
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
        row.e_kelvin,
        row.dx,
    )
    return float(row.diss.sum()) if row.wl.shape[1] else 0.0


def remap_memory(
    row: Row, radius: float, elements: int, length: float, centre_profile: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The Kelvin state (wl, wb) of `row` (contact radius m) on a new grid of `elements`
    over (0, length] whose profile at the centres is `centre_profile` (m), each (elements,
    K); see `_remap`."""
    _check_scalars(radius=radius, length=length)
    if elements < 1 or not length > 0.0:
        raise ValueError(f"need elements >= 1 and length > 0 (got {elements}, {length!r})")
    _check("centre_profile", centre_profile, (int(elements),))
    out = np.empty((int(elements), row.wl.shape[1]))
    out_b = np.empty_like(out)
    _remap(
        row.wl, row.wb, float(radius), row.dx, row.g_c, float(length) / elements, centre_profile, out, out_b
    )
    return out, out_b


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
    row.regrid(
        dx=0.25,
        g_c=row.g_c.copy(),
        gf=row.gf.copy(),
        gint=row.gint.copy(),
        df=row.df,
        reach=row.reach,
        wl=np.zeros((n, k)),
    )
    advance(row, 0.0, 0.0, 0.1, 0.01, max_substep=0.0, max_edge_move=0.25)
    advance(row, 0.3, 0.1, 0.2, 0.0, max_substep=0.0, max_edge_move=0.25)
    force(row, 0.3, 0.1)
    # The simulator's transaction journal and force-search restores call these from Python.
    _copy_state(row.wl, row.wb, row.txn, row.txn_b)
    _restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
    # The simulator's step calls the kernel through its two buffers (`_step_packed`'s entry
    # point; `_advance_packed`, the same without the derived outputs, is the benchmarks').
    step = step_entry()
    params = step_params(0.0, 1.0, 1.0, 1.0, 1.0)
    step(*row.addresses, params.ctypes.data, True, 0.0, 0.0, 0.1, 0.01, math.nan, 0.0, -0.0, -0.0)
    step(*row.addresses, params.ctypes.data, False, 0.0, 0.0, 0.1, 0.01, 0.0, 0.0, -0.0, -0.0)
    _restore_state(row.wl, row.wsum, row.wb, row.bsum, row.txn, row.txn_b)
    _g_at(0.3, row.gf, row.df)
    stored_energy(row, 0.3, 0.1)
    criterion_gap(row, 0.3, 0.1, 0.3, interior=True)
    memory_at(row, 0.3, 0.3, interior=True)
    kelvin_update(row, 2, 0.0, 0.1, 0.01)
    remap_memory(row, 0.3, 3, 2.0, ((np.arange(3) + 0.5) * 2.0 / 3.0) ** 2)
    times = np.array([0.0, 0.1, 0.2])
    depths = np.array([0.0, 0.3, 0.1])
    _advance_rows(
        *row.kernel_args,
        np.empty_like(row.wl),
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
