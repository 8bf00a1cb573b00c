"""Closed-form limits (physics.md s4) on a slowly relaxing pad pressed 100 d_c deep.

slow: glassy press, long hold, retraction slow against the retardation time -> pull-off
      -(3/2) pi R w_eff2.
fast: press and retract fast against the retardation time, no hold -> glassy JKR -(3/2) pi R w.
Errors relative to the pull-off force. Invariants on every row: finite, dissipated >= 0 and
non-decreasing.
"""

import math
import sys
import time as _t

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import bad, contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

R, G0, G1, W = 5e-3, 1e6, 5e4, 0.05
ginf = G0 * G1 / (G0 + G1)
er = 4 * ginf
weff2 = W * (G0 + G1) / G1
dc = (3 * math.pi**2 * weff2**2 * R / (64 * er**2)) ** (1 / 3)
F_slow = -1.5 * math.pi * R * weff2
F_fast = -1.5 * math.pi * R * W


def run(tau_ret, depth_factor, preset, tol=0.0, mode="slow"):
    mat = {"glass_shear_modulus": G0, "kelvin_shear_moduli": [G1], "kelvin_viscosities": [G1 * tau_ret]}
    num = {"preset": preset}
    if tol:
        num["tolerance"] = tol
    sim = ContactSimulator(contact(material=mat, numerics=num))
    D = depth_factor * dc
    if mode == "slow":
        t_press = 1e-3 * tau_ret
        hold = 20 * tau_ret
        t_ret = 2e3 * tau_ret * (D + 2 * dc) / dc  # ~2000 tau_ret per d_c
        n_press, n_ret = 200, 40000
    else:
        t_press = 1e-4 * tau_ret
        hold = 0.0
        t_ret = 1e-4 * tau_ret * (D + 2 * dc) / D
        n_press, n_ret = 200, 40000
    tp = np.linspace(0, t_press, n_press + 1)[1:]
    dp = D * tp / t_press
    th = np.array([t_press + hold]) if hold else np.empty(0)
    dh = np.full(th.size, D)
    tr = t_press + hold + np.linspace(0, t_ret, n_ret + 1)[1:]
    dr = D - (D + 2 * dc) * (tr - t_press - hold) / t_ret
    t = np.concatenate([tp, th, tr])
    d = np.concatenate([dp, dh, dr])
    w0 = _t.perf_counter()
    out = sim.step_depths(t, d)
    wall = _t.perf_counter() - w0
    f = out["force"]
    ed = out["energy_dissipated"]
    nonfin = sum(bad(out[k]) for k in ("force", "contact_radius", "energy_input", "energy_dissipated"))
    drops = np.diff(ed)
    return dict(
        pull=f.min(),
        peak=f.max(),
        nonfinite=nonfin,
        ed_min=ed.min(),
        ed_drop=drops.min() if drops.size else 0.0,
        ed_end=ed[-1],
        ein_end=out["energy_input"][-1],
        detached=out["contact_radius"][-1] == 0.0,
        wall=wall,
        elements=sim.numerics.elements,
    )


if __name__ == "__main__":
    print(f"d_c={dc * 1e6:.2f} um  F_slow={F_slow * 1e3:.3f} mN  F_fast={F_fast * 1e3:.4f} mN")
    for mode, ref in (("slow", F_slow), ("fast", F_fast)):
        for tau in (10.0, 1000.0):
            for depth_factor in (1.0, 100.0):
                for preset in ("fast", "balanced"):
                    r = run(tau, depth_factor, preset, mode=mode)
                    err = (r["pull"] - ref) / abs(ref)
                    print(
                        f"{mode:4s} tau_ret={tau:6g} D={depth_factor:5g}d_c {preset:8s} N={r['elements']:4d} "
                        f"pull={r['pull'] * 1e3:9.4f} mN err/Fpo={err:+.2%} peak/|Fpo|={r['peak'] / abs(ref):9.1f} "
                        f"nonfinite={r['nonfinite']} ed_min={r['ed_min']:.3g} ed_drop={r['ed_drop']:.3g} "
                        f"ed={r['ed_end']:.4g} ein={r['ein_end']:.4g} detached={r['detached']} wall={r['wall']:.2f}s",
                        flush=True,
                    )
