"""plot: figures from CSV and MCAP, JKR reference landmarks, bad input."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from viscoadh_ros.cli.main import main
from viscoadh_ros.plotting import Curve, JkrReference, plot_loops

REF = JkrReference(radius=0.01, relaxed_modulus=4e5, work_indentation=0.025, work_detachment=0.1)


def test_reference_branch_has_jkr_landmarks() -> None:
    # JKR: the force minimum of the branch (displacement control passes it) is the pull-off
    # force under force control, -(3/2) pi R w, at a = a_c; the scales are its units.
    radius = np.linspace(1e-7, 2e-3, 200001)
    depth, force = REF.branch(REF.work_detachment, radius)
    f_c, a_c, d_c = REF.scales
    np.testing.assert_allclose(force.min(), -f_c, rtol=1e-6, err_msg="force-controlled pull-off")
    np.testing.assert_allclose(radius[force.argmin()], a_c, rtol=1e-3, err_msg="pull-off radius a_c")
    np.testing.assert_allclose(f_c, 1.5 * math.pi * 0.01 * 0.1, rtol=1e-12, err_msg="F_c")
    # d_c against its definition in physics.md (Figure 4 normalisation).
    np.testing.assert_allclose(
        d_c, (3 * math.pi**2 * 0.1**2 * 0.01 / (64 * 4e5**2)) ** (1 / 3), rtol=1e-12, err_msg="d_c"
    )


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_plot_from_csv(tmp_path: Path, suffix: str) -> None:
    a = np.linspace(0.0, 4e-4, 50)
    depth, force = REF.branch(REF.work_indentation, a)
    csv = tmp_path / "result.csv"
    np.savetxt(
        csv,
        np.column_stack([np.arange(50) * 0.01, depth, force, a]),
        delimiter=",",
        header="time,depth,force,contact_radius",
        comments="",
    )
    fig = tmp_path / f"fig{suffix}"
    assert main(["plot", str(csv), "-o", str(fig)]) == 0
    assert fig.stat().st_size > 1000


def test_plot_loops_normalised_needs_reference(tmp_path: Path) -> None:
    curve = Curve(np.zeros(3), np.zeros(3), np.zeros(3), "c")
    with pytest.raises(ValueError, match="normalised units need"):
        plot_loops([curve], tmp_path / "f.png", normalised=True)
    assert not (tmp_path / "f.png").exists()


@pytest.mark.parametrize(
    "content, args, expected",
    [
        ("a,b\n1,2\n3,4\n", [], "lacks the columns"),
        ("depth,force,contact_radius\n1,2,3\n", [], "fewer than two rows"),
        ("depth,force,contact_radius\n1,2,3\n2,3,4\n", ["-o", "fig.pdf"], "must be a .png or .svg"),
        (
            "depth,force,contact_radius\n1,2,3\n2,nan,4\n3,4,5\n",
            [],
            "in.csv:3: column 'force' must be finite",
        ),
        ("depth,force,contact_radius\n1,2,3\n2,abc,4\n", [], "in.csv:3: column 'force' is not a number"),
        ("depth,force,contact_radius\n1,2,3\n2,3,4\n", ["-o", "missing/fig.png"], "does not exist"),
    ],
    ids=["columns", "rows", "format", "nan-row", "text-row", "missing-folder"],
)
def test_plot_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture, content: str, args: list, expected: str
) -> None:
    csv = tmp_path / "in.csv"
    csv.write_text(content)
    out = args[1] if args else "fig.png"
    code = main(["plot", str(csv), "-o", str(tmp_path / out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and expected in err[0], err
    assert not (tmp_path / "missing").exists(), "no folder is created"


def test_plot_reads_a_csv_with_a_byte_order_mark(tmp_path: Path) -> None:
    csv = tmp_path / "excel.csv"
    csv.write_text("depth,force,contact_radius\n0,0,0\n1e-6,1e-3,1e-4\n", encoding="utf-8-sig")
    assert main(["plot", str(csv), "-o", str(tmp_path / "fig.png")]) == 0
