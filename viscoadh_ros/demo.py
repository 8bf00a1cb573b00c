"""The main job: one approach, hold and retract cycle, driven through the node's ROS interface.

`run_demo` starts the ``viscoadh`` node in this process on a ``MultiThreadedExecutor`` and
drives it the way a controller would: a small driver node publishes
``IndentationCommand`` messages on ``<contact>/indentation`` and reads ``ContactState`` back
from ``<contact>/state``; at the end of the hold it calls ``<contact>/predict_pull_off`` with
the speed it is about to retract at. The node logs the run to MCAP (its logging is switched on
through its parameters) and the figure is drawn from that log by :mod:`viscoadh_ros.plotting`.

The cycle runs on a simulated clock (``use_sim_time``, the driver publishes ``/clock``) in
lockstep: the driver advances the clock by one command period, publishes the command stamped
with that time and waits for the node's answer. The physics then does not depend on how fast
this machine is, and a cycle that lasts minutes of material time (slow enough for the paper's
quasistatic limits) takes seconds of wall time. All ROS traffic stays inside this process
(``ROS_AUTOMATIC_DISCOVERY_RANGE=OFF``), so the simulated ``/clock`` never reaches other ROS
programs on the machine.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import threading
import time as wallclock
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import rclpy
from numpy.typing import NDArray
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from viscoadh_msgs.msg import ContactState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff

from viscoadh_ros.core.config import ContactConfig, SceneConfig, default_scene_path
from viscoadh_ros.core.errors import ConfigError
from viscoadh_ros.core.rheology import CreepElement
from viscoadh_ros.core.simulator import Phase
from viscoadh_ros.plotting import Curve, JkrReference, plot_loops
from viscoadh_ros.ros import conversions
from viscoadh_ros.ros.node import GIL_SWITCH_INTERVAL_S, ViscoadhNode

_DISCOVERY_RANGE = "ROS_AUTOMATIC_DISCOVERY_RANGE"
#: The simulated clock starts here, s: a zero stamp would mean "now" to the node.
_CLOCK_START_S = 1.0
#: How far ahead of the node's clock the demo's node accepts commands, s (see `run_demo`).
DRIVER_MAX_FUTURE_S = 30.0
#: How long the driver waits for any one answer of the node, s (wall clock).
_TIMEOUT_S = 10.0


@dataclass(frozen=True)
class CyclePlan:
    """The depth-controlled cycle the demo drives (SI units).

    start_depth: m, < 0 (above the surface, so the first touch is part of the run).
    max_depth: m, the depth held during the hold.
    approach_speed, retract_speed: m/s (> 0).
    hold_time: s.
    end_depth: m, the lowest depth the retraction goes to if the contact has not let go
        before (the driver stops as soon as the contact is out of touch).
    command_rate: Hz of the simulated clock (commands per simulated second).
    """

    start_depth: float
    max_depth: float
    approach_speed: float
    hold_time: float
    retract_speed: float
    end_depth: float
    command_rate: float

    def schedule(self) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
        """Sampled command history: (time s, depth m, index of the last hold sample).

        Shape (n,) each; the depth is piecewise linear between the samples (as the node
        integrates it), with one sample exactly at each corner of the cycle.
        """
        dt = 1.0 / self.command_rate
        t_in = (self.max_depth - self.start_depth) / self.approach_speed
        t_out = (self.max_depth - self.end_depth) / self.retract_speed
        approach = np.linspace(0.0, t_in, max(2, round(t_in / dt) + 1))
        hold = t_in + np.linspace(0.0, self.hold_time, max(2, round(self.hold_time / dt) + 1))
        retract = hold[-1] + np.linspace(0.0, t_out, max(2, round(t_out / dt) + 1))
        time = np.concatenate([approach, hold[1:], retract[1:]])
        depth = np.concatenate(
            [
                self.start_depth + self.approach_speed * approach,
                np.full(hold.size - 1, self.max_depth),
                self.max_depth - self.retract_speed * (retract[1:] - retract[0]),
            ]
        )
        return time, depth, approach.size + hold.size - 2


def creep_time(contact: ContactConfig) -> float:
    """The longest retardation time ``eta_k / G_k`` of the contact's material, s (0 if elastic).

    The slowest memory of the body: under a constant load it takes a few of these to creep to
    its relaxed state, so ramps much slower than this follow the paper's quasistatic limits.
    (The relaxation times at fixed strain, ``eta_k / (G0 + G_k)`` for K = 1, are shorter.)
    """
    times = CreepElement.from_config(contact.material).retardation_times
    return float(times.max()) if times.size else 0.0


def sphere_reference(contact: ContactConfig) -> JkrReference:
    """The paper's quasistatic JKR branches of the contact; ConfigError if the demo cannot
    show them (not a sphere, or no adhesion)."""
    reference = JkrReference.from_contact(contact)
    if reference is None:
        raise ConfigError(
            f"{contact.id}: the demo shows adhesion of a sphere; got indenter.shape "
            f"{contact.indenter.shape!r} and adhesion.work_of_adhesion "
            f"{contact.adhesion.work_of_adhesion!r} (use a sphere with a work of adhesion > 0)"
        )
    return reference


def plan_cycle(contact: ContactConfig) -> CyclePlan:
    """A cycle that shows the paper's effect on this contact.

    Depths scale with the critical depth d_c of the release branch: start at -d_c (out of
    touch), press to 4 d_c (a compressive force of a few pull-off forces). Each ramp lasts 40
    creep times, slow enough for the paper's quasistatic limits (weak adhesion w_eff1 on the
    way in, strong w_eff2 on the way out: on the built-in scene the edge reaches 94 % of
    w_eff2 at pull-off, 58 % with ramps of 5 creep times); the hold lasts a quarter of a
    ramp so the interior relaxes. The simulated clock makes slow ramps cheap: 400 commands
    per ramp whatever its length. An elastic body (no memory) gets 1 s ramps.
    """
    _, _, d_c = sphere_reference(contact).scales
    creep = creep_time(contact)
    ramp_time = 40.0 * creep if creep > 0.0 else 1.0
    start, peak = -d_c, 4.0 * d_c
    approach_speed = (peak - start) / ramp_time
    return CyclePlan(
        start_depth=start,
        max_depth=peak,
        approach_speed=approach_speed,
        hold_time=ramp_time / 4.0,
        retract_speed=approach_speed,
        # JKR under displacement control lets go at about -2.1 d_c; -6 d_c leaves room for
        # rate effects, and the driver stops as soon as the contact lets go.
        end_depth=peak - 2.0 * (peak - start),
        command_rate=400.0 / ramp_time,
    )


@dataclass(frozen=True)
class PullOffPrediction:
    """The node's answer to ``predict_pull_off`` at the end of the hold (N, m, s)."""

    pull_off_force: float
    pull_off_depth: float
    time_to_detach: float


