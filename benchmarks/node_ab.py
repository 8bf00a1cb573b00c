"""Node drops and round trips side by side: this checkout's node, another checkout's, the echo node.

Alternating runs of the latency bench's load (`viscoadh_ros.bench.latency`: N contacts at a
rate, one HandCommand per tick with --hand, MCAP logging on), each server in its own process on
its own ROS domain, the client in another. Per run, besides the client's round trips:

- where each lost command was lost: the client's stamps of the commands that got no state,
  looked up in the node's MCAP log (a command in the log reached the node; one not in it was
  lost before, in the node's reader history or in DDS);
- how late the node took each command (its log time minus the command's stamp);
- the node's garbage collections (``gc.callbacks``), MCAP chunk flushes, the time per hand
  command handled and per publish (wall and thread CPU), and the process's CPU per second
  (``/proc``), from a wrapper that instruments the node before ``main`` runs (a diagnostic
  only; the product is unchanged).

The other checkout runs on this venv: its package is put first on ``sys.path`` with the
editable finder removed (the message package and rclpy are the same).

    .venv/bin/python benchmarks/node_ab.py --base /work/ab/base --pairs 2 --duration 60 --hand

Prints one JSON line per run and a table of medians per server at the end.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from viscoadh_ros.bench.latency import _ros_env, _stop, bench_scene, pick_domain_id, write_scene

HERE = Path(__file__).resolve().parents[1]

#: Runs the node of checkout $NODE_AB_SRC instrumented; writes $NODE_AB_DIAG (npz) at exit.
WRAPPER = r"""
import gc, os, sys, time
import numpy as np
src = os.environ["NODE_AB_SRC"]
sys.meta_path[:] = [f for f in sys.meta_path if "__editable__" not in getattr(f, "__module__", "")]
sys.path.insert(0, src)
collections = []
def on_gc(phase, info, out=collections, now=time.time_ns):
    out.append((now(), 0 if phase == "start" else 1, info["generation"]))
gc.callbacks.append(on_gc)
from viscoadh_ros.io import mcap_log
flushes = []
finish_chunk = mcap_log._File._finish_chunk
def timed_finish(self):
    t0 = time.time_ns(); finish_chunk(self); flushes.append((t0, time.time_ns()))
mcap_log._File._finish_chunk = timed_finish
from viscoadh_ros.ros import node as node_module
handled = []
name = "handle_command" if hasattr(node_module._Hand, "handle_command") else "on_command"
handle = getattr(node_module._Hand, name)
def timed_handle(self, *args):
    t0 = time.time_ns(); handle(self, *args); handled.append((t0, time.time_ns()))
setattr(node_module._Hand, name, timed_handle)
import rclpy.publisher
publishes = []
publish = rclpy.publisher.Publisher.publish
def timed_publish(self, msg, wall=time.perf_counter_ns, cpu=time.thread_time_ns):
    w0, c0 = wall(), cpu(); publish(self, msg); publishes.append((wall() - w0, cpu() - c0))
rclpy.publisher.Publisher.publish = timed_publish
import viscoadh_ros
assert viscoadh_ros.__file__.startswith(src), viscoadh_ros.__file__
from viscoadh_ros.cli.main import main
try:
    code = main()
finally:
    def table(rows, width):
        return np.array(rows, np.int64).reshape(-1, width)
    np.savez(os.environ["NODE_AB_DIAG"], gc=table(collections, 3), flushes=table(flushes, 2),
             handled=table(handled, 2), publishes=table(publishes, 2))
