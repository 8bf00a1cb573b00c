"""History CSV in, result CSV out (the file side of `viscoadh simulate`).

History: a header row ``time,depth`` (s, m) or ``time,force`` (s, N), then one sample per
row; blank lines and lines starting with ``#`` are skipped. Errors name the file, the line
number and the column. Result: a header row of the `HistoryResult.columns()` names, one row
per input sample, floats written with ``repr`` precision (round-trips exactly).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from viscoadh_ros.core.errors import InputError
from viscoadh_ros.core.history import HistoryResult

CONTROLS = ("depth", "force")


@dataclass(frozen=True)
class History:
    """A loading history: sample times (s, shape (n,)) and one control column (shape (n,)),
    named ``control`` ("depth", m, or "force", N)."""

    time: NDArray[np.float64]
    control: str
    values: NDArray[np.float64]


def read_history(path: str | Path) -> History:
    """Read a history CSV; raises `InputError` naming the file, line and column."""
    name = str(path)
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            lines = list(enumerate(csv.reader(handle), start=1))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"cannot read history {name!r}: {exc}") from None
    rows = [
        (n, [c.strip() for c in row])
        for n, row in lines
        if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#")
    ]
    if not rows:
        raise InputError(f"{name}: empty file (expected a header row time,depth or time,force)")
    header_line, header = rows[0]
    if len(header) != 2 or header[0] != "time" or header[1] not in CONTROLS:
        raise InputError(
            f"{name}:{header_line}: header must be 'time,depth' or 'time,force' (got {','.join(header)!r})"
        )
    control = header[1]
    if len(rows) < 2:
        raise InputError(f"{name}: no samples after the header")
    values = np.empty((len(rows) - 1, 2))
    for i, (line, row) in enumerate(rows[1:]):
        if len(row) != 2:
            raise InputError(f"{name}:{line}: expected 2 columns (time,{control}), got {len(row)}")
        for j, column in enumerate(("time", control)):
            try:
                number = float(row[j])
            except ValueError:
                raise InputError(f"{name}:{line}: column {column!r} is not a number ({row[j]!r})") from None
            if not math.isfinite(number):
                raise InputError(f"{name}:{line}: column {column!r} must be finite (got {row[j]!r})")
            values[i, j] = number
        if i and values[i, 0] <= values[i - 1, 0]:
            raise InputError(
                f"{name}:{line}: column 'time' must increase strictly "
                f"({row[0]} after {float(values[i - 1, 0])!r})"
            )
    return History(values[:, 0].copy(), control, values[:, 1].copy())


def write_result(path: str | Path, result: HistoryResult) -> None:
    """Write `result` as CSV: header of column names, one row per sample (bools as 0/1)."""
    columns = result.columns()
    names = list(columns)
    rows = zip(*(columns[n].tolist() for n in names), strict=True)
    try:
        with open(path, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(names)
            for row in rows:
                writer.writerow(
                    [int(v) if isinstance(v, bool) else repr(v) if isinstance(v, float) else v for v in row]
                )
    except OSError as exc:
        raise InputError(f"cannot write {str(path)!r}: {exc}") from None
