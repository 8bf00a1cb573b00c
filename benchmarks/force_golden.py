"""Write the force-control golden file from a checkout's core (issue 13, force search).

    .venv/bin/python benchmarks/force_golden.py <checkout root> [out.npz]

Runs every case of tests/force_histories.py (this checkout's copy) on the core of
<checkout root> (e.g. a `git archive` of main unpacked under /tmp) and saves the commands and
outputs; default output tests/force_control_golden.npz beside this script's checkout.
"""

from __future__ import annotations

import sys
from pathlib import Path

here = Path(__file__).resolve().parents[1]
root = sys.argv[1]
sys.path.insert(0, str(here / "tests"))
sys.path.insert(0, root)

import numpy as np  # noqa: E402

import viscoadh_ros  # noqa: E402

assert viscoadh_ros.__file__.startswith(str(Path(root).resolve())), viscoadh_ros.__file__

import force_histories as fh  # noqa: E402

out = Path(sys.argv[2]) if len(sys.argv) > 2 else here / "tests" / "force_control_golden.npz"
arrays = {}
for name, (contact_name, commands) in fh.cases().items():
    result = fh.run(fh.CONTACTS[contact_name](), commands)
    arrays[f"{name}/commands"] = fh.encode(commands)
    for key, values in result.items():
        arrays[f"{name}/{key}"] = values
    print(name, len(commands), "commands,", int(result["refused"].sum()), "refused")
np.savez_compressed(out, **arrays)
print("wrote", out)
