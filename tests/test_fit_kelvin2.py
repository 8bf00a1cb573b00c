"""A two-element chain (K = 2, six free parameters) from a start off by up to x3 (issue 13, Fit).

The record: the standard history, 5000 samples (the bench's length: `viscoadh bench --sections
fit`, case kelvin_2), an independent model run (``accurate`` preset, its own grid) of the
bench's K = 2 body (retardation times 10 ms and 100 ms against a 0.2 s record) plus 1 % noise.
The start: the bench's own seeded factors for this case; a second case guards the
retardation scan.

On 0.3.0 this fit ended at a false stop (eta2 -47 %, G1 +22 %: the slow mode's retardation
time at half the truth's) and said ``misfit``: its start descent ran out of evaluations while
crawling along the flat valley of that retardation time, and the polish stayed where it began,
though the cost profile over that time falls all the way to the truth. The same factors rounded
to three digits let 0.3.0 pass: where its descent stopped hung on the start's last digits. About
10 s of CPU per case (record and fit).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fit_records import DEPTH_TOPIC, scene, standard_history, true_force, write_record

from viscoadh_ros.bench.fit_speed import KELVIN2
from viscoadh_ros.experiment import load_experiment, run_model
from viscoadh_ros.fitting import by_retardation, coarse_record, fit
from viscoadh_ros.io.bag import Bag

SAMPLES = 5000


def _factors(seed: int) -> dict[str, float]:
    """The bench's seeded start factors (`fit_speed._case`): the truth times these."""
    rng = np.random.default_rng(seed)
    return {n: float(math.exp(rng.uniform(-math.log(3.0), math.log(3.0)))) for n in KELVIN2}


@pytest.mark.parametrize(
    ("noise_seed", "start_seed"),
    [
        # The bench's case (G0 x1.03, G1 x2.69, G2 x0.46, eta1 x2.68, eta2 x0.66, w x0.85).
        (1, 1),
        # A start (G0 x2.26, w x2.49, the fast time x2.9, the slow x1.3) whose coarse stage, on the
        # thinned record without the retardation scan, stopped at the slow time x0.5 and said
        # "ok" with eta2 -44 % and no truth in its intervals.
        (2, 9),
    ],
    ids=["bench", "flat_valley"],
)
def test_a_two_element_chain_from_a_start_off_by_three_finds_the_truth(
    tmp_path, noise_seed, start_seed
) -> None:
    path = tmp_path / "kelvin2.mcap"
    time, depth = standard_history(SAMPLES)
    force = true_force(KELVIN2, time, depth, kelvin=2)
    write_record(path, time, depth, force, noise=0.01, seed=noise_seed)
    record = load_experiment(Bag(path), input_topic=DEPTH_TOPIC)
    factors = _factors(start_seed)
    start = scene({n: KELVIN2[n] * factors[n] for n in KELVIN2}, kelvin=2).contacts[0]
    result = fit(start, record, list(KELVIN2), kelvin=2)
    assert result.status == "ok", result.reason
    for name, truth in KELVIN2.items():
        value, sigma = result.values[name], result.uncertainty[name] / result.values[name]
        off = abs(math.log(value / truth))
        assert off < 0.05, f"{name}: {value:g} vs truth {truth:g}"
        # Within 3 stated standard deviations (99.7 %), a single fit's check as in
        # test_fit_identification (the flat_valley fit holds G0 at 2.2 of them: outside its 95 %
        # interval, as 5 % of intervals are); the bench's case has every truth inside its 95 %.
        assert off <= 3.0 * sigma, f"{name}: {value:g} +- {sigma:.2%}, truth {truth:g}"
        lo, hi = result.interval[name]
        if (noise_seed, start_seed) == (1, 1):
            assert lo <= truth <= hi, f"{name}: truth {truth:g} outside its 95 % interval {lo:g}..{hi:g}"


def test_the_coarse_record_runs_the_same_model_on_fewer_stamps(tmp_path) -> None:
    """`coarse_record` keeps the picked samples and the inputs that reach them: the model's force
    there stays within a fraction of the noise of the full record's (the first-order hold ramps
    over the kept inputs as over the dense ones), while the model steps a third as often."""
    path = tmp_path / "thin.mcap"
    time, depth = standard_history(3000)
    force = true_force(KELVIN2, time, depth, kelvin=2)
    sigma = write_record(path, time, depth, force, noise=0.01, seed=2)
    record = load_experiment(Bag(path), input_topic=DEPTH_TOPIC)
    picked = np.zeros(record.measured_force.size, dtype=bool)
    picked[7::3] = True
    thinned = coarse_record(record, picked, 3)
    assert thinned.measured_force.size == int(np.count_nonzero(picked))
    assert np.array_equal(thinned.measured_ns, record.measured_ns[picked])
    assert thinned.input_ns.size < 0.4 * record.input_ns.size
    contact = scene(KELVIN2, kelvin=2).contacts[0]
    full = run_model(contact, record).model_force[picked]
    thin = run_model(contact, thinned).model_force
    assert float(np.max(np.abs(thin - full))) < 0.5 * sigma, float(np.max(np.abs(thin - full))) / sigma
    # Nothing to thin: the record itself.
    assert coarse_record(record, picked, 1) is record


def test_a_free_chain_is_labelled_by_retardation_time() -> None:
    swapped = {**KELVIN2, "G1": KELVIN2["G2"], "eta1": KELVIN2["eta2"], "G2": 1.0e5, "eta2": 1.0e2}
    relabelled = by_retardation(swapped, 2)
    assert relabelled == {**KELVIN2, "G1": 1.0e5, "eta1": 1.0e2, "G2": KELVIN2["G2"], "eta2": KELVIN2["eta2"]}
    assert by_retardation(KELVIN2, 2) == KELVIN2
