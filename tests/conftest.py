"""Shared test set-up: hermetic ROS 2 for every test, in-process and across processes.

Isolation (applied when this file is imported, before any test creates a ROS context):

* ``ROS_DOMAIN_ID`` is unique to this test process (each pytest-xdist worker is a process of
  its own): ``1 + pid % 101``, or ``VISCOADH_TEST_DOMAIN_ID`` when set. Valid ids are 0..101.
* ``ROS_AUTOMATIC_DISCOVERY_RANGE=OFF``: every ``rclpy.Context`` only sees the nodes of the
  same context, so tests that share the process (or run in parallel) never hear each other.
* ``ROS_LOCALHOST_ONLY`` (deprecated, overrides the range) is removed.

Fixtures (rclpy is imported lazily, so tests of the pure core never load it):

``ros_context``
    A fresh ``rclpy.context.Context``, initialised for the test and shut down after it.
    Nodes created with ``context=ros_context`` talk to each other and to nobody else.
``ros_localhost_context``
    Like ``ros_context`` but with discovery range ``LOCALHOST``: use it to talk to a node in
    a child process started with ``ros_env``.
``ros_env``
    ``dict`` environment for a child process (``subprocess.Popen(..., env=ros_env)``): this
    session's ``ROS_DOMAIN_ID`` and ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``.
``ros_executor``
    A ``SingleThreadedExecutor`` on ``ros_context``. Add nodes with ``add_node``; at the end
    of the test every node added to it is destroyed and the executor shut down.
``spin_until``
    ``spin_until(executor, predicate, timeout_sec=5.0) -> bool``: spin ``executor`` until
    ``predicate()`` is true or the timeout passes; returns the last value of ``predicate()``.
    Assert on it: ``assert spin_until(ex, lambda: got, 5.0), "no message received"``.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

DOMAIN_ID = int(os.environ.get("VISCOADH_TEST_DOMAIN_ID", 1 + os.getpid() % 101))
os.environ["ROS_DOMAIN_ID"] = str(DOMAIN_ID)
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "OFF"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.pop("ROS_STATIC_PEERS", None)


def _init_context(monkeypatch: pytest.MonkeyPatch, discovery_range: str) -> Any:
    """An initialised Context; rcl reads the discovery range from the environment at init."""
    import rclpy
    from rclpy.context import Context

    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", discovery_range)
    context = Context()
    rclpy.init(context=context)
    return context


@pytest.fixture
def ros_context(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """A fresh rclpy Context of this test alone (discovery OFF)."""
    context = _init_context(monkeypatch, "OFF")
    yield context
    context.try_shutdown()


@pytest.fixture
def ros_localhost_context(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """A fresh rclpy Context that discovers nodes of other processes on this host."""
    context = _init_context(monkeypatch, "LOCALHOST")
    yield context
    context.try_shutdown()


@pytest.fixture
def ros_env() -> dict[str, str]:
    """Environment for a child process that must talk to this test's LOCALHOST context."""
    env = dict(os.environ)
    env["ROS_DOMAIN_ID"] = str(DOMAIN_ID)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    return env


@pytest.fixture
def ros_executor(ros_context: Any) -> Iterator[Any]:
    """A SingleThreadedExecutor on ``ros_context``; its nodes are destroyed after the test."""
    from rclpy.executors import SingleThreadedExecutor

    executor = SingleThreadedExecutor(context=ros_context)
    yield executor
    for node in executor.get_nodes():
        executor.remove_node(node)
        node.destroy_node()
    executor.shutdown(timeout_sec=1.0)


def _spin_until(executor: Any, predicate: Callable[[], bool], timeout_sec: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout_sec
    while not predicate():
        remaining = deadline - time.monotonic()
        if remaining <= 0.0:
            return bool(predicate())
        executor.spin_once(timeout_sec=min(0.05, remaining))
    return True


@pytest.fixture
def spin_until() -> Callable[..., bool]:
    """``spin_until(executor, predicate, timeout_sec=5.0) -> bool`` (see module docstring)."""
    return _spin_until
