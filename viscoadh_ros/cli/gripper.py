"""`viscoadh gripper`: the MuJoCo pick-and-place with viscoadh pads (docs/gripper.md)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

SCENARIO_NAMES = ("pick", "transport", "place", "controller", "weights")
DEFAULT_OUT = Path("viscoadh_gripper_out")


def _grid(text: str) -> tuple[int, int]:
    try:
        rows, columns = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected ROWSxCOLUMNS, e.g. 2x2 (got {text!r})") from None
    if not (1 <= rows <= 8 and 1 <= columns <= 8):
        raise argparse.ArgumentTypeError(f"rows and columns must be 1..8 (got {text!r})")
    return rows, columns


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `viscoadh gripper`."""
    parser.add_argument(
        "--cell",
        type=Path,
        default=None,
        metavar="FILE",
        help="gripper file: pad scene + 'gripper' section (default: config/gripper_cell.yaml)",
    )
    parser.add_argument(
        "--scenario",
        choices=(*SCENARIO_NAMES, "all"),
        default="all",
        help="which scenario to run (default: all)",
    )
    parser.add_argument(
        "--pads",
        type=_grid,
        default=None,
        metavar="RxC",
        help="pad array, e.g. 2x2 (default: the cell file's)",
    )
    parser.add_argument(
        "--node",
        action="store_true",
        help="step the pads through the viscoadh node over DDS (default: in process)",
    )
    parser.add_argument(
        "--frames",
        type=Path,
        default=None,
        metavar="DIR",
        help="also render offscreen frames into DIR/<scenario>/<run>/frame_NNNNN.png; "
        "MUJOCO_GL picks the backend: egl (default) or osmesa",
    )
    parser.add_argument(
        "--fps",
        type=float,
        default=30.0,
        help="frames per simulated second with --frames (default: 30)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_OUT,
        metavar="DIR",
        help=f"folder for the figures (created; default: ./{DEFAULT_OUT})",
    )


def main(args: argparse.Namespace) -> int:
    """Run the scenarios, write one PNG each, print the outcomes; 2 for bad input (every
    scenario is planned and checked first: then nothing is written)."""
    import os
    import re
    from dataclasses import replace

    recorders: list = []
    if not args.fps > 0.0:
        print(f"viscoadh gripper: error: --fps must be > 0 (got {args.fps:g})", file=sys.stderr)
        return 2
    if args.frames is not None:
        # Before the first import of mujoco, which reads MUJOCO_GL.
        backend = os.environ.setdefault("MUJOCO_GL", "egl").lower()
        if backend not in ("egl", "osmesa"):
            print(
                f"viscoadh gripper: error: --frames: MUJOCO_GL={backend!r}: offscreen frames need "
                "'egl' or 'osmesa'",
                file=sys.stderr,
            )
            return 2
    try:
        import mujoco  # noqa: F401
    except Exception as error:  # a MUJOCO_GL backend whose library is missing fails the import
        gl = os.environ.get("MUJOCO_GL", "")
        print(
            f"viscoadh gripper: error: mujoco does not import with MUJOCO_GL={gl!r} "
            f"({type(error).__name__}: {error}); install that backend's library (egl: libegl1, "
            "osmesa: libosmesa6) or choose the other one",
            file=sys.stderr,
        )
        return 2
    from viscoadh_ros.gripper import render, scenarios
    from viscoadh_ros.gripper.config import default_cell_path, load_cell
    from viscoadh_ros.gripper.figures import plot_runs, plot_weights
    from viscoadh_ros.gripper.scenarios import library_bank

    path = args.cell if args.cell is not None else default_cell_path()
    if not path.is_file():
        print(f"viscoadh gripper: error: --cell: no such file: {path}", file=sys.stderr)
        return 2
    cell = load_cell(path)
    if args.pads is not None:
        cell = replace(cell, gripper=cell.gripper.with_pads(*args.pads))
    bank = library_bank
    if args.node:
        from viscoadh_ros.gripper.node_loop import NodePads

        bank = NodePads
    names = SCENARIO_NAMES if args.scenario == "all" else (args.scenario,)
    # Every scenario planned and checked before anything is written or run: exit 2 means
    # nothing written (docs/cli.md), also when a later scenario's run would be refused.
    planned = {name: scenarios.plan(name, cell) for name in names}
    scenarios.check(planned)
    args.out.mkdir(parents=True, exist_ok=True)
    scenario_name = ""
    if args.frames is not None:

        def recorder(label: str) -> render.FrameRecorder:
            slug = re.sub(r"[^a-z0-9]+", "_", label.lower()).strip("_")
            folder = args.frames / scenario_name / f"{len(recorders):02d}_{slug}"
            recorders.append(render.FrameRecorder(folder, fps=args.fps))
            return recorders[-1]

        scenarios.FRAMES = recorder
    path_name = "node in the loop" if args.node else "library"
    for name in names:
        scenario_name = name
        started = time.perf_counter()
        try:
            runs = [scenarios.run_planned(run, bank) for run in planned[name]]
        finally:
            for recording in recorders:
                recording.close()
            if args.frames is not None and name == names[-1]:
                scenarios.FRAMES = None
        wall = time.perf_counter() - started
        figure = args.out / f"gripper_{name}.png"
        if name == "weights":
            plot_weights(runs, figure)
        else:
            plot_runs(
                runs, figure, title=f"viscoadh gripper: {name} ({cell.gripper.pad_count} pad(s), {path_name})"
            )
        print(f"{name} ({wall:.1f} s wall): {figure}")
        for run in runs:
            print(f"  {run.label.replace('|', ', ')}: {run.trajectory.outcome}")
    if recorders:
        print(f"frames: {sum(r.count for r in recorders)} PNGs under {args.frames}")
    return 0
