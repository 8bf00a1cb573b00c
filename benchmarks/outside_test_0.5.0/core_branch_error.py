"""Indentation-branch force error of a glassy press to 100 d_c (standard solid, retardation
10 s, press in 0.1 s, 1000 rows), relative to the pull-off force, against N = 4096 and 8192.

Documented (docs/configuration.md, core/presets.py): balanced <= 1 % and fast <= 7 % of the
pull-off on each branch for 5..300 d_c; tolerance T <= T on every row (known exception only
for a *relaxed* body pressed that deep). Prints the error profile along the press."""

import sys

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

DC = 41.27e-6
MAT = {"glass_shear_modulus": 1e6, "kelvin_shear_moduli": [5e4], "kelvin_viscosities": [5e5]}
FPO = 24.74e-3  # slow pull-off of this scene, -(3/2) pi R w_eff2 (N)

t = np.linspace(1e-4, 0.1, 1000)
d = 100 * DC * t / 0.1


def force(num):
    s = ContactSimulator(contact(material=MAT, numerics=num))
    o = s.step_depths(t, d)
    return o["force"], s


ref, _ = force({"preset": "accurate", "elements": 8192})
ref2, _ = force({"preset": "accurate", "elements": 4096})
print(
    f"reference 4096 vs 8192: max |dF|/Fpo = {np.max(np.abs(ref2 - ref)) / FPO:.2e}; peak/Fpo = {ref.max() / FPO:.0f}"
)
for num, promise in (
    ({"preset": "fast"}, 0.07),
    ({"preset": "balanced"}, 0.01),
    ({"preset": "accurate"}, 0.005),
    ({"tolerance": 1e-2}, 1e-2),
    ({"tolerance": 3e-3}, 3e-3),
    ({"tolerance": 1e-3}, 1e-3),
):
    f, s = force(num)
    err = np.abs(f - ref) / FPO
    bands = [
        err[(d >= lo * DC) & (d < hi * DC)].max()
        for lo, hi in ((0, 25), (25, 50), (50, 75), (75, 90), (90, 101))
    ]
    over = np.flatnonzero(err > promise)
    print(
        f"{str(num):24s} N={s.numerics.elements:5d} max={err.max():.2e} (promise {promise:g}) rows over: {over.size}/{err.size} "
        f"max by depth band 0-25/25-50/50-75/75-90/90-100 d_c: " + " ".join(f"{b:.1e}" for b in bands)
    )
