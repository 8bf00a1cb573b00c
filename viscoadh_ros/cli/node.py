"""`viscoadh node [--ros-args ...]`: run the ROS 2 node (default: the built-in scene).

Everything from ``--ros-args`` on goes to rclpy unchanged, so a scene is given with
``--ros-args --params-file SCENE.yaml`` and single values with ``-p name:=value``; remapping
(``-r``) and namespaces (``-r __ns:=/left``) work as for any ROS node.
"""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The node takes no options of its own: ROS arguments follow ``--ros-args``."""
    parser.epilog = (
        "ROS arguments: --ros-args --params-file SCENE.yaml -p publish_rate:=100 "
        "-r __ns:=/gripper (see docs/ros_interface.md)"
    )


def main(args: argparse.Namespace) -> int:
    """Spin the node until Ctrl-C; 2 with one error line for an invalid scene."""
    from viscoadh_ros.ros.node import main as node_main

    return node_main(["viscoadh", *args.ros_args])
