"""BENCHMARKS.md and its figure from the results dictionary of one `viscoadh bench` run."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from viscoadh_ros.bench.accuracy import pareto_front

# Targets of issue 6, stated once: the report marks each measured number against them.
KERNEL_RATIO_TARGET = 2.0  # product step / minimal stepper, from Python and in batch
STEP_BOUND_TARGET = 20.0  # largest step / median step of the scene
FORCE_CONTROL_TARGET = 3.0  # force-control step / depth-control step, mean and p99
P99_RATIO_TARGET = 1.25
DEADLINE_MISS_TARGET = 1e-3
REPLAY_FACTOR_TARGET = 500.0
SOAK_MEMORY_GROWTH_TARGET = 0.05
SOAK_P99_DRIFT_TARGET = 0.10
# Targets of issue 12 for the fit: wall time per fit on one core.
FIT_SECONDS_TARGET = {1: 5.0, 2: 10.0}

# What the stability property tests (tests/test_stability_*.py) cover; the bench does not run
# them, the test suite does, so this table describes the suite rather than measuring it.
#: Written by `python benchmarks/convergence.py` (minutes; not a `viscoadh bench` section):
#: copied into BENCHMARKS.md as its last section.
CONVERGENCE_REPORT = Path(__file__).resolve().parents[2] / "benchmarks" / "convergence.md"

STABILITY_COVERAGE = (
    (
        "huge G0/G1 with tiny tau",
        "G0/G1 up to 1e6, tau down to 1e-6 s, steps up to 1 s",
        "finite output, force within the glass and relaxed elastic bounds",
    ),
    (
        "coarse steps",
        "steps from 1e-6 s to 1 s against tau from 1e-6 s to 1e4 s",
        "finite output, no sign-alternating force (no oscillation)",
    ),
    (
        "sudden depth jumps",
        "step changes of depth in and out of contact",
        "finite output, dissipation never negative and never decreasing",
    ),
    (
        "force control at pull-off",
        "force held at and just beyond the pull-off force",
        "instability reported (`unstable`), no NaN, no divergence",
    ),
    (
        "convergence with refinement",
        "elements and steps halved",
        "pull-off force error shrinks toward the closed form",
    ),
    (
        "every regime of a press and pull",
        "creep times 1e-6..1e8 s against histories 1e-3..1e3 s, G0/G1 up to 1e4, 0.5..1000 d_c",
        "finite output, lets go, dissipation >= 0 and never decreasing, pull-off within JKR bounds",
    ),
)


def _mark(ok: bool) -> str:
    return "met" if ok else "**missed**"


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return lines


def _g(value: float) -> str:
    return f"{value:.3g}"


def _row_work(costs: dict[str, Any], name: str) -> str:
    """The slowest row of a bound-section run and what it did, against the median row
    (results from before 0.7.0 lack the counts)."""
    if f"{name}_slowest_trials" not in costs:
        return "-"
    return (
        f"row {costs[f'{name}_slowest_row']}: {costs[f'{name}_slowest_trials']}, "
        f"{costs[f'{name}_slowest_substeps']} ({_g(costs[f'{name}_median_trials'])}, "
        f"{_g(costs[f'{name}_median_substeps'])})"
    )


def _median(values: list[float]) -> float:
    ordered = sorted(values)
    if not ordered:
        return math.nan
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else 0.5 * (ordered[mid - 1] + ordered[mid])


def fit_section(fit: dict[str, Any]) -> list[str]:
    """The fit section: recovery, interval coverage and time per fit against issue 12's targets."""
    lines = [
        "## Fit",
        "",
        f"Records by an independent model run (`accurate` preset) plus {fit['noise']:.0%} noise; fits "
        "(every parameter free; coarse stage on the start's `fast` preset, polish on the element count "
        "the record's noise calls for, `fitting.polish_elements`) from the truth times a seeded factor "
        "in 1/3..3 per parameter (`viscoadh_ros/bench/fit_speed.py`). Recovered: every parameter within "
        f"{fit['recovery']:.0%}. Covered: truth within the stated 95 % interval, per parameter. "
        "CPU time is the process's own (the wall time counts what other processes took).",
        "",
    ]
    rows = []
    for name, case in fit["cases"].items():
        target = FIT_SECONDS_TARGET.get(case["kelvin"], math.nan)
        rows.append(
            [
                f"{name} (K = {case['kelvin']})",
                str(case["samples"]),
                f"{case['recovered']}/{len(case['fits'])}",
                f"{case['covered']}/{case['checks']}",
                _g(_median([f["rmse_over_noise"] for f in case["fits"] if "rmse_over_noise" in f])),
                _g(case["median_model_runs"]),
                _g(case["median_wall_s"]),
                _g(case["median_cpu_s"]),
                f"{target:g} s: {_mark(case['median_cpu_s'] <= target)}",
            ]
        )
    header = ["case", "samples", "recovered", "covered", "RMSE/noise", "model runs", "wall s", "CPU s"]
    lines += _table([*header, "target (CPU)"], rows)
    missed = [
        (name, f)
        for name, case in fit["cases"].items()
        for f in case["fits"]
        if f["status"] != "failed" and not f.get("recovered")
    ]
    if missed:
        lines += ["", "Fits that reported but missed the truth by more than the recovery bound:", ""]
        lines += [
            f"- {name}, RMSE/noise {_g(f['rmse_over_noise'])}, errors "
            + ", ".join(f"{n} {e:+.1%}" for n, e in f["errors"].items())
            + f", {f['covered']} of {len(f['errors'])} truths inside the stated 95 % interval"
            + (", flagged `misfit` (correlated residuals)" if f["status"] == "misfit" else ", status ok")
            for name, f in missed
        ]
    failed = [
        (name, f) for name, case in fit["cases"].items() for f in case["fits"] if f["status"] == "failed"
    ]
    if failed:
        lines += ["", "Fits that refused to report (not converged, never a false success):", ""]
        lines += [f"- {name}, CPU {_g(f['cpu_s'])} s: {f['reason']}" for name, f in failed]
    return lines + [""]


