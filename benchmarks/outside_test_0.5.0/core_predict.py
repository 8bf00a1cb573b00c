"""predict_pull_off (what the node's service answers) against doing that retraction: the
same state, retracted at the same speed with 5x finer rows. Relative to the pull-off force."""

import sys

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.history import predict_pull_off  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

DC = 41.27e-6
K2 = {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4, 2e5], "kelvin_viscosities": [1.05e5, 2e3]}
for label, mat in (("default K=1", None), ("K=2", K2)):
    for depth_f, hold, speed in (
        (4, 1.0, 1e-5),
        (4, 1.0, 1e-3),
        (100, 10.0, 1e-4),
        (1, 0.01, 1e-2),
        (0.3, 0.0, 1e-6),
    ):
        c = contact(material=mat) if mat else contact()
        s = ContactSimulator(c)
        D = depth_f * DC
        s.step_depths(np.linspace(1e-3, 0.1, 100), np.linspace(D / 100, D, 100))
        if hold:
            s.step(0.1 + hold, depth=D)
        p = predict_pull_off(s, speed)
        # do it: retract at `speed` with rows 5x finer than the prediction's until detached
        t0, d0 = s.time, s.output.depth
        dt = p.time_to_detach / 2000 if p.detached else 1e-3
        n = 2400
        tt = t0 + dt * np.arange(1, n + 1)
        out = s.step_depths(tt, d0 - speed * (tt - t0))
        i = int(np.argmin(out["force"]))
        det = np.flatnonzero(out["contact_radius"] == 0.0)
        t_det = tt[det[0]] - t0 if det.size else float("nan")
        fpo = abs(out["force"][i])
        print(
            f"{label:12s} D={depth_f:5g}d_c hold={hold:5g}s v={speed:g}: predicted {p.pull_off_force * 1e3:9.4f} mN, "
            f"done {out['force'][i] * 1e3:9.4f} mN, diff/Fpo={(p.pull_off_force - out['force'][i]) / fpo:+.2e}; "
            f"detach predicted {p.time_to_detach:.4g} s, done {t_det:.4g} s ({p.message[:40]})",
            flush=True,
        )
