"""Seeded random histories through zero (many snap-ins and pull-offs with memory left), K = 1,
2, 4 with retardation times 1e-4..1e3 s, sphere/cone/power law, random dt 1e-5..1 s."""

import numpy as np
from scenes import CHAINS, CONE, POWER, SPHERE, section

dc = 41e-6


def scenes():
    rng = np.random.default_rng(2026)
    out = []
    inds = (("sphere", SPHERE), ("cone", CONE), ("power", POWER))
    for i in range(18):
        k = (1, 2, 4)[i % 3]
        iname, ind = inds[(i // 3) % 3]
        n = 300
        dt = 10 ** rng.uniform(-5, 0, n)
        t = np.cumsum(dt)
        # piecewise walk: segments of random sign, crossing zero often
        d = dc * np.cumsum(rng.normal(0, 0.4, n))
        d = d - np.median(d) + dc * rng.uniform(-0.3, 0.6)
        d = np.clip(d, -3 * dc, 6 * dc)
        out.append((f"fuzz{i}_{iname}_K{k}", section(ind, *CHAINS[k]), t, d))
    return out
