"""A lab's archive in one command: `viscoadh replay` over many bags (paths and a glob) on a
local Dask cluster of two worker processes, one summary row per bag, a bad bag a row with its
reason; batch fit wired to `fitting.fit_file`; Dask missing is one clear line."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path
from typing import Any

import pytest

from viscoadh_ros import batch
from viscoadh_ros.bench.replay_speed import record_stream
from viscoadh_ros.cli.main import main


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as stream:
        return list(csv.DictReader(stream))


def test_replay_batch_on_a_local_cluster_of_two_workers(tmp_path: Path, capsys: Any) -> None:
    lab = tmp_path / "lab"
    lab.mkdir()
    for name, seconds in (("a", 0.05), ("b", 0.08), ("c", 0.03)):
        record_stream(lab / f"{name}.mcap", seconds)
    broken = tmp_path / "broken.mcap"
    broken.write_bytes(b"not a bag")
    # The same bag as the glob's first: replayed once.
    out = tmp_path / "out"
    args = ["replay", str(lab / "b.mcap"), str(lab / "*.mcap"), str(broken), "-o", str(out), "--workers", "2"]
    code = main([*args, "--json", str(tmp_path / "rows.json")])
    captured = capsys.readouterr()
    assert code == 1, "a failed bag makes the exit status 1, never a lost batch"
    rows = _rows(out / "summary.csv")
    assert [Path(r["bag"]).name for r in rows] == ["b.mcap", "a.mcap", "c.mcap", "broken.mcap"]
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "error"]
    assert "not an MCAP file" in rows[3]["error"] and "broken.mcap" in captured.err
    assert rows == [{k: ("" if v is None else str(v)) for k, v in r.items()} for r in _json_rows(tmp_path)]

    # Each row is what replaying that bag alone gives (the per-bag file included).
    single = tmp_path / "single.json"
    assert main(["replay", str(lab / "a.mcap"), "-o", str(tmp_path / "a.mcap"), "--json", str(single)]) == 0
    alone = json.loads(single.read_text())
    row = rows[1]
    for key in ("samples", "rmse_N", "max_error_N", "commands", "commands_rejected"):
        assert float(row[key]) == pytest.approx(float(alone[key]), rel=1e-12, abs=0.0), key
    assert Path(row["output"]) == out / "a.replay.mcap" and Path(row["output"]).stat().st_size > 0
    assert float(row["wall_s"]) > 0.0
    assert sorted(p.name for p in out.iterdir()) == [
        "a.replay.mcap",
        "b.replay.mcap",
        "c.replay.mcap",
        "summary.csv",
    ]


def _json_rows(tmp_path: Path) -> list[dict[str, Any]]:
    rows = json.loads((tmp_path / "rows.json").read_text())
    columns = list(batch.BASE_COLUMNS)
    for row in rows:
        columns += [k for k in row if k not in columns]
    return [{c: (repr(r[c]) if isinstance(r.get(c), float) else r.get(c, "")) for c in columns} for r in rows]


def test_output_names_are_unique() -> None:
    bags = [Path("x/run.mcap"), Path("y/run.mcap"), Path("z/run"), Path("run_2.mcap")]
    assert batch.output_names(bags, ".replay.mcap") == [
        "run.replay.mcap",
        "run_2.replay.mcap",
        "run_3.replay.mcap",
        "run_2_2.replay.mcap",
    ]


def test_batch_refuses_before_starting(tmp_path: Path, capsys: Any) -> None:
    """A summary path that is a bag, a glob that matches nothing, --summary for one bag: one
    line, exit 2, nothing written and no cluster started."""
    bag = tmp_path / "a.mcap"
    record_stream(bag, 0.02)
    before = bag.read_bytes()
    cases = [
        (["replay", str(bag), str(bag), "-o", str(tmp_path / "o"), "--summary", str(bag)], "would overwrite"),
        (["replay", str(tmp_path / "*.bag"), "-o", str(tmp_path / "o")], "no bag matches"),
        (
            ["replay", str(bag), "-o", str(tmp_path / "o.mcap"), "--summary", "s.csv"],
            "--summary is for batch",
        ),
        (["replay", str(bag), "-o", str(tmp_path / "o"), "--workers", "0"], "--workers must be >= 1"),
    ]
    for args, expected in cases:
        assert main(args) == 2, args
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and expected in err, (args, err)
    assert bag.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["a.mcap"]


def test_missing_dask_is_one_line(tmp_path: Path, capsys: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    bag = tmp_path / "a.mcap"
    record_stream(bag, 0.02)
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if absent
    assert main(["replay", str(bag), "--workers", "2", "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "viscoadh replay: error: batch mode needs Dask: pip install 'viscoadh_ros[batch]' (dask, distributed)"
    )


def test_fit_batch_calls_fit_file_per_bag(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The wiring of `viscoadh fit` in batch mode: `fitting.fit_file(path, options)` per bag with
    the fit's options and its output file; rows in bag order (run in-process here: the cluster
    itself is the replay test's)."""
    import viscoadh_ros.fitting as fitting

    calls: list[tuple[str, dict]] = []

    def fit_file(path: str, options: dict) -> dict:
        calls.append((path, options))
        if path.endswith("bad.mcap"):
            return {"status": "error", "error": "no pull-off"}
        return {"G0_Pa": 1.0e6, "G0_Pa_low": 0.9e6, "G0_Pa_high": 1.1e6, "rmse_N": 1e-4}

    def in_process(task: str, bags: list, options: list, **_: Any) -> list[dict]:
        return [batch.call_task(task, str(b), o) for b, o in zip(bags, options, strict=True)]

    monkeypatch.setattr(fitting, "fit_file", fit_file, raising=False)
    monkeypatch.setattr(batch, "run_batch", in_process)
    bags = [tmp_path / "good.mcap", tmp_path / "bad.mcap"]
    for bag in bags:
        bag.write_bytes(b"x")
    out = tmp_path / "fits"
    code = main(["fit", *map(str, bags), "-o", str(out), "--kelvin", "2", "--free", "G0", "--workers", "2"])
    assert code == 1
    assert [Path(p).name for p, _ in calls] == ["good.mcap", "bad.mcap"]
    assert calls[0][1]["kelvin"] == 2 and calls[0][1]["free"] == "G0"
    assert calls[0][1]["output"] == str(out / "good.fit.yaml")
    rows = _rows(out / "summary.csv")
    assert [r["status"] for r in rows] == ["ok", "error"] and rows[1]["error"] == "no pull-off"
    assert rows[0]["G0_Pa_low"] == "900000.0" and rows[1]["G0_Pa"] == ""


def test_replay_batch_on_an_existing_scheduler(tmp_path: Path) -> None:
    """--scheduler: the bags run on a cluster someone else started (here an in-process one);
    the cluster stays up afterwards."""
    from dask.distributed import Client, LocalCluster

    bags = [tmp_path / f"{name}.mcap" for name in ("x", "y")]
    for bag in bags:
        record_stream(bag, 0.03)
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster:
        out = tmp_path / "out"
        assert (
            main(["replay", *map(str, bags), "--scheduler", cluster.scheduler_address, "-o", str(out)]) == 0
        )
        rows = _rows(out / "summary.csv")
        assert [r["status"] for r in rows] == ["ok", "ok"] and all(float(r["samples"]) > 0 for r in rows)
        with Client(cluster.scheduler_address) as client:
            assert len(client.scheduler_info()["workers"]) == 1, "the user's cluster is left running"
