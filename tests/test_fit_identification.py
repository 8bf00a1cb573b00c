"""Identification from a poor start with honest intervals (issue 12, item 1).

Records come from an independent model run (`fit_records`: ``accurate`` preset, its own
grid) with seeded 1 % noise; the fit runs the ``fast`` preset on its own fixed grid. The
scene is a standard solid (K = 1), so ``model: auto`` routes every run to the time-stepped
1D model (only elastic scenes have a closed form).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fit_records import DEPTH_TOPIC, TRUE, scene, standard_history, true_force, write_record

from viscoadh_ros.experiment import load_experiment
from viscoadh_ros.fitting import fit
from viscoadh_ros.io.bag import Bag

FREE = ["G0", "G1", "eta1", "work_of_adhesion"]


@pytest.fixture(scope="module")
def record(tmp_path_factory: pytest.TempPathFactory):
    """A 1000-sample record of the standard history with 1 % noise."""
    path = tmp_path_factory.mktemp("ident") / "record.mcap"
    time, depth = standard_history(1000)
    write_record(path, time, depth, true_force(TRUE, time, depth), noise=0.01, seed=1)
    return load_experiment(Bag(path), input_topic=DEPTH_TOPIC)


@pytest.mark.parametrize(
    "factors",
    [
        # The case: w at half the truth, everything else off too.
        {"G0": 1.5, "G1": 0.7, "eta1": 1.5, "work_of_adhesion": 0.5},
        # A start the 0.1.0 fit left in a far valley (G0 0.46, G1 0.10, w 0.23 of the truth)
        # and called success.
        {"G0": 1.67, "G1": 0.43, "eta1": 0.79, "work_of_adhesion": 1.04},
    ],
    ids=["w_half", "far_valley"],
)
def test_fit_from_a_poor_start_finds_the_truth_within_its_stated_interval(record, factors) -> None:
    start = scene({n: TRUE[n] * factors[n] for n in TRUE}).contacts[0]
    result = fit(start, record, FREE)
    assert result.status == "ok", result.reason
    for name, truth in TRUE.items():
        value, sigma = result.values[name], result.uncertainty[name] / result.values[name]
        assert abs(math.log(value / truth)) < 0.05, f"{name}: {value:g} vs truth {truth:g} ({result})"
        # Within 3 stated standard deviations (99.7 %): a single fit's check that cannot pass
        # by luck with a narrow error bar on a stuck value; the 95 % intervals' calibration is
        # tested over many records in test_fit_coverage.py.
        off = abs(math.log(value / truth))
        assert off <= 3.0 * sigma, f"{name}: {value:g} +- {sigma:.2%}, truth {truth:g}"


def test_the_fits_grid_makes_the_cost_smooth_along_w(record) -> None:
    """The cause of the stuck w: on the fit's one grid (`fit_grid`, sized from the deepest
    point and the box) the cost along a fine scan of w (steps of 1e-4 in log w, the old
    finite-difference step) has one minimum; the simulator's own domain, sized from each
    trial's w, changed sign 5 times over this scan in 0.1.0."""
    import dataclasses

    from viscoadh_ros.experiment import run_model
    from viscoadh_ros.fitting import fit_grid, smooth_samples, with_parameters

    contact = scene(TRUE).contacts[0]
    bounds = {n: (v / 10.0, v * 10.0) for n, v in TRUE.items()}
    domain, elements = fit_grid(contact, record, bounds)
    grid = dataclasses.replace(
        contact, numerics=dataclasses.replace(contact.numerics, domain_radius=domain, elements=elements)
    )
    keep = smooth_samples(record.measured_force)
    costs = []
    for w in TRUE["work_of_adhesion"] * np.exp(np.linspace(-0.003, 0.003, 61)):
        run = run_model(with_parameters(grid, {**TRUE, "work_of_adhesion": float(w)}, 1), record)
        costs.append(float(np.sum((run.model_force - record.measured_force)[keep] ** 2)))
    turns = int(np.count_nonzero(np.diff(np.sign(np.diff(costs)))))
    assert turns <= 2, f"the cost along w turns {turns} times: {np.round(np.array(costs) / min(costs), 5)}"
