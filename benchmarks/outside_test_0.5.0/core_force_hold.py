"""Force control held over long times at F = 0 and small tensile forces after a press
(the node's hold timer does exactly this: step(t, force=F) at publish_rate). K = 1 and 2,
retardation 10-1000 s. Checks: |F - F*| relative to the pull-off, no NaN, energy dissipated
never decreasing, the phase/unstable flags, and time per step."""

import math
import sys
import time as _t

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

for label, mat in (
    (
        "K=1 tau_ret 10 s",
        {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4], "kelvin_viscosities": [5e5]},
    ),
    (
        "K=2 tau_ret 10/1000 s",
        {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4, 1e5], "kelvin_viscosities": [5e5, 1e8]},
    ),
):
    for target in (0.0, -1e-4, -1e-3, -5e-3):
        s = ContactSimulator(contact(material=mat))
        s.step_depths(np.linspace(1e-3, 0.1, 100), np.linspace(1e-6, 200e-6, 100))
        fpo = 24.74e-3
        worst, nonfin, drops, unstable, slow = 0.0, 0, 0, 0, 0.0
        ed = s.output.energy_dissipated
        t = 0.1
        detached_at = None
        for k in range(400):
            t += 10.0 ** (-2 + 5 * k / 400)  # steps from 10 ms to 1000 s
            w = _t.perf_counter()
            try:
                o = s.step(t, force=target)
            except Exception as e:  # noqa: BLE001
                print(
                    f"   {label} F*={target}: step {k} at t={t:.4g} raised {type(e).__name__}: {str(e)[:120]}"
                )
                break
            slow = max(slow, _t.perf_counter() - w)
            vals = (o.force, o.depth, o.contact_radius, o.energy_dissipated)
            nonfin += not all(math.isfinite(v) for v in vals)
            drops += o.energy_dissipated < ed
            ed = o.energy_dissipated
            unstable += o.unstable
            if o.contact_radius > 0:
                worst = max(worst, abs(o.force - target) / fpo)
            elif detached_at is None:
                detached_at = (t, o.force)
        print(
            f"{label:22s} F*={target:+.0e}: max |F-F*|/Fpo in contact {worst:.1e}, nonfinite {nonfin}, "
            f"dissipated drops {drops}, unstable rows {unstable}, detached at {detached_at}, "
            f"final d={o.depth * 1e6:.2f} um a={o.contact_radius * 1e3:.3f} mm, slowest step {slow * 1e3:.1f} ms",
            flush=True,
        )