sys.exit(code)
"""


def _threads_cpu_s(pid: int) -> float:
    """CPU seconds of every thread of a live process so far (Linux /proc)."""
    total = 0.0
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            raw = Path(f"/proc/{pid}/task/{tid}/stat").read_text()
        except OSError:
            continue
        fields = raw[raw.rindex(")") + 2 :].split()
        total += int(fields[11]) + int(fields[12])
    return total / os.sysconf("SC_CLK_TCK")


def run(server: str, src: Path | None, args: argparse.Namespace, folder: Path) -> dict[str, Any]:
    """One run of `server` ("node" from checkout `src`, or "echo"); its figures."""
    folder.mkdir(parents=True, exist_ok=True)
    log_path = folder / "node.mcap"
    scene, amplitude = bench_scene(args.contacts, log_path=log_path)
    scene_path = write_scene(scene, folder / "scene.yaml")
    ids = scene["/**"]["ros__parameters"]["contacts"]
    env = _ros_env(pick_domain_id())
    env.update(NODE_AB_SRC=str(src), NODE_AB_DIAG=str(folder / "diag.npz"))
    wrapper = folder / "wrapper.py"
    wrapper.write_text(WRAPPER)
    py = sys.executable
    if server == "echo":
        server_cmd = [py, "-m", "viscoadh_ros.bench.echo", *ids]
    else:
        server_cmd = [py, str(wrapper), "node", "--ros-args", "--params-file", str(scene_path)]
    client_cmd = [
        py, "-m", "viscoadh_ros.bench.latency_client", "--reply", "state" if server == "node" else "echo",
        "--rate", repr(args.rate), "--duration", repr(args.duration), "--warmup", "2.0",
        "--ready-timeout", "120", "--depth-amplitude", repr(amplitude), "--out", str(folder / "client.npz"),
        *(["--hand"] if args.hand else []), *ids,
    ]  # fmt: skip
    cpu = None
    with open(folder / "server.log", "wb") as server_log, open(folder / "client.log", "wb") as client_log:
        server_proc = subprocess.Popen(server_cmd, env=env, stdout=server_log, stderr=subprocess.STDOUT)
        try:
            client = subprocess.Popen(client_cmd, env=env, stdout=client_log, stderr=subprocess.STDOUT)
            started, first = time.time(), None
            while client.poll() is None and server_proc.poll() is None:
                if time.time() - started > 15.0:  # past start-up and warm-up
                    sample = (time.time(), _threads_cpu_s(server_proc.pid))
                    first = first or sample
                    if sample[0] > first[0]:
                        cpu = (sample[1] - first[1]) / (sample[0] - first[0])
                time.sleep(0.5)
            client.wait()
        finally:
            _stop(server_proc)
    if client.returncode != 0:
        logs = [(folder / name).read_text()[-2000:] for name in ("client.log", "server.log")]
        raise RuntimeError("\n".join(logs))
    data = np.load(folder / "client.npz")
    latency, stamps = data["latency_s"], data["stamp_ns"]
    lost = np.isnan(latency)
    answered = latency[~lost]
    result: dict[str, Any] = {
        "server": server if server == "echo" else f"node {src}",
        "sent": int(latency.size),
        "dropped": int(lost.sum()),
        "p50_ms": float(np.percentile(answered, 50.0)) * 1e3,
        "p99_ms": float(np.percentile(answered, 99.0)) * 1e3,
        "deadline_miss": float(np.count_nonzero(~(latency <= 1.0 / args.rate))) / latency.size,
        "process_cpu_per_s": cpu,
    }
    if server == "node":
        from viscoadh_ros.io.bag import Bag

        bag = Bag(log_path, recover=True)
        log_ns, received = [], []
        for topic in bag.topics:
            if topic.endswith("/indentation"):
                times, _, payloads = bag.raw(topic)
                log_ns.append(times)
                # header.stamp: sec (int32) and nanosec (uint32) after the 4-byte CDR header
                sec = [int.from_bytes(p[4:8], "little") for p in payloads]
                nanosec = [int.from_bytes(p[8:12], "little") for p in payloads]
                received.append(np.array(sec, np.int64) * 10**9 + np.array(nanosec, np.int64))
        log_ns, received = np.concatenate(log_ns), np.concatenate(received)
        reached = np.isin(stamps[lost], received)
        late_ms = (log_ns - received) / 1e6
        diag = np.load(folder / "diag.npz")
        collections = diag["gc"]
        starts, stops = collections[collections[:, 1] == 0], collections[collections[:, 1] == 1]
        during = starts[: len(stops), 0] >= received.min()
        pause_ms = (stops[:, 0] - starts[: len(stops), 0]) / 1e6
        handled = (diag["handled"][:, 1] - diag["handled"][:, 0]) / 1e3
        publishes = diag["publishes"] / 1e3
        flushes_ms = np.diff(diag["flushes"], axis=1) / 1e6
        result.update(
            lost_before_the_node=int((~reached).sum()),
            lost_after_the_node=int(reached.sum()),
            take_late_p99_ms=float(np.percentile(late_ms, 99.0)),
            take_late_max_ms=float(late_ms.max()),
            full_collections_during_run=int(np.count_nonzero(during & (starts[: len(stops), 2] == 2))),
            longest_collection_during_run_ms=float(pause_ms[during].max()) if during.any() else 0.0,
            handle_us_p50=float(np.percentile(handled, 50.0)) if len(handled) else None,
            publish_cpu_us_p50=float(np.percentile(publishes[:, 1], 50.0)) if len(publishes) else None,
            publish_wall_us_p50=float(np.percentile(publishes[:, 0], 50.0)) if len(publishes) else None,
            longest_flush_ms=float(flushes_ms.max()) if len(flushes_ms) else 0.0,
        )
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", type=Path, required=True, help="the other checkout (its repository root)")
    parser.add_argument("--pairs", type=int, default=1)
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--contacts", type=int, default=16)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--hand", action="store_true")
    parser.add_argument("--keep", type=Path, help="keep each run's files under this folder")
    args = parser.parse_args()
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory(prefix="node_ab_") as tmp:
        root = args.keep or Path(tmp)
        for pair in range(args.pairs):
            servers = (("base", "node", args.base), ("this", "node", HERE), ("echo", "echo", HERE))
            for label, server, src in servers:
                row = {"run": f"{label}{pair}", **run(server, src, args, root / f"{label}{pair}")}
                print(json.dumps(row), flush=True)
                rows.append(row)
    keys = [
        "dropped",
        "lost_before_the_node",
        "p50_ms",
        "p99_ms",
        "deadline_miss",
        "process_cpu_per_s",
        "take_late_max_ms",
        "full_collections_during_run",
        "handle_us_p50",
        "publish_cpu_us_p50",
    ]
    print("| server | " + " | ".join(keys) + " |")
    print("|---" * (len(keys) + 1) + "|")
    for label in ("base", "this", "echo"):
        mine = [r for r in rows if r["run"].startswith(label)]
        cells = []
        for key in keys:
            values = [r[key] for r in mine if r.get(key) is not None]
            cells.append(f"{np.median(values):.4g}" if values else "-")
        print(f"| {label} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
