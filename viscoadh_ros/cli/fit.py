"""`viscoadh fit BAG -o SCENE.yaml`: identify material parameters from a recorded force history.

The indenter geometry and the start values come from ``--scene`` (or the scene stored in a
log of our node); the result is that scene with the fitted material, as a ROS 2 parameters
file the node and ``viscoadh replay`` accept.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import yaml

from viscoadh_ros.cli._paths import refuse_overwrite
from viscoadh_ros.cli.replay import (
    add_input_arguments,
    batch_bags,
    batch_main,
    input_options,
    open_experiment,
)
from viscoadh_ros.core.errors import InputError
from viscoadh_ros.experiment import choose_contact
from viscoadh_ros.fitting import fit, parameter_names, parse_free, unit_of
from viscoadh_ros.io.mcap_log import plain


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
        "-o", "--output", type=Path, required=True, help="scene YAML to write (a folder in batch mode)"
    )


def main(args: argparse.Namespace) -> int:
    bags = batch_bags(args)
    if bags is not None:
        return _batch(args, bags)
    if args.output.suffix not in (".yaml", ".yml"):
        raise InputError(f"--output must be a .yaml file (got {str(args.output)!r})")
    refuse_overwrite([args.bag, args.scene], [("--output", args.output)])
    _, scene, experiment = open_experiment(args)
    contact = choose_contact(scene, args.contact, experiment.input_topic)
    free = parse_free(args.free, args.kelvin) if args.free else parameter_names(args.kelvin)
    result = fit(contact, experiment, free, kelvin=args.kelvin)
    contacts = tuple(result.contact if c.id == contact.id else c for c in scene.contacts)
    fitted = dataclasses.replace(scene, contacts=contacts)
    args.output.write_text(yaml.safe_dump(plain(fitted.to_dict()), sort_keys=False), encoding="utf-8")

    print(f"fit of {contact.id} to {experiment.force_topic} ({result.samples} samples):")
    for name, value in result.values.items():
        if name in result.uncertainty:
            sigma = result.uncertainty[name]
            print(f"  {name:>16} = {value:.6g} +- {sigma:.2g} {unit_of(name)} ({100 * sigma / value:.2g}%)")
        else:
            print(f"  {name:>16} = {value:.6g} {unit_of(name)} (held)")
    print(f"fit error: RMSE {result.rmse:.6g} N, max {result.max_error:.6g} N\nwrote {args.output}")
    return 0


def _batch(args: argparse.Namespace, bags: list) -> int:
    """Many bags on a Dask cluster: ``fitting.fit_file(path, options)`` per bag (one summary
    row; it writes ``options["output"]``, the fitted scene, beside the others in OUTPUT)."""
    import viscoadh_ros.fitting as fitting

    if not hasattr(fitting, "fit_file"):
        raise InputError("batch fit needs viscoadh_ros.fitting.fit_file, which this version lacks")
    options = {**input_options(args), "free": args.free, "kelvin": args.kelvin}
    return batch_main(
        "fit", args, bags, task="viscoadh_ros.fitting:fit_file", suffix=".fit.yaml", options=options
    )
