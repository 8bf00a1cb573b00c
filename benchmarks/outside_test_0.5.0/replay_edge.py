"""`viscoadh replay` on recordings users have: duplicate and out-of-order stamps, unrelated
topics, an empty bag, a truncated node log. Each case prints exit code, stderr's last line
and the summary (RMSE, max error, pull-off) next to the clean record's."""

import json
import subprocess
import sys
from pathlib import Path

from geometry_msgs.msg import PointStamped, WrenchStamped
from std_msgs.msg import String

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
from fit_records import TRUE, scene, standard_history, true_force  # noqa: E402

from viscoadh_ros.io.mcap_log import McapRecorder, plain  # noqa: E402
from viscoadh_ros.ros.conversions import ns_to_stamp  # noqa: E402

OUT = Path("/tmp/t5_replay")
OUT.mkdir(exist_ok=True)
VISCOADH = str(Path(sys.executable).parent / "viscoadh")
T0 = 5_000_000_000


def write(path, rows, extra_topic=False):
    """rows: (depth stamp ns, depth, force stamp ns, force) in recording order."""
    sc = plain(scene(TRUE).to_dict())
    with McapRecorder(path, scene=sc) as rec:
        for k, (ts, d, tf, f) in enumerate(rows):
            p = PointStamped()
            p.header.stamp = ns_to_stamp(ts)
            p.point.z = float(d)
            w = WrenchStamped()
            w.header.stamp = ns_to_stamp(tf)
            w.wrench.force.z = float(f)
            rec.record("/probe/depth", p, ts + 300_000)
            rec.record("/loadcell/wrench", w, tf + 400_000)
            if extra_topic and k % 7 == 0:
                rec.record("/chatter", String(data="x"), ts + 350_000)
    return path


def replay(bag, *args):
    js = OUT / (Path(bag).stem + ".json")
    if js.exists():
        js.unlink()
    r = subprocess.run(
        [
            VISCOADH,
            "replay",
            str(bag),
            "-o",
            str(OUT / (Path(bag).stem + ".out.mcap")),
            "--json",
            str(js),
            *args,
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    s = json.loads(js.read_text()) if js.exists() else {}
    last = (r.stderr.strip().splitlines() or [""])[-1]
    return r.returncode, last, s


def show(label, res):
    code, last, s = res
    keys = ("samples", "rmse_N", "max_error_N", "model_pull_off_force_N", "commands")
    print(
        f"{label:34s} exit={code} "
        + " ".join(f"{k}={s.get(k)}" for k in keys)
        + (f" | {last[:150]}" if code else ""),
        flush=True,
    )


if __name__ == "__main__":
    t, d = standard_history(200)
    f = true_force(TRUE, t, d)
    ns = [T0 + round(x * 1e9) for x in t]
    clean = list(zip(ns, d, ns, f))
    show("clean", replay(write(OUT / "clean.mcap", clean)))
    dup = list(clean)
    dup.insert(101, (ns[100], d[100] + 1e-6, ns[100], f[100]))  # same stamp, another depth
    show("duplicate stamp, other depth", replay(write(OUT / "dup.mcap", dup)))
    dup2 = list(clean)
    dup2.insert(101, clean[100])  # exact duplicate message
    show("exact duplicate message", replay(write(OUT / "dup2.mcap", dup2)))
    ooo = list(clean)
    ooo[50], ooo[51] = ooo[51], ooo[50]  # recorded out of order
    show("two samples out of order", replay(write(OUT / "ooo.mcap", ooo)))
    rev = list(reversed(clean))
    show("whole record reversed order", replay(write(OUT / "rev.mcap", rev)))
    show("extra unrelated topic", replay(write(OUT / "extra.mcap", clean, extra_topic=True)))
    show("empty bag", replay(write(OUT / "empty.mcap", [])))
    zero = [(T0, 0.0, T0, 0.0)] + [(T0 + 1000, 1e-6, T0 + 1000, 0.0)]
    show("two samples", replay(write(OUT / "two.mcap", zero)))
    # truncated copies of the clean record
    raw = (OUT / "clean.mcap").read_bytes()
    for frac in (0.5, 0.9):
        p = OUT / f"trunc{int(frac * 100)}.mcap"
        p.write_bytes(raw[: int(len(raw) * frac)])
        show(f"truncated at {frac:.0%}", replay(p))
        show(f"truncated at {frac:.0%} --recover", replay(p, "--recover"))
    p = OUT / "zero_bytes.mcap"
    p.write_bytes(b"")
    show("zero-byte file", replay(p))
    p = OUT / "magic_only.mcap"
    p.write_bytes(raw[:8])
    show("magic only", replay(p))
    show("magic only --recover", replay(p, "--recover"))
