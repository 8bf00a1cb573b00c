# ruff: noqa: E501
"""Scenes for the outside test of the 0.4.0 kernel changes (tester).

Each scene: (name, contact section dict, times, depths) -- depth control, so that step()
per call, step_depths and the old core (c28c75b) can all be run on the same history.
Depths are built relative to the scene's characteristic depth where adhesion matters.
"""

from __future__ import annotations

import numpy as np

G0 = 1.0e6


def section(indenter, kelvin=(), visc=(), work=0.05, numerics=None, g0=G0):
    material = {"glass_shear_modulus": g0}
    if kelvin:
        material.update(kelvin_shear_moduli=list(kelvin), kelvin_viscosities=list(visc))
    s = {"indenter": dict(indenter), "material": material, "adhesion": {"work_of_adhesion": work}}
    num = {"model": "time_stepped"}
    num.update(numerics or {})
    s["numerics"] = num
    return s


SPHERE = {"shape": "sphere", "radius": 5e-3}
CONE = {"shape": "cone", "half_angle": 1.4}
PUNCH = {"shape": "flat_punch", "radius": 1e-3}
POWER = {"shape": "power_law", "coefficient": 3.0e4, "exponent": 3.0}

# Kelvin chains (G_k, eta_k): retardation times eta/G far apart.
CHAINS = {
    0: ((), ()),
    1: ((5e4,), (1.05e5,)),  # default scene, creep 2.1 s
    2: ((1e5, 3e5), (1e5 * 1e-4, 3e5 * 1e3)),  # 1e-4 s and 1e3 s
    4: ((2e5, 2e5, 2e5, 2e5), (2e5 * 1e-4, 2e5 * 1e-2, 2e5 * 1.0, 2e5 * 1e3)),
}


def piecewise(points, dt):
    """Times and depths linear between (t, d) knots, sampled every dt (the knots included)."""
    ts = [points[0][0]]
    ds = [points[0][1]]
    for (t0, d0), (t1, d1) in zip(points[:-1], points[1:], strict=False):
        n = max(1, int(round((t1 - t0) / dt)))
        for i in range(1, n + 1):
            ts.append(t0 + (t1 - t0) * i / n)
            ds.append(d0 + (d1 - d0) * i / n)
    return np.array(ts[1:]), np.array(ds[1:])


def cycle(depth, speed_in, hold, speed_out, pull, dt, recontact=True):
    """Press to depth at speed_in, hold, pull to -pull at speed_out, then (re)press quickly
    while memory is left, pull off again."""
    t1 = depth / speed_in
    t2 = t1 + hold
    t3 = t2 + (depth + pull) / speed_out
    pts = [(0.0, 0.0), (t1, depth), (t2, depth), (t3, -pull)]
    if recontact:
        t4 = t3 + 0.05 * (t3 - t2) + dt
        t5 = t4 + (depth + pull) / speed_in
        t6 = t5 + (depth + pull) / speed_out
        pts += [(t4, -pull), (t5, 0.5 * depth), (t6, -2 * pull)]
    return piecewise(pts, dt)


