"""The report of a fit: a figure and a table written beside the fitted scene (matplotlib Agg).

For ``fitted.yaml`` it writes ``fitted.report.png`` and ``fitted.report.md``:

- figure: measured and fitted force against time (samples left out of the fit marked),
  against depth with the quasistatic JKR branches of the fitted material (indentation with
  ``w_eff1``, detachment with ``w_eff2``; sphere with adhesion only, see plotting.JkrReference),
  the residuals against time with the noise band (+-2 sigma), and the table of values;
- table (markdown): each free parameter with its value, 95 % interval, relative standard
  deviation and whether the record identifies it; the held ones; RMSE and r^2 against the
  record's noise level, samples, model runs, wall time, the fit's grid and its status.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from viscoadh_ros.experiment import Experiment
    from viscoadh_ros.fitting import FitResult


def report_paths(output: Path) -> tuple[Path, Path]:
    """(figure, table) paths beside the scene file ``output``."""
    stem = output.with_suffix("")
    return stem.with_name(stem.name + ".report.png"), stem.with_name(stem.name + ".report.md")


def table(result: FitResult, title: str = "") -> str:
    """The fit's values, intervals and errors as a markdown document."""
    from viscoadh_ros.fitting import unit_of

    lines = [f"# Fit report{': ' + title if title else ''}", ""]
    lines += [
        "| parameter | value | 95 % interval | sigma | identified | unit |",
        "|---|---|---|---|---|---|",
    ]
    for name, value in result.values.items():
        if name in result.interval:
            lo, hi = result.interval[name]
            rel = result.uncertainty[name] / value
            ok = "yes" if result.identified[name] else "**no**"
            cells = (name, f"{value:.6g}", f"{lo:.4g} .. {hi:.4g}", f"{100 * rel:.2g} %", ok, unit_of(name))
            lines.append("| " + " | ".join(cells) + " |")
        else:
            lines.append(f"| {name} | {value:.6g} | held | | | {unit_of(name)} |")
    if result.offset is not None and result.offset_interval is not None:
        lo, hi = result.offset_interval
        lines.append(
            f"| load-cell offset | {result.offset:.4g} | {lo:.4g} .. {hi:.4g} | "
            f"{result.offset_uncertainty:.2g} N | yes | N |"
        )
    ratio = result.rmse / result.noise if result.noise > 0 else float("nan")
    grid = result.model_contact.numerics
    lines += [
        "",
        f"- status: {result.status}{' (' + result.reason + ')' if result.reason else ''}",
        f"- RMSE {result.rmse:.4g} N against the record's noise level {result.noise:.4g} N "
        f"(ratio {ratio:.3f}; about 1 when the model explains everything but the noise)",
        f"- r^2 {result.r2:.6f}, max error {result.max_error:.4g} N, {result.samples} samples fitted "
        f"({int(result.used.size - np.count_nonzero(result.used))} left out: jumps, segment, time range, "
        "at rest after a reset)",
        f"- stationarity: the last proposed step is {result.stationarity:.2g} standard deviations",
        f"- {result.model_runs} model runs in {result.wall_time:.3g} s; grid {grid.elements} elements "
        f"over {1e6 * grid.domain_radius:.4g} um",
        "- intervals: linearised (central secant over about 3 standard deviations) with the residual "
        "variance, plus the shift of the optimum under the last grid refinement, in quadrature",
    ]
    if result.offset is not None:
        lines.append(
            "- load-cell offset (what the load cell reads at zero force) fitted beside the parameters "
            "and subtracted from the record: the model plus it is fitted, the residuals and RMSE are "
            "its; its sigma is that of the augmented fit (noise over the samples and the parameters' "
            "covariance through the mean force's slope) plus the grid refinement's shift"
        )
    elif np.isfinite(result.offset_score):
        lines.append(
            f"- offset check: score z = {result.offset_score:.2f} for a constant force offset "
            "(|z| > 4 is a misfit: tare the record or fit with --fit-offset)"
        )
    lines.append("")
    return "\n".join(lines)


def _depth_at(experiment: Experiment, ns: NDArray[np.int64]) -> NDArray[np.float64]:
    return np.interp(
        experiment.time(ns), experiment.time(experiment.input_ns), experiment.input_value
    ).astype(np.float64)


