"""Run every scene of scenes.py through step() per call and step_depths; save all outputs.

usage: <venv python> repro/run_scenes.py OUT.npz   (run with main's and c28c75b's venvs)
"""

import sys
import time

import numpy as np
from scenes import contact_of, scenes

from viscoadh_ros.core.simulator import STEP_OUTPUT_FIELDS, ContactSimulator

FIELDS = [f for f in STEP_OUTPUT_FIELDS if f not in ("time", "depth")]


def main(path):
    saved = {}
    for name, sec, t, d in scenes():
        c = contact_of(sec)
        sim = ContactSimulator(c)
        t0 = time.perf_counter()
        rows = []
        err = ""
        for ti, di in zip(t, d, strict=False):
            try:
                o = sim.step(float(ti), depth=float(di))
            except Exception as e:  # noqa: BLE001
                err = f"{type(e).__name__}: {e}"
                break
            rows.append([float(getattr(o, f)) for f in FIELDS])
        t_call = time.perf_counter() - t0
        a = np.array(rows).reshape(-1, len(FIELDS))
        saved[name + "/call"] = a
        sim2 = ContactSimulator(c)
        try:
            cols = sim2.step_depths(t, d)
            b = np.column_stack([np.asarray(cols[f], dtype=float) for f in FIELDS])
        except Exception as e:  # noqa: BLE001
            b = np.zeros((0, len(FIELDS)))
            err += f" | step_depths {type(e).__name__}: {e}"
        saved[name + "/rows"] = b
        print(f"{name:28s} n={len(t):6d} call_rows={a.shape[0]:6d} {t_call:6.2f}s {err}", flush=True)
    np.savez(path, fields=np.array(FIELDS), **saved)


if __name__ == "__main__":
    main(sys.argv[1])
