"""Figures of the gripper scenarios (matplotlib Agg: no display, no GPU).

`plot_runs`: part height, total pad force and contact radius against time, one colour per
run, the pick (part leaves the table, ^) and release (every pad out of touch, v) moments
marked. `plot_weights`: outcome of each part mass for each grip against the model's predicted
capacity.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .scenarios import CAPACITY_MARGIN, Run  # noqa: E402


def plot_runs(runs: list[Run], output: Path, *, title: str) -> Path:
    """Three stacked panels against time for ``runs``; writes ``output`` (PNG)."""
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 7.0), sharex=True)
    for index, run in enumerate(runs):
        tr = run.trajectory
        colour = f"C{index}"
        panels = (
            (tr.part_rise * 1e3, "part height (mm)"),
            (tr.force.sum(axis=1) * 1e3, "pad force (mN)\n>0 presses, <0 pulls"),
            (tr.contact_radius.max(axis=1) * 1e3, "contact radius (mm)"),
        )
        for ax, (values, label) in zip(axes, panels, strict=True):
            ax.plot(tr.time, values, color=colour, lw=1.2, label=f"{run.label}: {tr.outcome}")
            ax.set_ylabel(label)
            for step, marker in ((tr.pick_step, "^"), (tr.release_step, "v")):
                if step is not None:
                    ax.plot(tr.time[step], values[step], marker, color=colour, ms=8, mec="k")
    force_axis = axes[1]
    low = min(float(r.trajectory.force.sum(axis=1).min()) for r in runs) * 1e3
    if low < 0.0:  # the press peaks far above: keep the pull readable
        force_axis.set_ylim(low * 1.3, -low * 4.0)
    force_axis.axhline(0.0, color="k", lw=0.5)
    axes[0].legend(loc="upper left", fontsize=7, frameon=False)
    axes[0].set_title(
        f"{title}\n^ part lifted off the table   v released (every pad out of touch)", fontsize=9
    )
    axes[-1].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(output, dpi=90)
    plt.close(fig)
    return output


def plot_weights(runs: list[Run], output: Path) -> Path:
    """Outcome (held / not) of each part mass, one row per grip, with the predicted capacity
    (the heaviest part the predicted pull-off lifts at the lift's acceleration)."""
    grips: dict[str, list[Run]] = {}
    for run in runs:
        grips.setdefault(run.label.split("|")[0], []).append(run)
    fig, ax = plt.subplots(figsize=(7.5, 2.8))
    for row, grip_runs in enumerate(grips.values()):
        for run in grip_runs:
            tr = run.trajectory
            ax.plot(
                tr.part_mass * 1e3,
                row,
                "o" if tr.success else "x",
                color="tab:green" if tr.success else "tab:red",
                ms=10,
                mew=2,
            )
        # Each run predicts from its own live pads; the grips' runs agree within a few %.
        limits = [
            r.trajectory.predictions["pick_capacity_kg"] * 1e3
            for r in grip_runs
            if "pick_capacity_kg" in r.trajectory.predictions
        ]
        limit = float(np.mean(limits))
        ax.fill_betweenx([row - 0.3, row + 0.3], limit, CAPACITY_MARGIN * limit, color="0.85", zorder=0)
        ax.plot([limit, limit], [row - 0.35, row + 0.35], "k--", lw=1.5)
        ax.annotate(f"predicted {limit:.2f} g", (limit, row + 0.38), fontsize=8, ha="center")
    ax.set_yticks(range(len(grips)), list(grips))
    ax.set_ylim(-0.6, len(grips) - 0.2)
    ax.set_xlabel("part mass (g)")
    ax.set_title(
        "pick: o held, x failed; -- heaviest part the live pads' predicted pull-off lifts\n"
        f"(grey: up to {CAPACITY_MARGIN:g}x, where a hanging part's contact creeps stronger)",
        fontsize=9,
    )
    ax.grid(alpha=0.3, axis="x")
    fig.tight_layout()
    fig.savefig(output, dpi=90)
    plt.close(fig)
    return output
