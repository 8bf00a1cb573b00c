"""Fit benchmark: recovery from poor starts, stated intervals and time per fit (issue 12).

Records are made here by an independent model run (`simulate_history` at the ``accurate``
preset, the simulator's own grid) plus seeded 1 % Gaussian load-cell noise, on a 10 mm sphere:
a fast press to 10 um, a hold, a partial unload, a slower press to 20 um, a hold and a
retraction past pull-off over 0.2 s (ramps of 10-70 ms against a retardation time of 10 ms).
The fits (`fitting.fit`, all parameters free; the start scene's ``fast`` preset on the fit's
grid for the coarse stage, the polish on the element count the record's noise calls for,
`fitting.polish_elements`) start from the truth times a seeded factor in 1/3 .. 3 per
parameter. Per fit: wall and CPU time, model runs and the share
of time in them, whether every parameter is within 5 % of the truth and whether the truth
lies within the stated 95 % intervals.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

#: Standard solid (retardation time eta1/G1 = 10 ms) and a K = 2 chain (10 ms and 100 ms).
STANDARD = {"G0": 1.0e6, "G1": 2.0e5, "eta1": 2.0e3, "work_of_adhesion": 0.05}
KELVIN2 = {"G0": 1.0e6, "G1": 4.0e5, "G2": 4.0e5, "eta1": 4.0e3, "eta2": 4.0e4, "work_of_adhesion": 0.05}
NOISE = 0.01
RECOVERY = 0.05  # "recovered": every parameter within 5 % of the truth


def probe_scene(values: dict[str, float], *, preset: str = "fast", kelvin: int = 1) -> Any:
    """The one-contact scene the fit records are made and fitted with: contact "probe", a
    sphere R = 10 mm, ``values`` named as `fitting` names parameters (``G0``, ``G1..GK``,
    ``eta1..etaK``, ``work_of_adhesion``), ``kelvin`` Kelvin elements, numerics ``preset``."""
    from viscoadh_ros.core.config import SceneConfig

    return SceneConfig.from_parameters(
        {
            "contacts": ["probe"],
            "probe.indenter.shape": "sphere",
            "probe.indenter.radius": 0.01,
            "probe.material.glass_shear_modulus": values["G0"],
            "probe.material.kelvin_shear_moduli": [values[f"G{k}"] for k in range(1, kelvin + 1)],
            "probe.material.kelvin_viscosities": [values[f"eta{k}"] for k in range(1, kelvin + 1)],
            "probe.adhesion.work_of_adhesion": values["work_of_adhesion"],
            "probe.numerics.preset": preset,
        }
    )


def _contact(values: dict[str, float], kelvin: int, preset: str) -> Any:
    return probe_scene(values, preset=preset, kelvin=kelvin).contacts[0]


def make_record(path: Path, values: dict[str, float], kelvin: int, samples: int, seed: int) -> None:
    """Write the benchmark record (PointStamped depth, WrenchStamped force) to ``path``."""
    from geometry_msgs.msg import PointStamped, WrenchStamped

    from viscoadh_ros.core.history import simulate_history
    from viscoadh_ros.io.mcap_log import McapRecorder
    from viscoadh_ros.ros.conversions import ns_to_stamp

    t = np.linspace(0.0, 0.2, samples, endpoint=False)
    depth = np.interp(
        t, [0, 0.01, 0.03, 0.05, 0.08, 0.10, 0.2], [-1e-6, 10e-6, 10e-6, 3e-6, 20e-6, 20e-6, -30e-6]
    )
    force = simulate_history(_contact(values, kelvin, "accurate"), t, depth=depth).force
    force = force + np.random.default_rng(seed).normal(0.0, NOISE * float(np.max(np.abs(force))), force.size)
    with McapRecorder(path, queue_size=2 * samples + 16) as recorder:
        for ti, di, fi in zip(t, depth, force, strict=True):
            stamp_ns = 1_000_000_000 + round(ti * 1e9)
            point, wrench = PointStamped(), WrenchStamped()
            point.header.stamp = wrench.header.stamp = ns_to_stamp(stamp_ns)
            point.point.z, wrench.wrench.force.z = float(di), float(fi)
            recorder.record("/probe/depth", point, stamp_ns)
            recorder.record("/probe/force", wrench, stamp_ns)
    if recorder.error is not None or recorder.dropped:
        raise RuntimeError(f"writing the fit record failed: {recorder.error!r}, {recorder.dropped} dropped")


def _case(values: dict[str, float], kelvin: int, samples: int, starts: int, seed: int) -> dict[str, Any]:
    from viscoadh_ros.experiment import load_experiment
    from viscoadh_ros.fitting import FitError, fit
    from viscoadh_ros.io.bag import Bag

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "record.mcap"
        make_record(path, values, kelvin, samples, seed)
        experiment = load_experiment(Bag(path), input_topic="/probe/depth")
    rng = np.random.default_rng(seed)
    fits = []
    for _ in range(starts):
        factors = {n: float(math.exp(rng.uniform(-math.log(3.0), math.log(3.0)))) for n in values}
        start = _contact({n: values[n] * factors[n] for n in values}, kelvin, "fast")
        wall, cpu = time.perf_counter(), time.process_time()
        row: dict[str, Any] = {"start_factors": factors}
        try:
            result = fit(start, experiment, list(values), kelvin=kelvin)
        except FitError as exc:
            row.update(status="failed", reason=str(exc))
        else:
            errors = {n: result.values[n] / values[n] - 1.0 for n in values}
            row.update(
                status=result.status,
                errors=errors,
                recovered=all(abs(e) <= RECOVERY for e in errors.values()),
                covered=sum(lo <= values[n] <= hi for n, (lo, hi) in result.interval.items()),
                rmse_over_noise=result.rmse / result.noise,
                model_runs=result.model_runs,
                model_time_share=result.model_time / result.wall_time,
                elements=result.model_contact.numerics.elements,
            )
        row.update(wall_s=time.perf_counter() - wall, cpu_s=time.process_time() - cpu)
        fits.append(row)
    done = [f for f in fits if f["status"] != "failed"]
    return {
        "kelvin": kelvin,
        "samples": samples,
        "parameters": len(values),
        "fits": fits,
        "recovered": sum(bool(f.get("recovered")) for f in fits),
        "covered": sum(f.get("covered", 0) for f in fits),
        "checks": len(values) * len(fits),
        "median_wall_s": float(np.median([f["wall_s"] for f in fits])),
        "median_cpu_s": float(np.median([f["cpu_s"] for f in fits])),
        "median_model_runs": float(np.median([f["model_runs"] for f in done])) if done else math.nan,
    }


def fit_benchmark(*, samples: int, starts: int, kelvin_starts: int, seed: int = 0) -> dict[str, Any]:
    """Both cases: the standard solid (``starts`` fits) and K = 2 (``kelvin_starts`` fits)."""
    from viscoadh_ros.core.history import simulate_history

    # Load the compiled kernels before any fit is timed.
    simulate_history(_contact(STANDARD, 1, "fast"), [0.0, 1e-3], depth=[0.0, 1e-6])
    cases = {"standard_solid": _case(STANDARD, 1, samples, starts, seed)}
    if kelvin_starts:
        cases["kelvin_2"] = _case(KELVIN2, 2, samples, kelvin_starts, seed + 1)
    return {"noise": NOISE, "recovery": RECOVERY, "cases": cases}
