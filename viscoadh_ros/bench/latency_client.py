"""The latency client process: publish IndentationCommands at a fixed rate, time every reply.

Run by `viscoadh_ros.bench.latency` as `python -m viscoadh_ros.bench.latency_client ...`, in its
own process so the server under test shares nothing with it but DDS. It imports only rclpy and
numpy (no core, no numba) so it starts fast and its own work stays the same for both servers.
It saves the raw samples to an .npz file; the orchestrator reduces them.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
import rclpy
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from viscoadh_msgs.msg import ContactState, HandCommand, HandState, IndentationCommand

QOS_DEPTH = 100
# Depth cycle the client drives: from 20% of the amplitude above the surface to the full amplitude
# in, so every contact touches, sticks, detaches and leaves contact once per cycle.
CYCLE_PERIOD_S = 2.0
LIFT_FRACTION = 0.2
# Slot of a readiness probe in the client's table of commands awaiting a reply.
PROBE = -1


def _stamp_ns(header) -> int:  # noqa: ANN001 - std_msgs/msg/Header
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


class _Client:
    """One node with a publisher and a reply subscription per contact, served by one wait set.

    No executor and no second thread: rclpy's Python executor costs tens of microseconds per
    callback and a spinning thread fights the publishing loop for the GIL, which would put the
    client's own overhead into both servers' numbers. Waiting on a raw wait set until the next
    publishing deadline and taking replies directly keeps the client thin and single-threaded.
    """

    def __init__(self, contact_ids: list[str], reply: str, samples: int, *, hand: bool = False) -> None:
        self.node = rclpy.create_node("viscoadh_bench_client")
        # Hand mode: one HandCommand for every contact per tick on hand/indentation, answered on
        # hand/state (node) or hand/echo (echo node); one "channel" in the tables below.
        self.hand_contacts = len(contact_ids) if hand else 0
        if hand:
            reply_type = HandState if reply == "state" else HandCommand
            self.publishers = [self.node.create_publisher(HandCommand, "hand/indentation", QOS_DEPTH)]
            channels = ["hand"]
        else:
            reply_type = ContactState if reply == "state" else IndentationCommand
            self.publishers = [
                self.node.create_publisher(IndentationCommand, f"{c}/indentation", QOS_DEPTH)
                for c in contact_ids
            ]
            channels = list(contact_ids)
        self.subscriptions = [
            self.node.create_subscription(reply_type, f"{c}/{reply}", lambda _msg: None, QOS_DEPTH)
            for c in channels
        ]
        self.wait_set = _rclpy.WaitSet(len(channels), 0, 0, 0, 0, 0, self.node.context.handle)
        # Slot (sample index or PROBE) of each stamp awaiting its reply, per channel.
        self.pending: list[dict[int, int]] = [{} for _ in channels]
        self.last_stamp = [0] * len(channels)
        self.latency = np.full(samples, np.nan)
        # Stamp (wall ns) of each sample's command: tells which commands a server's log holds.
        self.stamps = np.zeros(samples, np.int64)
        self.answered = [False] * len(channels)
        self.first_reply_wall = math.nan

    def publish(self, contact: int, depth: float, slot: int | None) -> None:
        """Publish a DEPTH command stamped with the wall time now; remember it under `slot`."""
        if self.hand_contacts:
            msg = HandCommand(mode=HandCommand.DEPTH, depth=[depth] * self.hand_contacts)
        else:
            msg = IndentationCommand(mode=IndentationCommand.DEPTH, depth=depth)
        # Strictly increasing stamps: the node rejects a stamp older than the last one.
        stamp = max(time.time_ns(), self.last_stamp[contact] + 1)
        self.last_stamp[contact] = stamp
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
        if slot is not None:
            self.pending[contact][stamp] = slot
            if slot != PROBE:
                self.stamps[slot] = stamp
        self.publishers[contact].publish(msg)

    def serve_until(self, deadline: float) -> None:
        """Take and time replies until `deadline` (time.perf_counter() seconds)."""
        while True:
            remaining = deadline - time.perf_counter()
            if remaining <= 0.0:
                return
            self.wait_set.clear_entities()
            for subscription in self.subscriptions:
                self.wait_set.add_subscription(subscription.handle)
            self.wait_set.wait(int(remaining * 1e9))
            ready = self.wait_set.get_ready_entities("subscription")
            for contact, subscription in enumerate(self.subscriptions):
                if subscription.handle.pointer in ready:
                    self._take_all(contact, subscription)

    def _take_all(self, contact: int, subscription) -> None:  # noqa: ANN001 - rclpy Subscription
        while (taken := subscription.handle.take_message(subscription.msg_type, False)) is not None:
            received = time.time_ns()
            stamp = _stamp_ns(taken[0].header)
            slot = self.pending[contact].pop(stamp, None)
            if slot == PROBE:
                self.answered[contact] = True
                if math.isnan(self.first_reply_wall):
                    self.first_reply_wall = received * 1e-9
            elif slot is not None:
                self.latency[slot] = (received - stamp) * 1e-9


def run_client(args: argparse.Namespace) -> int:
    """The client process: wait for the server, warm up, publish at the rate, save samples."""
    period = 1.0 / args.rate
    n_ticks = max(1, round(args.duration * args.rate))
    n_contacts = 1 if args.hand else len(args.contact_ids)  # commands per tick

    def depth_at(t: float) -> float:
        phase = 0.5 - 0.5 * math.cos(2.0 * math.pi * t / CYCLE_PERIOD_S)
        return args.depth_amplitude * ((1.0 + LIFT_FRACTION) * phase - LIFT_FRACTION)

    rclpy.init()
    client = _Client(args.contact_ids, args.reply, n_ticks * n_contacts, hand=args.hand)
    try:
        # Ready = a probe command came back on every contact (the server is up and serving).
        give_up = time.perf_counter() + args.ready_timeout
        while not all(client.answered):
            if time.perf_counter() > give_up:
                print(f"server not ready after {args.ready_timeout} s", file=sys.stderr)
                return 1
            for contact in range(n_contacts):
                if not client.answered[contact]:
                    client.publish(contact, depth_at(0.0), slot=PROBE)
            client.serve_until(time.perf_counter() + 0.05)
        # Warm-up at the full rate, discarded: first passes through every code path of the server.
        start = time.perf_counter()
        warmup_ticks = round(args.warmup * args.rate)
        for tick in range(warmup_ticks):
            client.serve_until(start + tick * period)
            for contact in range(n_contacts):
                client.publish(contact, depth_at(tick * period), slot=None)

        send_time = np.empty(n_ticks * n_contacts)
        send_lag = np.empty(n_ticks * n_contacts)
        start = time.perf_counter()
        for tick in range(n_ticks):
            scheduled = start + tick * period
            client.serve_until(scheduled)
            for contact in range(n_contacts):
                slot = tick * n_contacts + contact
                now = time.perf_counter()
                send_time[slot] = now - start
                send_lag[slot] = now - scheduled
                client.publish(contact, depth_at((warmup_ticks + tick) * period), slot=slot)
        # Replies still in flight get a generous grace period before they count as lost.
        client.serve_until(time.perf_counter() + max(0.5, 100 * period))
    finally:
        client.node.destroy_node()
        rclpy.try_shutdown()
    np.savez(
        args.out,
        send_time_s=send_time,
        send_lag_s=send_lag,
        latency_s=client.latency,
        first_reply_wall=client.first_reply_wall,
        stamp_ns=client.stamps,
    )
    return 0


def _client_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m viscoadh_ros.bench.latency_client")
    parser.add_argument("contact_ids", nargs="+")
    parser.add_argument("--reply", choices=("state", "echo"), required=True)
    parser.add_argument("--rate", type=float, required=True)
    parser.add_argument("--duration", type=float, required=True)
    parser.add_argument("--warmup", type=float, required=True)
    parser.add_argument("--ready-timeout", type=float, required=True)
    parser.add_argument("--depth-amplitude", type=float, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--hand", action="store_true", help="one HandCommand for all contacts per tick")
    return parser


if __name__ == "__main__":
    sys.exit(run_client(_client_parser().parse_args()))
