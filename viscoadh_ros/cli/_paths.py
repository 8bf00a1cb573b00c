"""One check for every verb that writes files: an output path must never be one of its inputs.

``viscoadh replay X.mcap -o X.mcap`` once overwrote its input. The verbs read their inputs
into memory before writing, so nothing stopped it. :func:`refuse_overwrite` compares each
output with each input by resolved path (``./``, ``..``, symlinks) and, when both exist, by
``os.path.samefile`` (hard links, bind mounts); an output inside an input folder (a rosbag2
folder) is refused too, since the next read of that folder would pick it up. Call it before
anything is opened for writing.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from viscoadh_ros.core.errors import InputError


def _same(a: Path, b: Path) -> bool:
    if a.resolve() == b.resolve():
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet): resolved paths decide
        return False


def _inside(output: Path, folder: Path) -> bool:
    if not folder.is_dir():
        return False
    parent = output.resolve().parent
    folder = folder.resolve()
    return parent == folder or folder in parent.parents


def refuse_overwrite(
    inputs: Iterable[Path | str | None], outputs: Iterable[tuple[str, Path | str | None]]
) -> None:
    """Raise InputError when an output is an input (or lies inside an input folder).

    ``outputs``: ``(option, path)`` pairs, e.g. ``("--output", args.output)``; None entries
    (options not given) are skipped, in both lists.
    """
    sources = [Path(p) for p in inputs if p is not None]
    targets = [(flag, Path(p)) for flag, p in outputs if p is not None]
    for flag, target in targets:
        for source in sources:
            if _same(target, source) or _inside(target, source):
                raise InputError(
                    f"{flag} {str(target)!r} would overwrite the input {str(source)!r}; "
                    "choose another output path"
                )
    for k, (flag, target) in enumerate(targets):
        for other_flag, other in targets[k + 1 :]:
            if _same(target, other):
                raise InputError(f"{flag} and {other_flag} are the same file {str(target)!r}")
