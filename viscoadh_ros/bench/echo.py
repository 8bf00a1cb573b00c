"""The latency baseline: a minimal rclpy node that republishes every IndentationCommand untouched.

For each contact id `C` it subscribes `C/indentation` and publishes the same message object on
`C/echo`, and `hand/indentation` (HandCommand) back on `hand/echo`, with the same QoS as the
simulator node's topics. A client timing command -> echo round
trips measures the DDS + rclpy floor on this machine, to set beside the command -> state round
trips of `viscoadh node` in the same run.

Run as a child process: `python -m viscoadh_ros.bench.echo ID [ID ...]`.
"""

from __future__ import annotations

import sys

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from viscoadh_msgs.msg import HandCommand, IndentationCommand

# Same depth as the client's; a round trip never has more than a few messages in flight.
QOS_DEPTH = 100


class EchoNode(Node):
    """Republish each `C/indentation` command on `C/echo`, doing nothing else."""

    def __init__(self, contact_ids: list[str]) -> None:
        super().__init__("viscoadh_bench_echo")
        for contact_id in contact_ids:
            publisher = self.create_publisher(IndentationCommand, f"{contact_id}/echo", QOS_DEPTH)
            # Default argument binds this contact's publisher to its callback.
            self.create_subscription(
                IndentationCommand,
                f"{contact_id}/indentation",
                lambda msg, pub=publisher: pub.publish(msg),
                QOS_DEPTH,
            )
        # The hand topic: every contact in one message (the node's hand/indentation).
        hand = self.create_publisher(HandCommand, "hand/echo", QOS_DEPTH)
        self.create_subscription(HandCommand, "hand/indentation", hand.publish, QOS_DEPTH)


def main(argv: list[str] | None = None) -> int:
    """Serve the echo topics for the contact ids given on the command line until interrupted."""
    args = rclpy.utilities.remove_ros_args(sys.argv if argv is None else argv)[1:]
    if not args:
        print("usage: python -m viscoadh_ros.bench.echo ID [ID ...]", file=sys.stderr)
        return 2
    rclpy.init(args=argv)
    node = EchoNode(args)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
