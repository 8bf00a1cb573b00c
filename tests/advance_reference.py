"""The substep loop as it was before the deferred elements (0.3.0 `_kernels._advance_from`), kept
as a test-only reference: every accepted substep updates the whole row and computes the force
over the whole interior. `tests/test_deferred_substeps.py` compares the product's deferred
substeps (O(window) per accepted substep) with it. The body is main's at 7bcb817
(the snap-in located in time, before the deferral), renamed, with
the attempt guard that grows with the row (0.4.0) as the product's;
it calls the product's per-element kernels, which the deferral does not touch.
"""

from __future__ import annotations

import math

import numba

from viscoadh_ros.core._kernels import (
    _ATTEMPTS_PER_ELEMENT,
    _MAX_ATTEMPTS,
    _MAX_TOUCH_PLANS,
    JUMP_RESOLUTION,
    MOTION_NONE,
    OUT_DISSIPATED,
    OUT_FORCE,
    OUT_LET_GO,
    OUT_MEMORY,
    OUT_MOTION,
    OUT_RADIUS,
    OUT_SUBSTEPS,
    OUT_WORK,
    STATUS_GROW,
    STATUS_OK,
    _adhesion_loss,
    _copy_range,
    _edge_outputs,
    _first_touch,
    _force,
    _interior_count,
    _locate_edge,
    _memory_peak,
    _restore_range,
    _retime_crossed,
    _substep_coefficients,
    _touch_step,
    _trial_window,
    _update_range,
)


def advance_reference(
    row, radius: float, d0: float, d1: float, dt: float, *, max_substep: float, max_edge_move: float
):
    """`_kernels.advance` through the reference loop: ``(status, out)``, the row advanced in place."""
    args = row.kernel_args
    # kernel_args: wl, wsum, wb, bsum, scratch, scratch_b, diss, coef, dx, g_c, gf, gint, gmin,
    # gmax, df, e0, c_crit, reach, p, p_inv, lam, beta, rate, kap, e_kelvin, out
    wl, wsum, wb, bsum = args[0:4]
    dx, g_c, gf, gint, df, e0, kap = args[8], args[9], args[10], args[11], args[14], args[15], args[23]
    p, p_inv, lam, beta = args[18], args[19], args[20], args[21]
    force_prev = _force(
        radius, d0, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, wsum[:0], wb, p, p_inv, lam, beta
    )
    status = advance_from_reference(
        *args,
        float(radius),
        float(d0),
        float(d1),
        float(dt),
        float(max_substep),
        float(max_edge_move),
        force_prev,
    )
    return int(status), row.out


@numba.njit(cache=False, nogil=True)
def advance_from_reference(
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
):
    """`_advance` given the force at the step's start, ``force_prev`` (N: `_force` at (a, d0)
    on the current memory; `_advance_rows` has it from the row before).

    A substep trial with the motion limit (in contact) journals and updates only the window
    of elements the limited edge search reads (`_trial_window`): a rejected trial restores
    that window and costs O(window), not O(N). An accepted one updates the other elements
    with the same coefficients (element by element the same arithmetic as one pass over the
    row) and sums their losses and the memory peak on the way, in index order. Without the
    limit (no contact: the first-touch search reads the whole row; or the shortest substep)
    the trial updates every element.
    """
    n, k_count = wl.shape
    h_min = dt * JUMP_RESOLUTION
    step = dt if max_substep <= 0.0 or max_substep > dt else max_substep
    tau = 0.0
    work = 0.0
    lost = 0.0
    motion = MOTION_NONE
    substeps = 0
    attempts = 0
    jumped_before = False
    let_go = math.nan
    # Touch times planned this step (`_touch_time`), whether the substep being tried ends
    # just before a planned touch (then the jump substep follows) and whether it is the jump
    # substep that crosses one.
    plans = 0
    jump_next = False
    crossing = False
    # Largest |wsum| after the last accepted substep (summed with its update; K = 0: no memory).
    peak = 0.0
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
            new_a, d1, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, wsum[:0], wb, p, p_inv, lam, beta
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
            return STATUS_GROW
        attempts += 1
        if abs(new_a - a) > max_edge_move and limited:
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
        # Accepted: the elements before the window (in index order: their losses first) ...
        viscous = 0.0
        if k_count:
            viscous, peak = _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                0,
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
            )
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
            for i in range(lo, hi):
                viscous += diss[i]
                peak = max(peak, abs(wsum[i]))
            viscous, peak = _update_range(
                wl,
                wsum,
                wb,
                bsum,
                diss,
                hi,
                n,
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
            )
        lost += viscous + _adhesion_loss(hysteresis, a, new_a, max_edge_move)
        force_new = _force(
            new_a, db, wsum, bsum, dx, g_c, gf, gint, df, e0, kap, wsum[:0], wb, p, p_inv, lam, beta
        )
        work += 0.5 * (force_prev + force_new) * (db - da)
        force_prev = force_new
        if sub_motion != MOTION_NONE:
            motion = sub_motion
        jumped = abs(new_a - a) > max_edge_move
        if new_a <= 0.0 < a:
            let_go = db
        a = new_a
        tau += h
        substeps += 1
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
    out[OUT_MEMORY] = peak if k_count else _memory_peak(wsum)
    out[OUT_LET_GO] = let_go
    _edge_outputs(a, d1, wsum, bsum, dx, g_c, gf, df, c_crit, out)
    return STATUS_OK
