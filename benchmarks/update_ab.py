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

roots = [a for a in sys.argv[1:] if not a.startswith(("nk=", "in="))]
fraction = float(next((a[3:] for a in sys.argv[1:] if a.startswith("in=")), "0.6"))
cases = [tuple(int(x) for x in a[3:].split(",")) for a in sys.argv[1:] if a.startswith("nk=")] or [(512,1),(1024,1),(4096,1),(256,4),(1024,4)]
mods = [renamed_kernels(r) for r in roots]

def make(mod):
    upd = mod._update_range
    @numba.njit
    def loop(wl, wsum, wb, bsum, diss, n_in, depth, dt, g_c, p, p_inv, lam, beta, coef, ek, dx):
        n = wl.shape[0]
        tot = 0.0; pk = 0.0
        for s in range(1, depth.shape[0]):
            t, q = upd(wl, wsum, wb, bsum, diss, 0, n, n_in, depth[s-1], depth[s], (depth[s]-depth[s-1])/dt,
                       g_c, p, p_inv, lam, beta, coef, ek, dx, 0.0, 0.0)
            tot += t; pk = max(pk, q)
        return tot, pk
    return loop

loops = [make(m) for m in mods]
rng = np.random.default_rng(1)
for n, k in cases:
    dx = 1e-6
    g_c = ((np.arange(n) + 0.5) * dx) ** 2 / 2e-3
    lam = np.logspace(1, 3, k) if k > 1 else np.array([100.0])
    beta = np.linspace(1.0, 2.0, k)
    p = np.eye(k) + 0.1 * rng.standard_normal((k, k))
    p_inv = np.linalg.inv(p)
    rate = lam * 0.7
    ek = np.linspace(1e6, 2e6, k)
    wl0 = 1e-7 * rng.random((n, k)); wb0 = 0.5 * rng.random((n, k))
    steps = 400
    depth = 1e-6 * (1.0 + 0.3 * np.sin(np.arange(steps + 1) * 0.01))
    n_in = int(n * fraction)
    states = []
    for mod, loop in zip(mods, loops):
        coef = mod.coefficient_workspace(k)
        mod._substep_coefficients(lam, rate, 1e-3, coef)
        st = [wl0.copy(), wl0.sum(1), wb0.copy(), wb0.sum(1), np.zeros(n)]
        if k == 1 and "wsum" not in dict(mod._state_layout(n, k)):
            # As in the module's own rows: wsum and bsum are wl and wb (0.10.0).
            st[1], st[3] = st[0].reshape(n), st[2].reshape(n)
        states.append((st, coef))
    def run(j):
        mod, loop = mods[j], loops[j]
        st, coef = states[j]
        st[0][:] = wl0; st[2][:] = wb0
        return loop(st[0], st[1], st[2], st[3], st[4], n_in, depth, 1e-3, g_c, p, p_inv, lam, beta, coef, ek, dx)
    res = [run(j) for j in range(len(mods))]
    for j in range(1, len(mods)):
        st0, st = states[0][0], states[j][0]
        same = all(np.array_equal(a.view(np.int64), b.view(np.int64)) for a, b in zip(st0[:4], st[:4]))
        print(f"  [{j}] state equal {same}, total {res[j][0]==res[0][0]} ({(res[j][0]-res[0][0])/res[0][0]:.2e}), peak {res[j][1]==res[0][1]}")
    samples = [[] for _ in mods]
    for r in range(int(9 if n <= 1024 else 5) * 3):
        for j in range(len(mods)):
            t0 = time.thread_time(); run(j); samples[j].append(time.thread_time() - t0)
    med = [np.median(s) / steps * 1e6 for s in samples]
    print(f"N={n} K={k}: " + "  ".join(f"{roots[j].split('/')[-1]} {med[j]:.3f} us ({med[j]/n*1e3:.2f} ns/el)" for j in range(len(mods))) + f"  B/A {med[-1]/med[0]:.3f}")
