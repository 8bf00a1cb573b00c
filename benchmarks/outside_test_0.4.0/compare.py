# ruff: noqa: E501
"""Compare run_scenes outputs: new per-call vs new step_depths (bit for bit), new vs old
(c28c75b), and invariants (finite, dissipated >= 0 and non-decreasing).

usage: python repro/compare.py NEW.npz OLD.npz
"""

import sys

import numpy as np

new = np.load(sys.argv[1])
old = np.load(sys.argv[2])
fields = list(new["fields"])
names = sorted(
    {k.split("/")[0] for k in new.files if "/" in k}, key=lambda s: list(new.files).index(s + "/call")
)
fi = {f: i for i, f in enumerate(fields)}
cols = ["force", "contact_radius", "energy_input", "energy_dissipated", "phase"]
print(
    f"{'scene':28s} {'call!=rows':>10s} | new vs old, max |diff| / column max:",
    "  ".join(f"{c[:10]:>10s}" for c in cols),
    " rows/first",
)
for name in names:
    a = new[name + "/call"]
    b = new[name + "/rows"]
    o = old[name + "/call"]
    same = (
        "equal"
        if a.shape == b.shape and np.array_equal(a, b)
        else (f"{np.count_nonzero(np.any(a != b, axis=1)) if a.shape == b.shape else 'shape'}")
    )
    bad = []
    if not np.all(np.isfinite(a)):
        bad.append("NONFINITE")
    dis = a[:, fi["energy_dissipated"]]
    if np.any(dis < 0) or np.any(np.diff(dis) < 0):
        bad.append(f"DISSIPATED-DECREASES(min diff {np.min(np.diff(dis)):.3g})")
    rel = []
    first = ""
    if a.shape == o.shape:
        for c in cols:
            x, y = a[:, fi[c]], o[:, fi[c]]
            scale = max(np.max(np.abs(y)), 1e-300)
            r = np.max(np.abs(x - y)) / scale
            rel.append(f"{r:10.2e}")
            if c == "force" and r > 0:
                idx = np.flatnonzero(x != y)
                first = f"{idx.size}/{idx[0]}"
    else:
        rel = [f"shape {a.shape} vs {o.shape}"]
    print(f"{name:28s} {same:>10s} | {'  '.join(rel)} {first} {' '.join(bad)}")
