"""History CSV in, result CSV out (the file side of `viscoadh simulate`).

History: a header row ``time,depth`` (s, m) or ``time,force`` (s, N), then one sample per
row; blank lines and lines starting with ``#`` are skipped. Errors name the file, the line
number and the column.

Rules shared by every verb that reads or writes files (docs/cli.md): a UTF-8 file may start
with a byte-order mark (spreadsheets write one); a number that is not finite (or not a
number) is an error naming its line and column, never silently drawn or skipped; an output
whose folder does not exist is an error (no folder is created).

Result: a header row of the `HistoryResult.columns()` names, one row per input sample, floats
written with ``repr`` precision (round-trips exactly).
"""

from __future__ import annotations

import csv
import math
import re
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


def check_output_folder(path: str | Path) -> None:
    """InputError unless the folder ``path`` goes into exists (every verb's output rule)."""
    folder = Path(path).parent
    if not folder.is_dir():
        raise InputError(f"output folder {str(folder)!r} of {str(path)!r} does not exist (create it first)")


def _rows(path: str | Path, what: str) -> list[tuple[int, list[str]]]:
    """(line number, stripped cells) of the non-blank, non-comment rows of a CSV file."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            lines = list(enumerate(csv.reader(handle), start=1))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"cannot read {what} {str(path)!r}: {exc}") from None
    return [
        (n, [c.strip() for c in row])
        for n, row in lines
        if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#")
    ]


#: A decimal number as a CSV cell may hold one (Python's `float` also takes "1_0", full-width
#: digits and other Unicode digits, which a spreadsheet would not write; 0.8.0's tester found
#: "1_0" read as 10 m): sign, digits with an optional point, an optional exponent, or
#: inf/nan (refused as not finite, with their own message).
_NUMBER = re.compile(
    r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf(?:inity)?|nan)", re.IGNORECASE
)


def _number(name: str, line: int, column: str, text: str) -> float:
    if not _NUMBER.fullmatch(text.strip()):
        raise InputError(f"{name}:{line}: column {column!r} is not a number ({text!r})")
    try:
        number = float(text)
    except ValueError:
        raise InputError(f"{name}:{line}: column {column!r} is not a number ({text!r})") from None
    if not math.isfinite(number):
        raise InputError(f"{name}:{line}: column {column!r} must be finite (got {text!r})")
    return number


def read_columns(path: str | Path, columns: tuple[str, ...]) -> dict[str, NDArray[np.float64]]:
    """The named columns of a CSV with a header row (other columns ignored), as float arrays;
    InputError naming the file, line and column for a missing column or a bad number."""
    name = str(path)
    rows = _rows(path, "CSV")
    if not rows:
        raise InputError(f"{name}: empty file (expected a header row with {', '.join(columns)})")
    header = rows[0][1]
    missing = [c for c in columns if c not in header]
    if missing:
        raise InputError(f"{name!r} lacks the columns {missing} (has {header})")
    index = [header.index(c) for c in columns]
    values = np.empty((len(rows) - 1, len(columns)))
    for i, (line, row) in enumerate(rows[1:]):
        if len(row) != len(header):
            raise InputError(f"{name}:{line}: expected {len(header)} columns, got {len(row)}")
        for j, (column, k) in enumerate(zip(columns, index, strict=True)):
            values[i, j] = _number(name, line, column, row[k])
    return {column: values[:, j].copy() for j, column in enumerate(columns)}


def read_history(path: str | Path) -> History:
    """Read a history CSV; raises `InputError` naming the file, line and column."""
    name = str(path)
    rows = _rows(path, "history")
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
            values[i, j] = _number(name, line, column, row[j])
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
