"""Parse a callgrind dump (--dump-instr=yes) into self cost per instruction address, and
attribute JIT addresses to functions by the map written by row_rest.py --map."""

import bisect
import collections
import re
import sys


def parse(path):
    cost = collections.Counter()
    calls = collections.Counter()  # (caller addr) -> calls count
    ipos = 0
    skip_next = False
    with open(path) as fh:
        for line in fh:
            if not line or line[0] not in "0123456789+-*c":
                continue
            if line.startswith("calls="):
                skip_next = int(line.split("=")[1].split()[0])
                continue
            if line[0] == "c":
                continue
            tok = line.split()
            t = tok[0]
            if t.startswith("0x"):
                ipos = int(t, 16)
            elif t[0] == "+":
                ipos += int(t[1:])
            elif t[0] == "-":
                ipos -= int(t[1:])
            # '*' same
            if skip_next:
                calls[ipos] += skip_next
                skip_next = False
                continue
            if len(tok) >= 3:
                cost[ipos] += int(tok[2])
    return cost, calls


def load_map(path):
    rows = []
    for line in open(path):
        a, off, name = line.split(maxsplit=2)
        rows.append((int(a, 16), int(off, 16), name.strip()))
    rows.sort()
    return rows


def short(name):
    m = re.search(r"_kernels\d+(\w+?)B\d+v(\d+)", name)
    if m:
        return f"{m.group(1)}#{m.group(2)}"
    return name[:60]


def by_function(cost, rows):
    starts = [r[0] for r in rows]
    out = collections.Counter()
    for addr, c in cost.items():
        i = bisect.bisect_right(starts, addr) - 1
        if i >= 0 and addr - starts[i] < 0x20000:
            out[short(rows[i][2])] += c
        else:
            out["(outside)"] += c
    return out


if __name__ == "__main__":
    full, empty, mp, per = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    rows = load_map(mp)
    cf, _ = parse(full)
    ce, _ = parse(empty)
    ff = by_function(cf, rows)
    fe = by_function(ce, rows)
    tot = (sum(cf.values()) - sum(ce.values())) / per
    print(f"per row: {tot:.1f}")
    for name in sorted(set(ff) | set(fe), key=lambda k: -(ff[k] - fe[k])):
        d = (ff[name] - fe[name]) / per
        if abs(d) >= 1:
            print(f"{d:9.1f}  {name}")
