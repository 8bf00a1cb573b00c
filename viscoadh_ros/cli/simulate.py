"""`viscoadh simulate SCENE HISTORY -o OUT`: run a loading history through the model offline.

HISTORY is a CSV with the header ``time,depth`` (s, m) or ``time,force`` (s, N); OUT gets one
row per input row with ``time,depth,force,contact_radius,phase`` and the other StepOutput
fields. ``--preset``, ``--model`` and ``--tolerance`` override the scene's ``numerics.preset``,
``numerics.model`` and ``numerics.tolerance`` (checked like the scene key, before anything runs).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.core.presets import MODEL_NAMES, PRESET_NAMES, resolve_numerics


def _number_or_text(text: str) -> float | str:
    """A command-line number as a float, anything else as given (the config check names it)."""
    try:
        return float(text)
    except ValueError:
        return text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", type=Path, help="scene YAML (ROS 2 parameters format)")
    parser.add_argument("history", type=Path, help="CSV with header time,depth (s, m) or time,force (s, N)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="result CSV, one row per input row")
    parser.add_argument("--contact", help="contact id of the scene (default: the only one)")
    parser.add_argument("--preset", choices=PRESET_NAMES, help="numerics preset (default: the scene's)")
    parser.add_argument("--model", choices=MODEL_NAMES, help="model path (default: the scene's)")
    parser.add_argument(
        "--tolerance",
        help="force error the numerics must meet, relative to the pull-off force: 0 (the preset) or "
        "in (0, 1); the cheapest element count that meets it for the scene (default: the scene's)",
    )


def main(args: argparse.Namespace) -> int:
    from viscoadh_ros.cli._paths import refuse_overwrite
    from viscoadh_ros.core.config import SceneConfig
    from viscoadh_ros.core.history import simulate_history
    from viscoadh_ros.experiment import choose_contact
    from viscoadh_ros.io.csv_io import check_output_folder, read_history, write_result

    # `-o` on the scene or the history replaced it with the results, exit 0 (0.8.0's tester).
    refuse_overwrite([args.scene, args.history], [("--output", args.output)])
    check_output_folder(args.output)
    contact = choose_contact(SceneConfig.from_yaml(args.scene), args.contact)
    overrides: dict[str, object] = {
        k: v for k, v in (("preset", args.preset), ("model", args.model)) if v is not None
    }
    if args.tolerance is not None:
        overrides["tolerance"] = _number_or_text(args.tolerance)
    if overrides:
        contact = replace(contact, numerics=replace(contact.numerics, **overrides))
        try:
            resolve_numerics(contact.numerics)
        except ConfigError as error:
            raise ConfigError(f"{contact.id}.{error}") from None
    history = read_history(args.history)
    result = simulate_history(contact, history.time, **{history.control: history.values})
    write_result(args.output, result)
    print(f"wrote {args.output} ({history.time.size} rows, model {result.model})")
    return 0
