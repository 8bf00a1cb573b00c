"""The `viscoadh` command: one dispatcher over lazily imported verb modules.

Each verb lives in ``viscoadh_ros.cli.<verb>`` and exposes
``add_arguments(parser: argparse.ArgumentParser) -> None`` and
``main(args: argparse.Namespace) -> int``. Only the chosen verb's module is imported, so
``viscoadh --help`` stays fast and does not load ROS or numba; the help lines of all verbs
therefore live here, in ``HELP``.

ROS arguments: everything from the first ``--ros-args`` on is kept out of argparse and handed
to the verb unchanged as ``args.ros_args`` (a list, empty when absent), the way ``ros2 run``
passes them on. Every verb's namespace has that attribute.

Exit codes: 0 success, 1 runtime failure, 2 usage or input error (one line on stderr,
``viscoadh <verb>: error: ...``, never a traceback), 130 interrupted.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from types import ModuleType
from typing import NoReturn

from viscoadh_ros import __version__

PROG = "viscoadh"

#: verb name -> module implementing it.
VERBS: dict[str, str] = {
    "simulate": "viscoadh_ros.cli.simulate",
    "node": "viscoadh_ros.cli.node",
    "demo": "viscoadh_ros.cli.demo",
    "replay": "viscoadh_ros.cli.replay",
    "fit": "viscoadh_ros.cli.fit",
    "plot": "viscoadh_ros.cli.plot",
    "bench": "viscoadh_ros.cli.bench",
    "gripper": "viscoadh_ros.cli.gripper",
}

#: verb name -> one-line help shown by `viscoadh --help`.
HELP: dict[str, str] = {
    "simulate": "run a loading history (depth or force vs time) through the contact model offline",
    "node": "run the ROS 2 node on a scene (default: the built-in scene)",
    "demo": "approach, hold and retract on the default scene through the node; log and plot it",
    "replay": "run the model over a recorded MCAP file or rosbag2 folder and compare forces",
    "fit": "identify material parameters from recorded force histories",
    "plot": "plot force-depth and force-radius loops from a result CSV or an MCAP log",
    "bench": "measure speed and accuracy of the numerics presets and the node on this machine",
    "gripper": "MuJoCo pick-and-place whose adhesive pads are the viscoadh model (extra: gripper)",
}

ROS_ARGS_FLAG = "--ros-args"


def _split_ros_args(argv: list[str]) -> tuple[list[str], list[str]]:
    """Split ``argv`` at the first ``--ros-args``: (for argparse, for ROS)."""
    if ROS_ARGS_FLAG in argv:
        i = argv.index(ROS_ARGS_FLAG)
        return argv[:i], argv[i:]
    return argv, []


def _chosen_verb(argv: Sequence[str]) -> str | None:
    """The verb the command line names: top-level options are all flags, so it is the first
    token that is not an option."""
    return next((tok for tok in argv if not tok.startswith("-")), None)


def _import_verb(verb: str) -> ModuleType | None:
    """The verb's module, or None when this installation does not have it."""
    name = VERBS[verb]
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        # Only the verb module itself missing means "not available"; a missing dependency
        # inside an existing verb is a real failure and keeps its traceback.
        if exc.name == name:
            return None
        raise


def _user_error_types() -> tuple[type[BaseException], ...]:
    """The core's input/config error types, which mean "the user's input is wrong"."""
    try:
        from viscoadh_ros.core.errors import ConfigError, InputError
    except ImportError:
        return ()
    return (ConfigError, InputError)


class _OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line on stderr and exit 2, as docs/cli.md
    promises for every usage or input error (argparse prints its usage block first: 6-9
    lines, 0.8.0's outside tester); the usage stays one `--help` away."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(verb: str | None = None) -> tuple[argparse.ArgumentParser, ModuleType | None]:
    """The top-level parser with a subparser per verb; ``verb``'s own arguments are added
    from its module (imported here). Returns the parser and that module (None if absent)."""
    parser = _OneLineParser(
        prog=PROG,
        description="Adhesive contact with viscoelastic materials (MDR + energy criterion), "
        "offline and as a ROS 2 node.",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="verb", metavar="<verb>", title="verbs")
    module = None
    for name, help_line in HELP.items():
        verb_parser = sub.add_parser(name, help=help_line, description=help_line)
        if name == verb:
            module = _import_verb(name)
            if module is not None:
                module.add_arguments(verb_parser)
    return parser, module


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `viscoadh`; returns the process exit code."""
    cli_args, ros_args = _split_ros_args(list(sys.argv[1:] if argv is None else argv))
    verb = _chosen_verb(cli_args)
    if verb is not None and verb not in VERBS:
        verb = None  # let argparse report the invalid choice with the list of verbs
    parser, module = build_parser(verb)
    args = parser.parse_args(cli_args)
    if args.verb is None:
        parser.print_help(sys.stderr)
        return 2
    if module is None:
        print(
            f"{PROG} {args.verb}: error: this verb is not available in this installation "
            f"(module {VERBS[args.verb]} is missing)",
            file=sys.stderr,
        )
        return 2
    args.ros_args = ros_args
    try:
        return int(module.main(args))
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # The reader of stdout went away (`viscoadh replay ... | head`): stop quietly, with the
        # exit status of a process SIGPIPE ended (128 + 13), and no traceback at exit either.
        _drop_stdout()
        return 141
    except Exception as exc:
        if isinstance(exc, _user_error_types()):
            print(f"{PROG} {args.verb}: error: {exc}", file=sys.stderr)
            return 2
        raise


def _drop_stdout() -> None:
    """Point stdout at the null device, so the interpreter's flush at exit does not raise
    BrokenPipeError again (the recipe of Python's `signal` documentation)."""
    import os

    try:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
    except (OSError, ValueError):  # no file descriptor (a test's captured stdout)
        pass
