"""In-process profile of the node's live path: where one command's time goes, without DDS noise.

The node runs on its own rclpy Context (discovery off) on the bench scene (N rate-dependent
standard-solid contacts, MCAP logging on), its live thread stopped. The profile hands pre-built
commands (serialised, as the live thread takes them) straight to the node's command handler
(1 kHz stamps per contact, the latency client's depth cycle), in ticks of one command per
contact (or one HandCommand per tick with ``--hand``), and reads:

- live-thread CPU and wall time per command (``time.thread_time`` / ``perf_counter``), and the
  CPU of the same steps on bare simulators in the same thread (the core's share),
- the MCAP writer thread's CPU per command (its thread CPU clock), which competes for the GIL,
- with ``--cprofile``, the top functions of the command handler.

A separate micro-measurement times taking one message off a subscription (object and raw).
Run: ``python -m viscoadh_ros.bench.live_profile --contacts 16 --ticks 2000 [--hand] [--cprofile]``.
"""

from __future__ import annotations

import argparse
import cProfile
import io
import math
import pstats
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from viscoadh_ros.bench.latency import bench_scene
from viscoadh_ros.bench.latency_client import CYCLE_PERIOD_S, LIFT_FRACTION


def _thread_cpu_s(thread: Any) -> float:
    """CPU time of a live Python thread, s (Linux thread CPU clock)."""
    return time.clock_gettime(time.pthread_getcpuclockid(thread.ident))


def profile_live(
    *, contacts: int = 16, ticks: int = 2000, hand: bool = False, log: bool = True, profile: bool = False
) -> dict[str, Any]:
    """Feed ``ticks`` x ``contacts`` commands to an in-process node; per-command costs in us."""
    import rclpy
    from rclpy.context import Context
    from rclpy.parameter import Parameter
    from viscoadh_msgs.msg import IndentationCommand

    from viscoadh_ros.core.config import SceneConfig
    from viscoadh_ros.ros.conversions import ns_to_stamp
    from viscoadh_ros.ros.node import GIL_SWITCH_INTERVAL_S, ViscoadhNode

    sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    with tempfile.TemporaryDirectory(prefix="viscoadh_profile_") as tmp:
        scene_map, amplitude = bench_scene(contacts, log_path=Path(tmp) / "p.mcap" if log else None)
        scene = SceneConfig.from_dict(scene_map)
        flat = scene.to_parameters()
        flat["command.max_future_s"] = 1.0e6  # stamps run ahead of the clock: fed faster than 1 kHz
        context = Context()
        rclpy.init(context=context)
        node = ViscoadhNode(
            context=context, parameter_overrides=[Parameter(k, value=v) for k, v in flat.items()]
        )
        try:
            ids = list(node.contacts)
            t0 = node.now_ns()

            def depth_at(t: float) -> float:
                phase = 0.5 - 0.5 * math.cos(2.0 * math.pi * t / CYCLE_PERIOD_S)
                return amplitude * ((1.0 + LIFT_FRACTION) * phase - LIFT_FRACTION)

            if hand:
                from viscoadh_msgs.msg import HandCommand

                messages = []
                for tick in range(ticks):
                    msg = HandCommand(mode=HandCommand.DEPTH)
                    msg.header.stamp = ns_to_stamp(t0 + tick * 1_000_000)
                    msg.depth = [depth_at(tick * 1e-3)] * contacts
                    messages.append(msg)
                feed = [(node.hand.on_command, m) for m in messages]
            else:
                # Serialised, as the live thread takes them (raw), when the node takes them so.
                from rclpy.serialization import serialize_message

                feed = []
                for tick in range(ticks):
                    for contact_id in ids:
                        msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=depth_at(tick * 1e-3))
                        msg.header.stamp = ns_to_stamp(t0 + tick * 1_000_000)
                        contact = node.contacts[contact_id]
                        raw = getattr(contact, "on_raw_command", None)
                        feed.append((raw, serialize_message(msg)) if raw else (contact.on_command, msg))
            # This thread does the live thread's work: stop the live thread, so no hold timer
            # contends for the contacts' locks (on the node they run on one thread).
            node._live.stop()
            recorder = node._recorder
            writer = recorder._thread if recorder is not None else None
            writer_cpu0 = _thread_cpu_s(writer) if writer is not None else 0.0
            profiler = cProfile.Profile() if profile else None
            cpu0, wall0 = time.thread_time(), time.perf_counter()
            if profiler is not None:
                profiler.enable()
            for handler, msg in feed:
                handler(msg)
            if profiler is not None:
                profiler.disable()
            cpu1, wall1 = time.thread_time(), time.perf_counter()
            backlog = len(recorder._pending) if recorder is not None else 0
            # Let the writer drain what is queued, then read its CPU.
            if recorder is not None:
                while recorder._pending and recorder.error is None:
                    time.sleep(0.01)
                time.sleep(0.05)
            writer_cpu = (_thread_cpu_s(writer) - writer_cpu0) if writer is not None else 0.0
            n = ticks * contacts
            # The same steps on bare simulators, same thread: the core's share of the cost.
            from viscoadh_ros.core.simulator import ContactSimulator

            bare = [ContactSimulator(c) for c in scene.contacts]
            depths = [depth_at(tick * 1e-3) for tick in range(ticks)]
            core0 = time.thread_time()
            for tick, depth in enumerate(depths):
                for simulator in bare:
                    simulator.step(tick * 1e-3, depth=depth)
            core_cpu = (time.thread_time() - core0) / n * 1e6
            result: dict[str, Any] = {
                "contacts": contacts,
                "ticks": ticks,
                "hand": hand,
                "log": log,
                "commands": n,
                "live_cpu_us_per_command": (cpu1 - cpu0) / n * 1e6,
                "live_wall_us_per_command": (wall1 - wall0) / n * 1e6,
                "writer_cpu_us_per_command": writer_cpu / n * 1e6,
                "core_step_cpu_us_per_command": core_cpu,
                "node_overhead_cpu_us_per_command": (cpu1 - cpu0) / n * 1e6 - core_cpu,
                "writer_backlog_at_end": backlog,
                "log_dropped": recorder.dropped if recorder is not None else 0,
                "step_mean_us": _step_mean_us(node),
            }
            if profiler is not None:
                text = io.StringIO()
                pstats.Stats(profiler, stream=text).sort_stats("tottime").print_stats(18)
                result["profile"] = text.getvalue()
        finally:
            node.destroy_node()
            context.try_shutdown()
    return result


