"""Force control through step(t, force=) on varied scenes; saves outputs. Also checks finite
outputs, dissipated non-decreasing. usage: <venv>/bin/python run_force.py OUT.npz"""

import sys

import numpy as np
from scenes import CHAINS, CONE, SPHERE, contact_of, section

from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

saved = {}
for k in (0, 1, 2, 4):
    for ind_name, ind in (("sphere", SPHERE), ("cone", CONE)):
        for dt in (1e-3, 2e-2):
            c = contact_of(section(ind, *CHAINS[k]))
            t = np.arange(1, int(2.0 / dt) + 1) * dt
            # press to 0.3 N, hold, pull to -30 mN (beyond pull-off for most), back
            f = np.interp(t, [0, 0.3, 1.0, 1.6, 1.7, 2.0], [0, 0.3, 0.3, -0.03, 0.05, -0.05])
            sim = ContactSimulator(c)
            rows = []
            for a, b in zip(t, f, strict=False):
                o = sim.step(float(a), force=float(b))
                rows.append([float(getattr(o, x)) for x in STEP_OUTPUT_FIELDS])
            arr = np.array(rows)
            name = f"force_{ind_name}_K{k}_dt{dt:g}"
            saved[name] = arr
            dis = arr[:, STEP_OUTPUT_FIELDS.index("energy_dissipated")]
            bad = "" if np.all(np.isfinite(arr)) and np.all(np.diff(dis) >= 0) else " BAD"
            print(name, len(t), bad, flush=True)
np.savez(sys.argv[1], fields=np.array(STEP_OUTPUT_FIELDS), **saved)