@dataclass(frozen=True)
class DemoRun:
    """What the driver saw: one ContactState per command, as arrays of shape (n,).

    time s, depth m, force N, contact_radius m, phase (Phase values),
    effective_work_of_adhesion J/m^2, energy_input J, energy_dissipated J;
    retract_index: first sample of the retraction; prediction: the service's answer;
    wall_time: s the cycle took on this machine.
    """

    time: NDArray[np.float64]
    depth: NDArray[np.float64]
    force: NDArray[np.float64]
    contact_radius: NDArray[np.float64]
    phase: NDArray[np.int64]
    effective_work_of_adhesion: NDArray[np.float64]
    energy_input: NDArray[np.float64]
    energy_dissipated: NDArray[np.float64]
    retract_index: int
    prediction: PullOffPrediction
    wall_time: float


class _Driver:
    """A controller-like client of one contact: publishes /clock and commands, reads states.

    Built on a node it does not own; all waiting happens on the caller's thread while an
    executor spins the node elsewhere.
    """

    def __init__(self, node: Node, contact_id: str, timeout: float) -> None:
        self._node = node
        self._timeout = timeout
        self._clock_msg = Clock()
        self._command = IndentationCommand()
        self._command.mode = IndentationCommand.DEPTH
        self._clock_pub = node.create_publisher(
            Clock, "/clock", QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
        )
        self._command_pub = node.create_publisher(IndentationCommand, f"{contact_id}/indentation", 10)
        node.create_subscription(ContactState, f"{contact_id}/state", self._on_state, 50)
        self._predict = node.create_client(PredictPullOff, f"{contact_id}/predict_pull_off")
        self._answer = threading.Condition()
        self._waiting_for = -1
        self._state: ContactState | None = None

    def _on_state(self, msg: ContactState) -> None:
        stamp = conversions.stamp_to_ns(msg.header.stamp)
        with self._answer:
            if stamp == self._waiting_for and self._state is None:
                self._state = msg
                self._answer.notify()

    def wait_for_node(self) -> None:
        """Block until the node's subscription and service are up (RuntimeError if not)."""
        deadline = wallclock.monotonic() + self._timeout
        while self._command_pub.get_subscription_count() == 0:
            if wallclock.monotonic() > deadline:
                raise RuntimeError("the viscoadh node did not subscribe to the command topic")
            wallclock.sleep(0.01)
        if not self._predict.wait_for_service(timeout_sec=max(0.0, deadline - wallclock.monotonic())):
            raise RuntimeError("the viscoadh node's predict_pull_off service did not come up")

    def command(self, time: float, depth: float) -> ContactState:
        """Command ``depth`` (m) at ``time`` (s), wait for the node's answer, then move the
        simulated clock to ``time``; returns the answer."""
        stamp_ns = round(time * 1e9)
        self._clock_msg.clock = self._command.header.stamp = conversions.ns_to_stamp(stamp_ns)
        self._command.depth = float(depth)
        with self._answer:
            self._waiting_for, self._state = stamp_ns, None
            self._command_pub.publish(self._command)
            if not self._answer.wait_for(lambda: self._state is not None, self._timeout):
                raise RuntimeError(f"the viscoadh node did not answer the command at t = {time:g} s")
        # The clock moves only once the command is applied: moved first, it would let the
        # node's hold timer keep the old depth up to t, and the command then jump the depth
        # at an instant (a glass-modulus force spike) instead of ramping it over the period.
        self._clock_pub.publish(self._clock_msg)
        return self._state

    def predict_pull_off(self, retract_speed: float) -> PullOffPrediction:
        """Call ``predict_pull_off`` (m/s); RuntimeError if it fails or times out."""
        request = PredictPullOff.Request()
        request.retract_speed = float(retract_speed)
        done = threading.Event()
        future = self._predict.call_async(request)
        future.add_done_callback(lambda _: done.set())
        if not done.wait(self._timeout) or future.result() is None:
            raise RuntimeError("predict_pull_off did not answer")
        answer = future.result()
        if not answer.success:
            raise RuntimeError(f"predict_pull_off failed: {answer.message}")
        return PullOffPrediction(answer.pull_off_force, answer.pull_off_depth, answer.time_to_detach)


