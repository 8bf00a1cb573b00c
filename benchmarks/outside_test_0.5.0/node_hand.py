"""HandCommand over DDS against `viscoadh node` (two contacts c0, c1; see node_client.py).

baseline: reset, hand good1, hand good2. probe: reset, hand good1, BAD hand command, hand good2.
good2's HandState must equal the baseline's bit for bit; one event on hand/events per bad one.
"""

import math

from node_client import CLOCK_S, events, hand_pub, hand_states, reset_all, spin, stamp  # noqa: F401
from viscoadh_msgs.msg import HandCommand

HF = (
    "depth",
    "force",
    "contact_radius",
    "phase",
    "edge_speed",
    "effective_work_of_adhesion",
    "energy_input",
    "energy_dissipated",
    "unstable",
)


def hand(ms, ids, mode, depth=(), force=(), raw_stamp=None):
    m = HandCommand(
        contact_ids=list(ids), mode=mode, depth=[float(x) for x in depth], force=[float(x) for x in force]
    )
    m.header.stamp = raw_stamp if raw_stamp is not None else stamp(ms)
    hand_pub.publish(m)


def wait_hand(ms, n0, timeout=3.0):
    want = stamp(ms)

    def find():
        for s in hand_states[n0:]:
            if (s.header.stamp.sec, s.header.stamp.nanosec) == (want.sec, want.nanosec):
                return s
        return None

    spin(lambda: find() is not None, timeout)
    return find()


def key(s):
    return tuple(tuple(getattr(s, f)) for f in HF)


def seq(g1, g2, bad=None):
    reset_all()
    n0 = len(hand_states)
    hand(*g1)
    s1 = wait_hand(g1[0], n0)
    evs = []
    extra = []
    if bad is not None:
        ne = len(events["hand"])
        n0 = len(hand_states)
        bad()
        spin(lambda: len(events["hand"]) > ne, 3.0)
        evs = events["hand"][ne:]
        extra = hand_states[n0:]
    n0 = len(hand_states)
    hand(*g2)
    s2 = wait_hand(g2[0], n0)
    return s1, s2, evs, extra


if __name__ == "__main__":
    fails = 0
    for label, g1, g2 in (
        ("depth", (10, [], 0, [20e-6, 10e-6]), (20, [], 0, [25e-6, 12e-6])),
        ("force", (10, ["c1", "c0"], 1, [], [1e-3, 2e-3]), (20, ["c1", "c0"], 1, [], [5e-4, -3e-4])),
    ):
        _, base, _, _ = seq(g1, g2)
        assert base is not None, "no baseline HandState"
        print(f"[{label}] baseline good2 force={list(base.force)} ids={list(base.contact_ids)}")
        m = g1[2]
        bads = {
            "nan in slot 1": lambda: hand(15, ["c0", "c1"], 0, [1e-5, math.nan]),
            "wrong length": lambda: hand(15, ["c0", "c1"], 0, [1e-5]),
            "other array wrong length": lambda: hand(15, ["c0", "c1"], 0, [1e-5, 1e-5], [0.0]),
            "unknown id": lambda: hand(15, ["c0", "thumb"], 0, [1e-5, 1e-5]),
            "listed twice": lambda: hand(15, ["c0", "c0"], 0, [1e-5, 1e-5]),
            "mode 7": lambda: hand(15, [], 7, [1e-5, 1e-5], [1e-5, 1e-5]),
            "time back": lambda: hand(5, [], 0, [1e-5, 1e-5]),
            "c1 depth 1e10 (c0 steps first)": lambda: hand(15, ["c0", "c1"], 0, [30e-6, 1e10]),
            "c1 force 1e12 (c0 force steps first)": lambda: hand(15, ["c0", "c1"], 1, [], [5e-3, 1e12]),
            "stamp 3 s ahead": lambda: hand(3000, [], 0, [1e-5, 1e-5]),
        }
        for name, bad in bads.items():
            _, s2, evs, extra = seq(g1, g2, bad)
            same = s2 is not None and key(s2) == key(base)
            ok = same and len(evs) == 1 and not extra
            fails += not ok
            diff = ""
            if s2 is not None and not same:
                diff = f"good2 force={list(s2.force)}"
            print(
                f"[{label}] {'OK ' if ok else 'BAD'} {name:38s} same={same} events={len(evs)} states_from_bad={len(extra)} "
                f"{diff} {evs[0].contact_id + ': ' + evs[0].reason[:100] if evs else ''}",
                flush=True,
            )
    print("failures:", fails)
