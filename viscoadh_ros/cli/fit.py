"""`viscoadh fit BAG -o SCENE.yaml`: identify material parameters from a recorded force history.

The indenter geometry and the start values come from ``--scene`` (or the scene stored in a
log of our node); the result is that scene with the fitted material, as a ROS 2 parameters
file the node and ``viscoadh replay`` accept, and beside it a report: ``SCENE.report.png``
(measured and fitted force against time and depth, residuals, the fitted material's JKR
branches) and ``SCENE.report.md`` (each value with its 95 % interval, RMSE and r^2 against the
record's noise level). The same fit of one bag is `viscoadh_ros.fitting.fit_file` for batch
runners.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from viscoadh_ros.cli._paths import refuse_overwrite
from viscoadh_ros.cli.replay import add_input_arguments, batch_bags, batch_main, input_options
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.fitting import BOUNDS_FACTOR, SEGMENTS, fit_bag, unit_of
from viscoadh_ros.io.csv_io import check_output_folder


def _kelvin(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1 (got {value})")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_input_arguments(parser)
    parser.add_argument(
        "--free",
        default=None,
        help="comma-separated parameters to fit (default: G0,G1..GK,eta1..etaK,work_of_adhesion)",
    )
    parser.add_argument(
        "--kelvin",
        type=_kelvin,
        default=1,
        metavar="K",
        help="number of Kelvin elements of the rheology (default 1: standard solid)",
    )
    parser.add_argument(
        "--segment",
        choices=SEGMENTS,
        default="both",
        help="fit the samples where the depth last moved in (approach), out (retract) or all (both)",
    )
    parser.add_argument(
        "--time-range",
        nargs=2,
        type=float,
        metavar=("T0", "T1"),
        help="fit only the samples between T0 and T1, s since the first input (the model runs from 0)",
    )
    parser.add_argument(
        "--bounds-factor",
        type=float,
        default=BOUNDS_FACTOR,
        metavar="F",
        help=f"search each free parameter within start/F .. start*F (default {BOUNDS_FACTOR:g})",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the global search (default 0)")
    parser.add_argument(
        "--fit-offset",
        action="store_true",
        help="fit a constant load-cell offset (N, what it reads at zero force) beside the parameters "
        "(default: none; a record whose residuals point to one is reported as a misfit)",
    )
    parser.add_argument("--no-report", action="store_true", help="do not write the report beside SCENE")
    parser.add_argument(
        "-o", "--output", type=Path, required=True, help="scene YAML to write (a folder in batch mode)"
    )


def main(args: argparse.Namespace) -> int:
    bags = batch_bags(args)
    if bags is not None:
        return _batch(args, bags)
    if args.output.suffix not in (".yaml", ".yml"):
        raise InputError(f"--output must be a .yaml file (got {str(args.output)!r})")
    from viscoadh_ros.fit_report import report_paths

    outputs = [args.output] if args.no_report else [args.output, *report_paths(args.output)]
    refuse_overwrite([args.bag, args.scene], [("--output", path) for path in outputs])
    check_output_folder(args.output)
    options = {
        "scene": args.scene,
        "contact": args.contact,
        "depth_topic": args.depth_topic,
        "force_topic": args.force_topic,
        "flip_force": args.flip_force,
        "recover": args.recover,
        "free": args.free,
        "kelvin": args.kelvin,
        "segment": args.segment,
        "time_range": args.time_range,
        "bounds_factor": args.bounds_factor,
        "seed": args.seed,
        "fit_offset": args.fit_offset,
        "output": args.output,
        "report": not args.no_report,
    }
    done = fit_bag(str(args.bag), options)
    result = done.result
    print(
        f"fit of {done.contact_id} to {done.experiment.force_topic} ({result.samples} samples, "
        f"{result.model_runs} model runs, {result.wall_time:.3g} s):"
    )
    if done.changed_at is not None:
        start = (
            "--scene with the parameters the change set" if args.scene is not None else "the contact it set"
        )
        print(f"  the record from the parameter change at t = {done.changed_at:.6g} s on; start: {start}")
    for name, value in result.values.items():
        unit = unit_of(name)
        if name not in result.uncertainty:
            print(f"  {name:>16} = {value:.6g} {unit} (held)")
            continue
        sigma = result.uncertainty[name]
        lo, hi = result.interval[name]
        if result.identified[name]:
            print(
                f"  {name:>16} = {value:.6g} +- {sigma:.2g} {unit} ({100 * sigma / value:.2g}%; "
                f"95% {lo:.4g} .. {hi:.4g})"
            )
        else:
            print(f"  {name:>16}   NOT IDENTIFIED: 95% {lo:.4g} .. {hi:.4g} {unit} (best {value:.4g})")
    if result.offset is not None and result.offset_interval is not None:
        lo, hi = result.offset_interval
        print(
            f"  {'load-cell offset':>16} = {result.offset:.4g} +- {result.offset_uncertainty:.2g} N "
            f"(95% {lo:.4g} .. {hi:.4g}; what the load cell reads at zero force)"
        )
    print(
        f"fit error: RMSE {result.rmse:.6g} N against noise level {result.noise:.6g} N "
        f"(ratio {result.rmse / result.noise:.3g}), r^2 {result.r2:.6f}, max {result.max_error:.6g} N"
    )
    if result.reason:
        print(f"warning: {result.reason}")
    print("wrote " + ", ".join(done.written))
    return 0


def _batch(args: argparse.Namespace, bags: list) -> int:
    """Many bags on a Dask cluster: ``fitting.fit_file(path, options)`` per bag (one summary
    row; it writes ``options["output"]``, the fitted scene, beside the others in OUTPUT)."""
    options = {
        **input_options(args),
        "free": args.free,
        "kelvin": args.kelvin,
        "segment": args.segment,
        "time_range": args.time_range,
        "bounds_factor": args.bounds_factor,
        "seed": args.seed,
        "fit_offset": args.fit_offset,
        "report": not args.no_report,
    }
    return batch_main(
        "fit", args, bags, task="viscoadh_ros.fitting:fit_file", suffix=".fit.yaml", options=options
    )