def drive_cycle(driver: _Driver, plan: CyclePlan) -> DemoRun:
    """Run ``plan`` through ``driver`` until the contact lets go during the retraction."""
    times, depths, last_hold = plan.schedule()
    states = []
    prediction = None
    started = wallclock.perf_counter()
    for index, (time, depth) in enumerate(zip(times, depths, strict=True)):
        state = driver.command(_CLOCK_START_S + time, depth)
        states.append(state)
        if index == last_hold:
            prediction = driver.predict_pull_off(plan.retract_speed)
        elif index > last_hold and state.phase == Phase.NO_CONTACT:
            break
    else:
        raise RuntimeError(
            f"the contact still held at depth {depths[-1]:.3g} m; the retraction was too short"
        )
    wall_time = wallclock.perf_counter() - started

    def column(name: str, dtype: type = np.float64) -> NDArray:
        return np.array([getattr(state, name) for state in states], dtype=dtype)

    return DemoRun(
        time=times[: len(states)].copy(),
        depth=column("depth"),
        force=column("force"),
        contact_radius=column("contact_radius"),
        phase=column("phase", np.int64),
        effective_work_of_adhesion=column("effective_work_of_adhesion"),
        energy_input=column("energy_input"),
        energy_dissipated=column("energy_dissipated"),
        retract_index=last_hold + 1,
        prediction=prediction,
        wall_time=wall_time,
    )


