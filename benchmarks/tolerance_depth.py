"""How the tolerance mode's viscoelastic error grows with depth and with G0/G_inf, measured.

    .venv/bin/python benchmarks/tolerance_depth.py     # a few minutes on one core

Why: the error model of numerics.tolerance (core/presets.py ERROR_MODEL) was fitted on the
convergence study (tests/convergence_cases.py), whose viscoelastic bodies have G0/G_inf = 1.1
and 11 and whose deepest viscoelastic press is ~12 relaxed d_c (300 glass-modulus units). An
outside tester (0.10.0 round) found 5-7x the bound at G0/G_inf = 101 and 10 relaxed d_c.

What: one adhesive sphere (R = 1 mm, G0 = 1 GPa, w = 0.01 J/m^2, one Kelvin element, or a
K = 3 Prony chain) pressed from 0.5 d_c above the surface to D relaxed d_c (docs/concepts.md:
E_r* and w_eff2) in 500 rows and pulled to -3 d_c in 501, the press taking p retardation times.
Grid: G0/G_inf (r) x p x D, D from 2 to 40 relaxed d_c in steps of 1.19x, so that the worst
alignment of the domain's doublings (a growth just before the turn leaves the deepest contact
on half the domain) is sampled. Each history runs with the tolerance mode's step control
(numerics.elements N with numerics.tolerance set: `fast`'s fine_factor 16, max_edge_cells 2,
`balanced`'s growth factor 2) at N = 96, 192, 384, against the core at 8192 elements with
`accurate` numerics (its own error ~C/8192^2, < 2 % of the errors measured here). The error is
the convergence study's: the largest of the pull-off error and the force error of every row of
both branches, relative to the reference pull-off force (tests/convergence_cases.py); the
printed C = max over N of err N^2, and F_max/F_po the reference's peak-to-pull-off ratio.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from scenes import one_contact  # noqa: E402

from viscoadh_ros.core import reference  # noqa: E402
from viscoadh_ros.core.history import simulate_history  # noqa: E402
from viscoadh_ros.core.presets import RATIO_DEPTH, RATIO_PEAK, predicted_error  # noqa: E402
from viscoadh_ros.core.rheology import CreepElement  # noqa: E402

RADIUS, G0, WORK, TAU = 1e-3, 1e9, 0.01, 1e-3
SPHERE = {"shape": "sphere", "radius": RADIUS}
ROWS, HALF = 1001, 500
LADDER = (96, 192, 384)
DEPTHS = tuple(round(2.0 * 1.19**k, 2) for k in range(18))  # 2 .. 38 relaxed d_c


def kelvin(ratio: float, chain: int) -> tuple[list[float], list[float]]:
    """Kelvin moduli and viscosities with G0/G_inf = ratio: one element (retardation TAU =
    eta/(G0+G1)), or `chain` equal-compliance elements with times TAU x 30^(k - (K-1)/2)."""
    compliance = (ratio - 1.0) / G0 / chain  # 1/G_inf - 1/G0 shared equally
    moduli = [1.0 / compliance] * chain
    times = [TAU * 30.0 ** (k - (chain - 1) / 2.0) for k in range(chain)]
    return moduli, [t * (G0 + g) for t, g in zip(times, moduli, strict=True)]


def history(contact, depth: float, presses: float) -> tuple[np.ndarray, np.ndarray]:
    creep = CreepElement.from_config(contact.material)
    unit = abs(reference.figure4_scales(RADIUS, WORK, creep).depth)
    depths = unit * np.concatenate([np.linspace(-0.5, depth, HALF), np.linspace(depth, -3.0, ROWS - HALF)])
    return np.linspace(0.0, 2.0 * presses * TAU, ROWS), depths


def error(force: np.ndarray, radius: np.ndarray, ref) -> float:
    """tests/convergence_cases.py's errors: pull-off and both branches / |pull-off|."""
    f_ref, r_ref = ref.force, ref.contact_radius
    pull_off = float(f_ref.min())
    both = (r_ref > 0.0) & (radius > 0.0)
    touch = int(np.argmax(r_ref > 0.0))
    rows = np.arange(ROWS)
    indent = rows[(rows >= touch + 2) & (rows < HALF) & both]
    retract = rows[(rows >= HALF) & (rows <= int(np.argmin(f_ref))) & both]
    worst = max(
        float(np.max(np.abs(force[indent] - f_ref[indent]), initial=0.0)),
        float(np.max(np.abs(force[retract] - f_ref[retract]), initial=0.0)),
    )
    return max(abs(float(force.min()) / pull_off - 1.0), worst / abs(pull_off))


