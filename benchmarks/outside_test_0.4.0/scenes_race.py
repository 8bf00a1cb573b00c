# ruff: noqa: E501
"""Racing scenes at 1 kHz: the edge crosses ~10-40 elements per step (many substeps)."""

from scenes import CHAINS, CONE, POWER, SPHERE, cycle, section

dc = 41e-6


def scenes():
    out = []
    for n in (1024, 4096):
        for k in (1, 2, 4):
            t, d = cycle(3 * dc, 2e-2, 0.05, 2e-2, 2 * dc, 1e-3)
            out.append((f"race2_N{n}_K{k}", section(SPHERE, *CHAINS[k], numerics={"elements": n}), t, d))
    t, d = cycle(3 * dc, 2e-2, 0.05, 2e-2, 2 * dc, 1e-3)
    out.append(
        ("race2_fast_K4", section(SPHERE, *CHAINS[4], numerics={"preset": "fast", "elements": 1024}), t, d)
    )
    out.append(("race2_cone_K4", section(CONE, *CHAINS[4], numerics={"elements": 1024}), t, d))
    out.append(("race2_power_K2", section(POWER, *CHAINS[2], numerics={"elements": 1024}), t, d))
    out.append(
        ("race2_cap_K4", section(SPHERE, *CHAINS[4], numerics={"elements": 1024, "max_substep": 1e-4}), t, d)
    )
    return out