def scenes():
    out = []
    dc = 41e-6  # default scene's characteristic depth
    # 1. default material, sphere, varied speeds and step sizes, K = 1
    for dt in (1e-3, 1e-2, 1e-4):
        t, d = cycle(3 * dc, 1e-3, 1.0, 1e-3, 2 * dc, dt)
        out.append((f"sphere_K1_dt{dt:g}", section(SPHERE, *CHAINS[1]), t, d))
    # fast edges racing: 1 kHz, fast press/pull
    t, d = cycle(3 * dc, 1e-1, 0.05, 1e-1, 2 * dc, 1e-3)
    out.append(("sphere_K1_fast_1kHz", section(SPHERE, *CHAINS[1]), t, d))
    # huge steps (dt 10 s) and tiny (1e-6)
    t, d = cycle(3 * dc, 1e-5, 100.0, 1e-5, 2 * dc, 10.0)
    out.append(("sphere_K1_dt10", section(SPHERE, *CHAINS[1]), t, d))
    t, d = cycle(0.3 * dc, 10.0, 1e-3, 10.0, 0.2 * dc, 1e-6)
    out.append(("sphere_K1_dt1e-6", section(SPHERE, *CHAINS[1]), t, d))
    # deep press 100 x dc
    t, d = cycle(100 * dc, 1e-2, 0.5, 1e-2, 2 * dc, 2e-3)
    out.append(("sphere_K1_deep100", section(SPHERE, *CHAINS[1]), t, d))
    # K = 0, 2, 4 (time-stepped), retardation times far apart
    for k in (0, 2, 4):
        for dt in (1e-3, 1e-1):
            t, d = cycle(3 * dc, 3e-3, 2.0, 3e-3, 2 * dc, dt)
            out.append((f"sphere_K{k}_dt{dt:g}", section(SPHERE, *CHAINS[k]), t, d))
        t, d = cycle(3 * dc, 1e-1, 0.02, 1e-1, 2 * dc, 1e-3)
        out.append((f"sphere_K{k}_fast", section(SPHERE, *CHAINS[k]), t, d))
    # indenters
    for name, ind in (("cone", CONE), ("punch", PUNCH), ("power", POWER)):
        for k in (1, 2):
            t, d = cycle(3 * dc, 1e-2, 0.5, 1e-2, 2 * dc, 1e-3)
            out.append((f"{name}_K{k}", section(ind, *CHAINS[k]), t, d))
    # presets, a substep cap, tolerance mode
    for preset in ("fast", "accurate"):
        t, d = cycle(3 * dc, 1e-1, 0.05, 1e-1, 2 * dc, 1e-3)
        out.append((f"sphere_K1_{preset}", section(SPHERE, *CHAINS[1], numerics={"preset": preset}), t, d))
    for cap in (1e-4, 3e-6):
        t, d = cycle(3 * dc, 1e-1, 0.05, 1e-1, 2 * dc, 1e-3)
        out.append(
            (f"sphere_K1_cap{cap:g}", section(SPHERE, *CHAINS[1], numerics={"max_substep": cap}), t, d)
        )
        out.append(
            (f"sphere_K4_cap{cap:g}", section(SPHERE, *CHAINS[4], numerics={"max_substep": cap}), t, d)
        )
    t, d = cycle(3 * dc, 1e-1, 0.05, 1e-1, 2 * dc, 1e-3)
    out.append(("sphere_K1_tol3e-3", section(SPHERE, *CHAINS[1], numerics={"tolerance": 3e-3}), t, d))
    out.append(("sphere_K2_tol1e-2", section(SPHERE, *CHAINS[2], numerics={"tolerance": 1e-2}), t, d))
    # random-walk history with re-contacts (seeded), K = 2 and K = 4
    rng = np.random.default_rng(13)
    for k in (1, 2, 4):
        n = 1500
        dt = 10 ** rng.uniform(-4, -1, n)
        t = np.cumsum(dt)
        v = np.cumsum(rng.normal(0, 1, n))
        d = dc * (1.5 * v / np.max(np.abs(v)) + 0.3)
        out.append((f"random_K{k}", section(SPHERE, *CHAINS[k]), t, d))
    # hard racing scenes: many elements, far-apart modes, fast preset (2 cells per substep)
    for n in (1024, 4096):
        for k in (1, 4):
            t, d = cycle(3 * dc, 2e-1, 0.02, 2e-1, 2 * dc, 1e-3)
            out.append((f"race_N{n}_K{k}", section(SPHERE, *CHAINS[k], numerics={"elements": n}), t, d))
    t, d = cycle(5 * dc, 5e-1, 0.01, 5e-1, 3 * dc, 1e-3)
    out.append(("race_fast_K4", section(SPHERE, *CHAINS[4], numerics={"preset": "fast"}), t, d))
    out.append(("race_fast_K2_cone", section(CONE, *CHAINS[2], numerics={"preset": "fast"}), t, d))
    out.append(
        (
            "race_N1024_K4_cap",
            section(SPHERE, *CHAINS[4], numerics={"elements": 1024, "max_substep": 2e-5}),
            t,
            d,
        )
    )
    # deep press with growth at 1 kHz then a fast pull: the edge recedes over many cells
    t, d = cycle(100 * dc, 2e-1, 0.01, 5e-1, 3 * dc, 1e-3)
    out.append(("race_deep_K2", section(SPHERE, *CHAINS[2]), t, d))
    out.append(("race_deep_K4_N1024", section(SPHERE, *CHAINS[4], numerics={"elements": 1024}), t, d))
    # same-time depth jumps (dt = 0 rows) inside a history
    t, d = cycle(3 * dc, 1e-2, 0.2, 1e-2, 2 * dc, 1e-3)
    t = t.copy()
    t[5::9] = t[4::9][: t[5::9].size]
    out.append(("dt0_jumps_K1", section(SPHERE, *CHAINS[1]), t, d))
    out.append(("dt0_jumps_K4", section(SPHERE, *CHAINS[4]), t, d))
    return out


def contact_of(sec):
    from viscoadh_ros.core.config import SceneConfig

    return SceneConfig.from_dict({"contacts": ["c"], "c": sec}).contact("c")