@dataclass(frozen=True)
class DemoSummary:
    """The numbers the demo prints (SI units).

    predicted_pull_off: N, the service's answer at the end of the hold.
    reached_pull_off: N, the most tensile force the driver then read.
    approach_work_of_adhesion: J/m^2, median effective work of adhesion the node reported
        while the edge advanced during the approach.
    release_work_of_adhesion: J/m^2, the one it reported at the most tensile force of the
        release (the work of adhesion that sets the pull-off force).
    reference: the paper's quasistatic branches for comparison (w_eff1, w_eff2, ...).
    loop_energy: J, the area of the force-depth loop (the integral of F dd over the cycle),
        i.e. the energy the cycle lost. dissipated_energy: J, the node's own bookkeeping.
    """

    predicted_pull_off: float
    reached_pull_off: float
    approach_work_of_adhesion: float
    release_work_of_adhesion: float
    reference: JkrReference
    loop_energy: float
    dissipated_energy: float
    simulated_time: float
    wall_time: float
    commands: int


def loop_energy(depth: NDArray[np.float64], force: NDArray[np.float64]) -> float:
    """Work done on the body, J: the integral of F dd along the path (trapezoids).

    depth m, force N, shape (n,). For a cycle that starts and ends out of contact this is
    the area of the force-depth loop, the energy lost in the cycle.
    """
    return float(np.sum(0.5 * (force[1:] + force[:-1]) * np.diff(depth)))


def summarize(run: DemoRun, reference: JkrReference) -> DemoSummary:
    """Reduce a driven cycle to the printed numbers."""
    approach = run.phase[: run.retract_index] == Phase.INDENTING
    if not approach.any():
        raise RuntimeError("the contact edge never advanced during the approach")
    pull_off = run.retract_index + int(np.argmin(run.force[run.retract_index :]))
    return DemoSummary(
        predicted_pull_off=run.prediction.pull_off_force,
        reached_pull_off=float(run.force[pull_off]),
        approach_work_of_adhesion=float(
            np.median(run.effective_work_of_adhesion[: run.retract_index][approach])
        ),
        release_work_of_adhesion=float(run.effective_work_of_adhesion[pull_off]),
        reference=reference,
        loop_energy=loop_energy(run.depth, run.force),
        dissipated_energy=float(run.energy_dissipated[-1]),
        simulated_time=float(run.time[-1] - run.time[0]),
        wall_time=run.wall_time,
        commands=int(run.time.size),
    )


def _si(value: float, unit: str) -> str:
    """``value`` with an SI prefix that keeps 1-3 integer digits, e.g. -1.234 mN."""
    exponent = 0 if value == 0.0 else max(-12, min(0, 3 * math.floor(math.log10(abs(value)) / 3)))
    prefix = {0: "", -3: "m", -6: "u", -9: "n", -12: "p"}[exponent]
    return f"{value / 10.0**exponent:.4g} {prefix}{unit}"


