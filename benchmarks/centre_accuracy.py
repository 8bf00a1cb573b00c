"""Depth-control force of the scenes whose tests moved with the centre-crossing blend, against
the same scene at 8192 elements (round 0.11.0-centre).

    PYTHONPATH=<checkout> python benchmarks/centre_accuracy.py <checkout> [out.npz [base.npz]]

Runs the tests' histories of <checkout> under depth control at the contact's own numerics and
at ``elements: 8192`` (same preset and model otherwise) and prints, per scene, the largest and
the RMS |F - F_8192| / P (P: the pull-off force, -min of the 8192-element force of the scene's
press-pull history), where the largest lies, and the mean signed (F - F_8192) / P (a bias
moves a fit). The four force-search cases run the depths 0.2.0 reached under force control
(tests/force_control_golden.npz), the node-log scene the finger's press-pull of
tests/test_fit_node_log.py (0.5 s, 10 ms rows), and the same at w = 0.2 J/m^2 the stretch
tests/test_replay_parameters.py fits G0 on (equal to the node's logged force to 1e-15).
With ``base.npz`` (this script's output for another kernel, e.g. main's) it also prints, per
scene, the rows this kernel moved (by more than 1e-12 P, same contact state in both): how many,
their mean and largest error before and after, how many got closer, the mean signed error.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

checkout = Path(sys.argv[1])
sys.path.insert(0, str(checkout / "tests"))
from force_histories import CONTACTS, cases, decode  # noqa: E402
from scenes import STANDARD_SOLID_FINGER  # noqa: E402

from viscoadh_ros.core.config import SceneConfig  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

GOLDEN = np.load(checkout / "tests" / "force_control_golden.npz")


def fine(contact):
    return dataclasses.replace(contact, numerics=dataclasses.replace(contact.numerics, elements=8192))


def forces(contact, times, depths):
    """Force and contact radius per row under depth control."""
    sim = ContactSimulator(contact)
    rows = [sim.step(float(t), depth=float(d)) for t, d in zip(times, depths, strict=True)]
    return np.array([o.force for o in rows]), np.array([o.contact_radius for o in rows])


scenes = {}
FORCE_SEARCH = (
    "default_bench_sine",
    "default_hold_pull",
    "finger_depth_then_force",
    "cone_k2_depth_then_force",
)
for name in FORCE_SEARCH:
    contact_name, _ = cases()[name]
    commands = decode(GOLDEN[f"{name}/commands"])
    times = np.array([c[1] for c in commands])
    depths = GOLDEN[f"{name}/depth"]
    scenes[name] = (CONTACTS[contact_name](), times, depths)
times = np.arange(0.0, 0.5, 0.01)
scenes["finger_node_log_cycle"] = (
    SceneConfig.from_parameters(STANDARD_SOLID_FINGER).contact("finger"),
    times,
    np.interp(times, [0.0, 0.2, 0.5], [-1e-6, 20e-6, -30e-6]),
)
# The same cycle at w = 0.2 J/m^2: the stretch tests/test_replay_parameters.py fits G0 on (after
# the logged change of the work of adhesion; the node's contact is out of touch and relaxed then).
scenes["finger_node_log_cycle_w02"] = (
    SceneConfig.from_parameters({**STANDARD_SOLID_FINGER, "finger.adhesion.work_of_adhesion": 0.2}).contact(
        "finger"
    ),
    times,
    np.interp(times, [0.0, 0.2, 0.5], [-1e-6, 20e-6, -30e-6]),
)

out = {}
print(
    f"{'scene':26s} {'elem':>4s} {'P (N)':>9s} {'max|dF|/P':>10s} {'row':>5s} {'rms':>9s}"
    f" {'state differs':>13s} {'min F: dP/P':>11s} {'mean signed':>11s}"
)
for name, (contact, t, d) in scenes.items():
    ref, a_ref = forces(fine(contact), t, d)
    own, a_own = forces(contact, t, d)
    # The pull-off force: the largest pull of the scene's own history at 8192 elements, else
    # (a history that never pulls) the finger press-pull's.
    p = -ref.min()
    if p <= 0.0:
        p = float("nan")
    # Rows in the same contact state (both attached or both detached); the rows where one
    # has let go (or touched) and the other not are counted, not differenced.
    same = (a_own > 0.0) == (a_ref > 0.0)
    signed = np.where(same, (own - ref) / p, 0.0)
    err = np.abs(signed)
    n = ContactSimulator(contact).numerics.elements
    i = int(np.argmax(err))
    rms = np.sqrt(np.mean(err[same] ** 2))
    print(
        f"{name:26s} {n:4d} {p:9.3e} {err.max():10.3e} {i:5d} {rms:9.3e}"
        f" {int((~same).sum()):13d} {(ref.min() - own.min()) / p:+11.2e} {signed[same].mean():+11.2e}"
    )
    out[f"{name}/ref"], out[f"{name}/own"], out[f"{name}/p"] = ref, own, p
    out[f"{name}/a_ref"], out[f"{name}/a_own"] = a_ref, a_own
if len(sys.argv) > 2:
    np.savez(sys.argv[2], **out)
if len(sys.argv) > 3:
    base = np.load(sys.argv[3])
    print(f"\nrows moved against {sys.argv[3]}: |F - F_8192| / P before -> after")
    for name in scenes:
        ref, p = out[f"{name}/ref"], out[f"{name}/p"]
        old, new = base[f"{name}/own"], out[f"{name}/own"]
        state = out[f"{name}/a_ref"] > 0.0
        same = ((base[f"{name}/a_own"] > 0.0) == state) & ((out[f"{name}/a_own"] > 0.0) == state)
        moved = same & (np.abs(new - old) > 1e-12 * p)
        if not moved.any():
            print(f"{name:26s} no row moved")
            continue
        e_old, e_new = (old - ref)[moved] / p, (new - ref)[moved] / p
        a_old, a_new = np.abs(e_old), np.abs(e_new)
        print(
            f"{name:26s} {int(moved.sum()):5d} rows: mean {a_old.mean():.3e} -> {a_new.mean():.3e},"
            f" largest {a_old.max():.3e} -> {a_new.max():.3e}, closer {int((a_new < a_old).sum())},"
            f" signed {e_old.mean():+.2e} -> {e_new.mean():+.2e}"
        )
