"""step() loop == step_depths on the same history; snapshot/restore repeatability; energy
dissipated >= 0 and never decreasing; no NaN. K = 0/1/2/4, slow pads (retardation 10-1000 s),
presses 100 d_c deep with holds and pull-offs, presets and numerics.tolerance."""

import sys

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import chain, contact  # noqa: E402

from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator  # noqa: E402

DC = 41.27e-6


def history(rng, n=600, t_total=5000.0, depth_max=100 * DC):
    knots_t = np.sort(rng.uniform(0, t_total, 12))
    knots_t[0] = 0.0
    knots_d = rng.uniform(-3 * DC, depth_max, 12)
    knots_d[rng.integers(0, 12, 3)] = -5 * DC  # some pull-offs
    t = np.sort(rng.uniform(1e-3, t_total, n))
    # stamps repeated on purpose (dt = 0 rows)
    t[rng.integers(1, n, 5)] = t[rng.integers(1, n, 5) - 1]
    t = np.sort(t)
    d = np.interp(t, knots_t, knots_d)
    return t, d


def compare(a, b):
    worst = {}
    for f in STEP_OUTPUT_FIELDS:
        x, y = np.asarray(a[f], float), np.asarray(b[f], float)
        if not np.array_equal(x, y):
            i = int(np.flatnonzero(x != y)[0])
            worst[f] = (i, x[i], y[i], float(np.max(np.abs(x - y))))
    return worst


def main():
    rng = np.random.default_rng(5)
    cases = []
    for K in (0, 1, 2, 4):
        for tau in (10.0, 1000.0):
            for num in ({"preset": "fast"}, {"preset": "balanced"}, {"tolerance": 1e-3}):
                cases.append((K, tau, num))
    problems = 0
    for K, tau, num in cases:
        c = contact(material=chain(K, tau_ret=(tau,)), numerics=dict(num, model="time_stepped"))
        t, d = history(rng)
        s1 = ContactSimulator(c)
        rows = [s1.step(float(ti), depth=float(di)) for ti, di in zip(t, d)]
        a = {f: np.array([getattr(r, f) for r in rows], dtype=float) for f in STEP_OUTPUT_FIELDS}
        s2 = ContactSimulator(c)
        b = s2.step_depths(t, d)
        diff = compare(a, b)
        # snapshot mid-way, restore into a fresh simulator, continue
        k = len(t) // 2
        s3 = ContactSimulator(c)
        s3.step_depths(t[:k], d[:k])
        snap = s3.snapshot()
        rest1 = s3.step_depths(t[k:], d[k:])
        s4 = ContactSimulator(c)
        s4.restore(snap)
        rest2 = s4.step_depths(t[k:], d[k:])
        s3.restore(snap)
        rest3 = s3.step_depths(t[k:], d[k:])
        dsnap = compare(rest1, rest2)
        dsnap3 = compare(rest1, rest3)
        ed = a["energy_dissipated"]
        nonfin = sum(int(np.count_nonzero(~np.isfinite(a[f]))) for f in STEP_OUTPUT_FIELDS)
        drop = float(np.min(np.diff(ed)))
        ok = not diff and not dsnap and not dsnap3 and nonfin == 0 and ed.min() >= 0 and drop >= 0
        problems += not ok
        print(
            f"K={K} tau={tau:6g} {num} N={s1.numerics.elements}: step==step_depths {not diff} "
            f"{'' if not diff else list(diff.items())[:2]} snapshot->new {not dsnap} "
            f"{'' if not dsnap else list(dsnap.items())[:2]} restore-same {not dsnap3} nonfinite={nonfin} "
            f"ed_min={ed.min():.3g} ed_drop={drop:.3g} pull={a['force'].min():.4g} peak={a['force'].max():.4g}",
            flush=True,
        )
    print("problems:", problems)


if __name__ == "__main__":
    main()
