"""`viscoadh bench` runs on tiny sizes and produces well-formed output (never a timing assert)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from viscoadh_ros.bench import accuracy, kernel, reference_stepper, report, suite
from viscoadh_ros.bench.latency import measure_round_trips, summarize_node_latency
from viscoadh_ros.bench.timing import interleaved_medians, latency_summary
from viscoadh_ros.cli.main import main as cli_main
from viscoadh_ros.core import _kernels
from viscoadh_ros.core.config import SceneConfig, default_scene_path
from viscoadh_ros.core.simulator import ContactSimulator

TINY = dataclasses.replace(
    suite.QUICK,
    kernel_elements=(32,),
    kernel_kelvin=(0, 1),
    kernel_steps=10,
    kernel_repeats=1,
    accuracy_elements=(16,),
    accuracy_rows=(51,),
    reference_elements=32,
    reference_rows=101,
    gripper_pads=(1,),
    gripper_seconds=0.01,
    accuracy_tolerances=(1e-2,),
)


def assert_finite_numbers(row: dict[str, Any], case: str) -> None:
    for key, value in row.items():
        if isinstance(value, float):
            assert math.isfinite(value), f"{case}: {key} = {value}"


def test_pareto_front_keeps_only_undominated_points() -> None:
    points = [
        {"us_per_step": 1.0, "rel_error": 0.1},
        {"us_per_step": 2.0, "rel_error": 0.2},  # dominated by the first
        {"us_per_step": 3.0, "rel_error": 0.01},
        {"us_per_step": 4.0, "rel_error": 0.01},  # same error, dearer
    ]
    assert accuracy.pareto_front(points) == [points[0], points[2]]


def test_timing_helpers_validate_and_summarise() -> None:
    assert set(interleaved_medians({"a": lambda: None, "b": lambda: None}, repeats=3)) == {"a", "b"}
    with pytest.raises(ValueError, match="repeats"):
        interleaved_medians({"a": lambda: None}, repeats=0)
    summary = latency_summary([1e-3] * 99 + [1e-2], prefix="x")
    np.testing.assert_allclose(summary["x_p50_ms"], 1.0, rtol=1e-12, err_msg="median of the sample")
    with pytest.raises(ValueError, match="no round trips"):
        latency_summary([], prefix="x")


def test_bare_loop_reads_and_writes_every_element_once_per_step() -> None:
    """The floor loop against a plain-numpy version of the same update."""
    rng = np.random.default_rng(1)
    wl, g_c, depth = rng.random((8, 3)), rng.random(8), rng.random(5)
    wsum = np.zeros(8)
    expected_wl = wl.copy()
    for d in depth:
        u = d - g_c
        expected_wl = 0.5 * expected_wl + 1e-3 * u[:, None]
        expected_wsum = expected_wl.sum(axis=1) + 1e-3 * u
    kernel._bare_steps(wl, wsum, g_c, depth)
    np.testing.assert_allclose(wl, expected_wl, rtol=1e-12, err_msg="bare loop state")
    np.testing.assert_allclose(wsum, expected_wsum, rtol=1e-12, err_msg="bare loop sums")


@pytest.mark.parametrize("kelvin", [0, 1, 4])
def test_kernel_row_is_well_formed(kelvin: int) -> None:
    row = kernel.measure_kernel(32, kelvin, steps=10, repeats=1)
    assert row["elements"] == 32 and row["kelvin"] == kelvin
    assert_finite_numbers(row, f"K={kelvin}")
    assert row["ns_per_element_step"] > 0 and row["baseline_ns_per_element_step"] > 0
    for ratio, over, under in (
        ("ratio", "ns_per_element_step", "baseline_ns_per_element_step"),
        ("python_ratio", "step_us", "minimal_step_us"),
        ("batch_ratio", "batch_us", "minimal_run_us"),
    ):
        np.testing.assert_allclose(
            row[ratio], row[over] / row[under], rtol=1e-12, err_msg=f"{ratio} of K={kelvin}"
        )
    assert row["substeps_per_step"] >= 1.0
    # The timed cycle is what the section says it is: ordinary in-contact steps (0.4.0: a K = 1
    # body let go of the indenter before the hold, and the cycle timed the re-contact).
    assert row["in_contact"] == 1.0, row
    # The minimal stepper computes the same model: its pull-off within a few percent even at
    # 32 elements (a baseline that computed something else would show here).
    assert row["pull_off_rel_diff"] < 0.05, row
    assert row["max_force_diff_rel"] < 0.2, row
    # Where a batch row goes: every part timed (no update without Kelvin elements).
    assert row["part_force_us"] > 0.0 and row["part_edge_us"] > 0.0
    assert (row["part_update_us"] > 0.0) == (kelvin > 0)
    assert math.isfinite(row["call_overhead_us"]) and math.isfinite(row["minimal_call_overhead_us"])


@pytest.mark.parametrize("kelvin", [1, 4])
def test_the_timed_parts_do_the_kernels_work(kelvin: int) -> None:
    """The part loops of the batch-row breakdown compute what the kernel computes (a loop
    that computed less would make a part look cheap): the update gives `_kelvin_update`'s
    memory bit for bit, the force and edge loops the kernel functions' own answers."""
    case = next(c for c in accuracy.cases() if c.name == "standard_solid_pull_off")
    material = kernel.kelvin_material(case, kelvin)
    contact = accuracy.contact_config(
        accuracy.Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": 96, "model": "time_stepped"},
    )
    sim = ContactSimulator(contact)
    for index, d in enumerate(np.linspace(0.0, 1.5, 60) * case.depth_scale):
        sim.step(index * kernel.STEP_S, depth=float(d))
    row, radius = sim._model.row, sim._model.radius
    depth = sim.output.depth * (1.0 + 0.01 * np.sin(np.arange(6.0)))
    wl0, wb0 = row.memory()
    runs = kernel._part_runs(row, radius, depth, float(sim.numerics.max_edge_cells * row.dx))
    runs["part_update"]()
    got = row.memory()
    row.set_memory(wl0, wb0)
    n_in = _kernels._interior_count(radius, row.dx, row.elements)
    for s in range(1, depth.size):
        _kernels._kelvin_update(
            row.wl, row.wsum, row.wb, row.bsum, row.diss, n_in, depth[s - 1], depth[s], kernel.STEP_S,
            row.g_c, row.p, row.p_inv, row.lam, row.beta, row.rate, row.e_kelvin, row.dx,
        )  # fmt: skip
    want = row.memory()
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    buf = np.empty(row.elements)
    # What both take after the radius and the depth(s): the row's memory, grid and modes.
    rest = (row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gint, row.df, row.e0, row.kap, buf)
    rest += (row.wb, row.p, row.p_inv, row.lam, row.beta)
    force = sum(_kernels._force(radius, d, *rest) for d in depth[1:])
    assert kernel._force_parts(radius, depth, *rest) == pytest.approx(force, rel=1e-14)
    edges = sum(
        _kernels._locate_edge(
            radius, d, row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.c_crit,
            row.reach, 1e-3,
        )[0]
        for d in depth[1:]
    )  # fmt: skip
    assert edges > 0.0
    assert kernel._edge_parts(
        radius, depth, row.wsum, row.bsum, row.dx, row.g_c, row.gf, row.gmin, row.gmax, row.df, row.c_crit,
        row.reach, 1e-3,
    ) == pytest.approx(edges, rel=1e-14)  # fmt: skip


