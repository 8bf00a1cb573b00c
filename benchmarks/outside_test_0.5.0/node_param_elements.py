"""A runtime parameter the schema accepts but the simulator cannot build:
c0.numerics.elements = 10**10 (schema: "integer, 0 or >= 4", no upper bound). Expected: refused
with a reason, nothing changed, the node keeps serving c0. Then c0 commands must still work."""

from node_client import call, cmd, events, reset_all, states, wait_state  # noqa: F401
from node_params import set_one, snapshot

reset_all()
print("before:", snapshot()["c0.numerics.elements"])
try:
    r = set_one("c0.numerics.elements", 10**10)
    print(f"set elements=1e10: successful={r.successful} reason={r.reason[:160]!r}")
except Exception as e:  # noqa: BLE001
    print("set call failed:", type(e).__name__, e)
try:
    print("after:", snapshot()["c0.numerics.elements"])
except Exception as e:  # noqa: BLE001
    print("get failed:", type(e).__name__, e)
ne = len(events["c0"])
n0 = cmd("c0", 10, depth=20e-6)
s = wait_state("c0", n0, 10)
print(
    "c0 command after it:",
    None if s is None else (s.force, s.contact_radius, s.model),
    "events:",
    [e.reason[:120] for e in events["c0"][ne:]],
)