def format_summary(summary: DemoSummary, files: dict[str, Path]) -> str:
    """The demo's printed report: a few lines, SI units with readable prefixes."""
    ref = summary.reference
    limit = -1.5 * math.pi * ref.radius * ref.work_detachment
    # The commentary follows the numbers: an elastic scene (`--scene`) adheres the same both
    # ways and stores nothing after the cycle (an outside tester read "weak on the way in" beside
    # two equal values).
    inward, outward = summary.approach_work_of_adhesion, summary.release_work_of_adhesion
    if outward > 1.05 * inward:
        way_in, way_out = "weak on the way in", "strong on the way out"
    else:
        way_in = way_out = "about the same both ways"
    loop, lost = summary.loop_energy, summary.dissipated_energy
    if abs(loop - lost) <= 1e-2 * max(abs(loop), abs(lost)):
        stored = "the same within 1 %: nothing is left stored"
    elif loop > lost:
        stored = "the rest is still stored in the creeping surface"
    else:
        stored = "more than the loop's area: the cycle did not return to where it started"
    lines = [
        (
            f"cycle: {summary.commands} commands over {summary.simulated_time:.3g} s of "
            f"material time, driven in {summary.wall_time:.2f} s"
        ),
        (
            f"pull-off force        predicted {_si(summary.predicted_pull_off, 'N')}, reached "
            f"{_si(summary.reached_pull_off, 'N')} (slow limit -3/2 pi R w_eff2 = {_si(limit, 'N')})"
        ),
        (
            f"work of adhesion in   {_si(summary.approach_work_of_adhesion, 'J/m^2')} "
            f"(paper's w_eff1 = {_si(ref.work_indentation, 'J/m^2')}): {way_in}"
        ),
        (
            f"work of adhesion out  {_si(summary.release_work_of_adhesion, 'J/m^2')} at pull-off "
            f"(paper's w_eff2 = {_si(ref.work_detachment, 'J/m^2')}): {way_out}"
        ),
        (
            f"energy lost in cycle  {_si(summary.loop_energy, 'J')} (force-depth loop area; "
            f"dissipated so far {_si(summary.dissipated_energy, 'J')}, {stored})"
        ),
    ]
    lines += [f"{name + ':':<22}{path}" for name, path in files.items()]
    return "\n".join(lines)


def plot_run(run: DemoRun, reference: JkrReference, output: Path, *, title: str) -> None:
    """Force-depth and force-radius loops of the run, approach+hold and retraction as two
    curves, with the paper's JKR branches (plotting.plot_loops)."""
    split = run.retract_index
    curves = [
        Curve(run.depth[:split], run.force[:split], run.contact_radius[:split], "approach and hold"),
        Curve(run.depth[split - 1 :], run.force[split - 1 :], run.contact_radius[split - 1 :], "retract"),
    ]
    plot_loops(curves, output, reference=reference, title=title)


