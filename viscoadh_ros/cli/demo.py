"""`viscoadh demo`: the main job (see :mod:`viscoadh_ros.demo`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

DEFAULT_OUT = Path("viscoadh_demo_out")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `viscoadh demo`."""
    parser.add_argument(
        "--scene",
        type=Path,
        default=None,
        metavar="FILE",
        help="scene file (ROS 2 parameters YAML; default: the built-in config/default.yaml)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_OUT,
        metavar="DIR",
        help=f"folder for the MCAP log and the figure (created; default: ./{DEFAULT_OUT})",
    )
    parser.add_argument(
        "--contact",
        default=None,
        metavar="ID",
        help="contact of the scene to drive (default: the scene's first contact)",
    )


def main(args: argparse.Namespace) -> int:
    """Run the demo and print its summary; 2 for a bad scene, 1 if the run fails."""
    from viscoadh_ros.demo import run_demo

    if args.scene is not None and not args.scene.is_file():
        print(f"viscoadh demo: error: --scene: no such file: {args.scene}", file=sys.stderr)
        return 2
    try:
        report = run_demo(scene_path=args.scene, out_dir=args.out, contact_id=args.contact)
    except RuntimeError as exc:
        print(f"viscoadh demo: error: {exc}", file=sys.stderr)
        return 1
    print(report)
    return 0
