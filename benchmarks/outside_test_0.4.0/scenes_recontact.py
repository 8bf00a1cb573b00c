# ruff: noqa: E501
"""Re-contact while memory is left (the snap-in located in time, 0.4.0): press and hold so the
Kelvin elements creep, pull out quickly, then (a) approach again in coarse steps, (b) hold
just above the surface while the surface creeps back up to the indenter, (c) retract slowly
while the surface creeps up faster (the gap rises, then falls)."""

from scenes import CHAINS, CONE, SPHERE, piecewise, section

dc = 41e-6


def scenes():
    out = []
    chains = {1: CHAINS[1], 2: ((1e5, 3e5), (1e5 * 1e-2, 3e5 * 1.0)), 4: CHAINS[4]}
    for k, (kel, vis) in chains.items():
        for dt in (1e-2, 1e-1):
            pts = [
                (0.0, 0.0),
                (0.1, 5 * dc),
                (5.0, 5 * dc),
                (5.01, -0.5 * dc),
                (5.5, -0.5 * dc),
                (8.0, 2 * dc),
                (8.1, -3 * dc),
            ]
            t, d = piecewise(pts, dt)
            out.append((f"reapproach_K{k}_dt{dt:g}", section(SPHERE, kel, vis), t, d))
            pts = [
                (0.0, 0.0),
                (0.1, 5 * dc),
                (5.0, 5 * dc),
                (5.001, -0.2 * dc),
                (9.0, -0.2 * dc),
                (9.1, -3 * dc),
            ]
            t, d = piecewise(pts, dt)
            out.append((f"creepup_K{k}_dt{dt:g}", section(SPHERE, kel, vis), t, d))
            pts = [
                (0.0, 0.0),
                (0.1, 5 * dc),
                (5.0, 5 * dc),
                (5.001, -0.1 * dc),
                (9.0, -1.5 * dc),
                (9.1, -3 * dc),
            ]
            t, d = piecewise(pts, dt)
            out.append((f"retractrise_K{k}_dt{dt:g}", section(SPHERE, kel, vis), t, d))
            out.append(
                (
                    f"cone_creepup_K{k}_dt{dt:g}",
                    section(CONE, kel, vis),
                    *piecewise(
                        [
                            (0.0, 0.0),
                            (0.1, 5 * dc),
                            (5.0, 5 * dc),
                            (5.001, -0.2 * dc),
                            (9.0, -0.2 * dc),
                            (9.1, -3 * dc),
                        ],
                        dt,
                    ),
                )
            )
    return out