@contextlib.contextmanager
def node_in_process(
    scene: SceneConfig, **parameters: Any
) -> Iterator[tuple[rclpy.context.Context, MultiThreadedExecutor]]:
    """Run the ``viscoadh`` node on ``scene`` in this process, spun by a background executor.

    ``parameters`` are extra node parameters by their flat names (``use_sim_time=True``,
    ``**{"log.enabled": True}``). Yields (context, executor): create client nodes with
    ``Node(name, context=context)`` and ``executor.add_node(node)``. The ROS traffic stays in
    this process (discovery range OFF while the context is created). On exit the spinner
    stops, then every node on the executor is destroyed (the ``viscoadh`` node's MCAP log is
    finished) and the context shut down: callers leave their nodes on the executor rather than
    destroying them while it spins.
    """
    # rcl reads these at init; ROS_LOCALHOST_ONLY (deprecated) would override the range.
    private = {_DISCOVERY_RANGE: "OFF", "ROS_LOCALHOST_ONLY": None}
    previous = {name: os.environ.get(name) for name in private}
    _set_environment(private)
    # The node's live thread, the executor and the caller's threads hand the GIL to each other
    # several times per command; at Python's default 5 ms switch interval a thread busy in
    # Python (an executor rebuilding its wait set) made each command take ~0.1 s. The same
    # interval `viscoadh node` runs with, for as long as the node runs here.
    previous_switch = sys.getswitchinterval()
    sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    context = rclpy.context.Context()
    try:
        rclpy.init(context=context, args=[])
        overrides = {**scene.to_parameters(), **parameters}
        node = ViscoadhNode(
            context=context,
            parameter_overrides=[Parameter(name, value=value) for name, value in overrides.items()],
        )
        executor = MultiThreadedExecutor(context=context)
        executor.add_node(node)
        stop = threading.Event()

        def spin() -> None:
            while not stop.is_set() and context.ok():
                executor.spin_once(timeout_sec=0.05)

        spinner = threading.Thread(target=spin, name="viscoadh-executor", daemon=True)
        spinner.start()
        try:
            yield context, executor
        finally:
            # Stop spinning before anything is torn down: rclpy's Executor.shutdown does not
            # wait for a spinning thread and destroys the guard condition that thread waits on
            # (an AttributeError inside the executor), so the spinner must be gone first.
            # The same holds for the caller's nodes: one destroyed while the spinner may still be
            # inside `spin_once` with its entities in the wait set raises InvalidHandle in the
            # spinner. So every node still on the executor is destroyed here, after it stopped.
            stop.set()
            spinner.join(timeout=5.0)
            for added in executor.get_nodes():
                executor.remove_node(added)
                added.destroy_node()
            executor.shutdown(timeout_sec=5.0)
    finally:
        rclpy.try_shutdown(context=context)
        _set_environment(previous)
        sys.setswitchinterval(previous_switch)


def _set_environment(values: dict[str, str | None]) -> None:
    """Set environment variables; None removes one."""
    for name, value in values.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value


def run_demo(*, scene_path: Path | None = None, out_dir: Path, contact_id: str | None = None) -> str:
    """The main job: drive one cycle through the node, log it, plot it; return the summary text.

    scene_path: scene YAML (None: the built-in scene). out_dir: created if missing; gets
    ``demo.mcap`` (the node's log) and ``demo.png`` (the figure). contact_id: the contact to
    drive (None: the scene's first). Raises ConfigError for a scene the demo cannot drive,
    RuntimeError if the run fails.
    """
    scene = SceneConfig.from_yaml(scene_path if scene_path is not None else default_scene_path())
    contact = scene.contact(contact_id) if contact_id is not None else scene.contacts[0]
    plan = plan_cycle(contact)
    reference = sphere_reference(contact)
    out_dir.mkdir(parents=True, exist_ok=True)
    log_path = (out_dir / "demo.mcap").resolve()
    figure_path = (out_dir / "demo.png").resolve()
    log_path.unlink(missing_ok=True)
    # The driver moves /clock after each answer, and the next command may reach the node before
    # that clock does (two topics, no order between them): from the clock's first value (0) the
    # second command is more than the default 1 s ahead. The demo drives the clock itself, so the
    # node allows commands up to DRIVER_MAX_FUTURE_S ahead of it.
    overrides = {"log.enabled": True, "log.path": str(log_path), "command.max_future_s": DRIVER_MAX_FUTURE_S}
    with node_in_process(scene, use_sim_time=True, **overrides) as (
        context,
        executor,
    ):
        client = Node("viscoadh_demo_driver", context=context)
        executor.add_node(client)
        driver = _Driver(client, contact.id, timeout=_TIMEOUT_S)
        driver.wait_for_node()
        run = drive_cycle(driver, plan)
    # The node finished its log when it was destroyed, on leaving the block.
    if not log_path.is_file():
        raise RuntimeError(f"the node wrote no log to {log_path} (log.enabled is set)")
    summary = summarize(run, reference)
    title = (
        f"viscoadh demo, contact '{contact.id}': in and out at "
        f"{_si(plan.approach_speed, 'm/s')}, hold {plan.hold_time:.3g} s"
    )
    plot_run(run, reference, figure_path, title=title)
    return format_summary(summary, {"log": log_path, "figure": figure_path})