def test_minimal_stepper_agrees_with_the_product_on_a_pull_off() -> None:
    """The bench's baseline is a stepper of the same model: on the product's own grid, its
    force along a press and pull-off from rest follows the product's (jump rows excluded)."""
    case = next(c for c in accuracy.cases() if c.name == "standard_solid_pull_off")
    contact = accuracy.contact_config(case, {"elements": 128, "model": "time_stepped", "domain_radius": 1e-3})
    sim = ContactSimulator(contact)
    row = sim._model._build_row(1e-3, None)
    model = sim._model
    minimal = reference_stepper.MinimalStepper(
        g_centres=row.g_c,
        dx=row.dx,
        e0=sim.physics.e0,
        e_kelvin=model.e_kelvin,
        eta_kelvin=model.e_kelvin / model.rate,
        c_crit=sim.physics.c_crit,
    )
    agreement = kernel._agreement(contact, row, minimal, case.depth_scale)
    assert agreement["pull_off_rel_diff"] < 0.01, agreement
    assert agreement["max_force_diff_rel"] < 0.05, agreement


@pytest.mark.parametrize("kelvin", [0, 1, 2, 4])
def test_minimal_stepper_is_the_plain_algorithm(kelvin: int) -> None:
    """The fast baseline (modal matrices, mode-major loops, two buffers, prefix sums, fastmath
    reassociation) computes what the plain element-by-element stepper computes, step for step:
    a press from rest, a pull-off past the fold, a re-contact and a creeping hold on the
    product's grid (radius and force; the force relative to the pull-off force)."""
    from plain_minimal_stepper import PlainMinimalStepper

    case = next(c for c in accuracy.cases() if c.name == "standard_solid_pull_off")
    material = kernel.kelvin_material(case, kelvin)
    contact = accuracy.contact_config(
        accuracy.Case(case.name, dict(case.contact, material=material), case.cycle_time, case.closed_form),
        {"elements": 96, "model": "time_stepped", "domain_radius": 1e-3},
    )
    sim = ContactSimulator(contact)
    sim.step(1e-3, depth=2.0 * case.depth_scale)
    fast = reference_stepper.MinimalStepper.on_grid_of(sim)
    plain = PlainMinimalStepper.on_grid_of(sim)
    scale = case.depth_scale
    depths = scale * np.concatenate(
        [
            np.linspace(0.0, 2.0, 61)[1:],
            np.linspace(2.0, -2.0, 200)[1:],
            np.linspace(-2.0, 1.5, 80)[1:],
            np.full(50, 1.5),
        ]
    )
    memory = np.zeros_like(sim._model.row.wl)
    forces, radii = [], []
    for stepper in (fast, plain):
        stepper.set_state(depth=0.0, radius=0.0, memory=memory)
        force = np.empty(depths.size)
        radius = np.empty(depths.size)
        for index, depth in enumerate(depths):
            # A step length that changes now and then: the fast stepper's cached matrices.
            force[index] = stepper.step(1e-3 if index % 7 else 2e-3, float(depth))
            radius[index] = stepper.radius
        forces.append(force)
        radii.append(radius)
    pull_off = abs(float(np.min(forces[1])))
    assert np.any(radii[1] > 0.0) and np.any(np.diff((radii[1] > 0.0).astype(int)) < 0), "no pull-off"
    np.testing.assert_allclose(radii[0], radii[1], rtol=1e-10, atol=1e-12 * sim._model.row.dx)
    assert np.max(np.abs(forces[0] - forces[1])) <= 1e-10 * pull_off
    # The batch entry point is the same stepper.
    fast.set_state(depth=0.0, radius=0.0, memory=memory)
    batch = fast.run(1e-3, depths)
    fast.set_state(depth=0.0, radius=0.0, memory=memory)
    single = np.array([fast.step(1e-3, float(d)) for d in depths])
    np.testing.assert_array_equal(batch, single)


