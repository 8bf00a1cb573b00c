"""Same as core_branch_error.py on a stiffer pad (G0 = 100 MPa, G1 = 5 MPa: the same G0/G1 = 20,
retardation 10 s) so that 100 d_c stays within the model's small-slope range (a/R ~ 0.19 at the
deepest point; ContactSimulator.model_validity is checked)."""

import math
import sys

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

R, G0, G1, W = 5e-3, 1e8, 5e6, 0.05
ginf = G0 * G1 / (G0 + G1)
weff2 = W * (G0 + G1) / G1
DC = (3 * math.pi**2 * weff2**2 * R / (64 * (4 * ginf) ** 2)) ** (1 / 3)
FPO = 1.5 * math.pi * R * weff2
MAT = {"glass_shear_modulus": G0, "kelvin_shear_moduli": [G1], "kelvin_viscosities": [G1 * 10.0]}
t = np.linspace(1e-4, 0.1, 1000)
d = 100 * DC * t / 0.1


def force(num):
    s = ContactSimulator(contact(material=MAT, numerics=num))
    o = s.step_depths(t, d)
    return o, s


ref, sref = force({"preset": "accurate", "elements": 8192})
ref2, _ = force({"preset": "accurate", "elements": 4096})
v = sref.model_validity
print(
    f"d_c={DC * 1e6:.2f} um, deepest a/R={ref['contact_radius'][-1] / R:.3f}, small_slope_ok={v.small_slope_ok} "
    f"(edge slope {v.edge_slope:.3f}); reference 4096 vs 8192: {np.max(np.abs(ref2['force'] - ref['force'])) / FPO:.1e} of Fpo"
)
for num, promise in (
    ({"preset": "fast"}, 0.07),
    ({"preset": "balanced"}, 0.01),
    ({"tolerance": 1e-2}, 1e-2),
    ({"tolerance": 3e-3}, 3e-3),
    ({"tolerance": 1e-3}, 1e-3),
):
    o, s = force(num)
    err = np.abs(o["force"] - ref["force"]) / FPO
    over = np.flatnonzero(err > promise)
    print(
        f"{str(num):24s} N={s.numerics.elements:5d} max err/Fpo={err.max():.2e} = {err.max() / promise:.1f}x the promise "
        f"{promise:g}; rows over it: {over.size}/{err.size} (from d={d[over[0]] / DC if over.size else float('nan'):.1f} d_c)"
    )