def case(ratio: float, chain: int, presses: float, depth: float) -> tuple[float, list[float]]:
    moduli, etas = kelvin(ratio, chain)

    def contact(**numerics):
        return one_contact(
            SPHERE, glass_shear_modulus=G0, kelvin=moduli, viscosities=etas, work=WORK,
            numerics={"model": "time_stepped", **numerics},
        )  # fmt: skip

    times, depths = history(contact(), depth, presses)
    ref = simulate_history(contact(preset="accurate", elements=8192), times, depth=depths)
    if not ref.force.min() < 0.0:
        # No pull-off: the surface, slower to recover (creep time ~ r x the retardation time)
        # than the pull, is left behind and never pulls on the indenter; nothing to normalise by.
        return math.nan, [math.nan] * len(LADDER)
    errs = []
    for n in LADDER:
        run = simulate_history(contact(elements=n, tolerance=1e-2), times, depth=depths)
        errs.append(error(run.force, run.contact_radius, ref))
    return float(ref.force.max() / -ref.force.min()), errs


def main() -> None:
    print("r = G0/G_inf, K Kelvin elements, p = press time / retardation time, D = depth in relaxed d_c")
    print("C = max_N err N^2 (N = 96, 192, 384); ratio = F_max / |F_pull-off| of the reference")
    rows = []
    for chain, ratios in ((1, (1.1, 3.0, 11.0, 101.0, 1001.0)), (3, (3.0, 19.3, 101.0))):
        for ratio in ratios:
            for presses in (0.5, 5.0, 50.0):
                cells = []
                for depth in DEPTHS:
                    peak, errs = case(ratio, chain, presses, depth)
                    if math.isnan(peak):
                        cells.append(f"{depth:g}: no pull-off")
                        continue
                    c = max(e * n * n for e, n in zip(errs, LADDER, strict=True))
                    rows.append((chain, ratio, presses, depth, peak, errs))
                    cells.append(f"{depth:g}: C {c:.3g} (ratio {peak:.0f}, err@384 {errs[-1]:.1e})")
                print(f"K={chain} r={ratio:g} p={presses:g}: " + ", ".join(cells), flush=True)

    def covered(row) -> bool:
        return row[3] <= RATIO_DEPTH and row[4] <= RATIO_PEAK * row[1]

    print(f"\nCovered: D <= {RATIO_DEPTH:g} relaxed d_c and F_max <= {RATIO_PEAK:g} r |F_pull-off|.")
    print("Envelope of C / r over p and D, per body (RATIO_TERM is this with a 20 % margin):")
    for chain in (1, 3):
        for ratio in sorted({r for k, r, *_ in rows if k == chain}):
            inside = [
                max(e * n * n for e, n in zip(row[5], LADDER, strict=True))
                for row in rows
                if row[:2] == (chain, ratio) and covered(row)
            ]
            print(
                f"  K={chain} r={ratio:g}: C/r {max(inside) / ratio:.3g} "
                f"(C {max(inside):.3g}, {len(inside)} histories)"
            )
    print("Largest measured / predicted error (presets.predicted_error at N = 96, 192, 384):")
    for label, keep in (
        ("covered", covered),
        (
            f"deeper than {RATIO_DEPTH:g} d_c, peak <= {RATIO_PEAK:g} r",
            lambda row: row[3] > RATIO_DEPTH and row[4] <= RATIO_PEAK * row[1],
        ),
        (
            f"peak > {RATIO_PEAK:g} r |F_pull-off| (a pull-off small against the peak)",
            lambda row: row[4] > RATIO_PEAK * row[1],
        ),
    ):
        worst = (0.0, None)
        for row in rows:
            if not keep(row):
                continue
            regime = "viscoelastic" if row[0] == 1 else "viscoelastic, K >= 2"
            for e, n in zip(row[5], LADDER, strict=True):
                worst = max(worst, (e / predicted_error(regime, n, row[1]), (row[:5], n)), key=lambda w: w[0])
        if worst[1] is None:
            print(f"  {label}: none")
            continue
        (chain, ratio, presses, depth, peak), n = worst[1]
        print(
            f"  {label}: {worst[0]:.2f} "
            f"(K={chain} r={ratio:g} p={presses:g} D={depth:g} ratio {peak:.0f}, N={n})"
        )


if __name__ == "__main__":
    main()
