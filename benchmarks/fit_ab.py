"""Side-by-side CPU of two versions of `viscoadh_ros/fitting.py` on the fit bench's records.

    python benchmarks/fit_ab.py KELVIN SAMPLES NOISE_SEED START_SEEDS [REV]

KELVIN 2: the bench's K = 2 body, starts ``exp(U(-ln 3, ln 3))`` per parameter from
``default_rng(start seed)`` for each of START_SEEDS (comma separated; seed 1 is the bench's
kelvin_2 start). KELVIN 1: the bench's standard solid, START_SEEDS[0] sequential starts of
``default_rng(NOISE_SEED)`` (the bench's standard_solid starts). Records as the bench's
(`fit_speed.make_record`). The old version is REV's fitting.py (default c28c75b, 0.3.0 + one
commit), loaded as a module beside the working tree's; each start runs both, the order
alternating; one JSON line per fit with the CPU (process) time, status, recovery and coverage.
"""

from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from viscoadh_ros.bench.fit_speed import KELVIN2, STANDARD, _contact, make_record
from viscoadh_ros.core.history import simulate_history
from viscoadh_ros.experiment import load_experiment
from viscoadh_ros.io.bag import Bag


def _old_fitting(rev: str):
    root = Path(__file__).resolve().parents[1]
    command = ["git", "show", f"{rev}:viscoadh_ros/fitting.py"]
    source = subprocess.run(command, cwd=root, check=True, capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp()) / "fitting_old.py"
    path.write_text(source, encoding="utf-8")
    spec = importlib.util.spec_from_file_location("fitting_old", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["fitting_old"] = module
    spec.loader.exec_module(module)
    return module


def main() -> None:
    kelvin, samples, noise_seed = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    seeds = [int(x) for x in sys.argv[4].split(",")]
    rev = sys.argv[5] if len(sys.argv) > 5 else "c28c75b"
    import viscoadh_ros.fitting as new

    old = _old_fitting(rev)
    truth = KELVIN2 if kelvin == 2 else STANDARD
    folder = Path(tempfile.mkdtemp())
    make_record(folder / "record.mcap", truth, kelvin, samples, noise_seed)
    experiment = load_experiment(Bag(folder / "record.mcap"), input_topic="/probe/depth")
    simulate_history(_contact(truth, kelvin, "fast"), [0.0, 1e-3], depth=[0.0, 1e-6])
    if kelvin == 2:
        rngs = [(s, np.random.default_rng(s)) for s in seeds]
    else:
        shared = np.random.default_rng(noise_seed)
        rngs = [(s, shared) for s in range(seeds[0])]
    for s, rng in rngs:
        factors = {n: float(math.exp(rng.uniform(-math.log(3.0), math.log(3.0)))) for n in truth}
        start = _contact({n: truth[n] * factors[n] for n in truth}, kelvin, "fast")
        order = [("old", old), ("new", new)]
        for tag, module in order if s % 2 else order[::-1]:
            cpu = time.process_time()
            try:
                result = module.fit(start, experiment, list(truth), kelvin=kelvin)
            except module.FitError as exc:
                print(json.dumps({"start": s, "code": tag, "status": "failed", "reason": str(exc)[:200]}))
                continue
            cpu = time.process_time() - cpu
            errors = {n: result.values[n] / truth[n] - 1.0 for n in truth}
            row = {
                "start": s,
                "code": tag,
                "status": result.status,
                "cpu_s": round(cpu, 2),
                "model_runs": result.model_runs,
                "recovered": all(abs(e) <= 0.05 for e in errors.values()),
                "covered": sum(lo <= truth[n] <= hi for n, (lo, hi) in result.interval.items()),
                "errors": {n: round(e, 4) for n, e in errors.items()},
                "rmse_over_noise": round(result.rmse / result.noise, 4),
            }
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
