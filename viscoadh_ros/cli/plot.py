"""`viscoadh plot INPUT -o FIG.png`: force-depth and force-radius loops with JKR reference branches.

INPUT is a result CSV (columns ``depth``, ``force``, ``contact_radius``, as `viscoadh simulate`
writes) or an MCAP log/replay output (its ``ContactState`` messages). The reference branches
need the scene: ``--scene``, or the one stored in the MCAP file.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from viscoadh_ros.cli._paths import refuse_overwrite
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.io.csv_io import check_output_folder, read_columns
from viscoadh_ros.plotting import Curve, JkrReference, plot_loops

STATE = "viscoadh_msgs/msg/ContactState"
COLUMNS = ("depth", "force", "contact_radius")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "input", type=Path, help="result .csv, or .mcap file / rosbag2 folder with ContactState"
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="figure file, .png or .svg")
    parser.add_argument(
        "--scene", type=Path, help="scene YAML for the reference branches (default: stored in the MCAP)"
    )
    parser.add_argument("--contact", help="contact id (default: the only one)")
    parser.add_argument(
        "--normalised", action="store_true", help="the paper's Figure-4 units F/F_c, a/a_c, d/d_c"
    )
    parser.add_argument(
        "--recover", action="store_true", help="read unfinished MCAP files up to their last complete chunk"
    )


def _csv_curves(path: Path) -> list[Curve]:
    table = read_columns(path, COLUMNS)
    if table[COLUMNS[0]].size < 2:
        raise InputError(f"{str(path)!r} has fewer than two rows")
    return [Curve(*(table[c] for c in COLUMNS), label=path.stem)]


def _mcap_curves(args: argparse.Namespace):
    from viscoadh_ros.io.bag import Bag

    bag = Bag(args.input, recover=args.recover)
    topics = bag.topics_of_type(STATE)
    if args.contact:
        topics = [t for t in topics if t.strip("/").split("/")[-2:-1] == [args.contact]]
    if not topics:
        raise InputError(
            f"no ContactState topic{' of ' + args.contact if args.contact else ''} in {str(args.input)!r}"
        )
    curves = []
    for topic in topics:
        rows = np.array([(m.msg.depth, m.msg.force, m.msg.contact_radius) for m in bag.messages([topic])])
        if len(rows) < 2:
            raise InputError(f"topic {topic!r} has fewer than two states")
        bad = np.flatnonzero(~np.isfinite(rows).all(axis=1))
        if bad.size:
            raise InputError(
                f"topic {topic!r}: state {int(bad[0])} has a value that is not finite "
                f"(depth, force, contact_radius = {', '.join(repr(float(v)) for v in rows[bad[0]])})"
            )
        curves.append(Curve(rows[:, 0], rows[:, 1], rows[:, 2], label=topic))
    return curves, bag.scene()


def main(args: argparse.Namespace) -> int:
    refuse_overwrite([args.input, args.scene], [("--output", args.output)])
    check_output_folder(args.output)
    stored = None
    if args.input.suffix.lower() == ".csv":
        curves = _csv_curves(args.input)
    else:
        curves, stored = _mcap_curves(args)
    reference = None
    if args.scene is not None or stored is not None:
        from viscoadh_ros.core.config import SceneConfig
        from viscoadh_ros.experiment import choose_contact

        scene = SceneConfig.from_yaml(args.scene) if args.scene is not None else SceneConfig.from_dict(stored)
        topic = curves[0].label if len(curves) == 1 and curves[0].label.startswith("/") else None
        reference = JkrReference.from_contact(choose_contact(scene, args.contact, topic))
        if reference is None:
            print("viscoadh plot: note: no JKR reference (it needs a sphere with work_of_adhesion > 0)")
    plot_loops(curves, args.output, reference=reference, normalised=args.normalised, title=args.input.name)
    print(f"wrote {args.output}")
    return 0