def test_step_costs_names_the_jump_rows_and_the_ratios() -> None:
    costs = kernel.step_costs(repeats=1, seconds=1.0)
    assert_finite_numbers(costs, "step costs")
    large = costs["large"]
    assert large["elements"] == 8192 and large["rows"] == 120
    assert large["snap_in_row"] == 0 < large["pull_off_row"] < large["rows"]
    assert 0 < large["median_us"] <= large["max_us"]
    assert large["max_us"] >= max(large["snap_in_us"], large["pull_off_us"])
    np.testing.assert_allclose(large["max_over_median"], large["max_us"] / large["median_us"], rtol=1e-12)
    assert 0 < costs["snap_in_row"] < costs["pull_off_row"] < costs["rows"] == 1000
    assert 0 < costs["hold_pull_pull_off_row"] < costs["hold_pull_rows"]
    assert 0 <= costs["hold_pull_slowest_row"] < costs["hold_pull_rows"]
    for name in ("depth", "force", "hold_pull"):
        assert 0 < costs[f"{name}_median_us"] <= costs[f"{name}_p99_us"] <= costs[f"{name}_max_us"]
        np.testing.assert_allclose(
            costs[f"{name}_max_over_median"], costs[f"{name}_max_us"] / costs[f"{name}_median_us"], rtol=1e-12
        )
    np.testing.assert_allclose(
        costs["force_mean_ratio"], costs["force_mean_us"] / costs["depth_mean_us"], rtol=1e-12
    )
    # What the slowest row did: a depth step is one trial; every row runs the kernel at least
    # once in contact; a force row searches (at least one trial).
    assert costs["depth_median_trials"] == 1.0 and costs["depth_slowest_trials"] == 1
    for name in ("depth", "force", "hold_pull"):
        assert costs[f"{name}_slowest_trials"] >= 1 and costs[f"{name}_median_trials"] >= 1.0
        shares = [costs[f"{name}_rows_{n}_trial{'' if n == 'one' else 's'}"] for n in ("one", "two", "more")]
        assert sum(shares) == pytest.approx(1.0) and costs[f"{name}_p99_row_trials"] >= 1
        assert 0 <= costs[f"{name}_slowest_row"] < (costs["hold_pull_rows"] if name == "hold_pull" else 1000)
    assert costs["depth_rows_one_trial"] == 1.0
    assert large["max_row_substeps"] >= 1 and large["median_substeps"] >= 1.0


