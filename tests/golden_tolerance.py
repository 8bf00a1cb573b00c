"""The comparison with a golden file that the edge root finder's change (0.3.0, `edge`) allows.

`_kernels._bisect` became a safeguarded secant (ITP): it stops at the same tolerance as the
0.2.0 bisection (`EDGE_TOLERANCE` = 1e-12 of an element) but at another point of the final
bracket, so edge positions moved by up to ~1e-12 dx (tests/test_edge_root.py proves that
bound against the old bisection on random brackets). An edge position enters the force, the
work and the elements' attach times linearly; over the golden scenes' thousands of steps the
outputs moved by at most ~1e-12 of each output's own largest value (8e-13 for the unit-input
memory, 2e-13 for the force search's depths, ~1e-14 for radius and force). So every float
column is compared within `RELATIVE` = 1e-11 of that column's largest golden value; integer
codes (status, substeps, motion, flags) must be equal, since that tolerance is below their
unit; a phase may differ only where the edge stood still to rounding (|edge speed| below
`RELATIVE` of its column's largest value in both runs): there the phase of a pinned edge is
decided by which way a 1e-13 dx jitter of the re-located edge went, in the golden as now.
The criterion gaps at the new edge (`_kernels.advance`'s outputs) are h at a root, rounding
noise by definition: they are compared on the scale of the radius.

The 0.4.0 kernel (`elem`) sums the K = 1 update's losses in four interleaved lanes instead of
one chain in index order (`_kernels._sum_losses`; one chain of dependent additions was
latency-bound). Only the rounding of that sum changes: nothing in the state, the edge or the
force reads it, so the energy dissipated alone moves, by the rounding of a sum of N
non-negative terms (~N eps of it; on the golden scenes at most 1.2e-15 of its column's largest
value), far below `RELATIVE`; it stays non-negative and its running sum monotone.

The 0.7.0 kernel sums the K = 2..4 losses in the same four lanes, and takes the force's memory
integral in its sum form (a trapezoid of the nodal deviations and a weighted sum of B with the
grid's weights, `_kernels._fill_force_weights`): the same integral to rounding, so the force and
the work move by ~1e-15 of their largest values and the energy dissipated by ~1e-15 of it; the
state, the edge and every code are unchanged (nothing in them reads the force or the losses).

Force control (`FORCED_RELATIVE` = 1e-7): a force step stops anywhere inside its stop band
(half the force tolerance, >= 1e-5 of the commanded force in every preset), so trials whose
forces moved at the 1e-15 level may stop at another point of that band (two rows of one
golden scene did: depth, force and radius moved by ~1e-8 of their largest values). 1e-7 is
still two orders below the band. That pins the search's own trials too: in 0.5.0 the force
search starts elsewhere (from rest at the glass JKR contact, after converged steps on the
path extrapolated in time, `force0`), so its steps end at other points of the band; the
`forced` arrays were written again from it (the rest of the file unchanged). Against the
0.4.0 arrays, every row's force is within the force tolerance of its target in both (the same
5 rows of `default_sine` beyond it in both: flagged pull-off rows), the contact is the same on
every row, and the depth moved by up to 1.8e-3 of its largest value (`k1_regrowth` on `fast`,
where F(d) is flat while the edge crosses a cell; 2e-5 or less on the other scenes).

In 0.10.0 the detachment search aims its trials at the fold the trials that let go predict
(`ContactSimulator._detachment`) instead of bisecting: it brackets the let-go depth to the same
width (half the force tolerance of the depth, 2.8e-11 m at `default_sine`'s pull-off, 4e-7 of
the largest depth), but ends at another point of it. `default_sine/forced` alone was written
again (every other array, the other scenes' `forced` ones included, is bit for bit the file's):
against the 0.5.0 array the pull-off row's depth moved by 1.67e-11 m and the rows after it,
held at that depth, with it (depth <= 2.4e-7 of its largest value, energies in and dissipated
<= 8.6e-8, radius and edge speed <= 1e-9, force 3e-15); the contact and the phase are the same
on every row.
"""

from __future__ import annotations

import numpy as np

RELATIVE = 1e-11
FORCED_RELATIVE = 1e-7


def column_failures(
    want: np.ndarray,
    got: np.ndarray,
    phase: int | None = None,
    speed: int | None = None,
    scale_of: dict[int, int] | None = None,
    relative: float = RELATIVE,
) -> list[str]:
    """Columns (last axis; a 1D array is one column) of `got` that leave the tolerance of
    `want`: ``column index: worst difference > allowed``. `phase`/`speed` name the phase and
    edge-speed columns; `scale_of` maps a column to the column whose largest value scales
    its tolerance (the criterion gaps, ~0 at an edge by definition: by the radius)."""
    if want.shape != got.shape:
        return [f"shape {want.shape} != {got.shape}"]
    w2 = want.reshape(-1, 1) if want.ndim == 1 else want.reshape(-1, want.shape[-1])
    g2 = got.reshape(-1, 1) if got.ndim == 1 else got.reshape(-1, got.shape[-1])
    failures = []
    for c in range(w2.shape[1]):
        a, b = w2[:, c], g2[:, c]
        if not np.array_equal(np.isnan(a), np.isnan(b)):
            failures.append(f"{c}: NaN rows differ")
            continue
        ok = ~np.isnan(a)
        a, b = a[ok], b[ok]
        if c == phase:
            va, vb = w2[ok, speed], g2[ok, speed]
            still = relative * np.max(np.abs(va), initial=0.0)
            bad = (a != b) & ~((np.abs(va) <= still) & (np.abs(vb) <= still))
            if np.any(bad):
                failures.append(f"{c}: phase differs at rows {np.flatnonzero(bad)[:5]} with a moving edge")
            continue
        scale = a if scale_of is None or c not in scale_of else w2[ok, scale_of[c]]
        allowed = relative * np.max(np.abs(scale), initial=0.0)
        worst = np.max(np.abs(a - b), initial=0.0)
        if worst > allowed:
            failures.append(f"{c}: {worst:.3g} > {allowed:.3g}")
    return failures
