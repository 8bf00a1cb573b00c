"""A lab's archive in parallel: one task per bag on a Dask cluster, one summary row per bag.

``viscoadh replay`` and ``viscoadh fit`` hand this module a task (an importable function
``task(path: str, options: dict) -> dict`` returning one summary row), the bags and the
options; :func:`run_batch` runs the tasks on a ``distributed`` cluster and returns one row per
bag, in the order the bags were given. A bag whose task raises (or whose worker dies) becomes
a row with ``status: error`` and the reason: a failure never loses the batch.

The cluster: by default a ``LocalCluster`` on this machine of ``workers`` processes with one
thread each (the model is CPU-bound numba and numpy; processes sidestep the GIL), listening on
the loopback interface only, without a dashboard; or an existing cluster at ``scheduler``
(``tcp://host:8786``), whose workers must see the same paths (a shared file system) and have
viscoadh_ros installed. Dask is the optional extra ``batch`` (``pip install
'viscoadh_ros[batch]'``): imported here only, when a batch runs, so the default install and
every other verb stay free of it.
"""

from __future__ import annotations

import csv
import glob
import importlib
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from viscoadh_ros.core.errors import InputError

#: Columns every row starts with; the task's own follow in the order they first appear.
BASE_COLUMNS = ("bag", "status", "error", "wall_s")


def expand_bags(patterns: Sequence[str | Path]) -> list[Path]:
    """The bags ``patterns`` name: paths, or globs (``lab/2026-*/*.mcap``, ``**`` recursive),
    in the order given, each bag once. A pattern that matches nothing is an error."""
    bags: list[Path] = []
    for pattern in map(str, patterns):
        if glob.has_magic(pattern):
            found = sorted(glob.glob(pattern, recursive=True))
            if not found:
                raise InputError(f"no bag matches {pattern!r}")
        else:
            found = [pattern]
        for name in found:
            path = Path(name)
            if not any(path.resolve() == b.resolve() for b in bags):
                bags.append(path)
    return bags


def is_batch(patterns: Sequence[str | Path], *, workers: int | None, scheduler: str | None) -> bool:
    """Batch mode: several bags or a glob, or a cluster option given."""
    return (
        len(patterns) > 1
        or any(glob.has_magic(str(p)) for p in patterns)
        or workers is not None
        or scheduler is not None
    )


def output_names(bags: Sequence[Path], suffix: str) -> list[str]:
    """One output file name per bag, ``<stem><suffix>``, made unique (``<stem>_2<suffix>``)."""
    names: list[str] = []
    for bag in bags:
        stem = bag.name[: -len(".mcap")] if bag.name.endswith(".mcap") else bag.name
        name, k = f"{stem}{suffix}", 2
        while name in names:
            name, k = f"{stem}_{k}{suffix}", k + 1
        names.append(name)
    return names


def call_task(task: str, path: str, options: Mapping[str, Any]) -> dict[str, Any]:
    """Run ``task`` (``"module:function"``) on one bag and time it; on a worker. Never raises:
    an exception becomes the row's ``error`` (its last line; the type when it has none)."""
    started = time.perf_counter()
    try:
        module, name = task.split(":")
        row = dict(getattr(importlib.import_module(module), name)(path, dict(options)))
        row.setdefault("status", "error" if row.get("error") else "ok")
    except Exception as exc:  # noqa: BLE001 - one bag's failure is that bag's row
        text = str(exc).strip().splitlines()
        row = {"status": "error", "error": f"{type(exc).__name__}: {text[-1] if text else ''}".strip(": ")}
        if not isinstance(exc, ValueError):  # not a user error: keep where it came from
            row["error"] += " at " + traceback.extract_tb(exc.__traceback__)[-1].name
    row.setdefault("error", "")
    row["bag"] = path
    row["wall_s"] = time.perf_counter() - started
    return row


def connect(workers: int | None, scheduler: str | None) -> tuple[Any, Any]:
    """``(client, cluster or None)``: connected to ``scheduler``, or to a new LocalCluster."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError(
            "batch mode needs Dask: pip install 'viscoadh_ros[batch]' (dask, distributed)"
        ) from None
    if scheduler is not None:
        try:
            return Client(scheduler, timeout="10s"), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"cannot reach the Dask scheduler {scheduler!r} ({exc})") from None
    cluster = LocalCluster(
        n_workers=workers or 1,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=40,  # logging.ERROR: no worker chatter on the user's terminal
    )
    return Client(cluster), cluster


def run_batch(
    task: str,
    bags: Sequence[Path],
    options: Sequence[Mapping[str, Any]],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    on_row: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``task`` on every bag (``options[k]`` for ``bags[k]``) on a Dask cluster; one row
    per bag, in the order of ``bags``. ``on_row`` sees each row as it arrives (any order)."""
    if len(options) != len(bags):
        raise ValueError(f"{len(bags)} bags but {len(options)} option sets")
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be >= 1 (got {workers})")
    from tqdm import tqdm

    client, cluster = connect(workers, scheduler)
    rows: list[dict[str, Any] | None] = [None] * len(bags)
    try:
        from dask.distributed import as_completed

        futures = {
            client.submit(
                call_task, task, str(bag), dict(opts), key=f"viscoadh-{k}-{bag.name}", pure=False
            ): k
            for k, (bag, opts) in enumerate(zip(bags, options, strict=True))
        }
        bar = tqdm(total=len(bags), unit="bag", disable=None if progress else True, leave=False)
        with bar:
            for future in as_completed(futures):
                k = futures[future]
                try:
                    row = future.result()
                except Exception as exc:  # noqa: BLE001 - a dead worker: that bag's row says so
                    row = {"bag": str(bags[k]), "status": "error", "error": f"{type(exc).__name__}: {exc}"}
                rows[k] = row
                if on_row is not None:
                    on_row(row)
                bar.update(1)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return [row for row in rows if row is not None]


def write_summary(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    """One CSV row per bag: :data:`BASE_COLUMNS`, then every other key in first-seen order
    (a value a row lacks is empty)."""
    columns = list(BASE_COLUMNS)
    for row in rows:
        columns += [key for key in row if key not in columns]
    with open(path, "w", newline="", encoding="utf-8") as stream:
        writer = csv.DictWriter(stream, fieldnames=columns, restval="")
        writer.writeheader()
        for row in rows:
            writer.writerow({key: _cell(value) for key, value in row.items()})


def _cell(value: Any) -> Any:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return value
