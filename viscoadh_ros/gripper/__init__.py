"""A MuJoCo pick-and-place whose adhesive pads are the viscoadh model (issue 14).

An adapter beside ``ros/``: it imports mujoco (the ``gripper`` extra), numpy, matplotlib and,
for the node-in-the-loop path only, rclpy. The core stays free of all of them. See
docs/gripper.md.

Python API::

    from viscoadh_ros.gripper import load_cell, LibraryPads, Motion, run_cycle
    cell = load_cell("config/gripper_cell.yaml")
    trajectory = run_cycle(cell, Motion(press_depth=150e-6, hold_time=0.3),
                           LibraryPads(cell.pad, cell.gripper.pad_count))
    print(trajectory.outcome)
"""

from .config import Cell, GripperConfig, default_cell_path, load_cell
from .cycle import Trajectory, run_cycle, stability_number
from .motion import Motion
from .pads import LibraryPads, PadBank

__all__ = [
    "Cell",
    "GripperConfig",
    "LibraryPads",
    "Motion",
    "PadBank",
    "Trajectory",
    "default_cell_path",
    "load_cell",
    "run_cycle",
    "stability_number",
]
