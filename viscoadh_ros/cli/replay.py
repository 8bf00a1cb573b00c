"""`viscoadh replay BAG -o OUT.mcap`: run the model over a recorded experiment, compare forces.

OUT holds the model's ``<contact>/state`` (ContactState) and ``<contact>/wrench``
(WrenchStamped) on the input stamps, plus the scene, so it can be plotted or replayed again.
The summary (RMSE, max error, pull-off forces, speed) is printed and, with ``--json``, written.

Batch mode (several bags, a glob, ``--workers`` or ``--scheduler``): ``-o`` is a folder that
receives ``<bag>.replay.mcap`` per bag and ``summary.csv`` (one row per bag, see
:mod:`viscoadh_ros.batch`); the bags run in parallel on a Dask cluster. The same options and
:func:`batch_main` serve ``viscoadh fit``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from viscoadh_ros.cli._paths import refuse_overwrite
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.experiment import (
    Experiment,
    Material,
    ModelRun,
    choose_contact,
    compare,
    load_experiment,
    materials,
    run_model,
)
from viscoadh_ros.io.bag import Bag
from viscoadh_ros.io.csv_io import check_output_folder

if TYPE_CHECKING:
    from viscoadh_ros.core.config import ContactConfig, SceneConfig


def add_input_arguments(parser: argparse.ArgumentParser) -> None:
    """Options that choose the recorded experiment (shared by replay and fit)."""
    parser.add_argument(
        "bag",
        nargs="+",
        help="an .mcap file or a rosbag2 folder; several, or a glob ('lab/*.mcap'), for a batch",
    )
    parser.add_argument("--scene", type=Path, help="scene YAML (default: the one stored in BAG by the node)")
    parser.add_argument("--contact", help="contact id in the scene (default: the only one)")
    parser.add_argument(
        "--depth-topic",
        help="input topic: IndentationCommand, Float64 depth (m), "
        "or PointStamped/PoseStamped whose z is the depth (m)",
    )
    parser.add_argument(
        "--force-topic", help="measured force: WrenchStamped (force.z, N) or Float64 (N), > 0 compressive"
    )
    parser.add_argument(
        "--flip-force",
        action="store_true",
        help="negate the measured force (load cells that read tension positive)",
    )
    parser.add_argument(
        "--recover",
        action="store_true",
        help="read unfinished (truncated) files up to their last complete chunk",
    )
    batch = parser.add_argument_group("batch mode (several bags; needs the 'batch' extra: Dask)")
    batch.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="worker processes of the local Dask cluster (default 1; implies batch mode)",
    )
    batch.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on an existing Dask cluster (tcp://host:8786) instead; its workers must see the bags",
    )
    batch.add_argument("--summary", type=Path, help="summary table to write (default: OUTPUT/summary.csv)")


def batch_bags(args: argparse.Namespace) -> list[Path] | None:
    """The bags of a batch, or None for one bag (then ``args.bag`` becomes its Path)."""
    from viscoadh_ros import batch

    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be >= 1 (got {args.workers})")
    if batch.is_batch(args.bag, workers=args.workers, scheduler=args.scheduler):
        return batch.expand_bags(args.bag)
    if args.summary is not None:
        raise InputError("--summary is for batch mode (several bags, --workers or --scheduler)")
    args.bag = Path(args.bag[0])
    return None


def batch_main(
    verb: str,
    args: argparse.Namespace,
    bags: list[Path],
    *,
    task: str,
    suffix: str,
    options: dict,
) -> int:
    """Run ``task`` over ``bags`` (``options`` plus each bag's ``output`` file in the folder
    ``args.output``), write the summary table; 0 when every bag succeeded, else 1."""
    from viscoadh_ros import batch

    folder: Path = args.output
    if folder.exists() and not folder.is_dir():
        raise InputError(f"--output must be a folder in batch mode ({str(folder)!r} is a file)")
    outputs = [folder / name for name in batch.output_names(bags, suffix)]
    summary = args.summary if args.summary is not None else folder / "summary.csv"
    json_path = getattr(args, "json", None)
    refuse_overwrite(
        [*bags, options.get("scene")],
        [("--summary", summary), ("--json", json_path), *(("--output", o) for o in outputs)],
    )
    # The -o folder itself may be new (one file per bag goes into it); the folders it and the
    # summary go into must exist, as for every other output (docs/cli.md).
    for path in (folder, args.summary, json_path):
        if path is not None:
            check_output_folder(path)
    folder.mkdir(exist_ok=True)
    per_bag = [{**options, "output": str(o)} for o in outputs]
    rows = batch.run_batch(task, bags, per_bag, workers=args.workers, scheduler=args.scheduler)
    batch.write_summary(summary, rows)
    if json_path is not None:
        json_path.write_text(json.dumps(rows, indent=2) + "\n", encoding="utf-8")
    failed = [row for row in rows if row.get("status") != "ok"]
    print(f"{verb}: {len(rows) - len(failed)} of {len(rows)} bags done; wrote {summary} and {folder}/")
    for row in failed:
        print(f"viscoadh {verb}: failed: {row['bag']}: {row.get('error', '')}", file=sys.stderr)
    return 1 if failed else 0


def open_experiment(args: argparse.Namespace) -> tuple[Bag, SceneConfig, Experiment]:
    """The bag, scene and experiment the shared options name; InputError when unusable."""
    bag = Bag(args.bag, recover=args.recover)
    for path in bag.truncated:
        print(f"viscoadh: warning: {path} is unfinished; using its complete chunks", file=sys.stderr)
    experiment = load_experiment(
        bag,
        input_topic=args.depth_topic,
        force_topic=args.force_topic,
        contact=args.contact,
        flip_force=args.flip_force,
    )
    if experiment.force_topic is None:
        raise InputError(
            f"no measured force in {str(args.bag)!r}: record a WrenchStamped or name a Float64 "
            f"force with --force-topic (topics: {bag.topics})"
        )
    from viscoadh_ros.core.config import SceneConfig

    if args.scene is not None:
        scene = SceneConfig.from_yaml(args.scene)
    else:
        stored = bag.scene()
        if stored is None:
            raise InputError(f"{str(args.bag)!r} stores no scene (not a log of our node); pass --scene")
        scene = SceneConfig.from_dict(stored)
    return bag, scene, experiment


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_input_arguments(parser)
    parser.add_argument(
        "-o", "--output", type=Path, required=True, help="output .mcap file (a folder in batch mode)"
    )
    parser.add_argument("--json", type=Path, help="also write the summary to this JSON file")


def input_options(args: argparse.Namespace) -> dict:
    """The shared input options as plain values (what a batch task receives)."""
    return {
        "scene": None if args.scene is None else str(args.scene),
        "contact": args.contact,
        "depth_topic": args.depth_topic,
        "force_topic": args.force_topic,
        "flip_force": args.flip_force,
        "recover": args.recover,
    }


def main(args: argparse.Namespace) -> int:
    bags = batch_bags(args)
    if bags is not None:
        return batch_main(
            "replay",
            args,
            bags,
            task="viscoadh_ros.cli.replay:replay_file",
            suffix=".replay.mcap",
            options=input_options(args),
        )
    if args.output.suffix != ".mcap":
        raise InputError(f"--output must be an .mcap file (got {str(args.output)!r})")
    refuse_overwrite([args.bag, args.scene], [("--output", args.output), ("--json", args.json)])
    for path in (args.output, args.json):
        if path is not None:
            check_output_folder(path)
    result, experiment = replay_one(args, progress=True)
    skipped = experiment.rejected_index.size
    stretches = result.pop("_materials")
    # Every file written before the summary is printed: a reader that stops early (`| head`)
    # loses only the text.
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(
        f"replayed {experiment.input_ns.size} inputs of {result['contact']} over "
        f"{experiment.duration:.3f} s at {result['replay_speed_x_real_time']:.3g}x real time"
        + (f" (skipped {skipped} the node rejected)" if skipped else "")
        + (f" ({len(experiment.restarts)} resets/parameter changes applied)" if experiment.restarts else "")
        + "".join(f"\n  material {text}" for text in (stretches if len(stretches) > 1 else ()))
        + f"\nforce error vs {experiment.force_topic}: RMSE {result['rmse_N']:.6g} N, "
        f"max {result['max_error_N']:.6g} N ({result['samples']} samples)\n"
        f"pull-off force: measured {_pull_off_text(result['measured_pull_off_force_N'])}, "
        f"model {_pull_off_text(result['model_pull_off_force_N'])}\n"
        f"wrote {args.output}"
    )
    return 0


def replay_one(args: argparse.Namespace, *, progress: bool = False) -> tuple[dict, Experiment]:
    """Replay ``args.bag`` into ``args.output``: the summary row and the experiment."""
    bag, scene, experiment = open_experiment(args)
    contact = choose_contact(scene, args.contact, experiment.input_topic)
    stretches, start = _materials(args, bag, contact, experiment)
    changes = [m.contact for m in stretches[1:]]

    if progress and sys.stderr.isatty():
        # A bar on a terminal only (as tqdm's disable=None decides); tqdm is not imported
        # otherwise (~10-100 ms of a fresh process).
        from tqdm import tqdm

        events = experiment.input_ns.size + experiment.measured_ns.size
        with tqdm(total=events, unit="step", file=sys.stderr, leave=False) as bar:
            run = run_model(contact, experiment, progress=bar.update, changes=changes)
    else:
        run = run_model(contact, experiment, changes=changes)
    summary = compare(experiment, run)
    _write_output(args.output, scene, contact.id, experiment, run)
    result = {
        "bag": str(args.bag),
        "contact": contact.id,
        "input_topic": experiment.input_topic,
        "force_topic": experiment.force_topic,
        "output": str(args.output),
        **summary.as_dict(),
        **_event_counts(experiment),
        "materials": [m.as_dict(experiment) for m in stretches],
        "_materials": [m.describe(experiment, start) for m in stretches],
    }
    return result, experiment


def _materials(
    args: argparse.Namespace, bag: Bag, contact: ContactConfig, experiment: Experiment
) -> tuple[list[Material], str]:
    """The contact each stretch between the record's parameter changes runs with
    (`experiment.materials`), and what the first is, in words.

    Without --scene: the node's, as logged. With --scene (a candidate material compared with
    the log): the scene's contact, and at each logged PARAMETERS event the parameters that
    event changed set on it (docs/recording_and_replay.md); 0.10.0 and before ran the logged
    contact after a change whatever the scene (an outside tester's candidate replayed bit for
    bit as the node's own answer)."""
    if args.scene is None:
        return materials(experiment, contact, logged=None, given=False), "the scene stored in the log"
    from viscoadh_ros.core.config import SceneConfig
    from viscoadh_ros.core.errors import ConfigError

    start = f"{contact.id!r} of --scene {str(args.scene)!r}"
    logged = None
    stored = bag.scene()
    if stored is not None:
        try:
            logged = SceneConfig.from_dict(stored).contact(contact.id)
        except (ConfigError, ValueError):
            logged = None
    found = materials(experiment, contact, logged=logged, given=True)
    if len(found) > 1 and logged is None:
        start += " (the log stores no scene of the contact: its changes are taken against --scene)"
    return found, start


def replay_file(path: str, options: dict) -> dict:
    """One bag of a batch (run on a Dask worker): replay ``path`` into ``options["output"]``;
    the summary row. ``options``: the keys of :func:`input_options` plus ``output``."""
    args = argparse.Namespace(
        bag=Path(path),
        output=Path(options["output"]),
        **{k: v for k, v in options.items() if k not in ("output", "scene")},
        scene=None if options.get("scene") is None else Path(options["scene"]),
    )
    result, _ = replay_one(args)
    result["materials"] = "; ".join(result.pop("_materials"))
    return {"status": "ok", **result}


def _event_counts(experiment: Experiment) -> dict[str, int]:
    """What the node did besides accepting commands, as the summary reports it."""
    from viscoadh_ros.experiment import PARAMETERS, RESET

    kinds = [r.kind for r in experiment.restarts]
    return {
        "commands": int(experiment.input_ns.size + experiment.rejected_index.size),
        "commands_rejected": int(experiment.rejected_index.size),
        "resets": kinds.count(RESET),
        "parameter_changes": kinds.count(PARAMETERS),
        "restarts": len(kinds),
    }


def _pull_off_text(force: float | None) -> str:
    return "none (never tensile)" if force is None else f"{force:.6g} N"


def _write_output(
    path: Path, scene: SceneConfig, contact_id: str, experiment: Experiment, run: ModelRun
) -> None:
    """The model's states and wrenches on the input stamps, with the scene, as MCAP.

    The messages are those of ``ros.conversions.contact_state`` / ``wrench``, serialised in
    bulk (io/cdr.py) straight into the file's records (``cdr.Messages``): one message object
    per output cost more than the simulation.
    """

    import numpy as np

    from viscoadh_ros.io import cdr
    from viscoadh_ros.io.mcap_bulk import write_columns
    from viscoadh_ros.io.mcap_log import TopicData
    from viscoadh_ros.ros.conversions import MODEL_CODES, STATE_OUTPUT_FIELDS

    columns = {name: run.input_columns[name] for name in STATE_OUTPUT_FIELDS}
    received, rejected = experiment.counters
    stamps = experiment.input_ns
    if run.input_model is None:
        model: np.ndarray | int = MODEL_CODES[run.model]
    else:
        model = np.zeros(stamps.size, dtype=np.uint8)
        known = np.zeros(stamps.size, dtype=np.bool_)
        for name, code in MODEL_CODES.items():
            mine = run.input_model == name
            model[mine], known[mine] = code, True
        if not known.all():
            raise KeyError(str(run.input_model[np.flatnonzero(~known)[0]]))
    state = {**columns, "model": model, "commands_received": received, "commands_rejected": rejected}
    frame = scene.node.frame_id
    # The records' log times never go back, so the file keeps the run order where the stamps go
    # back (a new time origin after a reset or a clock jump back in a node log); the headers keep
    # the stamps. In stamp order the two histories' rows alternated in the file.
    logged = np.maximum.accumulate(stamps) if stamps.size else stamps
    if path.exists():
        path.unlink()
    write_columns(
        path,
        [
            TopicData(
                f"/{contact_id}/state",
                cdr.CONTACT_STATE,
                logged,
                cdr.Messages(cdr.CONTACT_STATE, stamps, frame, state),
            ),
            TopicData(
                f"/{contact_id}/wrench",
                cdr.WRENCH,
                logged,
                cdr.Messages(cdr.WRENCH, stamps, frame, {"wrench.force.z": columns["force"]}),
            ),
        ],
        scene=scene.to_dict(),
    )
