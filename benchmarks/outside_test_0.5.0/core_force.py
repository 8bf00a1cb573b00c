"""Force control from rest at F = 0 and small tensile / compressive forces, K = 0/1/2/4.

For each: the answer's force vs the target (relative to the pull-off force), and a
cross-check: the same step under depth control at the depth the force search published
must give the same force (step == step under depth control on the same history).
"""

import math
import sys
import time as _t

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import chain, contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

R, W = 5e-3, 0.05


def probe(K, targets, dt=1e-3, tau=(2.1,), preset="balanced"):
    mat = chain(K, tau_ret=tau)
    c = contact(material=mat, numerics={"preset": preset})
    g0 = mat["glass_shear_modulus"]
    gk = mat.get("kelvin_shear_moduli", [])
    ginf = 1 / (1 / g0 + sum(1 / g for g in gk))
    fpo = 1.5 * math.pi * R * W * g0 / ginf  # slow pull-off scale
    rows = []
    for target in targets:
        sim = ContactSimulator(c)
        snap = sim.snapshot()
        w0 = _t.perf_counter()
        try:
            o = sim.step(dt, force=target)
        except Exception as e:  # noqa: BLE001
            rows.append((K, target, None, str(e)[:100]))
            continue
        wall = _t.perf_counter() - w0
        # cross-check under depth control from the same start
        sim2 = ContactSimulator(c)
        sim2.restore(snap)
        o2 = sim2.step(dt, depth=o.depth)
        rows.append((K, target, o, wall, o2))
    return rows, fpo


if __name__ == "__main__":
    for K in (0, 1, 2, 4):
        targets = [0.0, -1e-7, -1e-5, -1e-4, 1e-7, 1e-5]
        rows, fpo = probe(K, targets)
        for row in rows:
            if row[2] is None:
                print(f"K={K} F*={row[1]:+.1e} REFUSED: {row[3]}")
                continue
            K_, target, o, wall, o2 = row
            print(
                f"K={K} F*={target:+.1e} -> F={o.force:+.4e} d={o.depth:+.4e} a={o.contact_radius:.3e} "
                f"phase={int(o.phase)} unstable={o.unstable} |F-F*|/Fpo={abs(o.force - target) / fpo:.2e} "
                f"depth-ctl F={o2.force:+.4e} a={o2.contact_radius:.3e} diff/Fpo={abs(o2.force - o.force) / fpo:.2e} "
                f"wall={wall * 1e3:.1f}ms",
                flush=True,
            )
