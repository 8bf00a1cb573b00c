"""A logged session against `viscoadh node` (sim time we publish, one contact 'finger'),
with everything a real session holds: rejections, holds (clock advancing), force control,
a reset, a parameter change, a clock jump back. Then `viscoadh replay` of the node's log must
give the node's forces (docs: to 1e-9 of the peak; the tests see 0 N).

  viscoadh node --ros-args -p use_sim_time:=true -p log.enabled:=true -p log.path:=/tmp/t5s/session.mcap
  python repro/node_session.py
"""

import math
import time

import rclpy
from builtin_interfaces.msg import Time
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Trigger
from viscoadh_msgs.msg import ContactEvent, ContactState, IndentationCommand
from viscoadh_msgs.srv import PredictPullOff, SimulateHistory

rclpy.init()
node = Node("tester5_session")
clock_pub = node.create_publisher(Clock, "/clock", 10)
states, events = [], []
node.create_subscription(ContactState, "finger/state", states.append, 1000)
node.create_subscription(ContactEvent, "finger/events", events.append, 100)
pub = node.create_publisher(IndentationCommand, "finger/indentation", 100)
reset = node.create_client(Trigger, "finger/reset")
pull = node.create_client(PredictPullOff, "finger/predict_pull_off")
hist = node.create_client(SimulateHistory, "finger/simulate_history")
params = node.create_client(SetParameters, "/viscoadh/set_parameters")
now_ns = [50 * 10**9]


def spin(pred, timeout=3.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.01)
        if pred():
            return True
    return False


def clock(ns):
    now_ns[0] = ns
    clock_pub.publish(Clock(clock=Time(sec=ns // 10**9, nanosec=ns % 10**9)))
    spin(lambda: False, 0.03)


def T(ns):
    return Time(sec=ns // 10**9, nanosec=ns % 10**9)


def send(dt_ms, depth=0.0, force=0.0, mode=0):
    m = IndentationCommand(mode=mode, depth=depth, force=force)
    m.header.stamp = T(now_ns[0] + int(dt_ms * 1e6))
    n = len(states)
    pub.publish(m)
    spin(lambda: len(states) > n, 2.0)


def call(client, req):
    fut = client.call_async(req)
    rclpy.spin_until_future_complete(node, fut, timeout_sec=30)
    return fut.result()


while pub.get_subscription_count() == 0:
    clock(now_ns[0])
for c in (reset, pull, hist, params):
    c.wait_for_service(timeout_sec=10)
clock(now_ns[0])
# 1) press at 1 kHz (stamps ahead of the clock by < 1 s), with bad commands in between
for i in range(1, 201):
    send(i, depth=i * 0.2e-6)
    if i % 50 == 0:
        send(i, depth=math.nan)  # rejected
        send(i - 5, depth=1e-6)  # older stamp: rejected
        send(i, mode=7)  # rejected
clock(now_ns[0] + 200 * 10**6)
# 2) hold: let the clock run, the timer advances the contact
for k in range(1, 40):
    clock(now_ns[0] + 25 * 10**6)
r = call(pull, PredictPullOff.Request(retract_speed=1e-4))
print("predict_pull_off:", r.success, r.pull_off_force, r.message)
for bad in (0.0, -1.0, math.nan, math.inf, 1e-13, 1e4):
    r = call(pull, PredictPullOff.Request(retract_speed=bad))
    print(f"predict_pull_off({bad}): success={r.success} {r.message[:90]}")
# 3) force control: unload to 1 mN, then pull -5 mN, hold while creeping
send(1, force=1e-3, mode=1)
for k in range(1, 20):
    clock(now_ns[0] + 20 * 10**6)
send(1, force=-5e-3, mode=1)
for k in range(1, 40):
    clock(now_ns[0] + 20 * 10**6)
# 4) reset, parameter change, new session
print("reset:", call(reset, Trigger.Request()).success)
p = Parameter(
    name="finger.adhesion.work_of_adhesion",
    value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=0.08),
)
print("param:", call(params, SetParameters.Request(parameters=[p])).results[0].successful)
for i in range(1, 101):
    send(i, depth=i * 0.3e-6)
clock(now_ns[0] + 100 * 10**6)
for i in range(1, 201):
    send(i, depth=30e-6 - i * 0.4e-6)
clock(now_ns[0] + 200 * 10**6)
# 5) clock jumps back by 2 s: the node resets the contact
clock(now_ns[0] - 2 * 10**9)
clock(now_ns[0] + 10 * 10**6)
for i in range(1, 51):
    send(i, depth=i * 0.4e-6)
clock(now_ns[0] + 50 * 10**6)
for k in range(1, 10):
    clock(now_ns[0] + 20 * 10**6)
# services with bad requests
for label, req in (
    ("non-monotonic", SimulateHistory.Request(mode=0, time=[0.0, 1.0, 0.5], depth=[0.0, 1e-6, 2e-6])),
    ("nan", SimulateHistory.Request(mode=0, time=[0.0, 1.0], depth=[0.0, math.nan])),
    ("lengths", SimulateHistory.Request(mode=0, time=[0.0, 1.0], depth=[0.0])),
    ("empty", SimulateHistory.Request(mode=0, time=[], depth=[])),
    ("mode 4", SimulateHistory.Request(mode=4, time=[0.0], depth=[0.0])),
    ("force mode", SimulateHistory.Request(mode=1, time=[0.0, 0.1, 0.2], force=[0.0, 1e-3, -1e-3])),
):
    r = call(hist, req)
    print(f"simulate_history {label}: success={r.success} n={len(r.force)} {r.message[:100]}")
spin(lambda: False, 0.5)
kinds = [e.kind for e in events]
print(
    f"states={len(states)} events: rejected={kinds.count(1)} reset={kinds.count(2)} params={kinds.count(3)}"
)
nan_states = sum(
    1 for s in states if not all(math.isfinite(getattr(s, f)) for f in ("depth", "force", "contact_radius"))
)
print("non-finite states:", nan_states, " min force:", min(s.force for s in states))
node.destroy_node()
rclpy.shutdown()