def write_report(
    result: FitResult, experiment: Experiment, output: Path, *, title: str = ""
) -> tuple[Path, Path]:
    """Write the figure and the table beside ``output`` (the fitted scene); returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from viscoadh_ros.experiment import run_model
    from viscoadh_ros.plotting import JkrReference

    figure_path, table_path = report_paths(output)
    text = table(result, title)
    run = run_model(result.model_contact, experiment, parameters=False)  # as the fit ran it
    t = experiment.time(experiment.measured_ns)
    measured, model, used = experiment.measured_force, run.model_force, result.used
    if result.offset is not None:
        model = model + result.offset  # what the load cell would read: the fitted record's scale
    depth = _depth_at(experiment, experiment.measured_ns)
    mn, um = 1e3, 1e6

    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5), constrained_layout=True)
    ax_t, ax_d, ax_r, ax_text = axes[0, 0], axes[0, 1], axes[1, 0], axes[1, 1]
    dot = {"s": 4, "alpha": 0.5, "linewidths": 0}
    ax_t.scatter(t[used], measured[used] * mn, color="0.45", label="measured (fitted)", **dot)
    if not np.all(used):
        ax_t.scatter(t[~used], measured[~used] * mn, color="tab:orange", marker="x", s=12, label="left out")
    label = "fitted model" if result.offset is None else f"fitted model + offset {result.offset * mn:.3g} mN"
    ax_t.plot(t, model * mn, color="tab:blue", lw=1.3, label=label)
    ax_t.set(xlabel="time t / s", ylabel="force F / mN  (> 0 compressive)", title="force vs time")

    ax_d.scatter(depth[used] * um, measured[used] * mn, color="0.45", label="measured", **dot)
    ax_d.plot(depth * um, model * mn, color="tab:blue", lw=1.1, label=label)
    reference = JkrReference.from_contact(result.contact)
    if reference is not None:
        radius = np.linspace(0.0, 1.15 * float(np.max(run.input_columns["contact_radius"])), 300)
        for work, style, name in (
            (reference.work_indentation, "--", "JKR indentation, w_eff1"),
            (reference.work_detachment, "-.", "JKR detachment, w_eff2"),
        ):
            d_jkr, f_jkr = reference.branch(work, radius)
            ax_d.plot(d_jkr * um, f_jkr * mn, style, color="0.2", lw=1.1, label=name)
        ax_d.set_xlim(np.min(depth) * um * 1.1 - 1, np.max(depth) * um * 1.1)
        low, high = np.min(measured) * mn, np.max(measured) * mn
        ax_d.set_ylim(low - 0.15 * (high - low), high + 0.1 * (high - low))
    ax_d.set(xlabel="depth d / um", ylabel="force F / mN", title="force vs depth")

    residual = (model - measured) * mn
    ax_r.axhspan(
        -2 * result.noise * mn,
        2 * result.noise * mn,
        color="tab:green",
        alpha=0.15,
        label=f"+-2 x noise level ({result.noise * mn:.3g} mN)",
    )
    ax_r.scatter(t[used], residual[used], color="tab:blue", **dot, label="model - measured")
    if not np.all(used):
        ax_r.scatter(t[~used], residual[~used], color="tab:orange", marker="x", s=12, label="left out")
        span = np.max(np.abs(residual[used])) * 1.5
        ax_r.set_ylim(-span, span)
    ax_r.set(
        xlabel="time t / s",
        ylabel="residual / mN",
        title=f"residuals: RMSE {result.rmse * mn:.3g} mN, r^2 {result.r2:.5f}",
    )
    for ax in (ax_t, ax_d, ax_r):
        ax.axhline(0.0, color="0.8", lw=0.8)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    ax_text.axis("off")
    rows = [line for line in text.splitlines() if line.startswith("| ") and "---" not in line]
    cells = [[c.strip().replace("**", "") for c in row.strip("|").split("|")] for row in rows]
    shown = ax_text.table(cellText=cells[1:], colLabels=cells[0], loc="upper center", cellLoc="left")
    shown.auto_set_font_size(False)
    shown.set_fontsize(8.5)
    shown.auto_set_column_width(list(range(len(cells[0]))))
    shown.scale(1.0, 1.4)
    notes = [line[2:] for line in text.splitlines() if line.startswith("- ")][:5]
    ax_text.text(
        0.0,
        0.02,
        "\n".join(_wrap(n, 95) for n in notes),
        fontsize=8,
        va="bottom",
        transform=ax_text.transAxes,
        family="monospace",
    )
    fig.suptitle(title or "fit report")
    fig.savefig(figure_path, dpi=110)
    plt.close(fig)
    table_path.write_text(text, encoding="utf-8")
    return figure_path, table_path


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))