def test_row_work_counts_what_each_step_ran() -> None:
    """`kernel._row_work` (the bound section's cause column): a depth row is one trial, with
    no kernel substep while the indenter stays above an idle surface (after the first row's
    look for a touch) and at least one once it presses; a force row counts every depth its
    search tried (each a call of the model)."""
    contact = SceneConfig.from_yaml(default_scene_path()).contacts[0]
    times = kernel.STEP_S * np.arange(1, 41)
    depths = np.where(np.arange(40) < 20, -5e-6, 20e-6)
    trials, substeps = kernel._row_work(contact, times, depths, "depth")
    assert np.all(trials == 1)
    assert np.all(substeps[1:20] == 0) and np.all(substeps[20:] >= 1)
    forces = ContactSimulator(contact).step_depths(times, depths)["force"]
    trials, substeps = kernel._row_work(contact, times, forces, "force")
    calls: list[int] = []
    row_now = [0]
    sim = ContactSimulator(contact)
    advance = None
    for index in range(times.size):
        row_now[0] = index
        if sim._model is not advance:
            model = sim._model
            original = model.advance

            def counted(*args, _original=original):
                calls.append(row_now[0])
                return _original(*args)

            model.advance = counted
            advance = model
        sim.step(float(times[index]), force=float(forces[index]))
    assert np.array_equal(trials, np.bincount(calls, minlength=times.size))
    assert trials[20:].sum() > 20  # a force search tries more than one depth somewhere


def test_accuracy_cases_use_the_closed_forms() -> None:
    by_name = {case.name: case for case in accuracy.cases()}
    jkr = by_name["jkr_pull_off"]
    np.testing.assert_allclose(
        jkr.exact_pull_off,
        -1.5 * math.pi * accuracy.RADIUS * accuracy.WORK_OF_ADHESION,
        rtol=1e-12,
        err_msg="elastic JKR pull-off",
    )
    enhanced = (
        accuracy.WORK_OF_ADHESION
        * (accuracy.GLASS_MODULUS + accuracy.KELVIN_MODULUS)
        / accuracy.KELVIN_MODULUS
    )
    np.testing.assert_allclose(
        by_name["standard_solid_pull_off"].exact_pull_off,
        -1.5 * math.pi * accuracy.RADIUS * enhanced,
        rtol=1e-12,
        err_msg="standard-solid quasistatic pull-off with w_eff2",
    )
    assert by_name["rate_dependent"].exact_pull_off is None


