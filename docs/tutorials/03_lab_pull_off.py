"""Lab exercise: how the pull-off force depends on the retract speed and the hold time.

Run:  .venv/bin/python docs/tutorials/03_lab_pull_off.py --out lab_out
Writes lab_out/pull_off.csv and lab_out/pull_off.png (see docs/tutorials/03_lab_pull_off.md).
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt
import numpy as np

from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.core.history import predict_pull_off
from viscoadh_ros.core.simulator import ContactSimulator
from viscoadh_ros.demo import creep_time
from viscoadh_ros.plotting import JkrReference


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=default_scene_path(), help="scene YAML")
    parser.add_argument("--out", type=Path, default=Path("lab_out"), help="output folder")
    parser.add_argument("--speeds", type=int, default=9, help="number of retract speeds")
    parser.add_argument(
        "--holds", type=float, nargs="+", default=[0.0, 0.03, 0.3, 3.0],
        help="hold times, in creep times",
    )
    return parser.parse_args()


# --8<-- [start:press]
def press(contact, d_c: float, creep: float, ramp_samples: int = 200) -> ContactSimulator:
    """Approach from above the surface (-d_c) to 4 d_c quickly, in 1 % of a creep time (s):
    the body has no time to creep, so whatever relaxes happens in the hold that follows."""
    simulator = ContactSimulator(contact)
    times = np.linspace(0.0, 0.01 * creep, ramp_samples)
    depths = np.linspace(-d_c, 4.0 * d_c, ramp_samples)
    for t, d in zip(times, depths, strict=True):
        simulator.step(t, depth=d)
    return simulator
# --8<-- [end:press]


def main() -> None:
    args = parse_args()
    scene = SceneConfig.from_yaml(args.scene)
    contact = scene.contacts[0]
    # --8<-- [start:scales]
    reference = JkrReference.from_contact(contact)  # the paper's quasistatic JKR branches
    _, _, d_c = reference.scales  # critical depth of the release branch, m
    creep = creep_time(contact)  # the material's longest creep time eta_k/G_k, s
    w = contact.adhesion.work_of_adhesion
    elastic_pull_off = 1.5 * math.pi * reference.radius * w  # JKR with the true w, N
    # --8<-- [end:scales]

    # --8<-- [start:sweep]
    # Dimensionless speed v T / d_c (T: creep time): 1e-2 is quasistatic, 1e2 far faster
    # than the material creeps.
    speeds = np.logspace(-2, 4, args.speeds) * d_c / creep
    simulator = press(contact, d_c, creep)
    hold_started = simulator.time
    rows = []
    for hold in sorted(args.holds):
        simulator.advance(hold_started + hold * creep)  # hold the depth: the body relaxes
        for speed in speeds:
            # Runs on a copy: the live simulator is untouched, so every speed starts
            # from the same state.
            prediction = predict_pull_off(simulator, speed)
            rows.append((hold, speed * creep / d_c, prediction.pull_off_force))
    # --8<-- [end:sweep]

    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "pull_off.csv", "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["hold_time_over_creep_time", "speed_times_creep_time_over_d_c", "pull_off_force"])
        writer.writerows(rows)

    # --8<-- [start:plot]
    table = np.array(rows)
    figure, axes = plt.subplots(figsize=(7, 4.5), layout="constrained")
    for hold in sorted(args.holds):
        mine = table[table[:, 0] == hold]
        axes.semilogx(mine[:, 1], -mine[:, 2] / elastic_pull_off, "o-", label=f"hold {hold:g} T")
    axes.axhline(
        reference.work_detachment / w, color="k", ls="--",
        label="quasistatic limit, $w_{eff2}/w$",
    )
    axes.axhline(1.0, color="grey", ls=":", label="elastic JKR with $w$")
    axes.set_xlabel(r"retract speed $v\,T/d_c$  (T: creep time)")
    axes.set_ylabel(r"pull-off force $|F| \,/\, (\frac{3}{2}\pi R w)$")
    axes.set_title("Pull-off force vs retract speed and hold time")
    axes.legend()
    figure.savefig(args.out / "pull_off.png", dpi=120)
    # --8<-- [end:plot]

    for hold, speed, force in rows:
        print(f"hold {hold:6.2f} T   speed {speed:9.3g} d_c/T   pull-off {force:.4e} N")
    print(f"wrote {args.out / 'pull_off.csv'} and {args.out / 'pull_off.png'}")


if __name__ == "__main__":
    main()
