# ruff: noqa: E501
"""The deferred substeps (0.4.0) against the whole-row-per-substep loop it replaced
(tests/advance_reference.py), step by step from the product's own state, over the scenes of
scenes.py driven through ContactSimulator.step (every scene, not only the test's racing
spheres): per output, max |product - reference| / max |reference| over the scene, and the
memory likewise. The CHANGELOG states <= 3e-14 (bench scenes) / 6e-13 (golden scenes).

usage: .venv/bin/python repro/defer_vs_reference.py [scene-substring]
"""

import sys

import numpy as np

sys.path.insert(1, "tests")
import importlib  # noqa: E402
import os  # noqa: E402

from advance_reference import advance_reference  # noqa: E402
from scenes import contact_of  # noqa: E402

scenes = importlib.import_module(os.environ.get("SCENES", "scenes")).scenes

from viscoadh_ros.core import _kernels as K  # noqa: E402
from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

COLS = {
    "radius": K.OUT_RADIUS,
    "force": K.OUT_FORCE,
    "work": K.OUT_WORK,
    "dissipated": K.OUT_DISSIPATED,
    "peak": K.OUT_MEMORY,
}


def run(name, sec, t, d):
    sim = ContactSimulator(contact_of(sec))
    model = sim._model
    outs, refs, mem_d, mem_s, codes_bad, multi = [], [], 0.0, 0.0, 0, 0
    worst = (0.0, -1)
    for i, (ti, di) in enumerate(zip(t, d, strict=False)):
        row = model.row
        ref = None
        if row is not None and row.wl.shape[1] > 0:
            ref = row.with_memory(row.wl.copy(), row.wb.copy())
            a, d0, dt = float(model.radius), float(sim._depth), float(ti) - sim.time
            idle = di < 0 and d0 < 0 and a <= 0 and model.is_relaxed()
            if idle:
                ref = None
            else:
                st, rout = advance_reference(
                    ref,
                    a,
                    d0,
                    float(di),
                    dt,
                    max_substep=model._max_substep,
                    max_edge_move=model._max_edge_cells * row.dx,
                )
                rout = rout.copy()
        sim.step(float(ti), depth=float(di))
        if ref is None or model.row is not row or st != K.STATUS_OK:
            continue
        out = row.out.copy()
        outs.append(out)
        refs.append(rout)
        if out[K.OUT_SUBSTEPS] != rout[K.OUT_SUBSTEPS] or out[K.OUT_MOTION] != rout[K.OUT_MOTION]:
            codes_bad += 1
        if rout[K.OUT_SUBSTEPS] > 1:
            multi += 1
        mem_d = max(mem_d, float(np.max(np.abs(row.wl - ref.wl))), float(np.max(np.abs(row.wb - ref.wb))))
        mem_s = max(mem_s, float(np.max(np.abs(ref.wl))), float(np.max(np.abs(ref.wb))))
        df = abs(out[K.OUT_FORCE] - rout[K.OUT_FORCE])
        if df > worst[0]:
            worst = (df, i)
    if not outs:
        return None
    o, r = np.array(outs), np.array(refs)
    rel = {
        c: float(np.max(np.abs(o[:, j] - r[:, j])) / max(np.max(np.abs(r[:, j])), 1e-300))
        for c, j in COLS.items()
    }
    rel["memory"] = mem_d / max(mem_s, 1e-300)
    return rel, codes_bad, multi, len(outs), worst


def main():
    key = sys.argv[1] if len(sys.argv) > 1 else ""
    print(
        f"{'scene':26s} rows multi codes "
        + " ".join(f"{c:>10s}" for c in list(COLS) + ["memory"])
        + "  worst-force-row"
    )
    for name, sec, t, d in scenes():
        if key not in name or "K0" in name:
            continue
        res = run(name, sec, t, d)
        if res is None:
            continue
        rel, bad, multi, n, worst = res
        flag = " <-- > 1e-12" if max(rel.values()) > 1e-12 else ""
        print(
            f"{name:26s} {n:5d} {multi:5d} {bad:5d} "
            + " ".join(f"{rel[c]:10.2e}" for c in rel)
            + f"  {worst[1]}{flag}",
            flush=True,
        )


if __name__ == "__main__":
    main()
