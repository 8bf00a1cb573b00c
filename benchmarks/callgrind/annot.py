"""annot.py CG_FULL CG_EMPTY MAP OBJ PER FUNC_SUBSTR: per-instruction self cost of one function
(per row), interleaved with objdump's disassembly."""

import subprocess
import sys

sys.path.insert(0, __import__("os").path.dirname(__file__))
from cgparse import load_map, parse, short

full, empty, mp, obj, per, want = sys.argv[1:7]
per = float(per)
rows = load_map(mp)
cf, callf = parse(full)
ce, calle = parse(empty)
found = [row for row in rows if short(row[2]) == want]
if not found:
    raise SystemExit("no such function")
start, off, name = found[0]
dis = subprocess.run(
    ["objdump", "-dr", "--no-show-raw-insn", "-M", "intel", f"--disassemble={name}", obj],
    capture_output=True,
    text=True,
).stdout
total = 0
for line in dis.splitlines():
    parts = line.split(":", 1)
    try:
        a = int(parts[0].strip(), 16)
    except ValueError:
        continue
    rt = start + (a - off)
    c = (cf.get(rt, 0) - ce.get(rt, 0)) / per
    k = (callf.get(rt, 0) - calle.get(rt, 0)) / per
    total += c
    ins = parts[1].strip()
    if "call" in ins:
        ins = ins[:120]
    print(f"{c:7.2f} {(f'c{k:.2f}') if k else '':7s} {a:6x} {ins[:140]}")
print("total", total)