def test_quick_cli_writes_json_report_and_figure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The verb end to end on tiny sizes: JSON keys, Markdown sections, figure file."""
    monkeypatch.setattr(suite, "QUICK", TINY)
    json_path, output = tmp_path / "out" / "results.json", tmp_path / "BENCH.md"
    status = cli_main(
        [
            "bench",
            "--quick",
            "--sections",
            "kernel,accuracy",
            "--json",
            str(json_path),
            "--output",
            str(output),
        ]
    )
    assert status == 0, capsys.readouterr().err
    results = json.loads(json_path.read_text())
    assert results["command"] == (
        f"viscoadh bench --quick --json {json_path} --output {output} --sections kernel,accuracy"
    )
    assert [(r["elements"], r["kelvin"]) for r in results["kernel"]] == [(32, 0), (32, 1)]
    assert {r["case"] for r in results["accuracy"]} == {c.name for c in accuracy.cases()}
    assert {r["preset"] for r in results["presets"]} == {"fast", "balanced", "accurate"}
    assert [(r["preset"], r["tolerance"]) for r in results["tolerance"]] == [("tolerance 0.01", 1e-2)] * 3
    viscous = {r["case"]: r["elements"] for r in results["tolerance"]}
    assert viscous["rate_dependent"] > viscous["jkr_pull_off"], "the elastic case resolves to fewer elements"
    for row in results["accuracy"] + results["presets"] + results["tolerance"]:
        assert set(row) >= {"preset", "elements", "time_step", "case", "rel_error", "us_per_step"}
        assert_finite_numbers(row, f"{row['case']} {row['preset']}")
        assert row["rel_error"] >= 0.0
    text = output.read_text()
    for heading in ("## Kernel", "## Accuracy", "## Fidelity presets", "## Tolerance mode", "## Stability"):
        assert heading in text, f"{heading} missing from the report"
    assert "](out/accuracy_pareto.png)" in text
    assert (tmp_path / "out" / "accuracy_pareto.png").stat().st_size > 0
    # Re-rendering from the JSON (after editing notes.md) measures nothing and keeps the tables.
    (tmp_path / "out" / "notes.md").write_text("## Notes\n\nA cause.\n")
    rendered = tmp_path / "RENDERED.md"
    assert cli_main(["bench", "--render", str(json_path), "--output", str(rendered)]) == 0
    assert rendered.read_text() == text.replace("## Kernel", "## Notes\n\nA cause.\n\n## Kernel", 1)


def test_sections_run_merges_into_the_existing_json(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A --sections run replaces only its sections and says which command measured what."""
    monkeypatch.setattr(suite, "QUICK", TINY)
    json_path, output = tmp_path / "results.json", tmp_path / "BENCH.md"

    def bench(sections: str) -> dict[str, Any]:
        argv = ["bench", "--quick", "--sections", sections, "--json", str(json_path), "--output", str(output)]
        assert cli_main(argv) == 0, capsys.readouterr().err
        return json.loads(json_path.read_text())

    first = bench("kernel")
    second = bench("accuracy")
    assert second["kernel"] == first["kernel"], "a run of accuracy must keep the kernel section"
    assert {r["preset"] for r in second["presets"]} == {"fast", "balanced", "accurate"}
    assert second["command"] == first["command"], "the header keeps the first run's command"
    assert {name: run["command"] for name, run in second["runs"].items()} == {
        "kernel": f"viscoadh bench --quick --json {json_path} --output {output} --sections kernel",
        "accuracy": f"viscoadh bench --quick --json {json_path} --output {output} --sections accuracy",
    }
    text = output.read_text()
    assert "## Kernel" in text and "## Accuracy" in text, "the report renders the merged results"
    assert f"- accuracy: `{second['runs']['accuracy']['command']}` on" in text
    assert "- kernel:" not in text, "the header's own run is not listed again"
    third = bench("kernel")
    assert len(third["kernel"]) == len(first["kernel"]), "a section is replaced, never appended"
    assert third["accuracy"] == second["accuracy"] and third["runs"]["accuracy"] == second["runs"]["accuracy"]


