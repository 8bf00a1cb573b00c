"""Lab exercise: when does an adhesive gripper's pick hold, and when does its release fail?

Run:  .venv/bin/python docs/tutorials/04_gripper_lab.py --out lab04_out
Writes lab04_out/picks.csv and lab04_out/releases.csv (see docs/tutorials/04_gripper_lab.md).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from viscoadh_ros.gripper import LibraryPads, Motion, default_cell_path, load_cell, run_cycle
from viscoadh_ros.gripper.cycle import GRAVITY
from viscoadh_ros.gripper.scenarios import with_holding_force, with_mass


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("lab04_out"), help="output folder")
    parser.add_argument("--mass", type=float, default=1.3e-3, help="part mass, kg")
    parser.add_argument("--depths", type=float, nargs="+", default=[20e-6, 150e-6], help="press depths, m")
    parser.add_argument("--holds", type=float, nargs="+", default=[0.0, 0.3], help="hold times, s")
    parser.add_argument(
        "--latches", type=float, nargs="+", default=[0.002, 0.02], help="fixture holding forces, N"
    )
    return parser.parse_args()


# --8<-- [start:pick]
def try_pick(cell, depth: float, hold: float):
    """One pick (press `depth` m, hold `hold` s, slow peel, lift at 2 m/s^2) with the model's
    own prediction: the live pad asked `predict_pull_off` when the press really ended."""
    motion = Motion(press_depth=depth, hold_time=hold)
    trajectory = run_cycle(cell, motion, LibraryPads(cell.pad, cell.gripper.pad_count))
    capacity = trajectory.predictions.get("pick_capacity_kg", 0.0)  # 0: the pad never touched
    return trajectory.success, capacity


# --8<-- [end:pick]


# --8<-- [start:release]
def try_release(cell, holding_force: float, retract_speed: float = 0.002):
    """Pick well, place into the fixture, latch it, retract at `retract_speed` m/s. Before the
    retraction the live pad is asked what pull-off that speed will meet."""
    asked = {}

    def decide(pads) -> float:
        asked["pull_off"] = float(pads.predict_pull_off(retract_speed).sum())
        return retract_speed

    motion = Motion(press_depth=150e-6, hold_time=0.3, place=True, retract_speed=None)
    cell = with_holding_force(cell, holding_force)
    trajectory = run_cycle(cell, motion, LibraryPads(cell.pad, 1), choose_retract_speed=decide)
    fixture_holds = holding_force + cell.gripper.part.mass * GRAVITY  # N the part resists with
    return trajectory.success, asked["pull_off"], fixture_holds


# --8<-- [end:release]


def main() -> None:
    args = parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    cell = with_mass(load_cell(default_cell_path()), args.mass)
    print(f"part {args.mass * 1e3:g} g")
    with open(args.out / "picks.csv", "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["press_depth_m", "hold_s", "predicted_capacity_kg", "held"])
        for depth in args.depths:
            for hold in args.holds:
                held, capacity = try_pick(cell, depth, hold)
                writer.writerow([depth, hold, capacity, int(held)])
                verdict = "held" if held else "dropped"
                print(
                    f"press {depth * 1e6:5.0f} um, hold {hold:.2f} s: predicted capacity "
                    f"{capacity * 1e3:.2f} g -> {verdict}"
                )
    with open(args.out / "releases.csv", "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["holding_force_N", "predicted_pull_off_N", "fixture_holds_N", "released"])
        for force in args.latches:
            released, pull_off, holds = try_release(cell, force)
            writer.writerow([force, pull_off, holds, int(released)])
            verdict = "released" if released else "pulled out of the fixture"
            print(
                f"latch {force * 1e3:g} mN: predicted pull-off {-pull_off * 1e3:.1f} mN, "
                f"fixture + weight {holds * 1e3:.1f} mN -> {verdict}"
            )


if __name__ == "__main__":
    main()