def accuracy_figure(results: dict[str, Any], path: Path) -> None:
    """Error against cost per case on shared log axes: the grid over elements and steps (grey),
    its Pareto front (line), the presets (stars) and the tolerance mode (diamonds, with the
    requested tolerance drawn as a dotted level), each labelled (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    floor = 1e-9
    case_names = sorted({point["case"] for point in results["accuracy"]})
    fig, axes = plt.subplots(
        1, len(case_names), figsize=(5.4 * len(case_names), 5.2), squeeze=False, sharey=True
    )
    for axis, name in zip(axes[0], case_names, strict=True):
        points = [p for p in results["accuracy"] if p["case"] == name]
        axis.scatter(
            [p["us_per_step"] for p in points],
            [max(p["rel_error"], floor) for p in points],
            s=14,
            color="0.65",
            label="elements x step grid",
        )
        front = pareto_front(points)
        axis.plot(
            [p["us_per_step"] for p in front],
            [max(p["rel_error"], floor) for p in front],
            "-",
            color="tab:blue",
            linewidth=1.2,
            label="Pareto front of the grid",
        )
        presets = [p for p in results.get("presets", []) if p["case"] == name]
        tolerance = [p for p in results.get("tolerance", []) if p["case"] == name]
        for group, marker, color, label in (
            (presets, "*", "tab:orange", "preset"),
            (tolerance, "D", "tab:green", "numerics.tolerance"),
        ):
            if not group:
                continue
            axis.scatter(
                [p["us_per_step"] for p in group],
                [max(p["rel_error"], floor) for p in group],
                marker=marker,
                s=150 if marker == "*" else 60,
                color=color,
                edgecolor="black",
                linewidth=0.5,
                zorder=3,
                label=label,
            )
            for point in group:
                text = point["preset"].replace("tolerance ", "tol ") + f" ({point['elements']})"
                # presets labelled above-left, tolerances below-right: they sit close together
                axis.annotate(
                    text,
                    (point["us_per_step"], max(point["rel_error"], floor)),
                    textcoords="offset points",
                    xytext=(7, -11) if marker == "D" else (-7, 7),
                    ha="left" if marker == "D" else "right",
                    fontsize=8,
                    color="darkgreen" if marker == "D" else "saddlebrown",
                )
        for point in tolerance:
            axis.axhline(point["tolerance"], color="tab:green", linestyle=":", linewidth=0.8, alpha=0.6)
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.margins(x=0.2)  # room for the labels of the cheapest and dearest points
        axis.set_xlabel("cost per history row (us)")
        axis.set_title(name.replace("_", " "))
        axis.grid(True, which="both", alpha=0.25)
    axes[0][0].set_ylabel("relative error of the pull-off force")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=9, frameon=False)
    fig.suptitle(
        "Error against cost: presets and numerics.tolerance, labelled with their element counts "
        "(dotted: the tolerance asked, a bound on the force error relative to the pull-off force)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0.0, 0.06, 1.0, 1.0))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def render_markdown(results: dict[str, Any], figure: Path | None, notes: str | None = None) -> str:
    """The whole BENCHMARKS.md text for one results dictionary (sections that ran only).

    notes: hand-written analysis (causes of missed targets), placed after the header verbatim,
    so it survives regenerating the tables.
    """
    lines = [
        "# Benchmarks",
        "",
        "Measured on this machine by the command below; every timing sits beside its baseline",
        "from the same run and is a median of repeats. Regenerate with the same command.",
        "",
        f"    {results['command']}",
        "",
        f"Date: {results['date']}. Machine: {results['machine']}.",
        "",
    ]
    header_run = (results["command"], results["date"])
    later = {
        name: run
        for name, run in results.get("runs", {}).items()
        if (run["command"], run["date"]) != header_run
    }
    if later:
        lines += ["Sections measured by another command (merged into the results JSON):", ""]
        lines += [
            f"- {name}: `{run['command']}` on {run['date']}"
            + (" (quick sizes)" if run["quick"] else "")
            + (f", machine: {run['machine']}" if run["machine"] != results["machine"] else "")
            for name, run in later.items()
        ]
        lines.append("")
    if notes:
        lines += [notes.strip(), ""]
    if "kernel" in results:
        lines += [
            "## Kernel against a minimal stepper of the same model",
            "",
            "Per step of a 1 kHz depth cycle (standard solid, contact open, edge moving), side by",
            "side in one run: the product against `bench.reference_stepper.MinimalStepper` on the",
            "same grid from the same state. Target: ratio <= "
            f"{KERNEL_RATIO_TARGET:g} from Python (`step` per call) and in batch (`step_depths`",
            "against `MinimalStepper.run`). The minimal stepper's agreement with the product on a",
            "pull-off from the same state: pull-off relative difference, and the largest force",
            "difference relative to the pull-off force (jump rows excluded).",
            "",
        ]
        # Results from before issue 13 lack the minimal stepper: their cells read nan.
        nan = float("nan")
        rows = []
        for item in results["kernel"]:
            rows.append(
                [
                    str(item["elements"]),
                    str(item["kelvin"]),
                    _g(item.get("step_us", nan)),
                    _g(item.get("minimal_step_us", nan)),
                    _g(item.get("python_ratio", nan)),
                    _mark(item.get("python_ratio", nan) <= KERNEL_RATIO_TARGET),
                    _g(item.get("batch_us", nan)),
                    _g(item.get("minimal_run_us", nan)),
                    _g(item.get("batch_ratio", nan)),
                    _mark(item.get("batch_ratio", nan) <= KERNEL_RATIO_TARGET),
                    _g(item.get("pull_off_rel_diff", nan)),
                    _g(item.get("max_force_diff_rel", nan)),
                    _g(item["substeps_per_step"]),
                    _g(item.get("in_contact", nan)),
                ]
            )
        header = [
            "N",
            "K",
            "step() us",
            "minimal step us",
            "ratio",
            "target",
            "step_depths us",
            "minimal run us",
            "ratio",
            "target",
            "pull-off diff",
            "max dF / F_po",
            "substeps",
            "in contact",
        ]
        lines += _table(header, rows)
        lines += [
            "",
            "The memory floor: ns per element step of the product's compiled kernel alone, of the",
            "minimal stepper's compiled run and of a bare loop that only reads and writes the",
            "state arrays once per step (no stepper reaches it).",
            "",
        ]
        rows = [
            [
                str(item["elements"]),
                str(item["kelvin"]),
                _g(item["ns_per_element_step"]),
                _g(item.get("minimal_ns_per_element_step", float("nan"))),
                _g(item["baseline_ns_per_element_step"]),
                _g(item["ratio"]),
            ]
            for item in results["kernel"]
        ]
        lines += _table(["N", "K", "kernel ns", "minimal ns", "bare loop ns", "kernel / bare"], rows)
        parted = [item for item in results["kernel"] if "part_force_us" in item]
        if parted:
            lines += [
                "",
                "Where a batch row goes (the measured cause of a missed batch target): each part of",
                "the kernel's row timed alone on the same row and history (`bench.kernel._part_runs`),",
                "us per row: the Kelvin update of every element (the A and B states, the damper work,",
                "the losses and the memory peak; none at K = 0), the force (its memory integral) and",
                "the edge search; `rest` is the batch row less those parts (extra substeps, retiming,",
                "outputs, the Python of `step_depths` per call). `update / minimal`: the update alone",
                "against the minimal stepper's whole row; where a part alone exceeds the target ratio,",
                "the target is out of reach without dropping that part's work. `per call`: what a",
                "`step()` call costs beyond its row (`step()` less `step_depths` over the same",
                "stretch: the Python around the kernel, the compiled call, the journal), beside the",
                "minimal stepper's (its `step` less its `run`): the cause of a missed per-call ratio",
                "where the rows are within reach.",
                "",
            ]
            rows = []
            for item in parted:
                parts = item["part_update_us"] + item["part_force_us"] + item["part_edge_us"]
                rows.append(
                    [
                        str(item["elements"]),
                        str(item["kelvin"]),
                        _g(item["batch_us"]),
                        _g(item["part_update_us"]),
                        _g(item["part_force_us"]),
                        _g(item["part_edge_us"]),
                        _g(item["batch_us"] - parts),
                        _g(item["substeps_per_step"]),
                        _g(item["minimal_run_us"]),
                        _g(item["part_update_us"] / item["minimal_run_us"]),
                        _g(item["part_force_us"] / item["minimal_run_us"]),
                        _g(item.get("call_overhead_us", float("nan"))),
                        _g(item.get("minimal_call_overhead_us", float("nan"))),
                    ]
                )
            header = [
                "N",
                "K",
                "step_depths us",
                "update us",
                "force us",
                "edge us",
                "rest us",
                "substeps",
                "minimal run us",
                "update / minimal",
                "force / minimal",
                "per call us",
                "minimal per call us",
            ]
            lines += _table(header, rows)
        lines += [
            "",
            "`substeps`: the kernel's adaptive substeps per 1 ms step; `in contact`: the fraction",
            "of the timed rows in contact (the cycle starts after a hold that relaxes the memory,",
            "so 1 means every timed step is an ordinary in-contact step).",
            "",
        ]
    if "step_costs" in results:
        costs = results["step_costs"]
        bound = STEP_BOUND_TARGET
        lines += [
            "## Every step bounded",
            "",
            f"`ContactSimulator.step` per call on the default scene ({costs['rows']} rows at 1 kHz: a sine",
            "press with snap-in, sticking, pull-off and memory left out of contact), per row the",
            f"median of the runs. Targets: no step above {bound:g}x the median step; force control",
            f"within {FORCE_CONTROL_TARGET:g}x depth control (mean and p99).",
            "",
        ]
        rows = [
            [
                name,
                _g(costs[f"{name}_median_us"]),
                _g(costs[f"{name}_mean_us"]),
                _g(costs[f"{name}_p99_us"]),
                _g(costs[f"{name}_max_us"]),
                _g(costs[f"{name}_max_over_median"]),
                _mark(costs[f"{name}_max_over_median"] <= bound),
                _row_work(costs, name),
            ]
            for name in ("depth", "force", "hold_pull")
            if f"{name}_median_us" in costs
        ]
        lines += _table(
            [
                "control",
                "median us",
                "mean us",
                "p99 us",
                "max us",
                "max / median",
                "target",
                "slowest row: trials, substeps (median row)",
            ],
            rows,
        )
        for name in ("force", "hold_pull"):
            if f"{name}_rows_one_trial" in costs:
                lines += [
                    "",
                    f"`{name}` rows by model trials: one {_g(100 * costs[f'{name}_rows_one_trial'])} %, two "
                    f"{_g(100 * costs[f'{name}_rows_two_trials'])} %, three or more "
                    f"{_g(100 * costs[f'{name}_rows_more_trials'])} %; the row at its p99 ran "
                    f"{costs[f'{name}_p99_row_trials']} trials "
                    f"({costs[f'{name}_p99_row_substeps']} substeps).",
                ]
        lines += [
            "",
            f"Snap-in row {costs['snap_in_row']}: {_g(costs['snap_in_us'])} us; pull-off row "
            f"{costs['pull_off_row']}: {_g(costs['pull_off_us'])} us. Force control / depth control: "
            f"mean {_g(costs['force_mean_ratio'])} "
            f"{_mark(costs['force_mean_ratio'] <= FORCE_CONTROL_TARGET)}, p99 "
            f"{_g(costs['force_p99_ratio'])} {_mark(costs['force_p99_ratio'] <= FORCE_CONTROL_TARGET)}.",
            "",
        ]
        if "hold_pull_rows" in costs:
            lines += [
                f"`hold_pull`: force control through a gripper's press, hold, pull until it lets go "
                f"(row {costs['hold_pull_pull_off_row']}), pulled on while the surface creeps back, "
                f"then touch again ({costs['hold_pull_rows']} rows at 1 kHz); its slowest row: "
                f"{costs['hold_pull_slowest_row']}.",
                "",
            ]
        large = costs.get("large")
        if large:
            lines += [
                f"Large-N scene (what `numerics.tolerance` 1e-4 picks for a two-mode standard solid: "
                f"{large['elements']} elements; {large['rows']} rows at 1 kHz: pressed from rest at 1 mm/s,",
                "held, pulled off, held; depth control): median "
                f"{_g(large['median_us'])} us, largest row {large['max_row']} {_g(large['max_us'])} us = "
                f"{_g(large['max_over_median'])}x {_mark(large['max_over_median'] <= bound)}; snap-in row "
                f"{large['snap_in_row']} {_g(large['snap_in_over_median'])}x, pull-off row "
                f"{large['pull_off_row']} {_g(large['pull_off_over_median'])}x the median"
                + (
                    f"; the largest row ran {large['max_row_substeps']} kernel substeps (the median row "
                    f"{_g(large['median_substeps'])})."
                    if "max_row_substeps" in large
                    else "."
                ),
                "",
            ]
    if "accuracy" in results:
        lines += [
            "## Accuracy against cost",
            "",
            "Pull-off force error over element counts and history steps (see",
            "`viscoadh_ros/bench/accuracy.py` for the cases). Pareto front per case:",
            "",
        ]
        if figure is not None:
            lines += [f"![error against cost]({figure.as_posix()})", ""]
        rows = []
        for name in sorted({p["case"] for p in results["accuracy"]}):
            for point in pareto_front(p for p in results["accuracy"] if p["case"] == name):
                rows.append(
                    [
                        name,
                        point["preset"],
                        str(point["elements"]),
                        _g(point["time_step"]),
                        _g(point["rel_error"]),
                        _g(point["us_per_step"]),
                    ]
                )
        lines += _table(["case", "preset", "elements", "step (s)", "rel. error", "us/step"], rows)
        lines += [""]
        jkr = [p for p in results["accuracy"] if p["case"] == "jkr_pull_off"]
        for limit, tolerance in ((256, 1e-3), (64, 1e-2)):
            best = min((p["rel_error"] for p in jkr if p["elements"] <= limit), default=None)
            if best is not None:
                lines.append(
                    f"- JKR pull-off with <= {limit} elements: best error {_g(best)} "
                    f"(target <= {tolerance:g}): {_mark(best <= tolerance)}"
                )
        lines += [""]
    if "presets" in results:
        lines += [
            "## Fidelity presets",
            "",
            "`numerics.preset` in the scene; each preset's own element count and steps, on the",
            "reference run's history rows (a pull-off sampled by coarser rows than the reference's",
            "differs from it by the sampling, which no numerics setting refines).",
            "",
        ]
        rows = [
            [
                p["preset"],
                p["case"],
                str(p["elements"]),
                _g(p["time_step"]),
                _g(p["rel_error"]),
                _g(p["us_per_step"]),
            ]
            for p in results["presets"]
        ]
        lines += _table(["preset", "case", "elements", "step (s)", "rel. error", "us/step"], rows)
        lines += [""]
    if "tolerance" in results:
        lines += [
            "## Tolerance mode",
            "",
            "`numerics.tolerance` in the scene (no `time_scale`): the element count it resolves for",
            "each case and what that gives, beside the presets above (same cases, rows and figure).",
            "The tolerance bounds the largest force error relative to the pull-off force",
            "(docs/configuration.md); here only the pull-off is measured.",
            "",
        ]
        rows = [
            [
                _g(p["tolerance"]),
                p["case"],
                str(p["elements"]),
                _g(p["rel_error"]),
                _mark(p["rel_error"] <= p["tolerance"]),
                _g(p["us_per_step"]),
            ]
            for p in results["tolerance"]
        ]
        lines += _table(["tolerance", "case", "elements", "rel. error", "met", "us/step"], rows)
        lines += [""]
    if "node" in results:
        node = results["node"]
        lines += [
            "## Node round trip through DDS",
            "",
            f"{node['contacts']} contacts at {node['rate_hz']:g} Hz for {node['duration_s']:g} s"
            " each, client in its own process; the echo node republishes each command."
            + (" One HandCommand for every contact per tick (hand topics)." if node.get("hand") else "")
            + (" The node writes its MCAP log." if node.get("log") else ""),
            "",
        ]
        lines += _table(
            ["", "p50 ms", "p99 ms", "p99.9 ms", "deadline misses", "dropped", "start-up s"],
            [
                [
                    "node",
                    _g(node["latency_p50_ms"]),
                    _g(node["latency_p99_ms"]),
                    _g(node["latency_p999_ms"]),
                    _g(node["deadline_miss_fraction"]),
                    str(node["dropped"]),
                    _g(node["startup_s"]),
                ],
                [
                    "echo",
                    _g(node["echo_p50_ms"]),
                    _g(node["echo_p99_ms"]),
                    _g(node["echo_p999_ms"]),
                    _g(node["echo_deadline_miss_fraction"]),
                    str(node["echo_dropped"]),
                    _g(node["echo_startup_s"]),
                ],
            ],
        )
        misses, echo_misses = node["deadline_miss_fraction"], node["echo_deadline_miss_fraction"]
        lines += [
            "",
            f"- p99 ratio {_g(node['p99_ratio'])} (target <= {P99_RATIO_TARGET:g}): "
            f"{_mark(node['p99_ratio'] <= P99_RATIO_TARGET)}",
            f"- deadline misses {_g(node['deadline_miss_fraction'])} against the echo's "
            f"{_g(node['echo_deadline_miss_fraction'])}: at most {DEADLINE_MISS_TARGET:g} more than the "
            "echo's (issue 13): "
            f"{_mark(misses <= echo_misses + DEADLINE_MISS_TARGET)}"
            f"; below {DEADLINE_MISS_TARGET:g} (issue 6, which the machine's own echo node "
            f"{'meets' if echo_misses < DEADLINE_MISS_TARGET else 'misses too'}): "
            f"{_mark(misses < DEADLINE_MISS_TARGET)}",
            f"- client's own send lag p99: {_g(node['client_send_lag_p99_ms'])} ms",
            "",
        ]
    if "replay" in results:
        replay = results["replay"]
        lines += [
            "## Replay speed",
            "",
            f"{replay['commands']} commands at 1 kHz with default numerics: realtime factor "
            f"{_g(replay['realtime_factor'])} (target >= {REPLAY_FACTOR_TARGET:g}): "
            f"{_mark(replay['realtime_factor'] >= REPLAY_FACTOR_TARGET)}.",
            "",
        ]
        if "non_simulation_us_per_command" in replay:
            lines += [
                f"Per command: {_g(replay['us_per_command'])} us in all; simulate "
                f"{_g(replay['simulate_us_per_command'])} us inside the verb (`step_depths` alone over "
                f"the same depth history {_g(replay['step_depths_us_per_command'])} us); everything "
                f"else (read, decode, compare, encode, write, the Python around the simulator) "
                f"{_g(replay['non_simulation_us_per_command'])} us.",
                "",
            ]
        if "minimal_us_per_command" in replay:
            lines += [
                f"The floor at these numerics: the bench's minimal compiled stepper "
                f"(`bench.reference_stepper.MinimalStepper`) over the same history on the product's "
                f"grid costs {_g(replay['minimal_us_per_command'])} us per command, so a replay with "
                f"that stepper and this run's non-simulation cost would reach "
                f"{_g(replay['floor_realtime_factor'])}x real time.",
                "",
            ]
        if "fresh_process_s" in replay:
            lines += [
                f"Those runs are warm (one process, imports and compiled code loaded before the "
                f"timing). A fresh `viscoadh replay` process, what a user waits for, took "
                f"{_g(replay['fresh_process_s'])} s from start to exit on the same recording: "
                f"{_g(replay['fresh_process_realtime_factor'])}x real time, of which "
                f"{_g(replay['fresh_process_start_s'])} s is start-up (interpreter, imports, the "
                f"numba cache load) that the warm figure leaves out.",
                "",
            ]
        if "fresh_process_s" in replay and "start_up_half_s" in replay:
            long_text = ""
            if "fresh_process_long" in replay:
                long = replay["fresh_process_long"]
                long_text = (
                    f" On a {_g(long['recorded_s'])} s recording a fresh process took "
                    f"{_g(long['wall_s'])} s: {_g(long['realtime_factor'])}x real time."
                )
            lines += [
                f"Start-up is paid once per process: it is half of a fresh run on a recording of "
                f"about {_g(replay['start_up_half_s'])} s, and the fresh factor approaches the warm "
                f"one on recordings well beyond that.{long_text}",
                "",
            ]
        lines += _table(
            ["stage", "share of time"],
            [[stage, f"{share:.1%}"] for stage, share in replay["time_share"].items()],
        )
        lines += [""]
    if "batch" in results:
        run = results["batch"]
        lines += [
            "## Batch throughput (replay on a local Dask cluster)",
            "",
            f"`viscoadh replay 'archive/*.mcap' -o OUT --workers N` over {run['bags']} node logs of "
            f"{_g(run['seconds_per_bag'])} s of 1 kHz commands each; wall time includes starting the "
            "cluster (its own column: an empty cluster started and stopped).",
            "",
        ]
        lines += _table(
            ["workers", "bags", "wall s", "bags/minute", "cluster start s", "load average before"],
            [
                [
                    str(r["workers"]),
                    str(r["bags"]),
                    _g(r["wall_s"]),
                    _g(r["bags_per_minute"]),
                    _g(r["cluster_start_s"]),
                    _g(r.get("load_average_1min", float("nan"))),
                ]
                for r in run["rows"]
            ],
        )
        lines += [""]
    if "gripper" in results:
        rows = results["gripper"]
        lines += [
            "## Gripper (MuJoCo cell)",
            "",
            "Real-time factor (simulated time / wall time; above 1 is faster than real time) of "
            "`viscoadh gripper`'s cell: the start of the standard pick (approach, press, hold) at "
            f"its {rows[0]['steps'] / rows[0]['sim_s']:.0f} Hz physics step, a part of 1 g per pad "
            "(stable at that step), library path and node path (the in-process node over DDS, "
            "lockstep on /clock) run alternately in one process.",
            "",
        ]
        lines += _table(
            ["pads", "part (g)", "simulated (s)", "library RTF", "node RTF", "library / node"],
            [
                [
                    str(row["pads"]),
                    f"{row['part_mass_kg'] * 1e3:g}",
                    f"{row['sim_s']:.3g}",
                    _g(row["library_rtf"]),
                    _g(row["node_rtf"]),
                    f"{row['library_rtf'] / row['node_rtf']:.0f}x",
                ]
                for row in rows
            ],
        )
        lines += [""]
    if "fit" in results:
        lines += fit_section(results["fit"])
    if "soak" in results:
        soak = results["soak"]
        lines += [
            "## Soak",
            "",
            f"Node under {soak['rate_hz']:g} Hz on {soak['contacts']} contacts with logging on "
            f"for {soak['minutes']:g} min"
            + (
                " by the hand topic (one HandCommand for every contact per tick: a command below is a tick)."
                if soak.get("hand")
                else "."
            ),
            "",
            f"- memory growth {soak['memory_growth']:.2%} (target < "
            f"{SOAK_MEMORY_GROWTH_TARGET:.0%}): {_mark(soak['memory_growth'] < SOAK_MEMORY_GROWTH_TARGET)}",
            f"- dropped {soak['dropped']} of {soak['commands_sent']}: {_mark(soak['dropped'] == 0)}"
            + (
                f" ({soak['dropped_before_node']} never reached the node: not in its log; the "
                f"others' answers were lost on the way back)"
                if "dropped_before_node" in soak and soak["dropped"]
                else ""
            ),
            f"- p99 drift {soak['p99_drift']:.2%} (target < {SOAK_P99_DRIFT_TARGET:.0%}): "
            f"{_mark(abs(soak['p99_drift']) < SOAK_P99_DRIFT_TARGET)}",
        ]
        if "echo_p99_ms" in soak:
            # The echo node under the same load for as long, right after (same run).
            lines += [
                f"- p99 of the answered commands {_g(soak['p99_ms'])} ms against the echo node's "
                f"{_g(soak['echo_p99_ms'])} ms: ratio {_g(soak['p99_ratio'])} (target <= "
                f"{P99_RATIO_TARGET:g}, nothing dropped): "
                f"{_mark(soak['p99_ratio'] <= P99_RATIO_TARGET and soak['dropped'] == 0)}",
                f"- deadline misses {_g(soak['deadline_miss_fraction'])} against the echo's "
                f"{_g(soak['echo_deadline_miss_fraction'])} (target: at most 0.001 more): "
                f"{_mark(soak['deadline_miss_fraction'] <= soak['echo_deadline_miss_fraction'] + 1e-3)}",
                f"- echo node dropped {soak['echo_dropped']}; commands in the node's log "
                f"{soak['logged_commands']}, recorder drops {soak.get('log_dropped')}",
            ]
        lines += [""]
    lines += [
        "## Stability at the extremes (property tests)",
        "",
        "`tests/test_stability_*.py` (hypothesis) run in the test suite and cover:",
        "",
    ]
    lines += _table(["extreme", "range", "checked"], [list(row) for row in STABILITY_COVERAGE])
    if CONVERGENCE_REPORT.is_file():
        lines += ["", "## Convergence against an independent reference", ""]
        lines += [CONVERGENCE_REPORT.read_text(encoding="utf-8").strip()]
    return "\n".join(lines) + "\n"
