"""Side-by-side cost of `viscoadh replay` and its stages, this checkout against a git ref, in one
process (issue 13's before/after for the replay paths).

    .venv/bin/python benchmarks/replay_ab.py [REF] [--new REF2] [--seconds 60] [--repeats 7]

REF (default ``main``) is read with ``git show``: its replay-side modules (io/bag.py, io/cdr.py,
io/mcap_bulk.py, experiment.py, cli/replay.py) are loaded under the package name ``_ab_old``
beside the current ones (or beside REF2's, ``--new``, loaded as ``_ab_new``: one change at a
time), both on the current core (the simulator is the same object code), so the two paths run
alternately on the same recording (a node-style log of 1 kHz depth commands and wrenches,
`bench.replay_speed.record_stream`) and only the replay-side code differs. Prints the median
of the repeats per stage, in us per command, and the ratio; also the bare
`ContactSimulator.step_depths` over the same depth history (what the simulate stage would cost
with no Python around the kernel), and whether both sides wrote the same output bytes.
Compare only the ratios of one sitting.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import re
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MODULES = {
    "io.bag": "viscoadh_ros/io/bag.py",
    "io.cdr": "viscoadh_ros/io/cdr.py",
    "io.mcap_bulk": "viscoadh_ros/io/mcap_bulk.py",
    "experiment": "viscoadh_ros/experiment.py",
    "cli.replay": "viscoadh_ros/cli/replay.py",
}


def load_old(ref: str, folder: Path, alias: str = "_ab_old") -> dict[str, ModuleType]:
    """The replay-side modules of ``ref``, importable as ``<alias>.<name>``."""
    package = folder / alias
    for sub in ("", "io", "cli"):
        (package / sub).mkdir(parents=True, exist_ok=True)
        (package / sub / "__init__.py").write_text("")
    names = "|".join(re.escape(n) for n in MODULES)
    for name, path in MODULES.items():
        source = subprocess.run(
            ["git", "show", f"{ref}:{path}"], cwd=ROOT, check=True, capture_output=True, text=True
        ).stdout
        source = re.sub(rf"\bviscoadh_ros\.({names})\b", rf"{alias}.\1", source)
        source = re.sub(
            r"from viscoadh_ros\.io import (bag|cdr|mcap_bulk)\b", rf"from {alias}.io import \1", source
        )
        (package / (name.replace(".", "/") + ".py")).write_text(source)
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    return {name: importlib.import_module(f"{alias}.{name}") for name in MODULES}


def _without_data_crc(data: bytes) -> bytes:
    """An MCAP file's bytes with its data-end record's CRC zeroed (the record ends right
    before the summary, or before the footer when there is none)."""
    import struct

    footer = len(data) - 8 - 29
    (summary_start,) = struct.unpack_from("<Q", data, footer + 9)
    at = (summary_start or footer) - 4
    return data[:at] + bytes(4) + data[at + 4 :]


def current() -> dict[str, ModuleType]:
    return {name: importlib.import_module(f"viscoadh_ros.{name}") for name in MODULES}


def stages(
    mods: dict[str, ModuleType], bag_path: Path, out: Path, clock: Callable[[], float] = time.perf_counter
) -> dict[str, Any]:
    """The verb's stages with one side's modules: each a callable on the same recording."""
    from viscoadh_ros.core.config import SceneConfig

    experiment_mod, replay = mods["experiment"], mods["cli.replay"]
    bag = mods["io.bag"].Bag(bag_path)
    experiment = experiment_mod.load_experiment(bag)
    scene = SceneConfig.from_dict(bag.scene())
    contact = experiment_mod.choose_contact(scene, None)
    run = experiment_mod.run_model(contact, experiment)
    parser = argparse.ArgumentParser()
    replay.add_arguments(parser)
    inner: list[float] = []  # run_model's time inside each whole run
    timed = replay.run_model

    def run_model(*args: Any, **kwargs: Any) -> Any:
        start = clock()
        try:
            return timed(*args, **kwargs)
        finally:
            inner.append(clock() - start)

    replay.run_model = run_model

    def whole() -> None:
        args = parser.parse_args([str(bag_path), "-o", str(out)])
        args.ros_args = []
        if out.exists():
            out.unlink()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            status = replay.main(args)
        assert status == 0

    return {
        "whole verb": whole,
        "read (Bag)": lambda: mods["io.bag"].Bag(bag_path),
        "decode (load_experiment)": lambda: experiment_mod.load_experiment(bag),
        "simulate (run_model)": lambda: experiment_mod.run_model(contact, experiment),
        "compare": lambda: experiment_mod.compare(experiment, run),
        "encode + write": lambda: replay._write_output(out, scene, contact.id, experiment, run),
        "_experiment": experiment,
        "_contact": contact,
        "_inner": inner,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ref", nargs="?", default="main")
    parser.add_argument("--new", help="a second ref in place of this checkout")
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--repeats", type=int, default=8)
    parser.add_argument(
        "--clock",
        choices=("wall", "cpu"),
        default="wall",
        help="wall: time.perf_counter; cpu: this thread's CPU time (time.thread_time: user and "
        "system), which leaves out the time other processes hold the CPU (a loaded machine)",
    )
    options = parser.parse_args()
    clock = time.perf_counter if options.clock == "wall" else time.thread_time

    from viscoadh_ros.bench.replay_speed import record_stream
    from viscoadh_ros.core.simulator import ContactSimulator

    with tempfile.TemporaryDirectory(prefix="replay_ab_") as tmp:
        folder = Path(tmp)
        bag_path = folder / "stream.mcap"
        record_stream(bag_path, options.seconds)
        sides = {
            "old": stages(load_old(options.ref, folder), bag_path, folder / "old.mcap", clock),
            "new": stages(
                current() if options.new is None else load_old(options.new, folder, "_ab_new"),
                bag_path,
                folder / "new.mcap",
                clock,
            ),
        }
        experiment, contact = sides["new"]["_experiment"], sides["new"]["_contact"]
        times = experiment.time(experiment.input_ns)
        depths = experiment.input_value
        bare = {"step_depths alone": lambda: ContactSimulator(contact).step_depths(times, depths)}
        names = [k for k in sides["new"] if not k.startswith("_")]
        samples: dict[tuple[str, str], list[float]] = {}
        runs = [((side, name), sides[side][name]) for name in names for side in sides]
        runs += [(("new", k), f) for k, f in bare.items()]
        for _, run in runs:
            run()  # warm: compiled code, caches, first-touch memory
        for side in sides.values():
            side["_inner"].clear()
        for repeat in range(options.repeats):
            # Each stage of both sides back to back, which side first alternating by repeat
            # (the second of a pair tends to find the memory the first freed, ~1.5x faster).
            for name in names:
                order = ("old", "new") if repeat % 2 == 0 else ("new", "old")
                for side in order:
                    start = clock()
                    sides[side][name]()
                    samples.setdefault((side, name), []).append(clock() - start)
            for key, run in runs[2 * len(names) :]:
                start = clock()
                run()
                samples.setdefault(key, []).append(clock() - start)
        n = experiment.input_ns.size
        # Everything but the simulation, per whole run: its time less its own run_model's.
        for side in sides:
            rest = np.array(samples[(side, "whole verb")]) - np.array(sides[side]["_inner"])
            samples[(side, "whole verb less its run_model")] = list(rest)
        names.append("whole verb less its run_model")
        med = {key: float(np.median(v)) / n * 1e6 for key, v in samples.items()}
        print(
            f"{n} commands ({options.seconds:g} s at 1 kHz), median of {options.repeats}, us per command "
            f"({options.clock} clock)"
        )
        print(f"| stage | {options.ref} | {options.new or 'this checkout'} | ratio |")
        print("|---|---|---|---|")
        for name in names:
            old, new = med[("old", name)], med[("new", name)]
            print(f"| {name} | {old:.3f} | {new:.3f} | {old / new:.2f}x |")
        for name in bare:
            print(f"| {name} | | {med[('new', name)]:.3f} | |")
        for side in ("old", "new"):
            print(
                f"{side}: whole {med[(side, 'whole verb')]:.3f} us/command = "
                f"{1e3 / med[(side, 'whole verb')]:.0f}x real time; run_model - step_depths alone "
                f"{med[(side, 'simulate (run_model)')] - med[('new', 'step_depths alone')]:.3f} us/command"
            )
        old_bytes, new_bytes = (folder / "old.mcap").read_bytes(), (folder / "new.mcap").read_bytes()
        print(
            f"output files byte-identical: {old_bytes == new_bytes}; "
            f"but for the data-section CRC: {_without_data_crc(old_bytes) == _without_data_crc(new_bytes)}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
