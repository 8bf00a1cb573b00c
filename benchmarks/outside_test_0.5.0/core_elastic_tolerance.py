"""numerics.tolerance on an elastic body (and a glassy one recognised through time_scale):
docs/configuration.md promises the largest force error of a press-and-pull history, every row,
relative to the pull-off force, <= tolerance for 5..300 d_c, "checked against the closed form
for the elastic and glassy bodies down to 1e-5". Reference here: the closed form (elastic) or
N = 8192 (glassy)."""

import math
import sys

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

R, G0, W = 5e-3, 1e6, 0.05
E = 4 * G0
dc = (3 * math.pi**2 * W**2 * R / (64 * E**2)) ** (1 / 3)
fpo = 1.5 * math.pi * R * W


def run(mat, num, depth_f, n=2000, t_total=1.0):
    s = ContactSimulator(contact(material=mat, numerics=num))
    t = np.linspace(1e-6, t_total, n)
    d = np.interp(t, [0, t_total / 2, t_total], [-dc, depth_f * dc, -3 * dc])
    return s.step_depths(t, d), s.numerics.elements, d


for depth_f in (5, 30, 100, 300):
    ref, _, d = run({"glass_shear_modulus": G0}, {"model": "closed_form"}, depth_f)
    for tol in (1e-2, 1e-3, 1e-4):
        o, n, _ = run({"glass_shear_modulus": G0}, {"model": "time_stepped", "tolerance": tol}, depth_f)
        err = np.abs(o["force"] - ref["force"]) / fpo
        i = int(np.argmax(err))
        po = (o["force"].min() - ref["force"].min()) / fpo
        print(
            f"elastic D={depth_f:3d} d_c tol={tol:g} N={n:4d}: max row err/Fpo={err.max():.2e} "
            f"({err.max() / tol:.1f}x tol) at d={d[i] / dc:.1f} d_c; pull-off err={po:+.1e}; peak/Fpo={ref['force'].max() / fpo:.0f}",
            flush=True,
        )
