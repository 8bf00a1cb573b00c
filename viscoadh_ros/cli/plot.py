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
    changes: dict[str, list] = {}  # topic -> its contact's PARAMETERS events (Restart), in order
    for topic in topics:
        messages = list(bag.messages([topic]))
        rows = np.array([(m.msg.depth, m.msg.force, m.msg.contact_radius) for m in messages])
        if len(rows) < 2:
            raise InputError(f"topic {topic!r} has fewer than two states")
        bad = np.flatnonzero(~np.isfinite(rows).all(axis=1))
        if bad.size:
            raise InputError(
                f"topic {topic!r}: state {int(bad[0])} has a value that is not finite "
                f"(depth, force, contact_radius = {', '.join(repr(float(v)) for v in rows[bad[0]])})"
            )
        restarts = _restarts(bag, topic)
        changes[topic] = [r for r in restarts if r.kind == 3]  # PARAMETERS
        if restarts:
            # No line across a reset or parameter change: a break (NaN row) before the first
            # state after each.
            orders = np.array([m.order for m in messages])
            cuts = np.unique(np.searchsorted(orders, [r.order for r in restarts]))
            cuts = cuts[(cuts > 0) & (cuts < len(rows))]
            rows = np.insert(rows, cuts, np.nan, axis=0)
        curves.append(Curve(rows[:, 0], rows[:, 1], rows[:, 2], label=topic))
    return curves, bag.scene(), changes


def _restarts(bag, state_topic: str) -> list:
    """The RESET and PARAMETERS events (``experiment.Restart``) logged beside ``state_topic``
    (``C/state`` -> ``C/events``), in recording order."""
    from viscoadh_ros.experiment import EVENT, PARAMETERS, RESET, Restart

    events = state_topic.rsplit("/", 1)[0] + "/events"
    if bag.topics.get(events) != EVENT:
        return []
    found = [
        Restart(m.msg.kind, m.log_time_ns, m.order, m.msg.contact_yaml)
        for m in bag.messages([events])
        if m.msg.kind in (RESET, PARAMETERS)
    ]
    return sorted(found, key=lambda r: r.order)


def main(args: argparse.Namespace) -> int:
    refuse_overwrite([args.input, args.scene], [("--output", args.output)])
    check_output_folder(args.output)
    stored, changes = None, {}
    if args.input.suffix.lower() == ".csv":
        curves = _csv_curves(args.input)
    else:
        curves, stored, changes = _mcap_curves(args)
    reference = None
    if args.scene is not None or stored is not None:
        from viscoadh_ros.core.config import SceneConfig
        from viscoadh_ros.experiment import changed_contact, choose_contact

        scene = SceneConfig.from_yaml(args.scene) if args.scene is not None else SceneConfig.from_dict(stored)
        topic = curves[0].label if len(curves) == 1 and curves[0].label.startswith("/") else None
        contact = choose_contact(scene, args.contact, topic)
        # A runtime parameter change in the record: the reference of the contact in force at
        # its end (the stored scene is the one the file started with), and say so.
        mine = next((c for t, c in changes.items() if t.strip("/").split("/")[-2:-1] == [contact.id]), [])
        if mine and args.scene is None:
            contact = changed_contact(mine[-1], contact.id)
            print(
                f"viscoadh plot: note: {contact.id}'s parameters change in the record ({len(mine)} "
                "PARAMETERS event(s)): the reference branches are those of the contact in force at "
                "its end (the last change's)"
            )
        elif mine:
            print(
                f"viscoadh plot: note: {contact.id}'s parameters change in the record ({len(mine)} "
                "PARAMETERS event(s)); the reference branches are those of --scene"
            )
        reference = JkrReference.from_contact(contact)
        if reference is None:
            print("viscoadh plot: note: no JKR reference (it needs a sphere with work_of_adhesion > 0)")
    plot_loops(curves, args.output, reference=reference, normalised=args.normalised, title=args.input.name)
    print(f"wrote {args.output}")
    return 0