def test_gripper_section_times_both_paths_and_renders(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(suite, "QUICK", TINY)
    json_path, output = tmp_path / "results.json", tmp_path / "BENCH.md"
    argv = ["bench", "--quick", "--sections", "gripper", "--json", str(json_path), "--output", str(output)]
    assert cli_main(argv) == 0, capsys.readouterr().err
    (row,) = json.loads(json_path.read_text())["gripper"]
    assert row["pads"] == 1 and row["steps"] == 51 and row["part_mass_kg"] == 1e-3
    assert_finite_numbers(row, "gripper")
    for path in ("library", "node"):
        assert row[f"{path}_rtf"] == pytest.approx(row["sim_s"] / row[f"{path}_wall_s"])
    text = output.read_text()
    assert "## Gripper (MuJoCo cell)" in text
    assert "| 1 | 1 | 0.0102 |" in text


def test_merge_into_a_file_written_before_runs_existed() -> None:
    run = {"command": "viscoadh bench", "date": "d0", "machine": "m", "quick": False}
    old = {
        **run,
        "kernel": [1],
        "accuracy": [2],
        "presets": [3],
        "node": {"startup_s": 1.0},
        "startup_s": 1.0,
    }
    new_run = {**run, "command": "viscoadh bench --sections node", "date": "d1"}
    new = {**new_run, "node": {"startup_s": 2.0}, "startup_s": 2.0, "runs": {"node": new_run}}
    merged = suite.merge(old, new)
    assert merged["startup_s"] == 2.0 and merged["kernel"] == [1] and merged["presets"] == [3]
    assert merged["runs"] == {"kernel": run, "accuracy": run, "node": new_run}
    assert merged["command"] == "viscoadh bench", "a partial run leaves the header to the full one"


def test_a_bound_run_replaces_the_files_bound_figures(monkeypatch: pytest.MonkeyPatch) -> None:
    """The `bound` section writes `step_costs`, not a key named after it: its run must still be
    listed, or a merge keeps the file's old figures (0.5.0-0.6.0 did: BENCHMARKS.md showed a
    bound section from 2026-11-22 under two later releases' notes)."""
    monkeypatch.setattr(kernel, "step_costs", lambda repeats: {"rows": 7, "depth_max_over_median": 1.5})
    new = suite.run(
        suite.QUICK, sections=["bound"], soak_minutes=None, command="viscoadh bench", progress=print
    )
    assert set(new["runs"]) == {"bound"}
    run = {"command": "viscoadh bench --soak 10.0", "date": "d0", "machine": "m", "quick": False}
    old = {**run, "step_costs": {"rows": 3000, "depth_max_over_median": 19.5}, "runs": {"bound": run}}
    merged = suite.merge(old, new)
    assert merged["step_costs"] == {"rows": 7, "depth_max_over_median": 1.5}
    assert merged["runs"]["bound"]["date"] == new["date"]


def test_unreadable_json_stops_the_run_with_nothing_changed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    json_path = tmp_path / "results.json"
    json_path.write_text('{"kernel": []}')
    assert cli_main(["bench", "--quick", "--sections", "kernel", "--json", str(json_path)]) == 2
    assert "--json: cannot merge into" in capsys.readouterr().err
    assert json_path.read_text() == '{"kernel": []}'


def test_unknown_section_exits_2_with_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli_main(["bench", "--sections", "kernel,warp"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown warp" in err


def test_non_positive_soak_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as raised:
        cli_main(["bench", "--soak", "-1"])
    assert raised.value.code == 2
    assert "--soak must be > 0 minutes" in capsys.readouterr().err


def test_echo_round_trips_all_come_back(ros_env: dict[str, str]) -> None:
    """Echo server and client in child processes: every command's echo is matched by stamp."""
    trips = measure_round_trips(
        "echo",
        contact_ids=["a", "b"],
        duration_s=0.5,
        rate_hz=100.0,
        depth_amplitude=1e-5,
        domain_id=int(ros_env["ROS_DOMAIN_ID"]),
        warmup_s=0.2,
    )
    assert trips.latency_s.size == 100
    assert trips.dropped == 0, "echoes lost or mismatched"
    assert np.all(trips.latency_s > 0.0)
    assert np.all(np.diff(trips.send_time_s) >= 0.0)
    assert trips.startup_s > 0.0
    summary = summarize_node_latency(trips, trips, rate_hz=100.0)
    np.testing.assert_allclose(summary["p99_ratio"], 1.0, rtol=1e-12, err_msg="ratio of a run to itself")


def test_soak_on_the_node_reports_memory_drops_and_log(ros_env: dict[str, str]) -> None:
    """A tiny soak: the node in a child process with logging on answers with states."""
    from viscoadh_ros.bench.soak import soak

    result = soak(minutes=0.02, contacts=1, rate_hz=50.0, domain_id=int(ros_env["ROS_DOMAIN_ID"]))
    assert result["commands_sent"] == 60
    assert result["dropped"] < result["commands_sent"], "no state came back from the node"
    assert result["logged_commands"] >= result["commands_sent"] - result["dropped"]
    assert 0 <= result["dropped_before_node"] <= result["dropped"]
    assert result["rss_start_mb"] > 0.0
    assert_finite_numbers(result, "soak")


def test_soak_tells_commands_lost_before_the_node_from_answers_lost_after(tmp_path: Path) -> None:
    """Of the unanswered commands, those the node's log lacks never reached it; channels are
    matched by topic (two contacts may share a stamp), the stamps by header, not log time."""
    from viscoadh_msgs.msg import IndentationCommand

    from viscoadh_ros.bench.latency import RoundTrips
    from viscoadh_ros.bench.soak import lost_before_node
    from viscoadh_ros.io.mcap_log import McapRecorder

    ticks, channels = 50, ["a/indentation", "b/indentation"]
    stamps = np.repeat(1_000_000_000 + 7 * 10**9 * np.arange(ticks, dtype=np.int64), 2)  # both share
    never_logged = {(0, 3), (1, 3), (1, 40)}  # (channel, tick)
    recorder = McapRecorder(tmp_path / "log.mcap", scene={}, queue_size=4 * ticks)
    for tick in range(ticks):
        for channel, topic in enumerate(channels):
            if (channel, tick) in never_logged:
                continue
            command = IndentationCommand(mode=IndentationCommand.DEPTH, depth=1e-6)
            command.header.stamp.sec, command.header.stamp.nanosec = divmod(int(stamps[2 * tick]), 10**9)
            recorder.record(f"/{topic}", command, 5)  # log time unrelated to the stamp
    recorder.close()
    latency = np.full(2 * ticks, 1e-3)
    unanswered = [(0, 3), (1, 3), (1, 40), (0, 10), (1, 11), (0, 49)]  # the last three reached it
    for channel, tick in unanswered:
        latency[2 * tick + channel] = np.nan
    trips = RoundTrips(
        send_time_s=np.arange(2 * ticks) * 1e-3,
        send_lag_s=np.zeros(2 * ticks),
        latency_s=latency,
        startup_s=1.0,
        rss_time_s=np.zeros(0),
        rss_bytes=np.zeros(0),
        stamp_ns=stamps,
    )
    assert trips.dropped == 6
    assert lost_before_node(tmp_path / "log.mcap", trips, channels) == 3
    # The other channel order reads the wrong topic for each sample: the count changes.
    assert lost_before_node(tmp_path / "log.mcap", trips, channels[::-1]) != 3


def test_replay_speed_reports_stage_shares() -> None:
    from viscoadh_ros.bench.replay_speed import replay_benchmark

    result = replay_benchmark(seconds=0.1, repeats=1, long_seconds=0.3)
    assert result["commands"] == 100
    assert result["realtime_factor"] > 0.0
    assert set(result["time_share"]) == {"decode", "simulate", "encode and compare"}
    assert all(0.0 <= share <= 1.0 for share in result["time_share"].values())
    # The reachable floor: the minimal stepper over the same history, plus replay's own cost.
    assert result["minimal_us_per_command"] > 0.0
    assert 0.0 < result["floor_realtime_factor"] < float("inf")
    # A fresh process replays the same recording: slower than the warm run by its start-up.
    assert result["fresh_process_s"] > result["fresh_process_start_s"] >= 0.0
    assert result["fresh_process_realtime_factor"] == pytest.approx(
        result["recorded_s"] / result["fresh_process_s"]
    )
    from viscoadh_ros.bench.report import render_markdown

    text = render_markdown({"command": "c", "date": "d", "machine": "m", "replay": result}, None)
    assert "A fresh `viscoadh replay` process" in text
    # The longer recording: its own duration, and start-up's weight against length.
    long = result["fresh_process_long"]
    assert long["recorded_s"] == pytest.approx(3 * result["recorded_s"], rel=0.02)
    assert long["realtime_factor"] == pytest.approx(long["recorded_s"] / long["wall_s"])
    assert result["start_up_half_s"] == pytest.approx(
        result["fresh_process_start_s"] * result["recorded_s"] / result["wall_s"]
    )
    assert f"On a {long['recorded_s']:.3g} s recording a fresh process took" in text
    assert "Start-up is paid once per process" in text
    del result["fresh_process_s"]  # results of an older run: rendered without the line
    older = render_markdown({"command": "c", "date": "d", "machine": "m", "replay": result}, None)
    assert "Start-up is paid once" not in older
    assert "A fresh" not in render_markdown(
        {"command": "c", "date": "d", "machine": "m", "replay": result}, None
    )


def test_report_marks_targets() -> None:
    """Rendering alone, on results shaped like a run's: targets met and missed are marked."""
    results = {
        "command": "viscoadh bench",
        "date": "today",
        "machine": "test",
        "node": {
            "contacts": 4,
            "rate_hz": 1000.0,
            "duration_s": 30.0,
            "latency_p50_ms": 1.0,
            "latency_p99_ms": 2.0,
            "latency_p999_ms": 3.0,
            "echo_p50_ms": 0.5,
            "echo_p99_ms": 1.0,
            "echo_p999_ms": 2.0,
            "p99_ratio": 2.0,
            "deadline_miss_fraction": 0.5,
            "echo_deadline_miss_fraction": 0.0,
            "dropped": 3,
            "echo_dropped": 0,
            "client_send_lag_p99_ms": 0.1,
            "startup_s": 1.0,
            "echo_startup_s": 0.5,
            "commands_sent": 100,
        },
    }
    text = report.render_markdown(results, None)
    assert "p99 ratio 2 (target <= 1.25): **missed**" in text


def test_contacts_out_of_range_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as raised:
        cli_main(["bench", "--contacts", "0"])
    assert raised.value.code == 2
    assert "--contacts must be in 1..256" in capsys.readouterr().err


def test_hand_round_trips_are_one_per_tick(ros_env: dict[str, str]) -> None:
    """Hand mode: one HandCommand for every contact per tick, echoed back on hand/echo."""
    trips = measure_round_trips(
        "echo",
        contact_ids=["a", "b", "c"],
        duration_s=0.5,
        rate_hz=100.0,
        depth_amplitude=1e-5,
        domain_id=int(ros_env["ROS_DOMAIN_ID"]),
        warmup_s=0.2,
        hand=True,
    )
    assert trips.latency_s.size == 50, "one round trip per tick, not per contact"
    assert trips.dropped == 0, "hand echoes lost or mismatched"