def _step_mean_us(node: Any) -> float:
    """Mean simulator step wall time over the node's last diagnostics window, us."""
    total, count = 0.0, 0
    for contact in node.contacts.values():
        steps = contact.counters.steps
        total += steps.total
        count += steps.count
    return total / count * 1e6 if count else float("nan")


def take_cost_us(samples: int = 2000) -> dict[str, float]:
    """Time to take one IndentationCommand off a subscription, as an object and raw, us."""
    import rclpy
    from rclpy.context import Context
    from viscoadh_msgs.msg import IndentationCommand

    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("take_probe", context=context)
    try:
        pub = node.create_publisher(IndentationCommand, "probe", 1000)
        sub = node.create_subscription(IndentationCommand, "probe", lambda _m: None, 1000)
        result = {}
        for raw in (False, True):
            total = 0.0
            taken = 0
            while taken < samples:
                for _ in range(500):
                    pub.publish(IndentationCommand(depth=1.0))
                time.sleep(0.05)
                start = time.perf_counter()
                got = 0
                while sub.handle.take_message(IndentationCommand, raw) is not None:
                    got += 1
                total += time.perf_counter() - start
                taken += got
            result["take_raw_us" if raw else "take_object_us"] = total / taken * 1e6
        return result
    finally:
        node.destroy_node()
        context.try_shutdown()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m viscoadh_ros.bench.live_profile")
    parser.add_argument("--contacts", type=int, default=16)
    parser.add_argument("--ticks", type=int, default=2000)
    parser.add_argument("--hand", action="store_true", help="feed HandCommands (one per tick)")
    parser.add_argument("--no-log", action="store_true")
    parser.add_argument("--cprofile", action="store_true")
    parser.add_argument("--take", action="store_true", help="also time taking a message")
    args = parser.parse_args(argv)
    result = profile_live(
        contacts=args.contacts, ticks=args.ticks, hand=args.hand, log=not args.no_log, profile=args.cprofile
    )
    text = result.pop("profile", None)
    for key, value in result.items():
        print(f"{key}: {value:.4g}" if isinstance(value, float) else f"{key}: {value}")
    if args.take:
        for key, value in take_cost_us().items():
            print(f"{key}: {value:.3g}")
    if text:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
