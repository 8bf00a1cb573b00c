"""Side-by-side A/B of the Kelvin update alone (`_update_range` over a whole row, 60 % of it in
contact (``in=``), 400 substeps of 1 ms on a synthetic row), several checkouts' kernel modules in ONE
process (issue 13, 0.10.0 `k1upd`):

    .venv/bin/python benchmarks/update_ab.py ROOT [ROOT ...] [nk=N,K ...] [in=FRACTION]

The first ROOT is the reference; each other one's state (wl, wsum, wb, bsum) must equal it bit for
bit, and its losses' sum and peak are compared; at K = 1 a module whose rows alias wsum and bsum
to wl and wb (`_state_layout`, 0.10.0) gets them so. Prints us per update and ns per element, median
thread CPU time of interleaved repeats.
"""

import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ab_cores import renamed_kernels  # noqa: E402

STEPS = 400
DT = 1e-3


def _loop(module):
    """`module`'s `_update_range` over every element of the row per step, compiled."""
    update = module._update_range

    @numba.njit
    def loop(state, n_in, depth, g_c, p, p_inv, lam, beta, coef, ek, dx):  # pragma: no cover
        wl, wsum, wb, bsum, diss = state
        n = wl.shape[0]
        total = 0.0
        peak = 0.0
        for s in range(1, depth.shape[0]):
            slope = (depth[s] - depth[s - 1]) / DT
            lost, top = update(
                wl, wsum, wb, bsum, diss, 0, n, n_in, depth[s - 1], depth[s], slope,
                g_c, p, p_inv, lam, beta, coef, ek, dx, 0.0, 0.0,
            )  # fmt: skip
            total += lost
            peak = max(peak, top)
        return total, peak

    return loop


def _case(roots, modules, loops, n, k, fraction, rng):
    dx = 1e-6
    g_c = ((np.arange(n) + 0.5) * dx) ** 2 / 2e-3
    lam = np.logspace(1, 3, k) if k > 1 else np.array([100.0])
    beta = np.linspace(1.0, 2.0, k)
    p = np.eye(k) + 0.1 * rng.standard_normal((k, k))
    p_inv = np.linalg.inv(p)
    rate = lam * 0.7
    ek = np.linspace(1e6, 2e6, k)
    wl0 = 1e-7 * rng.random((n, k))
    wb0 = 0.5 * rng.random((n, k))
    depth = 1e-6 * (1.0 + 0.3 * np.sin(np.arange(STEPS + 1) * 0.01))
    n_in = int(n * fraction)
    states = []
    for module in modules:
        coef = module.coefficient_workspace(k)
        module._substep_coefficients(lam, rate, DT, coef)
        state = [wl0.copy(), wl0.sum(1), wb0.copy(), wb0.sum(1), np.zeros(n)]
        if k == 1 and "wsum" not in dict(module._state_layout(n, k)):
            # As in the module's own rows: wsum and bsum are wl and wb (0.10.0).
            state[1], state[3] = state[0].reshape(n), state[2].reshape(n)
        states.append((tuple(state), coef))

    def run(j):
        state, coef = states[j]
        state[0][...] = wl0
        state[2][...] = wb0
        return loops[j](state, n_in, depth, g_c, p, p_inv, lam, beta, coef, ek, dx)

    results = [run(j) for j in range(len(modules))]
    for j in range(1, len(modules)):
        same = all(
            np.array_equal(a.view(np.int64), b.view(np.int64))
            for a, b in zip(states[0][0][:4], states[j][0][:4], strict=True)
        )
        (total0, peak0), (total, peak) = results[0], results[j]
        print(
            f"  [{j}] state equal {same}, total {total == total0} ({(total - total0) / total0:.2e}), "
            f"peak {peak == peak0}"
        )
    samples = [[] for _ in modules]
    for _ in range((9 if n <= 1024 else 5) * 3):
        for j in range(len(modules)):
            start = time.thread_time()
            run(j)
            samples[j].append(time.thread_time() - start)
    us = [np.median(values) / STEPS * 1e6 for values in samples]
    cells = "  ".join(
        f"{root.rstrip('/').split('/')[-1]} {value:.3f} us ({value / n * 1e3:.2f} ns/el)"
        for root, value in zip(roots, us, strict=True)
    )
    print(f"N={n} K={k}: {cells}  B/A {us[-1] / us[0]:.3f}")


def main() -> None:
    argv = sys.argv[1:]
    roots = [a for a in argv if not a.startswith(("nk=", "in="))]
    fraction = float(next((a[3:] for a in argv if a.startswith("in=")), "0.6"))
    cases = [tuple(int(x) for x in a[3:].split(",")) for a in argv if a.startswith("nk=")]
    cases = cases or [(512, 1), (1024, 1), (4096, 1), (256, 4), (1024, 4)]
    modules = [renamed_kernels(root) for root in roots]
    loops = [_loop(module) for module in modules]
    rng = np.random.default_rng(1)
    for n, k in cases:
        _case(roots, modules, loops, n, k, fraction, rng)


if __name__ == "__main__":
    main()
