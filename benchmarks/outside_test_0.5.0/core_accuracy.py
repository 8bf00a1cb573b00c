"""Preset / tolerance accuracy on deep presses into slowly relaxing pads (retardation 10-1000 s,
100 d_c), long hold, pull-off; error of every row and of the pull-off, normalised by the
reference's pull-off force (reference: elements 4096, accurate step control)."""

import sys
import time as _t

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

DC = 41.27e-6


def material(K, tau0):
    taus = [tau0 * 10.0**i for i in range(K)]
    return {
        "glass_shear_modulus": 1e6,
        "kelvin_shear_moduli": [5e4 * (i + 1) for i in range(K)],
        "kelvin_viscosities": [5e4 * (i + 1) * t for i, t in enumerate(taus)],
    }


def hist(tau0, K, hold_factor, ret_factor, depth=100 * DC, n=3000):
    tau_max = tau0 * 10.0 ** (K - 1)
    t_press = 0.01 * tau0
    hold = hold_factor * tau_max
    t_ret = ret_factor * tau0
    tk = [0, t_press, t_press + hold, t_press + hold + t_ret]
    dk = [-DC, depth, depth, -8 * DC]
    t = np.concatenate(
        [
            np.linspace(1e-6, t_press, n // 3),
            np.linspace(t_press, t_press + hold, 50)[1:],
            np.linspace(t_press + hold, tk[-1], n)[1:],
        ]
    )
    return t, np.interp(t, tk, dk)


def run(c, t, d):
    s = ContactSimulator(c)
    w = _t.perf_counter()
    o = s.step_depths(t, d)
    return o, _t.perf_counter() - w, s.numerics.elements


if __name__ == "__main__":
    for K, tau0, hold_f, ret_f in (
        (1, 10.0, 10, 10),
        (1, 1000.0, 10, 1),
        (2, 10.0, 10, 10),
        (4, 10.0, 3, 10),
    ):
        t, d = hist(tau0, K, hold_f, ret_f)
        ref, wref, nref = run(
            contact(material=material(K, tau0), numerics={"preset": "accurate", "elements": 4096}), t, d
        )
        fpo = abs(ref["force"].min())
        print(
            f"K={K} tau0={tau0:g} hold={hold_f}x ret={ret_f}x: ref pull-off {ref['force'].min() * 1e3:.4f} mN "
            f"peak/|Fpo|={ref['force'].max() / fpo:.0f} (N={nref}, {wref:.1f}s)",
            flush=True,
        )
        for num in (
            {"preset": "fast"},
            {"preset": "balanced"},
            {"preset": "accurate"},
            {"tolerance": 1e-2},
            {"tolerance": 3e-3},
        ):
            o, w, n = run(contact(material=material(K, tau0), numerics=num), t, d)
            err = np.abs(o["force"] - ref["force"]) / fpo
            i = int(np.argmax(err))
            ret = t > t[len(t) // 3 + 49]
            print(
                f"   {str(num):22s} N={n:5d} pull-off err={(o['force'].min() - ref['force'].min()) / fpo:+.2e} "
                f"max row err={err.max():.2e} at t={t[i]:.4g} d={d[i] / DC:.1f}d_c  retract-branch max={err[ret].max():.2e} "
                f"nonfinite={int(np.count_nonzero(~np.isfinite(o['force'])))} {w:.1f}s",
                flush=True,
            )
